"""Headless test of the Modal Bake add-on in the real Blender (the `bpy` module: Blender 4.5 LTS
and Blender 5.0, the releases CI runs it on).

    python3 blender/tests/test_addon.py [--binary target/release/modal-bake]

Installs the add-on as an extension (zip, `extensions.package_install_files`) into a temporary
user folder, enables it, points its preference at the modal-bake binary, and:

- bakes Blender's default cube (order 2, fixed below z = -0.9 m): one shape key per mode named
  "Mode N — F Hz", each with the object's vertex count, whose frequencies equal a CLI bake of the
  same exported OBJ run here (`modal-bake bake OBJ`, `modal-bake info --json`);
- checks the keys are the morph targets of `export --onto` (largest displacement 0.05 × the
  diagonal) and that Preview Mode animates one key through a sine period;
- bakes Suzanne (open eyes: needs `modal-bake mesh --mesher`, skipped with the reason if the
  binary has no such option; fTetWild takes minutes on it, so the CLI comparison bakes the
  add-on's tetrahedral mesh rather than meshing the OBJ again);
- bakes Suzanne fixed by a vertex group on its ears (`--fixed-near`, the group's vertices and
  faces): the ears' vertices stay still, the head between them moves, and a box around both
  ears (which spans the head) would fix over twice as many nodes;
- checks that a missing binary is a clear error, not a crash;
- bakes a 16-sided cylinder with *Uniform size*: the CLI's bake with `--uniform-size` has its
  frequencies, the one without (curvature sizing) does not;
- meshes Blender's glTF exports (GLB, and .gltf with its .bin) of a placed, rotated and mirrored
  torus with `modal-bake mesh`: the same closed solid as Blender's OBJ export of it;
- bakes a textured sphere with a shape key and its animation under a scaled, rotated empty from
  Blender's .gltf, and `export --onto`s it: imported back, the object tree, image, key and
  action are there and each mode key's world displacement peaks at scale × diagonal;
- builds the packaged extension (scripts/package_blender_addon.py: modal-bake in bin/, gmsh and
  pytetwild as wheels), installs it over the add-on with no binary preference, and bakes the
  default cube (gmsh from the wheel, run by this Python; the CLI's frequencies) and an open box
  (fTetWild from the wheel) with it; a package whose wheels are for another Python says so.

Prints one line per check and "N passed, N failed, N skipped"; exits 1 on a failure. The work
folder (about 320 MB) is removed after a passing run and kept, with its path printed, after a
failing one or with --keep. Without
bpy it skips, except with DCR_REQUIRE_BPY=1 (CI), where that is a failure.
"""

import argparse
import contextlib
import importlib.util
import io
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import traceback
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
ADDON_SRC = os.path.join(ROOT, "blender", "modal_bake")
NAME_RE = re.compile(r"^Mode (\d+) — ([0-9.]+) Hz$")

results = {"passed": 0, "failed": 0, "skipped": 0}


def check(name, fn):
    try:
        fn()
    except Skip as s:
        results["skipped"] += 1
        print(f"SKIPPED {name}: {s}", flush=True)
    except Exception:
        results["failed"] += 1
        print(f"FAILED {name}", flush=True)
        traceback.print_exc()
    else:
        results["passed"] += 1
        print(f"ok {name}", flush=True)


class Skip(Exception):
    pass


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    default_bin = os.path.join(os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target")),
                               "release", "modal-bake")
    ap.add_argument("--binary", default=default_bin, help="modal-bake executable to test with")
    ap.add_argument("--keep", action="store_true",
                    help="keep the work folder (the private Blender user folder, the bakes, the "
                         "package: about 320 MB) after a passing run; a failing run always keeps it")
    ap.add_argument("--blender", metavar="MAJOR.MINOR",
                    help="fail unless the bpy imported is this Blender release (e.g. 5.0), so a "
                         "PYTHONPATH that did not take effect is not a silent run on another one")
    args = ap.parse_args()
    exe = os.path.abspath(args.binary)
    if not os.path.isfile(exe):
        print(f"FAILED: no modal-bake at {exe} (cargo build --release -p modal-bake)")
        print("0 passed, 1 failed, 0 skipped")
        return 1

    work = tempfile.mkdtemp(prefix="modal_bake_addon_test_")
    try:
        rc = run(args, exe, work)
    except BaseException:
        print(f"work folder kept: {work}", flush=True)
        raise
    if rc == 0 and not args.keep:
        shutil.rmtree(work, ignore_errors=True)
    else:
        print(f"work folder kept: {work}", flush=True)
    return rc


def run(args, exe, work):
    """The tests, in the work folder `work`; returns the exit status."""
    # A private Blender user folder: nothing is installed into the user's own.
    for var, sub in (("BLENDER_USER_CONFIG", "config"), ("BLENDER_USER_SCRIPTS", "scripts"),
                     ("BLENDER_USER_EXTENSIONS", "extensions")):
        os.environ[var] = os.path.join(work, sub)
    try:
        import bpy
    except ImportError as e:
        msg = f"bpy is not installed ({e}): python3 -m pip install bpy==4.5.7"
        if os.environ.get("DCR_REQUIRE_BPY") == "1":
            print(f"FAILED: {msg} (DCR_REQUIRE_BPY=1)")
            print("0 passed, 1 failed, 0 skipped")
            return 1
        print(f"SKIPPED: {msg}")
        print("0 passed, 0 failed, 1 skipped")
        return 0
    print(f"Blender {bpy.app.version_string}, modal-bake {exe}", flush=True)
    have = ".".join(str(v) for v in bpy.app.version[:2])
    if args.blender and have != args.blender:
        print(f"FAILED: bpy is Blender {bpy.app.version_string} ({bpy.__file__}), not "
              f"{args.blender} (--blender): check PYTHONPATH or the installed bpy")
        print("0 passed, 1 failed, 0 skipped")
        return 1

    zpath = os.path.join(work, "modal_bake.zip")
    with zipfile.ZipFile(zpath, "w") as z:
        for name in sorted(os.listdir(ADDON_SRC)):
            if name.endswith((".py", ".toml")):
                z.write(os.path.join(ADDON_SRC, name), name)
    res = bpy.ops.extensions.package_install_files(
        filepath=zpath, repo="user_default", enable_on_install=True)
    assert res == {"FINISHED"}, f"extension install: {res}"
    pkg = "bl_ext.user_default.modal_bake"
    assert pkg in bpy.context.preferences.addons, "the extension is not enabled"
    prefs = bpy.context.preferences.addons[pkg].preferences
    prefs.binary = exe
    print(f"installed and enabled {pkg}", flush=True)

    def cli(*a):
        out = subprocess.run([exe, *a], capture_output=True, text=True)
        assert out.returncode == 0, f"modal-bake {' '.join(a)}:\n{out.stderr}"
        return out.stdout

    def select(obj):
        for o in bpy.context.view_layer.objects:
            o.select_set(False)
        obj.select_set(True)
        bpy.context.view_layer.objects.active = obj

    def mode_keys(obj):
        return [kb for kb in obj.data.shape_keys.key_blocks if NAME_RE.match(kb.name)]

    def cli_freqs(modes_path):
        return json.loads(cli("info", "--json", modes_path))["frequencies_hz"]

    def bake_and_check(obj, nmodes, cli_extra, from_msh=False):
        select(obj)
        res = bpy.ops.modal_bake.bake()
        assert res == {"FINISHED"}, f"bake operator: {res}"
        keys = mode_keys(obj)
        assert len(keys) == nmodes, f"{len(keys)} mode keys, want {nmodes}"
        nv = len(obj.data.vertices)
        for j, kb in enumerate(keys):
            assert int(NAME_RE.match(kb.name).group(1)) == j + 1, kb.name
            assert len(kb.data) == nv, f"{kb.name}: {len(kb.data)} points, object {nv}"
        freqs = list(obj["modal_bake_frequencies_hz"])
        for kb, f in zip(keys, freqs):
            shown = float(NAME_RE.match(kb.name).group(2))
            assert abs(shown - f) <= 0.05 + 1e-9 * f, f"{kb.name} vs {f} Hz"
        modes_path = obj["modal_bake_modes"]
        assert os.path.isfile(modes_path), modes_path
        # The CLI on the same OBJ the add-on wrote, with the same options (from_msh: on the
        # add-on's tetrahedral mesh of it, for a surface whose meshing takes minutes).
        obj_path = os.path.splitext(modes_path)[0] + ".obj"
        ref = os.path.join(work, obj.name + "_ref.modes")
        if from_msh:
            msh = os.path.splitext(modes_path)[0] + ".msh"
            cli("bake", msh, "-o", ref, "--modes", str(nmodes), *cli_extra)
        else:
            cli("bake", obj_path, "-o", ref, "--order", "2", "--modes", str(nmodes),
                *cli_extra)
        want = cli_freqs(ref)
        assert len(want) == nmodes
        for j, (a, b) in enumerate(zip(freqs, want)):
            assert abs(a - b) <= 1e-9 * b, f"mode {j + 1}: add-on {a} Hz, CLI {b} Hz"
        print(f"  {obj.name}: {nv} vertices, modes {', '.join(f'{f:.2f}' for f in freqs)} Hz "
              f"(= CLI bake of {os.path.basename(obj_path)})", flush=True)
        return keys

    def default_cube(folder):
        """The scene's default cube set up for the cube bakes: order 2, 6 modes, fixed below
        z = -0.9 m, output in `work/folder`."""
        cube = bpy.data.objects["Cube"]
        cube.modal_bake.order = "2"
        cube.modal_bake.modes = 6
        cube.modal_bake.fixed = "below"
        cube.modal_bake.fixed_height = -0.9
        cube.modal_bake.output_dir = os.path.join(work, folder)
        return cube

    cube = default_cube("cube")

    def cube_bake():
        bake_and_check(cube, 6, ["--fixed-below=z=-0.9"])

    check("default cube: shape keys per mode with the CLI's frequencies", cube_bake)

    def cube_key_shapes():
        keys = mode_keys(cube)
        basis = cube.data.shape_keys.reference_key
        mw = cube.matrix_world
        pts = [mw @ v.co for v in basis.data]
        diag = (max(p.x for p in pts) - min(p.x for p in pts)) ** 2 + \
               (max(p.y for p in pts) - min(p.y for p in pts)) ** 2 + \
               (max(p.z for p in pts) - min(p.z for p in pts)) ** 2
        diag = diag ** 0.5
        for kb in keys:
            peak = max(((mw @ k.co) - (mw @ b.co)).length for k, b in zip(kb.data, basis.data))
            assert abs(peak - 0.05 * diag) <= 1e-4 * diag, f"{kb.name}: peak {peak}"
            # Fixed below z = -0.9: the bottom face's vertices do not move.
            for k, b in zip(kb.data, basis.data):
                if (mw @ b.co).z < -0.9:
                    assert ((mw @ k.co) - (mw @ b.co)).length < 1e-6 * diag, kb.name
        assert "modal_bake_binary" in cube and exe in cube["modal_bake_binary"]

    check("cube keys: peak 0.05 × diagonal, fixed vertices still", cube_key_shapes)

    def preview():
        select(cube)
        assert bpy.ops.modal_bake.preview_mode(mode=2, frames=24) == {"FINISHED"}
        keys = cube.data.shape_keys
        action = keys.animation_data.action
        assert action is not None
        target = mode_keys(cube)[1]
        values = []
        for f in range(bpy.context.scene.frame_start, bpy.context.scene.frame_start + 25):
            bpy.context.scene.frame_set(f)
            values.append(target.value)
        assert abs(max(values) - 1.0) < 1e-6 and abs(min(values) + 1.0) < 1e-6, values
        assert all(kb.value == 0.0 for kb in mode_keys(cube) if kb != target)

    check("preview: mode 2's key runs one sine period, the others stay 0", preview)

    def suzanne():
        helptext = cli("mesh", "--help")
        if "--mesher" not in helptext:
            raise Skip("this modal-bake has no `mesh --mesher` (Suzanne's open eyes need "
                       "fTetWild)")
        bpy.ops.mesh.primitive_monkey_add(size=0.3, location=(0.0, 0.0, 0.0))
        monkey = bpy.context.active_object
        monkey.modal_bake.order = "2"
        monkey.modal_bake.modes = 4
        monkey.modal_bake.size = 0.04
        monkey.modal_bake.output_dir = os.path.join(work, "suzanne")
        bake_and_check(monkey, 4, [], from_msh=True)

    check("Suzanne: shape keys with the CLI's frequencies", suzanne)

    def suzanne_ears():
        helptext = cli("bake", "--help")
        if "--fixed-near" not in helptext:
            raise Skip("this modal-bake has no `bake --fixed-near`")
        bpy.ops.mesh.primitive_monkey_add(size=0.3, location=(0.0, 0.0, 0.0))
        monkey = bpy.context.active_object
        monkey.name = "SuzanneEars"
        mw = monkey.matrix_world
        xs = [(mw @ v.co).x for v in monkey.data.vertices]
        half = max(abs(x) for x in xs)
        # The ears: the vertices beyond 2/3 of the half-width, on both sides.
        ears = [v.index for v in monkey.data.vertices if abs((mw @ v.co).x) > 2 / 3 * half]
        group = monkey.vertex_groups.new(name="Ears")
        group.add(ears, 1.0, "REPLACE")
        monkey.modal_bake.order = "2"
        monkey.modal_bake.modes = 4
        monkey.modal_bake.size = 0.04
        monkey.modal_bake.fixed = "group"
        monkey.modal_bake.fixed_group = "Ears"
        monkey.modal_bake.output_dir = os.path.join(work, "suzanne_ears")
        region = os.path.join(work, "suzanne_ears", "SuzanneEars_fixed.obj")
        keys = bake_and_check(monkey, 4, ["--fixed-near", region], from_msh=True)
        with open(region) as f:
            lines = f.read().splitlines()
        assert sum(l.startswith("v ") for l in lines) == len(ears), "region file vertices"
        assert any(l.startswith("f ") for l in lines), "region file has the ears' faces"
        basis = monkey.data.shape_keys.reference_key
        rest = [mw @ b.co for b in basis.data]
        head = [v for v, p in enumerate(rest) if abs(p.x) < 0.3 * half]
        moved_head, moved_ears, still = 0.0, 0.0, len(ears)
        for kb in keys:
            d = [((mw @ k.co) - r).length for k, r in zip(kb.data, rest)]
            peak = max(d)
            moved_ears = max(moved_ears, max(d[v] for v in ears) / peak)
            moved_head = max(moved_head, max(d[v] for v in head) / peak)
            still = min(still, sum(d[v] <= 1e-6 * peak for v in ears))
        # A box around both ears (the old way of fixing a group) spans the head between
        # them and fixes its inside too: far more nodes than the ears' own region.
        msh = os.path.splitext(monkey["modal_bake_modes"])[0] + ".msh"
        lo = [min(rest[v][a] for v in ears) for a in range(3)]
        hi = [max(rest[v][a] for v in ears) for a in range(3)]
        box = ",".join(f"{x:.7g}" for x in lo + hi)

        def fixed_nodes(*selector):
            out = os.path.join(work, "ears_count.modes")
            return json.loads(cli("bake", msh, "-o", out, "--modes", "1", "--json",
                                  *selector))["fixed_nodes"]

        n_near, n_box = fixed_nodes("--fixed-near", region), fixed_nodes(f"--fixed-box={box}")
        print(f"  ears: {len(ears)} vertices in the group; {n_near} nodes fixed (a box around "
              f"both ears: {n_box}); {still} ear vertices still in every key, the others "
              f"(where the ears meet the head) move at most {moved_ears:.2e} of each key's "
              f"peak, the head between them up to {moved_head:.2f}", flush=True)
        # An ear vertex takes the motion of the closest point of the base's surface: inside
        # the ears it is fixed; at the ears' rim the closest triangle may have a free node.
        assert still >= len(ears) // 2, f"only {still} of {len(ears)} ear vertices are still"
        assert moved_ears < 0.1, f"ear vertices move {moved_ears:.3f} of the peak"
        assert moved_head > 0.1, f"the head moves only {moved_head} of the peak"
        assert 2 * n_near < n_box, f"{n_near} nodes near the ears, {n_box} in their box"
        for line in cli("info", monkey["modal_bake_modes"]).splitlines():
            if "near" in line:
                print(f"  info: {line.strip()}", flush=True)

    check("Suzanne's ears as a vertex group: exactly those vertices fixed", suzanne_ears)

    def missing_binary():
        prefs.binary = os.path.join(work, "no-such-modal-bake")
        select(cube)
        try:
            res = bpy.ops.modal_bake.bake()
        except RuntimeError as e:  # operator errors surface as RuntimeError in bpy
            assert "modal-bake not found" in str(e), str(e)
        else:
            raise AssertionError(f"bake without a binary returned {res}")
        finally:
            prefs.binary = exe

    check("missing binary: a clear error naming where it looked", missing_binary)

    def uniform_size():
        # A 16-sided cylinder baked with Uniform size: the add-on passes --uniform-size (the
        # CLI's bake of its OBJ with the flag gives the same frequencies; without it, gmsh's
        # curvature sizing meshes the rims finer and they differ).
        bpy.ops.mesh.primitive_cylinder_add(vertices=16, radius=0.1, depth=0.3,
                                            location=(3.0, 0.0, 0.0))
        cyl = bpy.context.active_object
        cyl.name = "Cylinder16"
        cyl.modal_bake.order, cyl.modal_bake.modes = "2", 4
        cyl.modal_bake.uniform_size = True
        cyl.modal_bake.material = "steel"
        cyl.modal_bake.output_dir = os.path.join(work, "cylinder")
        bake_and_check(cyl, 4, ["--uniform-size", "--material", "steel"])
        curved = os.path.join(work, "cylinder_curved.modes")
        obj_path = os.path.splitext(cyl["modal_bake_modes"])[0] + ".obj"
        cli("bake", obj_path, "-o", curved, "--order", "2", "--modes", "4", "--material", "steel")
        a, b = list(cyl["modal_bake_frequencies_hz"]), cli_freqs(curved)
        assert any(abs(x / y - 1) > 1e-6 for x, y in zip(a, b)), (a, b)

    check("Uniform size: the add-on meshes with --uniform-size", uniform_size)

    def gltf_export():
        # Blender's own glTF exporter (GLB, and .gltf with a .bin beside it) and its OBJ
        # exporter, on a torus placed, rotated and mirrored (scale y < 0) in the scene: the
        # glTF reader applies the node's transform and keeps the mirrored surface outward, so
        # all three describe the same solid (the exporters split the quads along different
        # diagonals: volumes within 0.5 %).
        for o in bpy.context.view_layer.objects:
            o.select_set(False)
        bpy.ops.mesh.primitive_torus_add(major_radius=0.2, minor_radius=0.05,
                                         location=(0.1, 0.3, 0.0), rotation=(0.3, 0.2, 0.0))
        bpy.context.active_object.scale = (1.0, -0.8, 1.2)
        paths = {fmt: os.path.join(work, "torus" + ext) for fmt, ext in
                 [("GLB", ".glb"), ("GLTF_SEPARATE", ".gltf"), ("OBJ", ".obj")]}
        for fmt in ("GLB", "GLTF_SEPARATE"):
            bpy.ops.export_scene.gltf(filepath=paths[fmt], export_format=fmt,
                                      use_selection=True)
        bpy.ops.wm.obj_export(filepath=paths["OBJ"], export_materials=False,
                              export_selected_objects=True)
        got = {}
        for fmt, path in paths.items():
            report = json.loads(cli("mesh", path, "-o", path + ".msh", "--json"))["report"]
            got[fmt] = report
            i = report["inspection"]
            assert report["backend"] == "gmsh", (fmt, report["backend"])
            assert (i["vertices"], i["triangles"], i["shells"]) == (576, 1152, 1), (fmt, i)
            assert i["open_edges"] == i["inconsistent_edges"] == 0, (fmt, i)
            # Outward as exported: not turned inside out by the mirror (`flipped`).
            assert report["volume_m3"] > 0 and not report["flipped"], (fmt, report["flipped"])
        assert got["GLB"]["volume_m3"] == got["GLTF_SEPARATE"]["volume_m3"]
        a, b = got["GLB"], got["OBJ"]
        for lo_hi in range(2):
            for k in range(3):
                x, y = a["inspection"]["bbox"][lo_hi][k], b["inspection"]["bbox"][lo_hi][k]
                assert abs(x - y) <= 2e-6, f"bbox {lo_hi} {k}: glb {x}, obj {y}"
        assert abs(a["volume_m3"] / b["volume_m3"] - 1) < 5e-3, (a["volume_m3"], b["volume_m3"])
        print(f"  torus: glb/gltf volume {a['volume_m3']:.6e} m³, obj {b['volume_m3']:.6e} m³, "
              f"bbox {a['inspection']['bbox']}", flush=True)

    check("Blender's glTF export (GLB and .gltf + .bin) meshes as its OBJ export", gltf_export)

    def gltf_onto():
        # A sphere under a rotated, non-uniformly scaled empty, with an image texture, a shape
        # key and an animation of it, exported as .gltf (.bin and .png beside it); baked and
        # `export --onto` it: imported back, Blender finds the same object tree, the material's
        # image, the Smile key and its action, and one key per mode after it whose world
        # displacement peaks at scale × diagonal.
        bpy.ops.wm.read_factory_settings(use_empty=True)
        bpy.ops.object.empty_add(location=(0.2, 0.0, 0.1), rotation=(0.0, 0.0, 0.7))
        rig = bpy.context.active_object
        rig.name, rig.scale = "Rig", (1.0, 1.5, 0.8)
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.1, segments=24, ring_count=12)
        ball = bpy.context.active_object
        ball.name, ball.parent = "Ball", rig
        image = bpy.data.images.new("Checker", 8, 8)
        image.generated_type = "COLOR_GRID"
        image.filepath_raw = os.path.join(work, "checker.png")
        image.file_format = "PNG"
        image.save()
        mat = bpy.data.materials.new("Painted")
        if bpy.app.version < (5, 0, 0):
            mat.use_nodes = True  # always on (and deprecated) from Blender 5.0
        tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
        tex.image = image
        bsdf = mat.node_tree.nodes["Principled BSDF"]
        mat.node_tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
        ball.data.materials.append(mat)
        ball.shape_key_add(name="Basis")
        smile = ball.shape_key_add(name="Smile")
        for v in smile.data:
            v.co.z *= 1.1
        smile.value = 0.0
        smile.keyframe_insert("value", frame=1)
        smile.value = 1.0
        smile.keyframe_insert("value", frame=24)
        asset = os.path.join(work, "ball.gltf")
        bpy.ops.export_scene.gltf(filepath=asset, export_format="GLTF_SEPARATE")
        assert os.path.exists(os.path.join(work, "ball.bin"))
        modes = os.path.join(work, "ball.modes")
        cli("bake", asset, "-o", modes, "--object", "Ball", "--order", "1", "--modes", "6",
            "--material", "steel")
        out = os.path.join(work, "ball_modes.glb")
        cli("export", modes, "--gltf", out, "--onto", asset, "--object", "Ball")
        bpy.ops.wm.read_factory_settings(use_empty=True)
        bpy.ops.import_scene.gltf(filepath=out)
        ball = bpy.data.objects["Ball"]
        assert ball.parent is not None and ball.parent.name == "Rig", ball.parent
        images = [n.image for n in ball.active_material.node_tree.nodes
                  if n.type == "TEX_IMAGE" and n.image is not None]
        assert images and images[0].size[0] == 8, images
        keys = ball.data.shape_keys.key_blocks
        names = [k.name for k in keys]
        assert names[:2] == ["Basis", "Smile"] and len(names) == 8, names
        assert all(re.match(r"^mode \d+ — [0-9.]+ Hz$", n) for n in names[2:]), names
        assert ball.data.shape_keys.animation_data is not None, "the Smile action is lost"
        with open(out, "rb") as f:
            data = f.read()
        n = int.from_bytes(data[12:16], "little")
        dcr = json.loads(data[20:20 + n])["extras"]["dcr"]
        want = dcr["scale"] * dcr["diagonal_m"]
        lin = ball.matrix_world.to_3x3()
        basis = [v.co.copy() for v in keys["Basis"].data]
        for k in keys[2:]:
            peak = max((lin @ (v.co - b)).length for v, b in zip(k.data, basis))
            assert abs(peak / want - 1) < 1e-4, (k.name, peak, want)
        print(f"  ball: {len(names) - 2} mode keys after Smile, peak {want:.4e} m; "
              f"{len(bpy.data.actions)} actions", flush=True)

    check("export --onto Blender's .gltf keeps its object tree, texture, shape key and animation",
          gltf_onto)

    def packaged():
        # scripts/package_blender_addon.py: one zip with modal-bake in bin/ and gmsh and
        # pytetwild as wheels. Installed over the plain add-on with no binary preference, it
        # bakes with nothing but itself: its own modal-bake, and the wheels' gmsh and pytetwild
        # run by Blender's Python.
        out = subprocess.run([sys.executable, os.path.join(ROOT, "scripts",
                                                           "package_blender_addon.py"),
                              "--binary", exe, "--out", os.path.join(work, "package")],
                             capture_output=True, text=True)
        assert out.returncode == 0, f"package_blender_addon.py:\n{out.stdout}{out.stderr}"
        zpath = out.stdout.strip().splitlines()[-1]
        print(f"  {os.path.basename(zpath)}: {os.path.getsize(zpath) / 2**20:.1f} MiB",
              flush=True)
        bpy.ops.wm.read_factory_settings()
        res = bpy.ops.extensions.package_install_files(
            filepath=zpath, repo="user_default", enable_on_install=True)
        assert res == {"FINISHED"}, f"extension install: {res}"
        bpy.context.preferences.addons[pkg].preferences.binary = ""
        site = os.path.join(bpy.utils.user_resource("EXTENSIONS"), ".local", "lib",
                            "python{}.{}".format(*sys.version_info[:2]), "site-packages")

        def bake_logged(obj, *a):
            log = io.StringIO()
            with contextlib.redirect_stdout(log):
                keys = bake_and_check(obj, *a)
            sys.stdout.write(log.getvalue())
            text = log.getvalue()
            assert "(bundled with the add-on)" in obj["modal_bake_binary"], \
                obj["modal_bake_binary"]
            assert f"meshers: gmsh and pytetwild bundled with the add-on ({site})" in text, text
            return keys, text

        _, text = bake_logged(default_cube("packaged_cube"), 6, ["--fixed-below=z=-0.9"])
        assert f"backend: gmsh 4.15.2 ({sys.executable} + gmsh module in {site})" in text, text
        # An open box (the top face removed): auto meshes it with fTetWild, from the wheel.
        bpy.ops.mesh.primitive_cube_add(size=0.2, location=(1.0, 0.0, 0.0))
        box = bpy.context.active_object
        box.name = "OpenBox"
        top = [p.index for p in box.data.polygons if p.normal.z > 0.5]
        import bmesh
        bm = bmesh.new()
        bm.from_mesh(box.data)
        bm.faces.ensure_lookup_table()
        bmesh.ops.delete(bm, geom=[bm.faces[i] for i in top], context="FACES_ONLY")
        bm.to_mesh(box.data)
        bm.free()
        box.modal_bake.modes = 4
        box.modal_bake.output_dir = os.path.join(work, "packaged_box")
        _, text = bake_logged(box, 4, [])
        assert f"backend: fTetWild 0.4.2 ({sys.executable} + pytetwild 0.4.2)" in text, text

    check("packaged extension: its own modal-bake, gmsh and pytetwild, nothing else installed",
          packaged)

    def wheels_for_another_python():
        # A package whose pytetwild wheel this Python cannot use (a Blender on another Python)
        # says so and how to fix it, rather than asking to reinstall; an abi3 wheel from this
        # Python's version down fits, and a fitting wheel Blender did not extract asks for a
        # reinstall. Plain Python: runner.py does not import bpy.
        spec = importlib.util.spec_from_file_location("mb_runner",
                                                      os.path.join(ADDON_SRC, "runner.py"))
        runner = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(runner)
        here = "{}{}".format(*sys.version_info[:2])
        other = "310" if here != "310" else "311"
        for n, (wheel, says) in enumerate([
                (f"pytetwild-0.4.2-cp{other}-cp{other}-manylinux2014_x86_64.whl",
                 f"for cp{other} only"),
                (f"pytetwild-0.4.2-cp{int(here) + 1}-abi3-manylinux2014_x86_64.whl",
                 f"for cp{int(here) + 1}+ only"),
                (f"pytetwild-0.4.2-cp{here}-abi3-manylinux2014_x86_64.whl", "reinstall"),
                (f"pytetwild-0.4.2-cp{here}-cp{here}-manylinux2014_x86_64.whl", "reinstall")]):
            pkg_dir = os.path.join(work, f"wheels_case_{n}")
            site = os.path.join(pkg_dir, "site-packages")
            os.makedirs(os.path.join(pkg_dir, "wheels"))
            os.makedirs(site)
            for w in ("gmsh-4.15.2-py2.py3-none-manylinux_2_24_x86_64.whl", wheel):
                open(os.path.join(pkg_dir, "wheels", w), "w").close()
            open(os.path.join(site, "gmsh.py"), "w").close()
            try:
                runner.bundled_meshers(pkg_dir, site)
            except runner.BakeError as e:
                assert says in str(e), (wheel, str(e))
            else:
                raise AssertionError(f"{wheel}: no error without pytetwild in {site}")

    check("packaged extension on another Python: the error names the wheels' Python",
          wheels_for_another_python)

    print(f"{results['passed']} passed, {results['failed']} failed, "
          f"{results['skipped']} skipped", flush=True)
    return 1 if results["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
