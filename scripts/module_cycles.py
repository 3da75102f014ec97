#!/usr/bin/env python3
"""List module dependency cycles between sibling modules, per crate.

Usage: python3 scripts/module_cycles.py [--tests] [CRATE_DIR ...]   (default: crates/*)

For every module of a crate (files and folders reached by `mod NAME;` from src/lib.rs and
src/main.rs), the references of each file (`use` items with their `{...}` groups expanded, and
inline `crate::`/`super::`/`self::` paths) are resolved to the module that defines the name,
following `pub use` re-exports. A reference from module A to module B adds the edge
"child of P containing A" -> "child of P containing B", where P is their deepest common
ancestor; a cycle is a strongly connected component of those sibling edges with two or more
members (e.g. `eigen/dense <-> eigen/lanczos`). Test modules (`#[cfg(test)] mod ...`) are left
out unless `--tests` is given. Each edge of a cycle is printed with one file:line that causes it.
The last line is the number of cycles. A text scan (comments and strings stripped), not a
compiler: macros and glob imports of items are not resolved.
"""
import pathlib
import re
import sys

MOD_DECL = re.compile(r'^\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+([A-Za-z0-9_]+)\s*;')
PATH_ATTR = re.compile(r'#\[path\s*=\s*"([^"]+)"\]')
INLINE = re.compile(r'\b((?:crate|super|self)(?:\s*::\s*[A-Za-z_][A-Za-z0-9_]*)+)')


def strip_code(text):
    """Remove comments, string and char literals, keeping line structure."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith('//', i):
            j = text.find('\n', i)
            i = n if j < 0 else j
        elif text.startswith('/*', i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith('/*', j):
                    depth, j = depth + 1, j + 2
                elif text.startswith('*/', j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append('\n' * text.count('\n', i, j))
            i = j
        elif c == 'r' and re.match(r'r#*"', text[i:i + 10]) and (i == 0 or not text[i - 1].isalnum()):
            m = re.match(r'r(#*)"', text[i:])
            end = text.find('"' + m.group(1), i + len(m.group(0)))
            end = n if end < 0 else end + 1 + len(m.group(1))
            out.append('""' + '\n' * text.count('\n', i, end))
            i = end
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == '\\' else 1
            out.append('""' + '\n' * text.count('\n', i, j))
            i = j + 1
        elif c == "'" and re.match(r"'(\\.[^']*|[^\\'])'", text[i:i + 12]):
            m = re.match(r"'(\\.[^']*|[^\\'])'", text[i:])
            out.append("''")
            i += len(m.group(0))
        else:
            out.append(c)
            i += 1
    return ''.join(out)


def drop_test_blocks(code):
    """Blank out inline `#[cfg(test)] mod x { ... }` blocks (keeping newlines)."""
    while True:
        m = re.search(r'#\[cfg\(test\)\]\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+\w+\s*\{', code)
        if not m:
            return code
        depth, j = 0, m.end() - 1
        while j < len(code):
            if code[j] == '{':
                depth += 1
            elif code[j] == '}':
                depth -= 1
                if depth == 0:
                    break
            j += 1
        code = code[:m.start()] + '\n' * code.count('\n', m.start(), j + 1) + code[j + 1:]


def expand_use(tree):
    """`a::{b, c::{d as e}}` -> [(['a','b'], 'b'), (['a','c','d'], 'e')]."""
    tree = re.sub(r'\s+', ' ', tree).strip()

    def parse(s, prefix):
        res, depth, start = [], 0, 0
        parts = []
        for k, ch in enumerate(s):
            if ch == '{':
                depth += 1
            elif ch == '}':
                depth -= 1
            elif ch == ',' and depth == 0:
                parts.append(s[start:k])
                start = k + 1
        parts.append(s[start:])
        for p in parts:
            p = p.strip()
            if not p:
                continue
            b = p.find('{')
            if b >= 0:
                head = [x.strip() for x in p[:b].split('::') if x.strip()]
                inner = p[b + 1:p.rfind('}')]
                res += parse(inner, prefix + head)
            else:
                alias = None
                m = re.match(r'(.*)\s+as\s+(\w+)$', p)
                if m:
                    p, alias = m.group(1), m.group(2)
                segs = [x.strip() for x in p.split('::') if x.strip()]
                if segs == ['self']:
                    segs = []
                full = prefix + segs
                if full:
                    res.append((full, alias or full[-1]))
        return res

    return parse(tree, [])


class Crate:
    def __init__(self, root):
        self.root = pathlib.Path(root)
        self.files = {}  # module tuple -> (path, code)
        self.with_tests = '--tests' in sys.argv

    def load(self):
        src = self.root / 'src'
        for top in ('lib.rs', 'main.rs'):
            if (src / top).exists():
                base = ('<lib>',) if top == 'lib.rs' else ('<bin>',)
                self.walk(src / top, base, src)

    def walk(self, path, modpath, dirpath):
        if modpath in self.files or not path.exists():
            return
        code = strip_code(path.read_text(errors='replace'))
        lines = code.split('\n')
        if not self.with_tests:
            code = drop_test_blocks(code)
        self.files[modpath] = (path, code)
        for k, line in enumerate(lines):
            m = MOD_DECL.match(line)
            if not m:
                continue
            attrs = ' '.join(lines[max(0, k - 3):k])
            if not self.with_tests and re.search(r'#\[cfg\(test\)\]\s*$', attrs):
                continue
            name = m.group(1)
            pm = PATH_ATTR.search(lines[k - 1] if k else '')
            if pm:
                child = (path.parent / pm.group(1)).resolve()
                self.walk(child, modpath + (name,), child.parent)
                continue
            for cand, d in ((dirpath / f'{name}.rs', dirpath / name), (dirpath / name / 'mod.rs', dirpath / name)):
                if cand.exists():
                    self.walk(cand, modpath + (name,), d)
                    break

    def child_dir(self, modpath):
        path, _ = self.files[modpath]
        if path.name in ('mod.rs', 'lib.rs', 'main.rs'):
            return path.parent
        return path.parent / path.stem

    def uses(self, modpath):
        """[(line, full_segments, alias, is_pub)] of the file's use items."""
        _, code = self.files[modpath]
        res = []
        for m in re.finditer(r'(^|[;{}\n])\s*(pub(?:\([^)]*\))?\s+)?use\s+([^;]+);', code):
            line = code.count('\n', 0, m.start(3)) + 1
            for full, alias in expand_use(m.group(3)):
                res.append((line, full, alias, bool(m.group(2))))
        return res

    def absolute(self, modpath, segs):
        root = modpath[:1]
        if not segs:
            return None
        if segs[0] == 'crate':
            return list(root) + segs[1:]
        if segs[0] in ('super', 'self'):
            cur = list(modpath)
            k = 0
            while k < len(segs) and segs[k] in ('super', 'self'):
                if segs[k] == 'super':
                    cur = cur[:-1]
                k += 1
            return cur + segs[k:]
        # 2018 uniform paths: a child module of the current one
        if tuple(modpath) + (segs[0],) in self.files:
            return list(modpath) + segs
        return None  # external crate or std

    def resolve(self, segs, depth=0):
        """Deepest module that defines the item named by absolute `segs`."""
        cur = tuple(segs[:1])
        k = 1
        while k < len(segs):
            nxt = cur + (segs[k],)
            if nxt in self.files:
                cur, k = nxt, k + 1
                continue
            # a re-export of this name in module `cur`?
            if depth < 8 and cur in self.files:
                for _, full, alias, is_pub in self.reexports.get(cur, []):
                    if alias == segs[k]:
                        target = self.absolute(cur, full)
                        if target:
                            return self.resolve(target + segs[k + 1:], depth + 1)
            break
        return cur

    def edges(self):
        self.reexports = {m: [u for u in self.uses(m) if u[3]] for m in self.files}
        found = {}
        for mod in self.files:
            path, code = self.files[mod]
            refs = [(line, full) for line, full, _, _ in self.uses(mod)]
            for m in INLINE.finditer(code):
                segs = [s.strip() for s in m.group(1).split('::')]
                refs.append((code.count('\n', 0, m.start()) + 1, segs))
            for line, segs in refs:
                absp = self.absolute(mod, segs)
                if not absp:
                    continue
                target = self.resolve(absp)
                k = 0
                while k < min(len(mod), len(target)) and mod[k] == target[k]:
                    k += 1
                if k >= len(mod) or k >= len(target):
                    continue  # same module, or a reference to an ancestor / descendant
                parent = mod[:k]
                a, b = mod[:k + 1], target[:k + 1]
                found.setdefault((parent, a, b), f'{path}:{line}')
        return found


def sccs(nodes, adj):
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in adj.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            out.append(comp)

    for v in nodes:
        if v not in index:
            visit(v)
    return out


def name(mod):
    return '/'.join(mod[1:]) or mod[0]


def main():
    args = [a for a in sys.argv[1:] if not a.startswith('--')]
    roots = args or sorted(str(p) for p in pathlib.Path('crates').iterdir() if (p / 'src').is_dir())
    total = 0
    for r in roots:
        c = Crate(r)
        c.load()
        edges = c.edges()
        by_parent = {}
        for (parent, a, b), where in edges.items():
            by_parent.setdefault(parent, {}).setdefault(a, {})[b] = where
        for parent in sorted(by_parent):
            adj = by_parent[parent]
            nodes = sorted(set(adj) | {b for x in adj.values() for b in x})
            for comp in sccs(nodes, adj):
                if len(comp) < 2:
                    continue
                total += 1
                comp = sorted(comp)
                kind = parent[0]
                print(f'{pathlib.Path(r).name} ({kind}) cycle: ' + ' <-> '.join(name(m) for m in comp))
                for a in comp:
                    for b in comp:
                        if b in adj.get(a, {}):
                            print(f'    {name(a)} -> {name(b)}   {adj[a][b]}')
    print(f'module cycles: {total}')


if __name__ == '__main__':
    main()
