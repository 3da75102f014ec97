"""Modal Bake: an object's vibration modes as shape keys on its own mesh.

Sidebar (N) > Modal Bake, on a mesh object: choose a material, a fixed region (a vertex group,
or everything below a height, drawn in the viewport), the mesher and the element order/size,
then Bake. The add-on writes the object's evaluated world-space mesh (m) to OBJ, runs
`modal-bake mesh`, `modal-bake bake` and `modal-bake export --gltf --onto` on it, and adds one
shape key per mode, "Mode N — F Hz", to the object's own mesh (same vertices, same order).
Preview Mode animates a key's value through one sine period. The `.modes` base's path is
stored on the object as the custom property `modal_bake_modes`.

modal-bake is found in this order: the path in the add-on preferences, `bin/modal-bake` inside
the add-on folder, `modal-bake` on PATH. Which one ran, and its version, is reported. A package
built by scripts/package_blender_addon.py bundles modal-bake and, as wheels Blender installs,
gmsh and pytetwild, which modal-bake then runs with Blender's own Python.
"""

import math
import os
import tempfile
import threading

import bpy
from bpy.props import (BoolProperty, EnumProperty, FloatProperty, IntProperty,
                       PointerProperty, StringProperty)

from . import runner

ADDON_DIR = os.path.dirname(os.path.abspath(__file__))
KEY_PREFIX = "Mode "


def _prefs(context):
    addon = context.preferences.addons.get(__package__)
    return addon.preferences if addon else None


def wheel_site_packages():
    """Where Blender extracts extensions' wheels: `.local/lib/pythonX.Y/site-packages` of the
    user's extensions folder (on every platform)."""
    import sys
    return os.path.join(bpy.utils.user_resource("EXTENSIONS"), ".local", "lib",
                        "python{}.{}".format(*sys.version_info[:2]), "site-packages")


def locate_binary(context):
    """(path, where, version) of the modal-bake this add-on runs; raises runner.BakeError."""
    prefs = _prefs(context)
    path, where = runner.find_binary(prefs.binary if prefs else "", ADDON_DIR)
    return path, where, runner.binary_version(path)


class ModalBakePreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    binary: StringProperty(
        name="modal-bake binary",
        description="Path of the modal-bake executable (empty: the one bundled in the add-on "
                    "folder's bin/, else modal-bake on PATH)",
        subtype="FILE_PATH",
    )

    def draw(self, context):
        self.layout.prop(self, "binary")
        try:
            path, where, version = locate_binary(context)
            self.layout.label(text=f"Using {version} ({where}): {path}")
            bundled = os.path.isdir(os.path.join(ADDON_DIR, "wheels"))
            self.layout.label(
                text="Meshers: gmsh and pytetwild bundled with the add-on, run by Blender's Python"
                if bundled else
                "Meshers: gmsh and pytetwild as modal-bake finds them (gmsh on PATH, python3)")
        except runner.BakeError as e:
            self.layout.label(text=str(e), icon="ERROR")


MATERIAL_ITEMS = [("default", "CLI default", "No material option: modal-bake's default (it warns)")] + [
    (m, m.capitalize(), f"--material {m}") for m in runner.MATERIALS
] + [("custom", "Custom", "Young's modulus, Poisson's ratio and density given below")]


class ModalBakeSettings(bpy.types.PropertyGroup):
    material: EnumProperty(name="Material", items=MATERIAL_ITEMS, default="default",
                           description="Material preset passed as --material (or explicit values)")
    youngs_pa: FloatProperty(name="Young's modulus (Pa)", default=1.1e9, min=1.0)
    poisson: FloatProperty(name="Poisson's ratio", default=0.3, min=0.0, max=0.499)
    density_kg_m3: FloatProperty(name="Density (kg/m³)", default=770.0, min=1e-3)
    fixed: EnumProperty(
        name="Fixed region",
        items=[("none", "None (free)", "Free-free: nothing held"),
               ("below", "Below a height", "Every node at or below the height (world Z) is fixed"),
               ("group", "Vertex group", "Every node on the region the group's vertices and "
                                         "faces cover is fixed (--fixed-near)")],
        default="none")
    fixed_height: FloatProperty(name="Height", subtype="DISTANCE", default=0.0,
                                description="World Z (scene units) at or below which nodes are fixed")
    fixed_group: StringProperty(name="Vertex group",
                                description="Vertex group whose vertices and faces are fixed")
    mesher: EnumProperty(
        name="Mesher",
        items=[("auto", "Auto", "modal-bake's choice (not passed)"),
               ("gmsh", "gmsh", "Remesh a clean closed surface (--mesher gmsh)"),
               ("ftetwild", "fTetWild", "Open or messy surfaces (--mesher ftetwild)")],
        default="auto")
    order: EnumProperty(name="Order", items=[("2", "2 (10-node)", "Accurate per dof"),
                                             ("1", "1 (4-node)", "Fast, stiff")], default="2")
    size: FloatProperty(name="Element size", subtype="DISTANCE", default=0.0, min=0.0,
                        description="Target tetrahedron size (scene units; 0: automatic)")
    uniform_size: BoolProperty(
        name="Uniform size", default=False,
        description="One element size everywhere (gmsh): no finer elements where the surface "
                    "curves. Where gmsh's curvature sizing over-refines a faceted, low-poly "
                    "model, the bake already meshes it again with sizes from the model's own "
                    "curvature (the bake log says so); this is the coarser, simpler choice")
    target_error: FloatProperty(name="Target error (%)", default=0.0, min=0.0, max=100.0,
                                description="Passed as --target-error when above 0")
    modes: IntProperty(name="Modes", default=12, min=1, max=200)
    output_dir: StringProperty(name="Output folder", subtype="DIR_PATH",
                               description="Where the .modes base is kept (empty: a modal_bake "
                                           "folder beside the saved .blend, else a temporary "
                                           "folder)")
    show_region: BoolProperty(name="Show fixed region", default=True)


def _is_mode_key(kb):
    return kb.name.startswith(KEY_PREFIX) and "Hz" in kb.name


def remove_mode_keys(obj):
    keys = obj.data.shape_keys
    if not keys:
        return
    for kb in [kb for kb in keys.key_blocks if _is_mode_key(kb)]:
        obj.shape_key_remove(kb)


def world_mesh(context, obj):
    """The object's evaluated world-space vertices (m) and polygons. Refuses modifiers that
    change the vertex count (the shape keys need the mesh's own vertices)."""
    unit = context.scene.unit_settings.scale_length or 1.0
    dg = context.evaluated_depsgraph_get()
    ev = obj.evaluated_get(dg)
    me = ev.to_mesh()
    try:
        if len(me.vertices) != len(obj.data.vertices):
            raise runner.BakeError(
                f"{obj.name}: its modifiers change the vertex count ({len(obj.data.vertices)} "
                f"-> {len(me.vertices)}); shape keys need the mesh's own vertices: apply or "
                "disable the modifiers that add or remove vertices (Subdivision, Remesh, ...)")
        mw = obj.matrix_world
        positions = [tuple(unit * c for c in (mw @ v.co)) for v in me.vertices]
        faces = [list(p.vertices) for p in me.polygons]
    finally:
        ev.to_mesh_clear()
    if not faces:
        raise runner.BakeError(f"{obj.name}: the mesh has no faces")
    return positions, faces


def bake_settings(context, obj):
    """The CLI settings dict (lengths in m) from the object's panel settings."""
    s = obj.modal_bake
    unit = context.scene.unit_settings.scale_length or 1.0
    out = {
        "order": int(s.order),
        "size_m": s.size * unit if s.size > 0 else None,
        "uniform_size": s.uniform_size,
        "mesher": s.mesher,
        "modes": s.modes,
        "material": None if s.material == "default" else s.material,
        "youngs_pa": s.youngs_pa, "poisson": s.poisson, "density_kg_m3": s.density_kg_m3,
        "target_error_pct": s.target_error or None,
    }
    if s.fixed == "below":
        out["fixed_below_z"] = s.fixed_height * unit
    elif s.fixed == "group":
        out["fixed_group"] = group_region(context, obj, s.fixed_group)
    return out


def group_region(context, obj, name):
    """The vertex group `name` as world-space points (m) and the faces whose vertices are all
    in it (0-based indices into the points): the region `--fixed-near` fixes."""
    vg = obj.vertex_groups.get(name)
    if vg is None:
        raise runner.BakeError(f"{obj.name}: no vertex group named '{name}' (Fixed region)")
    unit = context.scene.unit_settings.scale_length or 1.0
    mw = obj.matrix_world
    members = [v.index for v in obj.data.vertices
               if any(g.group == vg.index and g.weight > 0.0 for g in v.groups)]
    if not members:
        raise runner.BakeError(f"{obj.name}: vertex group '{name}' holds no vertex")
    local = {v: i for i, v in enumerate(members)}
    points = [tuple(unit * c for c in (mw @ obj.data.vertices[v].co)) for v in members]
    faces = [[local[v] for v in p.vertices] for p in obj.data.polygons
             if all(v in local for v in p.vertices)]
    return points, faces


def output_folder(obj):
    s = obj.modal_bake
    if s.output_dir:
        d = bpy.path.abspath(s.output_dir)
    elif bpy.data.filepath:
        d = os.path.join(os.path.dirname(bpy.data.filepath), "modal_bake")
    else:
        d = tempfile.mkdtemp(prefix="modal_bake_")
    os.makedirs(d, exist_ok=True)
    return d


def prepare(context, obj):
    """Main-thread part before the CLI runs: the OBJ written, the command lines built."""
    if obj is None or obj.type != "MESH":
        raise runner.BakeError("select a mesh object to bake")
    exe, where, version = locate_binary(context)
    remove_mode_keys(obj)
    positions, faces = world_mesh(context, obj)
    folder = output_folder(obj)
    stem = bpy.path.clean_name(obj.name)
    paths = {k: os.path.join(folder, stem + ext) for k, ext in
             (("obj", ".obj"), ("msh", ".msh"), ("modes", ".modes"), ("glb", "_modes.glb"))}
    runner.write_obj(paths["obj"], positions, faces)
    settings = bake_settings(context, obj)
    if "fixed_group" in settings:
        paths["fixed"] = os.path.join(folder, stem + "_fixed.obj")
        runner.write_obj(paths["fixed"], *settings.pop("fixed_group"))
        settings["fixed_near"] = paths["fixed"]
    mesh_extra, env, meshers = runner.bundled_meshers(ADDON_DIR, wheel_site_packages())
    steps = [
        ("mesh", runner.mesh_command(exe, paths["obj"], paths["msh"], settings, mesh_extra)),
        ("bake", runner.bake_command(exe, paths["msh"], paths["modes"], settings)),
        ("export", runner.export_command(exe, paths["modes"], paths["glb"], paths["obj"],
                                         settings["modes"])),
    ]
    return {"exe": exe, "where": where, "version": version, "paths": paths, "steps": steps,
            "vertices": len(positions), "env": env, "meshers": meshers}


def run_steps(job, progress):
    """The CLI part (any thread): runs the steps and reads the GLB back."""
    if job["meshers"]:
        progress(f"meshers: {job['meshers']}")
    for what, cmd in job["steps"]:
        runner.run_step(cmd, what, progress, job["env"])
    positions, modes, info = runner.read_onto_glb(job["paths"]["glb"])
    if len(positions) != job["vertices"]:
        raise runner.BakeError(
            f"the exported GLB has {len(positions)} vertices, the object {job['vertices']}")
    job["modes"], job["info"] = modes, info


def apply_result(context, obj, job):
    """Main-thread part after the CLI: one shape key per mode on the object's own mesh."""
    unit = context.scene.unit_settings.scale_length or 1.0
    inv = obj.matrix_world.to_3x3().inverted()
    if obj.data.shape_keys is None:
        obj.shape_key_add(name="Basis", from_mix=False)
    basis = obj.data.shape_keys.reference_key
    n = len(obj.data.vertices)
    rest = [0.0] * (3 * n)
    basis.data.foreach_get("co", rest)
    freqs = []
    for j, m in enumerate(job["modes"]):
        name = f"Mode {j + 1} — " + m["name"].split(" — ", 1)[1]
        kb = obj.shape_key_add(name=name, from_mix=False)
        kb.slider_min = -1.0
        kb.value = 0.0
        d = m["offsets"]
        co = list(rest)
        for v in range(n):
            local = inv @ bpy_vec(d[3 * v] / unit, d[3 * v + 1] / unit, d[3 * v + 2] / unit)
            co[3 * v] += local[0]
            co[3 * v + 1] += local[1]
            co[3 * v + 2] += local[2]
        kb.data.foreach_set("co", co)
        freqs.append(m["frequency_hz"])
    obj.data.update()
    obj["modal_bake_modes"] = job["paths"]["modes"]
    obj["modal_bake_frequencies_hz"] = freqs
    obj["modal_bake_binary"] = f"{job['version']} ({job['where']}): {job['exe']}"
    obj["modal_bake_mapping_distance_m"] = job["info"].get("max_mapping_distance_m", 0.0)
    return freqs


def bpy_vec(x, y, z):
    from mathutils import Vector
    return Vector((x, y, z))


def _console(msg):
    print(f"[modal-bake] {msg}", flush=True)


class MODALBAKE_OT_bake(bpy.types.Operator):
    """Bake the active mesh object's vibration modes into shape keys with modal-bake"""
    bl_idname = "modal_bake.bake"
    bl_label = "Bake Modes"
    bl_options = {"REGISTER", "UNDO"}

    _timer = None
    _thread = None

    @classmethod
    def poll(cls, context):
        return context.active_object is not None and context.active_object.type == "MESH"

    def execute(self, context):
        """Synchronous bake (scripts, background mode): progress on the console."""
        obj = context.active_object
        try:
            job = prepare(context, obj)
            _console(f"using {job['version']} ({job['where']}): {job['exe']}")
            run_steps(job, _console)
            freqs = apply_result(context, obj, job)
        except runner.BakeError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        self.report({"INFO"}, f"{len(freqs)} mode shape keys on {obj.name} "
                              f"({freqs[0]:.1f} … {freqs[-1]:.1f} Hz)")
        return {"FINISHED"}

    def invoke(self, context, event):
        """Interactive bake: modal-bake runs in a thread, its lines go to the status bar."""
        if bpy.app.background:
            return self.execute(context)
        obj = context.active_object
        try:
            self._job = prepare(context, obj)
        except runner.BakeError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        self._obj_name = obj.name
        self._lines = [f"using {self._job['version']} ({self._job['where']})"]
        self._error = None

        def work():
            try:
                run_steps(self._job, lambda s: (self._lines.append(s), _console(s)))
            except runner.BakeError as e:
                self._error = str(e)
            except Exception as e:  # reported in the UI rather than lost in a thread
                self._error = f"unexpected error: {e!r}"

        self._thread = threading.Thread(target=work, daemon=True)
        self._thread.start()
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.25, window=context.window)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        context.workspace.status_text_set(f"Modal Bake — {self._lines[-1][:160]}")
        if self._thread.is_alive():
            return {"PASS_THROUGH"}
        context.window_manager.event_timer_remove(self._timer)
        context.workspace.status_text_set(None)
        if self._error:
            self.report({"ERROR"}, self._error)
            return {"CANCELLED"}
        obj = bpy.data.objects.get(self._obj_name)
        freqs = apply_result(context, obj, self._job)
        self.report({"INFO"}, f"{len(freqs)} mode shape keys on {obj.name}")
        return {"FINISHED"}


class MODALBAKE_OT_preview_mode(bpy.types.Operator):
    """Animate one mode's shape key through a sine period (the others at 0)"""
    bl_idname = "modal_bake.preview_mode"
    bl_label = "Preview Mode"
    bl_options = {"REGISTER", "UNDO"}

    mode: IntProperty(name="Mode", default=1, min=1)
    frames: IntProperty(name="Frames per period", default=24, min=4)
    amplitude: FloatProperty(name="Amplitude", default=1.0, min=0.0, soft_max=3.0)

    def execute(self, context):
        obj = context.active_object
        keys = obj.data.shape_keys if obj and obj.type == "MESH" else None
        blocks = [kb for kb in keys.key_blocks if _is_mode_key(kb)] if keys else []
        if self.mode > len(blocks):
            self.report({"ERROR"}, f"no Mode {self.mode} shape key: bake first")
            return {"CANCELLED"}
        target = blocks[self.mode - 1]
        if keys.animation_data:
            keys.animation_data_clear()
        for kb in blocks:
            kb.value = 0.0
        start = context.scene.frame_start
        for f in range(self.frames + 1):
            target.slider_min = -max(1.0, self.amplitude)
            target.slider_max = max(1.0, self.amplitude)
            target.value = self.amplitude * math.sin(2.0 * math.pi * f / self.frames)
            target.keyframe_insert("value", frame=start + f)
        keys.animation_data.action.name = f"{obj.name} {target.name} preview"
        context.scene.frame_end = start + self.frames - 1
        self.report({"INFO"}, f"previewing {target.name} (play the timeline)")
        return {"FINISHED"}


class MODALBAKE_OT_check_binary(bpy.types.Operator):
    """Report which modal-bake the add-on runs and its version"""
    bl_idname = "modal_bake.check_binary"
    bl_label = "Find modal-bake"

    def execute(self, context):
        try:
            path, where, version = locate_binary(context)
        except runner.BakeError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        self.report({"INFO"}, f"{version} ({where}): {path}")
        return {"FINISHED"}


class VIEW3D_PT_modal_bake(bpy.types.Panel):
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Modal Bake"
    bl_label = "Modal Bake"

    @classmethod
    def poll(cls, context):
        return context.active_object is not None and context.active_object.type == "MESH"

    def draw(self, context):
        obj = context.active_object
        s = obj.modal_bake
        col = self.layout.column()
        col.prop(s, "material")
        if s.material == "custom":
            col.prop(s, "youngs_pa")
            col.prop(s, "poisson")
            col.prop(s, "density_kg_m3")
        col.separator()
        col.prop(s, "fixed")
        if s.fixed == "below":
            col.prop(s, "fixed_height")
        elif s.fixed == "group":
            col.prop_search(s, "fixed_group", obj, "vertex_groups")
        if s.fixed != "none":
            col.prop(s, "show_region")
        col.separator()
        col.prop(s, "mesher")
        col.prop(s, "order")
        col.prop(s, "size")
        col.prop(s, "uniform_size")
        col.prop(s, "target_error")
        col.prop(s, "modes")
        col.prop(s, "output_dir")
        col.separator()
        col.operator(MODALBAKE_OT_bake.bl_idname, icon="MOD_VERTEX_WEIGHT")
        col.operator(MODALBAKE_OT_check_binary.bl_idname, icon="VIEWZOOM")
        if "modal_bake_binary" in obj:
            col.label(text=f"Baked with {obj['modal_bake_binary']}")
        keys = obj.data.shape_keys
        blocks = [kb for kb in keys.key_blocks if _is_mode_key(kb)] if keys else []
        if blocks:
            box = col.box()
            box.label(text=f"Modes ({obj.get('modal_bake_modes', '')})")
            for j, kb in enumerate(blocks):
                row = box.row(align=True)
                row.prop(kb, "value", text=kb.name)
                op = row.operator(MODALBAKE_OT_preview_mode.bl_idname, text="", icon="PLAY")
                op.mode = j + 1


_draw_handle = None


def _draw_fixed_region():
    """Viewport overlay: the fixed-below plane (world Z) or the vertex group's vertices and
    faces."""
    import gpu
    from gpu_extras.batch import batch_for_shader
    obj = bpy.context.active_object
    if obj is None or obj.type != "MESH":
        return
    s = obj.modal_bake
    if s.fixed == "none" or not s.show_region:
        return
    corners = [obj.matrix_world @ bpy_vec(*c) for c in obj.bound_box]
    lo = [min(c[a] for c in corners) for a in range(3)]
    hi = [max(c[a] for c in corners) for a in range(3)]
    pad = 0.1 * max(hi[0] - lo[0], hi[1] - lo[1], 1e-6)
    shader = gpu.shader.from_builtin("UNIFORM_COLOR")
    gpu.state.blend_set("ALPHA")
    if s.fixed == "below":
        z = s.fixed_height
        quad = [(lo[0] - pad, lo[1] - pad, z), (hi[0] + pad, lo[1] - pad, z),
                (hi[0] + pad, hi[1] + pad, z), (lo[0] - pad, hi[1] + pad, z)]
        batch = batch_for_shader(shader, "TRIS", {"pos": quad}, indices=[(0, 1, 2), (0, 2, 3)])
        shader.uniform_float("color", (1.0, 0.35, 0.1, 0.35))
        batch.draw(shader)
    else:
        try:
            unit = bpy.context.scene.unit_settings.scale_length or 1.0
            points, faces = group_region(bpy.context, obj, s.fixed_group)
        except runner.BakeError:
            return
        pts = [tuple(c / unit for c in p) for p in points]
        tris = [(f[0], f[j], f[j + 1]) for f in faces for j in range(1, len(f) - 1)]
        shader.uniform_float("color", (1.0, 0.35, 0.1, 0.5))
        if tris:
            batch_for_shader(shader, "TRIS", {"pos": pts}, indices=tris).draw(shader)
        shader.uniform_float("color", (1.0, 0.35, 0.1, 1.0))
        gpu.state.point_size_set(6.0)
        batch_for_shader(shader, "POINTS", {"pos": pts}).draw(shader)
    gpu.state.blend_set("NONE")


CLASSES = (ModalBakePreferences, ModalBakeSettings, MODALBAKE_OT_bake, MODALBAKE_OT_preview_mode,
           MODALBAKE_OT_check_binary, VIEW3D_PT_modal_bake)


def register():
    global _draw_handle
    for c in CLASSES:
        bpy.utils.register_class(c)
    bpy.types.Object.modal_bake = PointerProperty(type=ModalBakeSettings)
    if not bpy.app.background:
        _draw_handle = bpy.types.SpaceView3D.draw_handler_add(
            _draw_fixed_region, (), "WINDOW", "POST_VIEW")


def unregister():
    global _draw_handle
    if _draw_handle is not None:
        bpy.types.SpaceView3D.draw_handler_remove(_draw_handle, "WINDOW")
        _draw_handle = None
    del bpy.types.Object.modal_bake
    for c in reversed(CLASSES):
        bpy.utils.unregister_class(c)
