"""The modal-bake side of the add-on, without bpy: finding the binary, building the command
lines, running them with progress, and reading the morph targets of an `export --onto` GLB.

Everything here is plain Python (subprocess, json, struct), so the test suite can call it
directly and the add-on's operators stay thin.
"""

import glob
import json
import os
import shutil
import stat
import struct
import subprocess
import sys

EXE = "modal-bake.exe" if sys.platform == "win32" else "modal-bake"

# Blender is a window program: on Windows a console program it starts opens a console window of
# its own unless started without one (the program and the meshers it starts then share a hidden
# console, which also carries Ctrl-C to them).
NO_WINDOW = {"creationflags": subprocess.CREATE_NO_WINDOW} if sys.platform == "win32" else {}

# Material presets the panel offers; passed as `--material NAME` (a newer modal-bake option).
MATERIALS = [
    "oak", "pine", "steel", "aluminium", "brass", "cast-iron", "glass", "ceramic", "concrete",
    "stone", "marble", "abs", "pla", "acrylic",
]


class BakeError(RuntimeError):
    """A failure the user can act on; the message says what and how to fix it."""


def find_binary(preference_path, addon_dir):
    """Returns (path, where) of the modal-bake executable: the add-on preference if set, else
    the copy bundled in the add-on folder (`bin/modal-bake`), else the one on PATH.

    Raises BakeError when none is found or the preference names a missing file.
    """
    if preference_path:
        p = os.path.abspath(os.path.expanduser(preference_path))
        if os.path.isdir(p):
            p = os.path.join(p, EXE)
        if not os.path.isfile(p):
            raise BakeError(
                f"modal-bake not found at the path set in the add-on preferences: {p} "
                "(Edit > Preferences > Add-ons > Modal Bake: fix the path or clear it to use "
                "the bundled binary or the one on PATH)")
        return p, "add-on preference"
    bundled = os.path.join(addon_dir, "bin", EXE)
    if os.path.isfile(bundled):
        # Blender extracts an extension's zip without the files' Unix modes.
        if sys.platform != "win32" and not os.access(bundled, os.X_OK):
            try:
                os.chmod(bundled, os.stat(bundled).st_mode | stat.S_IXUSR | stat.S_IXGRP
                         | stat.S_IXOTH)
            except OSError as e:
                raise BakeError(f"the bundled {bundled} is not executable and cannot be made "
                                f"so ({e}): set the add-on preference to a modal-bake") from e
        return bundled, "bundled with the add-on"
    on_path = shutil.which("modal-bake")
    if on_path:
        return on_path, "PATH"
    raise BakeError(
        "modal-bake not found: not set in the add-on preferences, not bundled in "
        f"{os.path.join(addon_dir, 'bin')}, not on PATH. Build it with "
        "`cargo build --release -p modal-bake` and set Preferences > Add-ons > Modal Bake > "
        "modal-bake binary to target/release/modal-bake, or put it on PATH.")


def bundled_meshers(addon_dir, site_packages, python=sys.executable):
    """How modal-bake meshes when this add-on package bundles gmsh and pytetwild as wheels (a
    `wheels/` folder beside this file, which Blender extracts into `site_packages`, its
    extensions' `.local/lib/pythonX.Y/site-packages`): returns (mesh arguments, environment
    additions, description) that make it run exactly those with Blender's own Python —
    `--gmsh FOLDER`, `MODAL_BAKE_PYTHON` and `PYTHONPATH` — or ([], {}, None) for a package
    without wheels, where modal-bake finds gmsh and pytetwild itself.

    Raises BakeError when the package has wheels that Blender did not install.
    """
    if not os.path.isdir(os.path.join(addon_dir, "wheels")):
        return [], {}, None
    for name, rel in (("gmsh", "gmsh.py"), ("pytetwild", os.path.join("pytetwild", "__init__.py"))):
        if os.path.isfile(os.path.join(site_packages, rel)):
            continue
        wheels = sorted(w for w in os.listdir(os.path.join(addon_dir, "wheels"))
                        if w.startswith(name + "-"))
        others = _wheel_pythons_other_than_this(wheels)
        if others:
            raise BakeError(
                f"this Modal Bake package bundles {name} for {', '.join(others)} only "
                f"({', '.join(wheels)}), and this Blender runs Python "
                f"{sys.version_info[0]}.{sys.version_info[1]}: build the package for it with "
                f"scripts/package_blender_addon.py, or use the add-on alone with gmsh and "
                f"pytetwild installed")
        raise BakeError(
            f"this Modal Bake package bundles {name} (wheels/), but Blender has not installed "
            f"it into {site_packages}: reinstall the extension (Edit > Preferences > Get "
            f"Extensions), which installs its wheels")
    _place_gmsh_library(site_packages)
    paths = [site_packages] + ([os.environ["PYTHONPATH"]] if os.environ.get("PYTHONPATH") else [])
    env = {"MODAL_BAKE_PYTHON": python, "PYTHONPATH": os.pathsep.join(paths)}
    what = f"gmsh and pytetwild bundled with the add-on ({site_packages}), run by {python}"
    return ["--gmsh", site_packages], env, what


def _wheel_pythons_other_than_this(wheels):
    """The CPython tags of `wheels` ("cp310", "cp312+" for an abi3 wheel, which serves 3.12 on)
    when none of them fits this Python, else []: pure-Python wheels (py3-none) say nothing."""
    here = int("{}{}".format(*sys.version_info[:2]))  # cp311: 311
    tags = [w.split("-")[2:4] for w in wheels]
    tags = [(int(py[2:]), abi) for py, abi in (t for t in tags if len(t) == 2)
            if py.startswith("cp") and py[2:].isdigit()]
    if not tags or any(v == here or (abi == "abi3" and v <= here) for v, abi in tags):
        return []
    return sorted({f"cp{v}" + ("+" if abi == "abi3" else "") for v, abi in tags})


def _place_gmsh_library(site_packages):
    """Puts gmsh's shared library beside gmsh.py, where gmsh.py looks first.

    The gmsh wheel ships it as a data file (`gmsh-X.data/data/lib/libgmsh.so.X`), which pip
    installs into the prefix's lib/ but Blender's wheel extraction leaves under
    `site-packages/gmsh-X.data/` (gmsh.py then finds no library: "undefined symbol:
    gmshInitialize"). Copied once (atomically), and again when the wheel's copy changes size."""
    pattern = os.path.join(glob.escape(site_packages), "gmsh-*.data", "data", "*", "*gmsh*")
    for src in sorted(glob.glob(pattern)):
        name = os.path.basename(src)
        if not (name.startswith(("libgmsh", "gmsh-")) and
                (".so" in name or name.endswith((".dylib", ".dll")))):
            continue
        dst = os.path.join(site_packages, name)
        if os.path.isfile(dst) and os.path.getsize(dst) == os.path.getsize(src):
            continue
        try:
            shutil.copy2(src, dst + ".partial")
            os.replace(dst + ".partial", dst)
        except OSError as e:
            raise BakeError(f"cannot place gmsh's library {src} beside gmsh.py in "
                            f"{site_packages}: {e}") from e


def binary_version(path):
    """`modal-bake --version` (e.g. "modal-bake 0.1.0"), or raises BakeError."""
    try:
        out = subprocess.run([path, "--version"], capture_output=True, text=True, timeout=30,
                             encoding="utf-8", errors="replace", **NO_WINDOW)
    except OSError as e:
        raise BakeError(f"cannot run {path}: {e}") from e
    if out.returncode != 0:
        raise BakeError(f"{path} --version failed: {out.stderr.strip()}")
    return out.stdout.strip()


def write_obj(path, positions, faces):
    """Writes an OBJ with `v` records in the given order (m) and polygon `f` records (0-based
    index lists), the vertex order `modal-bake export --onto` keeps."""
    with open(path, "w", encoding="ascii") as f:
        f.write("# written by the Modal Bake add-on: world space, metres\n")
        for p in positions:
            f.write(f"v {p[0]:.9g} {p[1]:.9g} {p[2]:.9g}\n")
        for face in faces:
            f.write("f " + " ".join(str(i + 1) for i in face) + "\n")


def num(x):
    """A length or modulus for the command line: 7 significant digits (Blender's properties are
    32-bit floats, so -0.9 arrives as -0.8999999761581421)."""
    return f"{float(x):.7g}"


def mesh_command(exe, obj, msh, settings, extra=()):
    """`modal-bake mesh` arguments for `settings` (a dict: order, size_m, uniform_size,
    mesher), then `extra` (the bundled meshers' `--gmsh`)."""
    cmd = [exe, "mesh", obj, "-o", msh, "--order", str(settings["order"]), *extra]
    if settings.get("size_m"):
        cmd += ["--size", num(settings["size_m"])]
    if settings.get("uniform_size"):
        cmd += ["--uniform-size"]
    if settings.get("mesher") and settings["mesher"] != "auto":
        cmd += ["--mesher", settings["mesher"]]
    return cmd


def bake_command(exe, msh, modes_path, settings):
    """`modal-bake bake` arguments: modes, material (preset name, or explicit E/ν/ρ), fixed
    region (`fixed_below_z` in m, `fixed_box` [x0,y0,z0,x1,y1,z1] in m, or `fixed_near`: an
    OBJ of the region's points and faces in m), target error."""
    cmd = [exe, "bake", msh, "-o", modes_path, "--modes", str(settings["modes"])]
    mat = settings.get("material")
    if mat == "custom":
        cmd += ["--youngs", num(settings["youngs_pa"]), "--poisson", num(settings["poisson"]),
                "--density", num(settings["density_kg_m3"])]
    elif mat:
        cmd += ["--material", mat]
    if settings.get("fixed_below_z") is not None:
        cmd += [f"--fixed-below=z={num(settings['fixed_below_z'])}"]
    if settings.get("fixed_box") is not None:
        cmd += ["--fixed-box=" + ",".join(num(x) for x in settings["fixed_box"])]
    if settings.get("fixed_near") is not None:
        cmd += ["--fixed-near", settings["fixed_near"]]
    if settings.get("target_error_pct"):
        cmd += ["--target-error", num(settings["target_error_pct"])]
    return cmd


def export_command(exe, modes_path, glb, obj, modes):
    """`modal-bake export --gltf --onto` arguments."""
    return [exe, "export", modes_path, "--gltf", glb, "--onto", obj, "--modes", str(modes)]


def _unknown_option(stderr):
    """The option an older modal-bake refused (clap's "unexpected argument"), or None."""
    for line in stderr.splitlines():
        if "unexpected argument '" in line:
            return line.split("unexpected argument '", 1)[1].split("'", 1)[0]
    return None


def run_step(cmd, what, progress, env=None):
    """Runs one modal-bake step (with the environment additions `env`), passing each
    stderr/stdout line to `progress(text)` as it comes (long bakes report their stages), and
    raises BakeError with the tool's own message on failure. Returns the full stdout."""
    progress(f"{what}: {' '.join(cmd)}")
    try:
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                encoding="utf-8", errors="replace", bufsize=1, env=dict(os.environ, NO_COLOR="1", **(env or {})),
                                **NO_WINDOW)
    except OSError as e:
        raise BakeError(f"cannot run {cmd[0]}: {e}") from e
    lines = []
    for raw in proc.stdout:
        for part in raw.replace("\r", "\n").splitlines():
            if part.strip():
                lines.append(part)
                progress(f"{what}: {part.strip()}")
    proc.wait()
    text = "\n".join(lines)
    if proc.returncode != 0:
        opt = _unknown_option(text)
        if opt:
            setting = {"--material": "set Material to Custom (explicit E, ν, ρ) or CLI default",
                       "--mesher": "set Mesher to Auto",
                       "--target-error": "set Target error to 0",
                       "--uniform-size": "clear Uniform size"}.get(opt, "reset that setting")
            raise BakeError(
                f"{what}: this modal-bake ({cmd[0]}) does not know the option {opt}: update "
                f"modal-bake, or {setting} so the option is not passed")
        tail = "\n".join(lines[-12:])
        raise BakeError(f"{what} failed (exit {proc.returncode}):\n{tail}")
    return text


def read_onto_glb(path):
    """Reads a `modal-bake export --onto` GLB: returns (positions, modes) where positions is a
    list of (x, y, z) in m and modes a list of dicts {name, frequency_hz, modal_coordinate,
    offsets: flat list of 3·nv floats (m)}."""
    with open(path, "rb") as f:
        data = f.read()
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    if magic != b"glTF" or version != 2:
        raise BakeError(f"{path}: not a glTF 2.0 binary file")
    off, doc, binary = 12, None, b""
    while off + 8 <= len(data):
        clen, ctype = struct.unpack_from("<II", data, off)
        chunk = data[off + 8: off + 8 + clen]
        if ctype == 0x4E4F534A:
            doc = json.loads(chunk.decode("utf-8"))
        elif ctype == 0x004E4942:
            binary = chunk
        off += 8 + clen
    if doc is None:
        raise BakeError(f"{path}: no JSON chunk")

    def floats(acc_index):
        acc = doc["accessors"][acc_index]
        view = doc["bufferViews"][acc["bufferView"]]
        n = acc["count"] * {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[acc["type"]]
        start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
        return list(struct.unpack_from(f"<{n}f", binary, start))

    mesh = doc["meshes"][0]
    prim = mesh["primitives"][0]
    pos = floats(prim["attributes"]["POSITION"])
    positions = [tuple(pos[i:i + 3]) for i in range(0, len(pos), 3)]
    info = doc.get("extras", {}).get("dcr", {})
    modes = []
    for j, t in enumerate(prim.get("targets", [])):
        m = info["modes"][j]
        modes.append({
            "name": mesh["extras"]["targetNames"][j],
            "frequency_hz": m["frequency_hz"],
            "modal_coordinate": m["modal_coordinate"],
            "offsets": floats(t["POSITION"]),
        })
    return positions, modes, info
