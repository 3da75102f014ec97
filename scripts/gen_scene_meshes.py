#!/usr/bin/env python3
"""Regenerate the scene meshes in data/scenes/ from the gmsh scripts in scenes/meshes/.

Usage (from the repository root):
    python3 scripts/gen_scene_meshes.py              # write data/scenes/*.msh + counts.json
    python3 scripts/gen_scene_meshes.py table roof   # only these
    python3 scripts/gen_scene_meshes.py --check      # regenerate into a temp dir, compare bytes

Each mesh is written as MSH 4.1 binary (only physical-group elements: the "volume" tets and
the named boundary triangles). Deterministic: single-threaded gmsh 4.15.x, fixed random seed
and 2D/3D algorithms, node coordinates snapped to 12 significant digits. The surface vertex
and triangle counts are computed from the tetrahedra (faces used by exactly one tet) and
checked against the paper's Table 1 (within +-20%).
"""

import filecmp
import importlib
import json
import os
import sys
import tempfile

import gmsh
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scenes", "meshes"))

import _common  # noqa: E402

OBJECTS = ["table", "roof", "scaffold", "ground", "cliff", "floor", "fridge"]


def snap_nodes(digits=12):
    tags, coords, _ = gmsh.model.mesh.getNodes()
    for i, tag in enumerate(tags):
        x = [float("%.*g" % (digits, coords[3 * i + k])) for k in range(3)]
        gmsh.model.mesh.setNode(int(tag), x, [])


def surface_counts():
    """(surface vertices, surface triangles, volume nodes, tets) counted from the tets."""
    etypes, _, enodes = gmsh.model.mesh.getElements(3)
    tets = None
    for et, en in zip(etypes, enodes):
        if et == 4:
            tets = np.asarray(en, dtype=np.int64).reshape(-1, 4)
    faces = np.concatenate([tets[:, [0, 1, 2]], tets[:, [0, 1, 3]], tets[:, [0, 2, 3]], tets[:, [1, 2, 3]]])
    faces.sort(axis=1)
    uniq, counts = np.unique(faces, axis=0, return_counts=True)
    boundary = uniq[counts == 1]
    return (
        int(np.unique(boundary).size),
        int(boundary.shape[0]),
        int(np.unique(tets).size),
        int(tets.shape[0]),
    )


def generate_one(name, out_dir):
    mod = importlib.import_module(name)
    _common.start()
    try:
        gmsh.model.add(name)
        mod.build()
        gmsh.model.mesh.generate(3)
        snap_nodes()
        sv, st, nodes, ntets = surface_counts()
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.Binary", 1)
        path = os.path.join(out_dir, name + ".msh")
        gmsh.write(path)
        groups = sorted(gmsh.model.getPhysicalName(d, t) for d, t in gmsh.model.getPhysicalGroups())
    finally:
        gmsh.finalize()
    target = mod.TARGET_SURFACE_VERTICES
    ok = abs(sv - target) <= 0.2 * target
    info = {
        "surface_vertices": sv,
        "surface_triangles": st,
        "volume_nodes": nodes,
        "tets": ntets,
        "paper_surface_vertices": target,
        "fixed": list(mod.FIXED),
        "groups": groups,
        "bytes": os.path.getsize(path),
    }
    print(
        f"{name:9s} surface vertices {sv:6d} (paper {target:5d}, {100.0 * (sv - target) / target:+5.1f}%"
        f"{'' if ok else ' OUT OF +-20%'})  triangles {st:6d}  nodes {nodes:6d}  tets {ntets:7d}"
        f"  {info['bytes'] / 1e6:.2f} MB",
        flush=True,
    )
    return info, ok


def generate(out_dir, names):
    os.makedirs(out_dir, exist_ok=True)
    counts, all_ok = {}, True
    for name in names:
        info, ok = generate_one(name, out_dir)
        counts[name] = info
        all_ok &= ok
    return counts, all_ok


def main():
    args = sys.argv[1:]
    check = "--check" in args
    names = [a for a in args if not a.startswith("--")] or OBJECTS
    out = os.path.join(ROOT, "data", "scenes")
    if check:
        with tempfile.TemporaryDirectory() as tmp:
            generate(tmp, names)
            bad = [n for n in names if not filecmp.cmp(os.path.join(tmp, n + ".msh"), os.path.join(out, n + ".msh"), shallow=False)]
        if bad:
            print("differs from data/scenes:", ", ".join(bad))
            sys.exit(1)
        print("data/scenes matches the scripts")
        return
    counts, ok = generate(out, names)
    if names == OBJECTS:
        with open(os.path.join(out, "counts.json"), "w") as f:
            f.write(json.dumps(counts, sort_keys=True, indent=1) + "\n")
    total = sum(os.path.getsize(os.path.join(out, n + ".msh")) for n in OBJECTS if os.path.exists(os.path.join(out, n + ".msh")))
    print(f"data/scenes total {total / 1e6:.2f} MB")
    if not ok:
        sys.exit(2)


if __name__ == "__main__":
    main()
