#!/usr/bin/env python3
"""NAFEMS FV32 P1 vs P2 accuracy table (docs/benchmarks.md): meshes from gen_fv32_meshes.py,
bakes with target/release/modal-bake (--max-freq 400, root clamped with --fixed-below x=0),
in-plane modes picked by their surface motion (< 1% of sum |u|^2 along z), errors against the
published frequencies. Prints a markdown table; median bake wall time over RUNS runs.

Usage: python3 scripts/fv32_bench.py [RUNS]   (build first: cargo build --release -p modal-bake)
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
BIN = ROOT / "target/release/modal-bake"
PUBLISHED = np.array([44.623, 130.03, 162.70, 246.05, 379.90, 391.44])
SPECS = ["1:0.5", "1:0.25", "1:0.125", "2:2", "2:1", "2:0.5"]


def in_plane(path):
    z = np.load(path)
    u = z["modes"]
    if "edge_modes" in z:
        u = np.concatenate([u, z["edge_modes"]])
    frac = (u[:, 2, :] ** 2).sum(0) / (u ** 2).sum((0, 1))
    return z["frequencies_hz"][frac < 0.01]


def main():
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    out = ROOT / "out/fv32"
    subprocess.run([sys.executable, str(ROOT / "scripts/gen_fv32_meshes.py"), str(out), *SPECS],
                   check=True, stdout=subprocess.DEVNULL)
    print(f"load: {os.getloadavg()[0]:.2f} (1-min average before the runs)\n")
    print("| order | size (m) | free dofs | base (KiB) | bake wall (s, median) | worst error | errors (%) of the six in-plane modes |")
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for spec in SPECS:
            order, size = spec.split(":")
            msh = out / f"fv32_p{order}_h{size.replace('.', 'p')}.msh"
            base = Path(tmp) / "fv32.modes"
            walls = []
            for _ in range(runs):
                t = time.perf_counter()
                r = subprocess.run([str(BIN), "bake", str(msh), "-o", str(base), "--youngs", "2e11",
                                    "--poisson", "0.3", "--density", "8000", "--fixed-below", "x=0",
                                    "--max-freq", "400", "--json"], check=True, capture_output=True)
                walls.append(time.perf_counter() - t)
            rep = json.loads(r.stdout)
            f = in_plane(base)
            n = min(len(f), 6)
            err = (f[:n] - PUBLISHED[:n]) / PUBLISHED[:n] * 100
            print(f"| P{order} | {size} | {rep['free_dofs']} | {base.stat().st_size / 1024:.0f} | "
                  f"{sorted(walls)[len(walls) // 2]:.2f} | {np.abs(err).max():.3f}% | "
                  f"{', '.join(f'{e:+.3f}' for e in err)} |")


if __name__ == "__main__":
    main()
