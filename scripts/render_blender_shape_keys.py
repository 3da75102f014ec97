"""Renders docs/pictures/blender_shape_keys.png: the Modal Bake add-on's shape keys in Blender.

    python3 scripts/render_blender_shape_keys.py [--binary target/release/modal-bake]

Needs the `bpy` module (python3 -m pip install bpy==4.5.7) and a release modal-bake. In a
fresh Blender scene (private user folder), installs the add-on from blender/modal_bake as an
extension, builds a 40 × 20 × 600 mm bar standing on the ground (its long edges cut 24 times so
the shape keys have vertices to bend), fixes it below z = 1 mm, and presses Bake (pine, order 2,
6 modes). It then renders, with Workbench at 750 × 600 (turned 45° so both bending directions show), the rest mesh beside four copies with
the keys "Mode 1 … 4" at 1.0 (the add-on's scale: largest displacement 5 % of the diagonal),
each labelled with its key's name.
"""

import argparse
import math
import os
import sys
import tempfile
import zipfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
OUT = os.path.join(ROOT, "docs", "pictures", "blender_shape_keys.png")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    tgt = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
    ap.add_argument("--binary", default=os.path.join(tgt, "release", "modal-bake"))
    ap.add_argument("--out", default=OUT)
    args = ap.parse_args()
    work = tempfile.mkdtemp(prefix="modal_bake_render_")
    for var, sub in (("BLENDER_USER_CONFIG", "config"), ("BLENDER_USER_SCRIPTS", "scripts"),
                     ("BLENDER_USER_EXTENSIONS", "extensions")):
        os.environ[var] = os.path.join(work, sub)
    import bpy
    import bmesh  # available once bpy is imported

    src = os.path.join(ROOT, "blender", "modal_bake")
    zpath = os.path.join(work, "modal_bake.zip")
    with zipfile.ZipFile(zpath, "w") as z:
        for name in sorted(os.listdir(src)):
            if name.endswith((".py", ".toml")):
                z.write(os.path.join(src, name), name)
    bpy.ops.extensions.package_install_files(filepath=zpath, repo="user_default",
                                             enable_on_install=True)
    prefs = bpy.context.preferences.addons["bl_ext.user_default.modal_bake"].preferences
    prefs.binary = os.path.abspath(args.binary)

    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0, 0, 0.3))
    bar = bpy.context.active_object
    bar.name = "Bar"
    bar.scale = (0.04, 0.02, 0.6)
    bpy.ops.object.transform_apply(scale=True)
    bm = bmesh.new()
    bm.from_mesh(bar.data)
    vertical = [e for e in bm.edges
                if abs(e.verts[0].co.z - e.verts[1].co.z) > 0.5]
    bmesh.ops.subdivide_edges(bm, edges=vertical, cuts=24, use_grid_fill=True)
    bm.to_mesh(bar.data)
    bm.free()
    s = bar.modal_bake
    s.material, s.order, s.modes = "pine", "2", 6
    s.fixed, s.fixed_height = "below", 0.001
    s.output_dir = os.path.join(work, "bake")
    try:
        res = bpy.ops.modal_bake.bake()
    except RuntimeError as e:
        if "--material" not in str(e):
            raise
        # A modal-bake without --material (the add-on said so): explicit pine-like values.
        print("this modal-bake has no --material: using E = 10 GPa, nu = 0.3, rho = 500 kg/m3")
        s.material = "custom"
        s.youngs_pa, s.poisson, s.density_kg_m3 = 1.0e10, 0.3, 500.0
        res = bpy.ops.modal_bake.bake()
    assert res == {"FINISHED"}, res
    keys = [kb for kb in bar.data.shape_keys.key_blocks if kb.name.startswith("Mode ")]

    scene = bpy.context.scene
    spacing = 0.2
    shown = [None] + keys[:4]
    for i, kb in enumerate(shown):
        obj = bar if i == 0 else bar.copy()
        if i:
            obj.data = bar.data.copy()
            scene.collection.objects.link(obj)
            obj.data.shape_keys.key_blocks[kb.name].value = 1.0
        # Turned 45° about z: both bending directions of the bar are seen from the camera.
        obj.location.x = (i - 2) * spacing
        obj.rotation_euler.z = math.radians(45)
        obj.color = (0.85, 0.6, 0.35, 1.0)
        bpy.ops.object.text_add(location=((i - 2) * spacing - 0.075, 0.0, 0.72))
        txt = bpy.context.active_object
        txt.data.body = "rest\n" if kb is None else kb.name.replace(" — ", "\n")
        txt.data.size = 0.03
        txt.rotation_euler = (math.radians(90), 0, 0)
        txt.color = (0.1, 0.1, 0.1, 1.0)
    bpy.ops.object.camera_add(location=(0, -2.2, 0.36), rotation=(math.radians(90), 0, 0))
    cam = bpy.context.active_object
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 1.1
    scene.camera = cam
    if scene.world is None:
        scene.world = bpy.data.worlds.new("World")
    scene.world.color = (1.0, 1.0, 1.0)
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.display.shading.light = "STUDIO"
    scene.display.shading.color_type = "OBJECT"
    scene.display.shading.show_cavity = True
    scene.view_settings.view_transform = "Standard"
    scene.render.resolution_x, scene.render.resolution_y = 750, 600
    scene.render.film_transparent = False
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.image_settings.color_depth = "8"
    scene.render.image_settings.compression = 100
    scene.render.dither_intensity = 0.0
    scene.render.filepath = args.out
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    bpy.ops.render.render(write_still=True)
    print(f"wrote {args.out}: {', '.join(kb.name for kb in keys[:4])}")


if __name__ == "__main__":
    sys.exit(main())
