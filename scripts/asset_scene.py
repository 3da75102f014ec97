#!/usr/bin/env python3
"""A packaged asset in a scene: the Stanford bunny (npm bunny@1.0.1) as the elastic object of a
`dcr-scenes` scene, run with and without the distant response — what an evaluator does with an
asset nobody here made (docs/scenes.md, "A packaged asset in a scene").

Steps, all into out/asset-scene/ (ignored by git):
  1. the bunny from its npm package, scaled to 0.3 m (largest side), faces as shipped
     (scripts/real_assets.py's loader);
  2. `modal-bake mesh bunny.obj -o bunny.msh --order 1 --size 0.04` (4-node tetrahedra of
     about 4 cm: the coupled reference takes linear meshes whose every mode fits its dense
     solve, 6000 free dofs by default);
  3. resting spots: vertical rays on the mesh's boundary, keeping the highest spots where the
     surface under a 1.2 x 1.2 cm pebble rises or falls by at most 2 mm (the ball's, 6 mm,
     7 cm from the pebbles'); a pebble's bottom is placed 0.1 mm above the highest point under it;
  4. the scene bunny.json: the bunny in ABS (E 2.3 GPa, nu 0.35, rho 1050 kg/m^3) standing on
     its feet (`fixed_below` y <= 1 cm above its lowest node, since an OBJ has no physical
     groups), 10 g pebbles on the two highest spots, a 5 kg steel ball thrown down at
     6 m/s from 0.3 m above the third, a fixed ground;
  5. `dcr-scenes run bunny.json --dcr both`.
Prints a markdown table of the outcomes and the run's warnings.

The coupled reference runs on the scene too: `dcr-lab scene-truth out/asset-scene/bunny.json`.

Usage: python3 scripts/asset_scene.py [--target DIR]
Needs node/npm (the package), meshio and numpy, gmsh (modal-bake mesh's default mesher), and
the release binaries (cargo build --release --workspace --bins).
"""
import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import real_assets  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "out/asset-scene"

ABS = {"youngs": 2.3e9, "poisson": 0.35, "density": 1050.0}
PEBBLE_HALF = [0.006, 0.003, 0.006]
# Clearance (m) between a pebble's bottom and the highest surface point under it.
GAP = 1e-4


def boundary(msh):
    """(nodes, boundary triangles) of a tetrahedral mesh."""
    import meshio

    m = meshio.read(msh)
    tets = m.cells_dict["tetra"]
    faces = np.concatenate([tets[:, [0, 1, 2]], tets[:, [0, 1, 3]], tets[:, [0, 2, 3]],
                            tets[:, [1, 2, 3]]])
    key = np.sort(faces, axis=1)
    _, inv, count = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    return m.points, faces[count[inv.ravel()] == 1]


def top(nodes, tris, x, z):
    """Height (m) of the highest boundary point above (x, z), or None."""
    a, b, c = nodes[tris[:, 0]], nodes[tris[:, 1]], nodes[tris[:, 2]]
    e1, e2 = b - a, c - a
    det = e1[:, 0] * e2[:, 2] - e1[:, 2] * e2[:, 0]
    px, pz = x - a[:, 0], z - a[:, 2]
    with np.errstate(all="ignore"):
        u = (px * e2[:, 2] - pz * e2[:, 0]) / det
        v = (e1[:, 0] * pz - e1[:, 2] * px) / det
    ok = (u >= 0) & (v >= 0) & (u + v <= 1) & (det != 0)
    if not ok.any():
        return None
    return float((a[ok, 1] + u[ok] * e1[ok, 1] + v[ok] * e2[ok, 1]).max())


def footprint(nodes, tris, x, z, half, exact=True):
    """(lowest, highest) boundary point (m) under a (2 half[0]) x (2 half[2]) footprint
    centred at (x, z), or None where a sample misses the mesh. The surface is flat on each
    triangle, so its highest point under the footprint is at a mesh vertex inside it or on the
    footprint's rim: both are taken (the rim every 0.5 mm, the inside on a 5 x 5 grid).
    `exact=False`: the 5 x 5 grid alone (a quick first pass)."""
    xs = np.linspace(-half[0], half[0], 5)
    zs = np.linspace(-half[2], half[2], 5)
    pts = [(x + dx, z + dz) for dx in xs for dz in zs]
    if not exact:
        ys = [top(nodes, tris, px, pz) for px, pz in pts]
        return None if any(y is None for y in ys) else (min(ys), max(ys))
    n = max(2, int(2 * max(half[0], half[2]) / 5e-4) + 1)
    for t in np.linspace(-1.0, 1.0, n):
        pts += [(x + t * half[0], z - half[2]), (x + t * half[0], z + half[2]),
                (x - half[0], z + t * half[2]), (x + half[0], z + t * half[2])]
    used = np.unique(tris.ravel())
    inside = used[(np.abs(nodes[used, 0] - x) <= half[0]) & (np.abs(nodes[used, 2] - z) <= half[2])]
    pts += [(nodes[v, 0], nodes[v, 2]) for v in inside]
    ys = [top(nodes, tris, px, pz) for px, pz in pts]
    return None if any(y is None for y in ys) else (min(ys), max(ys))


def resting_spots(nodes, tris, count=3, step=0.005, max_rise=0.002, spacing=0.03,
                  ball_spacing=0.07):
    """`count` spots (x, z, y): the `count` − 1 highest where the surface under a pebble's
    footprint rises or falls by at most `max_rise` (m), at least `spacing` m apart, for the
    pebbles — y the highest boundary point under the footprint, so a pebble whose bottom is at
    y touches the surface without entering it (and tips by at most `max_rise` as it settles) —
    and for the ball the highest spot at least `ball_spacing` m from them where the surface
    under the footprint rises or falls by at most 3 `max_rise`."""
    lo, hi = nodes.min(0), nodes.max(0)
    spots, targets = [], []
    for x in np.arange(lo[0] + step, hi[0] - step, step):
        for z in np.arange(lo[2] + step, hi[2] - step, step):
            f = footprint(nodes, tris, x, z, PEBBLE_HALF, exact=False)
            if f is not None and f[1] - f[0] <= max_rise:
                spots.append((float(x), float(z), f[1]))
            if f is not None and f[1] - f[0] <= 3 * max_rise:
                targets.append((float(x), float(z), f[1]))
    spots.sort(key=lambda s: -s[2])
    targets.sort(key=lambda s: -s[2])
    chosen = []
    for x, z, y in spots:
        if len(chosen) < count - 1:
            if all(np.hypot(x - c[0], z - c[1]) > spacing for c in chosen):
                f = footprint(nodes, tris, x, z, PEBBLE_HALF)
                if f is not None and f[1] - f[0] <= max_rise:
                    chosen.append((x, z, f[1]))
    for x, z, y in targets:
        if len(chosen) == count - 1 and all(
                np.hypot(x - c[0], z - c[1]) > ball_spacing for c in chosen):
            chosen.append((x, z, y))
    if len(chosen) < count:
        sys.exit(f"asset_scene: found {len(chosen)} resting spots on the mesh, need {count}")
    return chosen


def scene(mesh, nodes, spots):
    lowest = float(nodes[:, 1].min())
    (x0, z0, y0), (x1, z1, y1), (xb, zb, yb) = spots
    lift = PEBBLE_HALF[1] + GAP
    return {
        "name": "bunny",
        "description": "A 0.3 m ABS Stanford bunny (npm bunny@1.0.1) standing on its feet; a 5 kg "
                       "steel ball thrown down on its back makes the pebbles resting on it jump.",
        "h": 0.01,
        "restitution": 0.15,
        "seconds": 0.4,
        "test_seconds": 0.4,
        "elastic": [{
            "name": "bunny",
            "mesh": str(mesh),
            "material": ABS,
            "fixed_below": [{"axis": "y", "value": lowest + 0.01}],
            "modes": 20,
            "body": "static",
        }],
        "props": [
            {"name": "pebble", "colliders": [{"shape": {"cuboid": {"half_extents": PEBBLE_HALF}}}],
             "mass": 0.01, "copies": [[x0, y0 + lift, z0], [x1, y1 + lift, z1]]},
            {"name": "ball", "colliders": [{"shape": {"ball": {"radius": 0.04}}}], "mass": 5.0,
             "pose": {"translation": [xb, yb + 0.3, zb]}, "linvel": [0, -6.0, 0]},
            {"name": "ground", "colliders": [{"shape": {"cuboid": {"half_extents": [1, 0.01, 1]}}}],
             "mass": 1.0, "pose": {"translation": [float(nodes[:, 0].mean()), lowest - 0.01,
                                                   float(nodes[:, 2].mean())]},
             "fixed": True},
        ],
        "outcomes": [
            {"name": "pebbles_max_lift", "kind": "max_lift", "bodies": "pebble*"},
        ],
    }


def run(cmd, log):
    print("$ " + " ".join(str(c) for c in cmd), file=sys.stderr)
    with open(log, "w") as f:
        p = subprocess.run([str(c) for c in cmd], stdout=subprocess.PIPE, stderr=f, text=True)
    return p


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--target", default=os.environ.get("CARGO_TARGET_DIR", ROOT / "target"),
                    help="cargo target folder holding release/{modal-bake,dcr-scenes,dcr-lab}")
    a = ap.parse_args()
    rel = Path(a.target) / "release"
    for tool in ["modal-bake", "dcr-scenes"]:
        if not (rel / tool).is_file():
            sys.exit(f"asset_scene: {rel / tool} is missing; build it with `cargo build --release "
                     f"--workspace --bins` (or pass --target / set CARGO_TARGET_DIR)")
    OUT.mkdir(parents=True, exist_ok=True)
    v, f, size = real_assets.load("bunny")
    obj = OUT / "bunny.obj"
    real_assets.write_obj(obj, v, f, size)
    msh = OUT / "bunny.msh"
    p = run([rel / "modal-bake", "mesh", obj, "-o", msh, "--order", "1", "--size", "0.04",
             "--json"],
            OUT / "mesh.log")
    if p.returncode != 0:
        sys.exit(f"asset_scene: modal-bake mesh failed (see {OUT / 'mesh.log'})")
    rep = json.loads(p.stdout)
    nodes, tris = boundary(msh)
    spots = resting_spots(nodes, tris)
    desc = scene(msh, nodes, spots)
    path = OUT / "bunny.json"
    path.write_text(json.dumps(desc, indent=1))
    print(f"mesh: {len(nodes)} nodes ({rep.get('backend', '?')}); resting spots "
          + ", ".join(f"({x:.3f}, {y:.4f}, {z:.3f}) m" for x, z, y in spots), file=sys.stderr)
    rows = []
    p = run([rel / "dcr-scenes", "run", path, "--dcr", "both", "--out", OUT / "run"],
            OUT / "run.log")
    if p.returncode != 0:
        sys.exit(f"asset_scene: dcr-scenes run failed (see {OUT / 'run.log'})")
    for side in ["on", "off"]:
        s = json.loads((OUT / "run" / side / "summary.json").read_text())
        rows.append((f"dcr-scenes, 20 modes, response {side}",
                     f'{s["outcomes"]["pebbles_max_lift"][0]:.3f}', s.get("warnings", [])))
    print("| run | pebbles' largest lift (mm) | warnings |")
    print("|---|---|---|")
    for name, lift, warn in rows:
        print(f"| {name} | {lift} | {'; '.join(warn) or '–'} |")


if __name__ == "__main__":
    main()
