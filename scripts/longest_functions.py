#!/usr/bin/env python3
"""List the longest Rust functions (lines from `fn` to its closing brace) under the given folders.

Usage: python3 scripts/longest_functions.py [--top=N] [--min=L] [DIR ...]
(default: --top=10 --min=100 crates)
Prints `lines  name  file:line` longest first, then how many functions have L lines or more.
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
n, least = 10, 100
while roots and roots[0].startswith('--'):
    opt = roots.pop(0)
    if opt.startswith('--top='):
        n = int(opt[6:])
    elif opt.startswith('--min='):
        least = int(opt[6:])
    else:
        sys.exit(f"unknown option {opt}; usage: longest_functions.py [--top=N] [--min=L] [DIR ...]")
roots = roots or ['crates']
for r in roots:
    for p in pathlib.Path(r).rglob('*.rs'):
        if 'target' in p.parts: continue
        res += fns(p)
res.sort(reverse=True)
for l, loc, name in res[:n]: print(f"{l:5d}  {name:32s} {loc}")
print(f"functions >= {least} lines: {sum(1 for r in res if r[0] >= least)}")
