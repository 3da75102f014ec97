#!/usr/bin/env python3
"""NAFEMS FV32 (cantilevered tapered membrane) meshes for the P1/P2 accuracy benchmark.

Geometry: the trapezoid (0,0), (10,2), (10,3), (0,5) m (10 m long, 5 m wide at the root x = 0,
1 m at the tip), extruded 0.05 m in z with one layer of tetrahedra (gmsh geo kernel,
Frontal-Delaunay 2D, one thread, Mesh.RandomSeed 1). Second order: straight-sided 10-node
tetrahedra (Mesh.SecondOrderLinear = 1). MSH 4.1 binary.

Usage: python3 scripts/gen_fv32_meshes.py OUT_DIR [ORDER:SIZE ...]
Default set: 1:0.5 1:0.25 1:0.125 2:2 2:1 2:0.5 -> OUT_DIR/fv32_p{ORDER}_h{SIZE}.msh.
data/meshes/fv32_p2_h1.msh (the P2 test mesh) is `... data/meshes 2:1`.
"""
import sys
from pathlib import Path

import gmsh


def mesh(out: Path, order: int, size: float) -> None:
    gmsh.initialize(["gmsh"], readConfigFiles=False)
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.NumThreads", 1)
    gmsh.option.setNumber("Mesh.RandomSeed", 1)
    gmsh.option.setNumber("Mesh.Algorithm", 6)
    gmsh.option.setNumber("Mesh.SecondOrderLinear", 1)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 1)
    gmsh.model.add("fv32")
    g = gmsh.model.geo
    pts = [g.addPoint(x, y, 0, size) for x, y in [(0, 0), (10, 2), (10, 3), (0, 5)]]
    lines = [g.addLine(pts[i], pts[(i + 1) % 4]) for i in range(4)]
    s = g.addPlaneSurface([g.addCurveLoop(lines)])
    ext = g.extrude([(2, s)], 0, 0, 0.05, numElements=[1])
    g.synchronize()
    vol = [t for d, t in ext if d == 3]
    gmsh.model.addPhysicalGroup(3, vol, name="volume")
    gmsh.model.mesh.generate(3)
    if order == 2:
        gmsh.model.mesh.setOrder(2)
    gmsh.write(str(out))
    gmsh.finalize()


def main():
    out_dir = Path(sys.argv[1] if len(sys.argv) > 1 else "out/fv32")
    out_dir.mkdir(parents=True, exist_ok=True)
    specs = sys.argv[2:] or ["1:0.5", "1:0.25", "1:0.125", "2:2", "2:1", "2:0.5"]
    for spec in specs:
        order, size = spec.split(":")
        name = f"fv32_p{order}_h{size.replace('.', 'p')}.msh"
        mesh(out_dir / name, int(order), float(size))
        print(out_dir / name)


if __name__ == "__main__":
    main()
