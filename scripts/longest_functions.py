#!/usr/bin/env python3
"""List the longest Rust functions (lines from `fn` to its closing brace) under the given folders.

Usage: python3 scripts/longest_functions.py [--top=N] [DIR ...]   (default: --top=10 crates)
Prints `lines  name  file:line` longest first, then how many functions have 100 lines or more.
A text scan (braces outside strings and line comments), good enough to find what to split.
"""
import re, sys, pathlib
FN = re.compile(r'^\s*(pub(\([^)]*\))?\s+)?(const\s+)?(async\s+)?(unsafe\s+)?(extern\s+"[^"]*"\s+)?fn\s+([A-Za-z0-9_]+)')
def strip(line):
    # drop string literals and line comments (rough)
    line = re.sub(r'"(\\.|[^"\\])*"', '""', line)
    line = re.sub(r"'(\\.|[^'\\])'", "''", line)
    i = line.find('//')
    return line if i < 0 else line[:i]
def fns(path):
    lines = path.read_text(errors='replace').splitlines()
    out = []
    i = 0
    while i < len(lines):
        m = FN.match(lines[i])
        if m:
            name = m.group(7); depth = 0; started = False; j = i
            while j < len(lines):
                s = strip(lines[j])
                if not started and ';' in s and '{' not in s:
                    break
                for ch in s:
                    if ch == '{': depth += 1; started = True
                    elif ch == '}': depth -= 1
                if started and depth <= 0:
                    out.append((j - i + 1, f"{path}:{i+1}", name)); break
                j += 1
        i += 1
    return out
res = []
roots = sys.argv[1:] or ['crates']
n = 10
if roots and roots[0].startswith('--top='):
    n = int(roots[0][6:]); roots = roots[1:] or ['crates']
for r in roots:
    for p in pathlib.Path(r).rglob('*.rs'):
        if 'target' in p.parts: continue
        res += fns(p)
res.sort(reverse=True)
for l, loc, name in res[:n]: print(f"{l:5d}  {name:32s} {loc}")
print(f"functions >= 100 lines: {sum(1 for r in res if r[0] >= 100)}")
