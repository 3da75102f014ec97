"""Renders docs/pictures/blender_shape_keys.png: the Modal Bake add-on's shape keys in Blender.

    python3 scripts/render_blender_shape_keys.py [--binary target/release/modal-bake]

Needs the `bpy` module (python3 -m pip install bpy==4.5.7), a release modal-bake, gmsh and
pytetwild (modal-bake's meshers). In a fresh Blender scene (private user folder), installs the
add-on from blender/modal_bake as an extension, adds Blender's own Suzanne (size 0.2: 0.27 m
wide; its 507 vertices as Blender makes them: the artist's mesh, open eyes included) and presses Bake with
the panel's defaults but the material (ABS, order 2, free-free, 6 modes; the open surface goes
to fTetWild). It then renders, with Workbench at 1000 × 300 (turned 20° so motion towards the
camera shows), the rest mesh beside four copies with the keys "Mode 1 … 4" at KEY_VALUE (at 1.0 a
key's largest displacement is 5 % of the diagonal), each labelled with its key's name and
coloured by its displacement (a colour attribute on the copy: grey still, red the key's
largest displacement).
"""

import argparse
import math
import os
import sys
import tempfile
import zipfile

KEY_VALUE = 2.0

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
OUT = os.path.join(ROOT, "docs", "pictures", "blender_shape_keys.png")


def paint(mesh, key):
    """A point colour attribute "displacement": |key − basis| / its largest value from warm
    grey (still) to red (the largest motion); all grey for the rest mesh (`key` None)."""
    basis = mesh.shape_keys.reference_key.data if mesh.shape_keys else None
    d = [0.0] * len(mesh.vertices)
    if key is not None:
        d = [(k.co - b.co).length for k, b in zip(key.data, basis)]
    peak = max(d) or 1.0
    attr = mesh.color_attributes.new(name="displacement", type="FLOAT_COLOR", domain="POINT")
    grey, red = (0.45, 0.40, 0.34), (0.80, 0.01, 0.005)  # linear RGB
    for i, x in enumerate(d):
        t = x / peak
        attr.data[i].color = [g + t * (r - g) for g, r in zip(grey, red)] + [1.0]
    mesh.color_attributes.active_color = attr


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
    bpy.ops.mesh.primitive_monkey_add(size=0.2, location=(0, 0, 0))
    monkey = bpy.context.active_object
    monkey.name = "Suzanne"
    s = monkey.modal_bake
    s.material, s.order, s.modes = "abs", "2", 6
    s.fixed = "none"
    s.output_dir = os.path.join(work, "bake")
    res = bpy.ops.modal_bake.bake()
    assert res == {"FINISHED"}, res
    keys = [kb for kb in monkey.data.shape_keys.key_blocks if kb.name.startswith("Mode ")]

    scene = bpy.context.scene
    spacing = 0.3
    shown = [None] + keys[:4]
    for i, kb in enumerate(shown):
        obj = monkey if i == 0 else monkey.copy()
        if i:
            obj.data = monkey.data.copy()
            scene.collection.objects.link(obj)
            obj.data.shape_keys.key_blocks[kb.name].value = KEY_VALUE
        paint(obj.data, kb)
        # Turned 20° about z: motion towards the camera shows too.
        obj.location.x = (i - 2) * spacing
        obj.rotation_euler.z = math.radians(20)
        bpy.ops.object.text_add(location=((i - 2) * spacing - 0.08, 0.0, 0.15))
        txt = bpy.context.active_object
        txt.data.body = "rest\n" if kb is None else kb.name.replace(" — ", "\n")
        txt.data.size = 0.028
        txt.rotation_euler = (math.radians(90), 0, 0)
        txt.color = (0.1, 0.1, 0.1, 1.0)
    bpy.ops.object.camera_add(location=(0, -2.0, 0.02), rotation=(math.radians(90), 0, 0))
    cam = bpy.context.active_object
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 1.5
    scene.camera = cam
    if scene.world is None:
        scene.world = bpy.data.worlds.new("World")
    scene.world.color = (1.0, 1.0, 1.0)
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.display.shading.light = "STUDIO"
    scene.display.shading.color_type = "VERTEX"
    scene.display.shading.show_cavity = True
    scene.view_settings.view_transform = "Standard"
    scene.render.resolution_x, scene.render.resolution_y = 1000, 300
    scene.render.film_transparent = False
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.image_settings.color_depth = "8"
    scene.render.image_settings.compression = 100
    scene.render.dither_intensity = 0.0
    scene.render.filepath = args.out
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    bpy.ops.render.render(write_still=True)
    print(f"wrote {args.out}: {len(monkey.data.vertices)} vertices, keys at {KEY_VALUE}: "
          f"{', '.join(kb.name for kb in keys[:4])}")


if __name__ == "__main__":
    sys.exit(main())
