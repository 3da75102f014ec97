#!/usr/bin/env python3
"""Builds the Modal Bake Blender extension as one zip an artist installs and bakes with, nothing
else to install: the add-on (blender/modal_bake), the modal-bake program in bin/, and gmsh and
pytetwild (fTetWild) as Python wheels, which Blender installs into its extensions' site-packages
and the add-on then runs with Blender's own Python (`MODAL_BAKE_PYTHON`, `--gmsh`).

    python3 scripts/package_blender_addon.py --binary target/release/modal-bake [--out out/blender]
    python3 scripts/package_blender_addon.py \
        --binary target/x86_64-pc-windows-gnu/release/modal-bake.exe   # scripts/build_windows.sh

Writes OUT/modal_bake-VERSION-PLATFORM.zip (about 45 MB: gmsh's wheel is 40 MB) with Blender's
own extension builder (`blender_ext.py build`, from the installed `bpy`, Blender 4.5 LTS or 5.0),
which also validates the manifest, and prints its path. The platform is the program's: a Linux
x86-64 program makes a `linux-x64` package, a Windows x86-64 one (cross-built here by
scripts/build_windows.sh) a `windows-x64` package with `bin/modal-bake.exe` and the wheels'
Windows builds; macOS needs a modal-bake built there. A Linux program is run for its version; a
Windows one is not run here, and its version is read from crates/modal-bake/Cargo.toml (the log
says so; scripts/windows_check.py runs it under Wine). The wheels are the pinned versions the
CLI is tested with (gmsh 4.15.2, pytetwild 0.4.2), downloaded by pip (from its cache when it
has them).

Needs: python3 with pip and `bpy` (the builder; `pip install bpy==4.5.7`), network access to
PyPI or a pip cache holding the wheels. Exit status 0 on success, 1 on an error (the message
says what and how to fix it), 2 on a usage error.
"""

import argparse
import importlib.util
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
ADDON_SRC = os.path.join(ROOT, "blender", "modal_bake")
# The wheels the add-on bundles: the versions modal-bake's mesher tests pin.
WHEELS = ["gmsh==4.15.2", "pytetwild==0.4.2"]
# Per Blender platform name: the program's file name in bin/, the wheel platform tags pip may
# pick for it (Blender 4.5 and 5.0 run Python 3.11), and the strip programs that take its format.
PLATFORMS = {
    "linux-x64": {"exe": "modal-bake",
                  "pip": ["manylinux_2_28_x86_64", "manylinux_2_24_x86_64",
                          "manylinux_2_17_x86_64", "manylinux2014_x86_64"],
                  "strip": ["strip"]},
    "windows-x64": {"exe": "modal-bake.exe", "pip": ["win_amd64"],
                    "strip": ["x86_64-w64-mingw32-strip", "strip"]},
}
PYTHON_VERSION = "3.11"


class Failure(Exception):
    pass


def log(msg):
    print(f"[package_blender_addon] {msg}", flush=True)


def blender_ext():
    """Path of Blender's extension command-line tool inside the installed bpy."""
    spec = importlib.util.find_spec("bpy")
    if spec is None or not spec.submodule_search_locations:
        raise Failure("bpy is not installed: Blender's extension builder comes with it "
                      "(python3 -m pip install bpy==4.5.7)")
    base = spec.submodule_search_locations[0]
    for version in sorted(os.listdir(base), reverse=True):
        p = os.path.join(base, version, "scripts", "addons_core", "bl_pkg", "cli",
                         "blender_ext.py")
        if os.path.isfile(p):
            return p
    raise Failure(f"no scripts/addons_core/bl_pkg/cli/blender_ext.py under {base}: "
                  "reinstall bpy (python3 -m pip install --force-reinstall bpy==4.5.7)")


def program_platform(binary):
    """Blender's platform name of the program: an ELF x86-64 file is `linux-x64`, a PE x86-64
    file `windows-x64`; anything else is refused."""
    with open(binary, "rb") as f:
        head = f.read(4096)
    if head[:4] == b"\x7fELF" and head[18:20] == b"\x3e\x00":
        return "linux-x64"
    if head[:2] == b"MZ" and len(head) >= 0x40:
        pe = int.from_bytes(head[0x3C:0x40], "little")
        if head[pe:pe + 4] == b"PE\0\0" and head[pe + 4:pe + 6] == b"\x64\x86":
            return "windows-x64"
    raise Failure(f"{binary} is neither a Linux x86-64 nor a Windows x86-64 program: this "
                  f"script packages for {', '.join(PLATFORMS)}")


def source_version():
    """modal-bake's version: crates/modal-bake/Cargo.toml's, or the workspace's it inherits."""
    import tomllib
    with open(os.path.join(ROOT, "crates", "modal-bake", "Cargo.toml"), "rb") as f:
        version = tomllib.load(f)["package"]["version"]
    if isinstance(version, dict):  # version.workspace = true
        with open(os.path.join(ROOT, "Cargo.toml"), "rb") as f:
            version = tomllib.load(f)["workspace"]["package"]["version"]
    return version


def program_version(binary):
    """`modal-bake --version`'s version (a Linux program, run here)."""
    try:
        out = subprocess.run([binary, "--version"], capture_output=True, text=True, timeout=60)
    except OSError as e:
        raise Failure(f"cannot run {binary}: {e}") from e
    words = out.stdout.split()
    if out.returncode != 0 or len(words) != 2 or words[0] != "modal-bake":
        raise Failure(f"{binary} --version did not answer `modal-bake VERSION`: "
                      f"{(out.stdout + out.stderr).strip()}")
    return words[1]


def glibc_needed(binary):
    """The newest glibc symbol version the program links (`objdump -T`), e.g. "2.34", or None
    when objdump is missing: the oldest Linux the package runs on."""
    if not shutil.which("objdump"):
        return None
    out = subprocess.run(["objdump", "-T", binary], capture_output=True, text=True)
    found = set()
    for w in out.stdout.split():
        w = w.strip("()")
        v = w[len("GLIBC_"):]
        if w.startswith("GLIBC_") and v.replace(".", "").isdigit():
            found.add(tuple(int(x) for x in v.split(".")))
    return ".".join(map(str, max(found))) if found else None


def download_wheels(dest, platform):
    cmd = [sys.executable, "-m", "pip", "download", "--quiet", "--no-deps",
           "--only-binary=:all:", "--python-version", PYTHON_VERSION, "--dest", dest]
    for p in PLATFORMS[platform]["pip"]:
        cmd += ["--platform", p]
    cmd += WHEELS
    log("downloading " + ", ".join(WHEELS) + f" for Python {PYTHON_VERSION}, {platform}")
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        raise Failure(f"pip download failed (needs PyPI or a pip cache with the wheels):\n"
                      f"{out.stderr.strip()}")
    names = sorted(n for n in os.listdir(dest) if n.endswith(".whl"))
    if len(names) != len(WHEELS):
        raise Failure(f"expected {len(WHEELS)} wheels in {dest}, found {names}")
    return names


def manifest_with(src, platform, wheels):
    """The add-on's manifest with `platforms` and `wheels` (neither is in the source manifest,
    which is the platform-independent add-on without bundled parts)."""
    with open(src, encoding="utf-8") as f:
        text = f.read()
    for key in ("platforms", "wheels"):
        if any(line.split("=")[0].strip() == key for line in text.splitlines()):
            raise Failure(f"{src} already sets `{key}`: this script writes it")
    lines = [f'platforms = ["{platform}"]', "wheels = ["]
    lines += [f'  "./wheels/{w}",' for w in wheels]
    lines += ["]"]
    # Top-level keys must come before the first table ([permissions], [build]).
    head, sep, tail = text.partition("\n[")
    return head.rstrip("\n") + "\n" + "\n".join(lines) + "\n" + (sep + tail if sep else "")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n", 1)[1])
    ap.add_argument("--binary", required=True, help="the modal-bake program to bundle "
                    "(cargo build --release -p modal-bake: target/release/modal-bake; "
                    "scripts/build_windows.sh: its modal-bake.exe)")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "blender"),
                    help="folder of the zip (default: out/blender)")
    a = ap.parse_args()
    try:
        binary = os.path.abspath(a.binary)
        if not os.path.isfile(binary):
            raise Failure(f"no modal-bake at {binary}: build it with "
                          "`cargo build --release -p modal-bake`")
        platform = program_platform(binary)
        if platform == "linux-x64":
            version = program_version(binary)
        else:
            version = source_version()
            log(f"{binary} is a Windows program, not run here: its version {version} is "
                "crates/modal-bake/Cargo.toml's (scripts/windows_check.py runs it under Wine)")
        tool = blender_ext()
        os.makedirs(a.out, exist_ok=True)
        with tempfile.TemporaryDirectory(prefix="modal_bake_pkg_") as tmp:
            stage = os.path.join(tmp, "modal_bake")
            os.makedirs(os.path.join(stage, "bin"))
            for name in sorted(os.listdir(ADDON_SRC)):
                if name.endswith(".py"):
                    shutil.copy2(os.path.join(ADDON_SRC, name), stage)
            exe = os.path.join(stage, "bin", PLATFORMS[platform]["exe"])
            shutil.copy2(binary, exe)
            os.chmod(exe, 0o755)
            # The release profile keeps line tables for backtraces; the package leaves them out.
            strip = next((s for s in PLATFORMS[platform]["strip"] if shutil.which(s)), None)
            if strip:
                subprocess.run([strip, "--strip-debug", exe], check=True)
            else:
                log(f"no {' or '.join(PLATFORMS[platform]['strip'])} on PATH (binutils): "
                    "modal-bake is bundled with its debug lines")
            wheels_dir = os.path.join(stage, "wheels")
            os.makedirs(wheels_dir)
            wheels = download_wheels(wheels_dir, platform)
            with open(os.path.join(stage, "blender_manifest.toml"), "w", encoding="utf-8") as f:
                f.write(manifest_with(os.path.join(ADDON_SRC, "blender_manifest.toml"), platform,
                                      wheels))
            zname = f"modal_bake-{version}-{platform.replace('-', '_')}.zip"
            zpath = os.path.join(os.path.abspath(a.out), zname)
            partial = zpath + ".partial"
            log(f"building {zpath} with {tool}")
            out = subprocess.run([sys.executable, tool, "build", "--source-dir", stage,
                                  "--output-filepath", partial], capture_output=True, text=True)
            if out.returncode != 0 or not os.path.isfile(partial):
                raise Failure("Blender's extension builder failed:\n"
                              + (out.stdout + out.stderr).strip())
            out = subprocess.run([sys.executable, tool, "validate", partial],
                                 capture_output=True, text=True)
            if out.returncode != 0:
                os.remove(partial)
                raise Failure("Blender's extension validator refused the package:\n"
                              + (out.stdout + out.stderr).strip())
            os.replace(partial, zpath)
        size = os.path.getsize(zpath) / 2**20
        log(f"wrote {zpath} ({size:.1f} MiB: modal-bake {version}, {', '.join(wheels)})")
        if platform == "linux-x64":
            glibc = glibc_needed(binary)
            log(f"the bundled modal-bake needs glibc {glibc} or newer (the Linux it was built on "
                "sets this: build on an older one for older systems)" if glibc else
                "the glibc the bundled modal-bake needs is not known (objdump from binutils "
                "reads it)")
        print(zpath)
        return 0
    except Failure as e:
        print(f"error: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
