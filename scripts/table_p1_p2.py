#!/usr/bin/env python3
"""The dinner table (scenes/meshes/table.py, fixed at its feet, 20 modes) in P1 and P2 at
several sizes: free dofs, bake wall time, base size and the worst relative error of the 20
frequencies against a fine P2 reference (H = 0.03 m), for docs/benchmarks.md (the cost of P2 at
equal accuracy). Meshes go to out/table_p1_p2/.

Usage: python3 scripts/table_p1_p2.py   (build first: cargo build --release -p modal-bake)
"""
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scenes/meshes"))
import gmsh  # noqa: E402
import _common  # noqa: E402
import table  # noqa: E402

BIN = ROOT / "target/release/modal-bake"
OUT = ROOT / "out/table_p1_p2"
RUNS = [(1, 0.08), (1, 0.04), (1, 0.02), (2, 0.16), (2, 0.08), (2, 0.04)]
REFERENCE = (2, 0.03)


def mesh(order, h):
    path = OUT / f"table_p{order}_h{h}.msh"
    if path.exists():
        return path
    _common.start()
    gmsh.option.setNumber("Mesh.SecondOrderLinear", 1)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 1)
    table.H = h
    gmsh.model.add("table")
    table.build()
    gmsh.model.mesh.generate(3)
    if order == 2:
        gmsh.model.mesh.setOrder(2)
    gmsh.write(str(path))
    gmsh.finalize()
    return path


def bake(path, out):
    t = time.perf_counter()
    r = subprocess.run([str(BIN), "bake", str(path), "-o", str(out), "--fixed", "feet",
                        "--modes", "20", "--json"], check=True, capture_output=True)
    return json.loads(r.stdout), time.perf_counter() - t


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        ref, _ = bake(mesh(*REFERENCE), Path(tmp) / "ref.modes")
        f_ref = np.array(ref["frequencies_hz"])
        print(f"reference P{REFERENCE[0]} H={REFERENCE[1]}: {ref['free_dofs']} free dofs, "
              f"f1 {f_ref[0]:.3f} Hz, f20 {f_ref[-1]:.3f} Hz")
        print(f"load: {os.getloadavg()[0]:.2f}\n")
        print("| order | H (m) | free dofs | bake wall (s) | base (KiB) | worst error of 20 modes | mode 1 error |")
        print("|---|---|---|---|---|---|---|")
        for order, h in RUNS:
            out = Path(tmp) / "t.modes"
            rep, wall = bake(mesh(order, h), out)
            f = np.array(rep["frequencies_hz"])
            err = (f - f_ref) / f_ref * 100
            print(f"| P{order} | {h} | {rep['free_dofs']} | {wall:.2f} | {out.stat().st_size / 1024:.0f} | "
                  f"{np.abs(err).max():.2f}% | {err[0]:+.2f}% |")


if __name__ == "__main__":
    main()
