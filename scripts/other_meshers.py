#!/usr/bin/env python3
"""Volume meshes from tools other than gmsh through `modal-bake bake` (docs/benchmarks.md,
"Volume meshes from other meshers"): inputs nobody here made, written as each tool's users
write them.

- Netgen (PyPI `netgen-mesher`): a 0.2 x 0.1 x 0.05 m box and the box with a 20 mm hole,
  exported as "Gmsh2 Format" (MSH 2.0, six decimals) at order 1 and 2, and as "Gmsh Format"
  (MSH 1); the holed box's curved second-order mesh also with `--straighten`.
- TetGen (PyPI `tetgen`, with pyvista): a 50 mm sphere of 24 x 24 facets at order 1 and 2,
  saved as VTU and converted with meshio to gmsh's format.
- meshio (PyPI `meshio`): the TetGen VTU written as `.msh` without a format (meshio's default
  for that name is ANSYS Fluent) and with `file_format="gmsh"`.

Each file is baked with `modal-bake bake FILE --material steel --modes 5`; the table gives the
exit status, the mesh and the lowest frequency, or the first line of the error, with the
references: the box and the holed box meshed by gmsh at order 2 (`Mesh.SecondOrderLinear = 1`)
at 10 mm and 6 mm, and the free steel sphere's lowest mode (torsional, n = 2: omega R / c_s = 2.5011). Work files go
to out/other-meshers/ (ignored by git).

Usage: python3 scripts/other_meshers.py [--bin PATH-TO-modal-bake]
Needs: pip install netgen-mesher tetgen pyvista meshio gmsh
"""

import argparse
import json
import math
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WORK = os.path.join(ROOT, "out", "other-meshers")


def netgen_files():
    from netgen.csg import CSGeometry, Cylinder, OrthoBrick, Pnt

    out = []
    for name, hole in [("netgen_box", False), ("netgen_holed_box", True)]:
        geo = CSGeometry()
        box = OrthoBrick(Pnt(0, 0, 0), Pnt(0.2, 0.1, 0.05))
        geo.Add(box - Cylinder(Pnt(0.1, 0.05, 0), Pnt(0.1, 0.05, 1), 0.02) if hole else box)
        mesh = geo.GenerateMesh(maxh=0.02)
        p1 = os.path.join(WORK, f"{name}_p1.msh")
        mesh.Export(p1, "Gmsh2 Format")
        out.append((f"Netgen {name[7:].replace('_', ' ')}, order 1, Gmsh2 Format", p1))
        if not hole:
            msh1 = os.path.join(WORK, f"{name}_msh1.msh")
            mesh.Export(msh1, "Gmsh Format")
            out.append(("Netgen box, order 1, Gmsh Format (MSH 1)", msh1))
        mesh.SecondOrder()
        p2 = os.path.join(WORK, f"{name}_p2.msh")
        mesh.Export(p2, "Gmsh2 Format")
        out.append((f"Netgen {name[7:].replace('_', ' ')}, order 2, Gmsh2 Format", p2))
        if hole:
            out.append(("Netgen holed box, order 2, Gmsh2 Format, `--straighten`", p2,
                        ["--straighten"]))
    return out


def tetgen_files():
    import meshio
    import pyvista as pv
    import tetgen

    out = []
    surface = pv.Sphere(radius=0.05, theta_resolution=24, phi_resolution=24).triangulate()
    for order in (1, 2):
        t = tetgen.TetGen(surface)
        t.tetrahedralize(order=order, mindihedral=10, minratio=1.5)
        vtu = os.path.join(WORK, f"tetgen_sphere_p{order}.vtu")
        t.grid.save(vtu)
        mesh = meshio.read(vtu)
        msh = os.path.join(WORK, f"tetgen_sphere_p{order}.msh")
        meshio.write(msh, mesh, file_format="gmsh")
        out.append((f"TetGen sphere, order {order}, VTU → meshio gmsh", msh))
        if order == 1:
            default = os.path.join(WORK, "tetgen_sphere_meshio_default.msh")
            meshio.write(default, mesh)
            out.append(("TetGen sphere, VTU → meshio default `.msh`", default))
    return out


def gmsh_references():
    """The box and the holed box meshed by gmsh at order 2, straight-sided, finer."""
    out = []
    for name, size, hole in [("box", 0.01, False), ("holed box", 0.006, True)]:
        stem = name.replace(" ", "_") + "_ref"
        geo = os.path.join(WORK, stem + ".geo")
        with open(geo, "w") as f:
            f.write('SetFactory("OpenCASCADE");\nBox(1) = {0,0,0,0.2,0.1,0.05};\n')
            if hole:
                f.write("Cylinder(2) = {0.1,0.05,0, 0,0,0.05, 0.02};\n"
                        "BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };\n")
            f.write(f"Mesh.MeshSizeMax = {size};\nMesh.ElementOrder = 2;\n"
                    "Mesh.SecondOrderLinear = 1;\n")
        msh = os.path.join(WORK, stem + ".msh")
        subprocess.run(["gmsh", geo, "-3", "-format", "msh41", "-o", msh], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        out.append((f"gmsh {name}, order 2, {size * 1000:g} mm (reference)", msh))
    return out


def bake(binary, path, extra):
    modes = path + (".straightened" if extra else "") + ".modes"
    t = time.time()
    r = subprocess.run([binary, "bake", os.path.basename(path), "-o", os.path.basename(modes),
                        "--material", "steel", "--modes", "5", "--json", *extra],
                       capture_output=True, text=True, cwd=WORK)
    seconds = time.time() - t
    if r.returncode != 0:
        err = [line for line in r.stderr.splitlines() if line.startswith("error")]
        return r.returncode, seconds, None, (err[0] if err else r.stderr.strip())[:240]
    report = json.loads(r.stdout)
    return 0, seconds, report, None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "modal-bake"))
    a = ap.parse_args()
    if not os.access(a.bin, os.X_OK):
        sys.exit(f"other_meshers.py: no modal-bake at {a.bin}: build it "
                 "(cargo build --release -p modal-bake) or pass --bin")
    os.makedirs(WORK, exist_ok=True)
    # Netgen and TetGen print from C++ to the process's stdout: kept out of the table.
    sys.stdout.flush()
    saved = os.dup(1)
    os.dup2(2, 1)
    try:
        files = netgen_files() + tetgen_files() + gmsh_references()
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)
    import meshio
    import netgen
    import tetgen
    version = subprocess.run([a.bin, "--version"], capture_output=True, text=True).stdout.strip()
    load = open("/proc/loadavg").read().split()[:3]
    print(f"Netgen {netgen.__version__}, tetgen {tetgen.__version__}, meshio {meshio.__version__}, "
          f"{version}; {time.strftime('%Y-%m-%dT%H:%MZ', time.gmtime())}, load {' '.join(load)}")
    print()
    print("| file | bake exit | tetrahedra | mass kg | lowest elastic mode Hz | outcome |")
    print("|---|---|---|---|---|---|")
    material = None
    for label, path, *extra in files:
        rc, _seconds, report, error = bake(a.bin, path, extra[0] if extra else [])
        if rc == 0:
            material = report["material"]
            print(f"| {label} | 0 | {report['tets']:,} (order {report['order']}) | "
                  f"{report['mass_kg']:.4f} | {report['frequencies_hz'][0]:.1f} | baked |")
        else:
            error = error.replace("|", "\\|")
            print(f"| {label} | {rc} | – | – | – | {error} |")
    if material is None:
        return
    shear = material["youngs"] / (2 * (1 + material["poisson"]))
    cs = math.sqrt(shear / material["density"])
    print()
    print(f"Free steel sphere, R = 50 mm: lowest mode (torsional, n = 2) "
          f"{2.5011 * cs / (2 * math.pi * 0.05):.1f} Hz (exact sphere; the mesh is faceted).")


if __name__ == "__main__":
    main()
