#!/usr/bin/env python3
"""Checks the Windows build of modal-bake (scripts/build_windows.sh) the way a Windows user runs
it, under Wine on this Linux machine, against the Linux build of the same sources:

    bash scripts/build_windows.sh
    python3 scripts/windows_check.py [--exe target/x86_64-pc-windows-gnu/release/modal-bake.exe]
                                     [--linux target/release/modal-bake] [--no-package]
                                     [--linux-lib target/release/libdcr_capi.so] [--no-tests]

(the Windows C library's files are taken from the Windows program's folder; the Linux
libdcr_capi.so from the Linux program's unless --linux-lib names it).

1. the program imports Windows' own DLLs only (no MinGW runtime DLL to ship beside it);
2. `--version` answers the workspace's version;
3. bases baked by it (a P1 table with a transfer table, a P2 mesh in single precision, and a
   larger P2 mesh, the committed asset hp_body.obj meshed by gmsh, 50k dofs, where METIS
   orders the solver's unknowns too; under a folder whose name has a space and non-ASCII
   letters) are byte for byte the Linux program's bases (METIS draws from the program's own
   `rand`, glibc's generator on every platform: `modal_bake::ordering::c_rand`), the Linux
   program's `check` finds them up to date, and their glTF exports are byte-identical;
4. interrupting it (Ctrl-C: the console event Wine raises for SIGINT) while a mesher runs ends
   that mesher, removes its work folder, writes nothing and exits with STATUS_CONTROL_C_EXIT;
   ending it from outside (TerminateProcess; SIGKILL of its Wine process) ends the mesher too;
5. without a Python it says which interpreter it looked for (`python`, Windows' name);
6. the C library built beside it (dcr_capi.dll, libdcr_capi.a): the world example
   (crates/dcr-capi/examples/world.c) built with MinGW gcc against the DLL and statically
   prints, under Wine, exactly what the Linux build of the example prints (every contact,
   event and body state at %.17g; line ends aside);
7. the Blender extension packaged from it (scripts/package_blender_addon.py) is a
   `windows-x64` package with `bin/modal-bake.exe` and Windows wheels, which Blender's own
   validator accepts (skipped with --no-package, or when bpy is not installed unless
   DCR_REQUIRE_BPY=1);
8. the test programs of dcr-files, dcr-runtime and modal-bake built for Windows
   (`bash scripts/build_windows.sh --tests`) pass under Wine, each run from its package's
   folder as `cargo test` runs it (skipped with --no-tests). Tests that need a Unix facility
   (FIFOs, /dev devices, signals, a shell) are compiled out there; those that need Python
   (meshio, vtk, gmsh) skip or are ignored with the reason: no Windows Python runs here.
   A program that fails because Wine could not start a process (CreateProcess's
   ERROR_INTERNAL_ERROR: once in a CI run, in the batch test that starts modal-bake.exe 300
   times) runs once more, and its line says so.

Needs Wine (Debian: wine64) and the MinGW-w64 gcc (it builds two small helpers into a scratch
folder: a ProcessPrng for Wine 8, which lacks it, and a stand-in Python). Installs them with apt
when run as root. Exit status 0 when every check passes, 1 when one fails (each failure is
printed), 2 on a usage error.
"""

import argparse
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import zipfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from package_blender_addon import source_version  # noqa: E402  (modal-bake's version)

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
TARGET_DIR = os.environ.get("CARGO_TARGET_DIR") or os.path.join(ROOT, "target")
HELPERS = os.path.join(ROOT, "scripts", "windows")
MINGW_GCC = "x86_64-w64-mingw32-gcc"
# DLLs a Windows 10/11 installation has; anything else would have to ship beside the program.
SYSTEM_DLLS = re.compile(r"^(kernel32|ntdll|msvcrt|userenv|ws2_32|bcryptprimitives|advapi32|"
                         r"shell32|ole32|oleaut32|user32|gdi32|bcrypt|secur32|crypt32|"
                         r"api-ms-win-[a-z0-9-]+)\.dll$", re.I)
# Windows' exit status for a console program ended by Ctrl-C; Wine reports its low byte.
STATUS_CONTROL_C_EXIT = 0xC000013A

failures = []


def log(msg):
    print(f"[windows_check] {msg}", flush=True)


def check(ok, what):
    log(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)
    return ok


def ensure_tools():
    # Debian: `wine` holds the commands (wine, wineboot, wineserver), `wine64` the 64-bit loader.
    need = [pkg for tool, pkgs in (("wineboot", "wine wine64"),
                                   (MINGW_GCC, "gcc-mingw-w64-x86-64"))
            if not shutil.which(tool) for pkg in pkgs.split()]
    if not need:
        return
    if shutil.which("apt-get") and os.geteuid() == 0:
        log(f"installing {' '.join(need)} (apt)")
        subprocess.run(["apt-get", "update", "-qq"], check=True)
        subprocess.run(["apt-get", "install", "-y", "-qq", *need], check=True,
                       env=dict(os.environ, DEBIAN_FRONTEND="noninteractive"),
                       stdout=subprocess.DEVNULL)
    else:
        sys.exit(f"error: this check needs {' '.join(need)} (Debian packages) and cannot install "
                 "them here (apt-get as root)")


class Wine:
    """Runs Windows programs in a private Wine prefix, from a folder holding the program under
    test and the ProcessPrng helper."""

    def __init__(self, scratch, exe):
        self.env = dict(os.environ, WINEPREFIX=os.path.join(scratch, "wineprefix"),
                        WINEDEBUG="-all", WINEDLLOVERRIDES="mscoree,mshtml=")
        self.bin = os.path.join(scratch, "bin")
        os.makedirs(self.bin)
        self.exe = os.path.join(self.bin, "modal-bake.exe")
        shutil.copy2(exe, self.exe)
        subprocess.run([MINGW_GCC, "-O2", "-shared", "-o",
                        os.path.join(self.bin, "bcryptprimitives.dll"),
                        os.path.join(HELPERS, "bcryptprimitives.c"),
                        os.path.join(HELPERS, "bcryptprimitives.def"), "-ladvapi32"], check=True)
        self.fake_python = os.path.join(self.bin, "fake_python.exe")
        subprocess.run([MINGW_GCC, "-O2", "-o", self.fake_python,
                        os.path.join(HELPERS, "fake_python.c")], check=True)
        log("creating a Wine prefix (wineboot)")
        subprocess.run(["wineboot", "--init"], env=self.env, capture_output=True, timeout=300)

    def path(self, unix_path):
        """The Windows path Wine's Z: drive gives a Unix path."""
        return "Z:" + os.path.abspath(unix_path).replace("/", "\\")

    def run(self, args, cwd, env=None, timeout=900):
        return subprocess.run(["wine", self.exe, *args], cwd=cwd, capture_output=True,
                              text=True, encoding="utf-8", errors="replace", timeout=timeout,
                              env=dict(self.env, **(env or {})))

    def popen(self, args, cwd, env=None, stdout=subprocess.PIPE):
        return subprocess.Popen(["wine", self.exe, *args], cwd=cwd, stdout=stdout,
                                stderr=subprocess.STDOUT, text=True, encoding="utf-8",
                                errors="replace", env=dict(self.env, **(env or {})))

    def temp_dirs(self, prefix):
        drive = os.path.join(self.env["WINEPREFIX"], "drive_c", "users")
        found = []
        for base, dirs, _ in os.walk(drive):
            found += [os.path.join(base, d) for d in dirs if d.startswith(prefix)]
        return found

    def close(self):
        subprocess.run(["wineserver", "-k"], env=self.env, capture_output=True)


def check_imports(exe):
    objdump = "x86_64-w64-mingw32-objdump" if shutil.which("x86_64-w64-mingw32-objdump") \
        else "objdump"
    out = subprocess.run([objdump, "-p", exe], capture_output=True, text=True)
    dlls = sorted({m.group(1) for m in re.finditer(r"DLL Name: (\S+)", out.stdout)},
                  key=str.lower)
    extra = [d for d in dlls if not SYSTEM_DLLS.match(d)]
    check(out.returncode == 0 and dlls and not extra,
          f"imports Windows' own DLLs only ({', '.join(dlls) or 'none read'})"
          + (f"; would need {', '.join(extra)} beside it" if extra else ""))


def entries(path):
    with zipfile.ZipFile(path) as z:
        return {i.filename: z.read(i.filename) for i in z.infolist()}


def compare_bases(name, linux_base, windows_base):
    """Every entry of the two bases byte-identical."""
    a, b = entries(linux_base), entries(windows_base)
    if not check(sorted(a) == sorted(b), f"{name}: the same {len(a)} entries"):
        return
    differ = [k for k in a if a[k] != b[k]]
    check(not differ, f"{name}: every entry byte-identical to the Linux bake"
          + (f" (differ: {', '.join(differ)})" if differ else ""))


def check_bakes(wine, linux, work):
    cases = [
        ("P1 table, transfer table", os.path.join(ROOT, "data", "scenes", "table.msh"),
         ["--material", "oak", "--modes", "20", "--transfer-h", "0.01",
          "--transfer-order", "1", "--transfer-modes", "300"]),
        ("P2 mesh, single precision", os.path.join(ROOT, "data", "meshes", "fv32_p2_h1.msh"),
         ["--material", "steel", "--modes", "12", "--f32"]),
    ]
    folder = os.path.join(work, "bases für Windows")
    os.makedirs(folder)
    # A larger P2 mesh, meshed by gmsh (the Linux program) from the committed asset: 50k dofs.
    hp = os.path.join(work, "hp_body.msh")
    p = subprocess.run([linux, "mesh", os.path.join(ROOT, "data", "assets", "hp_body.obj"),
                        "--mesher", "gmsh", "-o", hp], capture_output=True, text=True)
    if check(p.returncode == 0, "hp_body.obj meshed at order 2 by gmsh (the Linux program)"):
        cases.append(("P2 hp_body, 50k dofs", hp, ["--material", "abs", "--modes", "20"]))
    else:
        log(p.stderr[-2000:])
    for name, mesh, opts in cases:
        stem = os.path.splitext(os.path.basename(mesh))[0]
        local = os.path.join(folder, os.path.basename(mesh))
        shutil.copy2(mesh, local)
        lin, win = os.path.join(folder, stem + ".linux.modes"), os.path.join(folder, stem + ".modes")
        p = subprocess.run([linux, "bake", local, "-o", lin, *opts], capture_output=True,
                           text=True)
        if not check(p.returncode == 0, f"{name}: the Linux program bakes it"):
            log(p.stderr[-2000:])
            continue
        t = time.monotonic()
        p = wine.run(["bake", wine.path(local), "-o", wine.path(win), *opts], cwd=folder)
        if not check(p.returncode == 0 and os.path.isfile(win),
                     f"{name}: modal-bake.exe bakes it under Wine "
                     f"({time.monotonic() - t:.1f} s, into a folder named 'bases für Windows')"):
            log((p.stdout + p.stderr)[-2000:])
            continue
        compare_bases(name, lin, win)
        p = subprocess.run([linux, "check", local, win, *opts], capture_output=True, text=True)
        check(p.returncode == 0, f"{name}: the Linux program's `check` finds the Windows base "
                                 f"up to date (exit {p.returncode})")
        glb_l, glb_w = os.path.join(folder, stem + ".linux.glb"), os.path.join(folder, stem + ".glb")
        pl = subprocess.run([linux, "export", lin, "--gltf", glb_l], capture_output=True)
        pw = wine.run(["export", wine.path(win), "--gltf", wine.path(glb_w)], cwd=folder)
        if pl.returncode != 0 or pw.returncode != 0 or not os.path.isfile(glb_w):
            check(False, f"{name}: `export --gltf` runs on both")
            continue
        with open(glb_l, "rb") as fl, open(glb_w, "rb") as fw:
            same = fl.read() == fw.read()
        check(same, f"{name}: `export --gltf` byte-identical to the Linux export")


def start_hanging_mesher(wine, folder, what, stdout=subprocess.PIPE):
    """Starts `modal-bake.exe mesh` on the committed hp_body.obj with the stand-in Python
    (output to `stdout`) and waits until the mesher runs in its work folder: (process, work
    folders), or None."""
    os.makedirs(folder)
    asset = os.path.join(folder, "hp_body.obj")
    shutil.copy2(os.path.join(ROOT, "data", "assets", "hp_body.obj"), asset)
    before = set(wine.temp_dirs("modal-bake-"))
    proc = wine.popen(["mesh", wine.path(asset), "--mesher", "gmsh", "-o",
                       wine.path(os.path.join(folder, "hp_body.msh"))], cwd=folder,
                      env={"MODAL_BAKE_PYTHON": wine.path(wine.fake_python)}, stdout=stdout)
    # Wait for the mesher's work folder: the stand-in Python then hangs in the meshing run.
    work_dirs, deadline = [], time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        work_dirs = sorted(set(wine.temp_dirs("modal-bake-")) - before)
        if work_dirs:
            break
        time.sleep(0.5)
    if not check(bool(work_dirs), f"{what}: modal-bake.exe starts the mesher in a work folder"):
        proc.kill()
        log((proc.communicate()[0] or "")[-2000:])
        return None
    time.sleep(1.0)
    return proc, work_dirs


def check_interrupt(wine, work):
    """Ctrl-C while the (stand-in) gmsh Python runs: the child ends, its work folder goes, no
    output, STATUS_CONTROL_C_EXIT."""
    folder = os.path.join(work, "interrupt")
    failed_before = len(failures)
    started = start_hanging_mesher(wine, folder, "interrupt")
    if started is None:
        return
    proc, work_dirs = started
    children = fake_python_pids()
    os.kill(proc.pid, signal.SIGINT)
    try:
        text = proc.communicate(timeout=60)[0]
    except subprocess.TimeoutExpired:
        proc.kill()
        text = proc.communicate()[0]
    time.sleep(1.0)
    check(proc.returncode == STATUS_CONTROL_C_EXIT & 0xFF,
          f"interrupt: exit status 0x{STATUS_CONTROL_C_EXIT:X} (Wine reports its low byte, "
          f"{STATUS_CONTROL_C_EXIT & 0xFF}; got {proc.returncode})")
    check(bool(children) and not (set(children) & set(fake_python_pids())),
          f"interrupt: the mesher child ended with it ({len(children)} running before)")
    check(not any(os.path.exists(d) for d in work_dirs),
          "interrupt: the mesher's work folder removed")
    check(not [n for n in os.listdir(folder) if n != "hp_body.obj"],
          f"interrupt: nothing written beside the asset ({sorted(os.listdir(folder))})")
    if len(failures) > failed_before:
        log(text[-2000:])


def check_hard_kill(wine, work):
    """modal-bake.exe ended from outside (TerminateProcess: here SIGKILL of its Wine process)
    while the stand-in Python runs: the mesher ends with it (the job object). Its output goes to
    a file: under Wine a child holding a pipe whose reader is gone ends anyway, which would
    hide a missing job."""
    with open(os.path.join(work, "hard_kill.log"), "w", encoding="utf-8") as out:
        started = start_hanging_mesher(wine, os.path.join(work, "hard_kill"), "hard kill", out)
        if started is None:
            return
        proc = started[0]
        children = fake_python_pids()
        proc.kill()
        proc.wait()
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline and set(children) & set(fake_python_pids()):
        time.sleep(0.5)
    check(bool(children) and not (set(children) & set(fake_python_pids())),
          f"hard kill: the mesher child ended with modal-bake.exe ({len(children)} running "
          "before)")
    for pid in fake_python_pids():
        os.kill(pid, signal.SIGKILL)


def fake_python_pids():
    """The processes running the stand-in Python (Wine runs each Windows process as a Linux
    one whose command line names the program)."""
    pids = []
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                if b"fake_python.exe" in f.read():
                    pids.append(int(pid))
        except OSError:
            pass
    return pids


def check_missing_python(wine, work):
    folder = os.path.join(work, "nopython")
    os.makedirs(folder)
    asset = os.path.join(folder, "hp_body.obj")
    shutil.copy2(os.path.join(ROOT, "data", "assets", "hp_body.obj"), asset)
    p = wine.run(["mesh", wine.path(asset), "--mesher", "gmsh", "-o",
                  wine.path(os.path.join(folder, "hp_body.msh"))], cwd=folder)
    text = p.stdout + p.stderr
    check(p.returncode == 1 and re.search(r"\bpython\b", text) is not None
          and "python3" not in text and os.listdir(folder) == ["hp_body.obj"],
          f"no Python: exit 1, the error names `python` (Windows' name), nothing written "
          f"(exit {p.returncode})")
    if p.returncode != 1:
        log(text[-2000:])


def check_capi(wine, work, win_lib, linux_lib, linux):
    """The world example against the Windows DLL and static library, under Wine, against the
    same example on the Linux library."""
    include = os.path.join(ROOT, "crates", "dcr-capi", "include")
    example = os.path.join(ROOT, "crates", "dcr-capi", "examples", "world.c")
    missing = [p for p in (os.path.join(win_lib, "dcr_capi.dll"),
                           os.path.join(win_lib, "libdcr_capi.dll.a"),
                           os.path.join(win_lib, "libdcr_capi.a"),
                           os.path.join(linux_lib, "libdcr_capi.so")) if not os.path.isfile(p)]
    if not check(not missing, "C library: the Windows and Linux builds are there"
                 + (f" (missing {', '.join(missing)}: bash scripts/build_windows.sh; cargo "
                    "build --release -p dcr-capi; or name the Linux library with --linux-lib)"
                    if missing else "")):
        return
    folder = os.path.join(work, "capi")
    os.makedirs(folder)
    base = os.path.join(folder, "cube.modes")
    subprocess.run([linux, "bake", os.path.join(ROOT, "data", "meshes", "cube_v41.msh"), "-o",
                    base, "--modes", "8"], check=True, capture_output=True)
    world = os.path.join(folder, "world")
    subprocess.run(["cc", "-std=c99", "-O2", "-I", include, example, "-L", linux_lib,
                    "-ldcr_capi", "-lm", f"-Wl,-rpath,{linux_lib}", "-o", world], check=True)
    ref = subprocess.run([world, base, "10"], capture_output=True, text=True)
    if not check(ref.returncode == 0 and ref.stdout.count("\nevent ") == 1,
                 "C library: the Linux world example runs (10 steps, one event)"):
        log(ref.stdout[-1000:] + ref.stderr[-1000:])
        return
    shutil.copy2(os.path.join(win_lib, "dcr_capi.dll"), wine.bin)
    builds = {
        "dcr_capi.dll": ["-L", win_lib, "-ldcr_capi"],
        "libdcr_capi.a": [os.path.join(win_lib, "libdcr_capi.a"), "-lws2_32", "-luserenv",
                          "-lntdll"],
    }
    for what, link in builds.items():
        exe = os.path.join(wine.bin, f"world_{what.split('.')[0]}_{what.split('.')[1]}.exe")
        p = subprocess.run([MINGW_GCC, "-std=c99", "-O2", "-I", include, example, *link, "-o",
                            exe], capture_output=True, text=True)
        if not check(p.returncode == 0, f"C library: world.c builds against {what}"):
            log(p.stderr[-2000:])
            continue
        p = subprocess.run(["wine", exe, wine.path(base), "10"], capture_output=True, text=True,
                           env=wine.env)
        out = p.stdout.replace("\r\n", "\n")
        check(p.returncode == 0 and out == ref.stdout,
              f"C library: world.exe on {what} prints what the Linux build prints "
              f"({len(ref.stdout.splitlines())} lines)")


def check_tests(wine):
    """The Windows test programs of dcr-files, dcr-runtime and modal-bake, under Wine."""
    built = subprocess.run(["bash", os.path.join(ROOT, "scripts", "build_windows.sh"),
                            "--tests"], capture_output=True, text=True)
    programs = [line.split("\t") for line in built.stdout.splitlines()[1:] if "\t" in line]
    if not check(built.returncode == 0 and programs,
                 f"tests: {len(programs)} Windows test programs built"):
        log(built.stderr[-3000:])
        return
    # The test programs and the modal-bake.exe they start find the ProcessPrng stand-in on
    # WINEPATH. No Python runs here, so the tests that require one under CI are told not to.
    env = {k: v for k, v in wine.env.items() if k != "CI" and not k.startswith("DCR_REQUIRE_")}
    env.update(WINEPATH=wine.path(wine.bin),
               WINEDLLOVERRIDES=wine.env["WINEDLLOVERRIDES"] + ";bcryptprimitives=n,b")
    for folder, program in programs:
        name = f"{os.path.basename(folder)}/{os.path.basename(program).rsplit('-', 1)[0]}"
        start = time.monotonic()
        note = ""
        try:
            p = run_test_program(program, folder, env)
            if p.returncode != 0 and WINE_SPAWN_FAILURE in p.stdout:
                # Wine's process creation fails now and then (STATUS_INTERNAL_ERROR) when a
                # test starts hundreds of modal-bake.exe: the program runs once more, and the
                # check says so; a second failure of any kind fails it.
                log(f"{name}: Wine could not start a process ({WINE_SPAWN_FAILURE}); once more")
                log(p.stdout[-1500:])
                note = "; second run, the first hit Wine's process-creation error"
                p = run_test_program(program, folder, env)
        except subprocess.TimeoutExpired:
            check(False, f"tests: {name} ended within 30 min")
            continue
        summary = [line for line in p.stdout.splitlines()
                   if line.startswith("test result:") or re.match(r"^\S+: \d+ passed$", line)]
        if not check(p.returncode == 0 and summary,
                     f"tests: {name} under Wine ({(summary or ['no summary'])[-1]}; "
                     f"{time.monotonic() - start:.0f} s{note})"):
            log((p.stdout + p.stderr)[-4000:])


# What a test prints when Wine refused to start a process: CreateProcess's ERROR_INTERNAL_ERROR.
WINE_SPAWN_FAILURE = 'Os { code: 1359, kind: Uncategorized, message: "Internal error." }'


def run_test_program(program, folder, env):
    """One test program under Wine, from its package's folder, as `cargo test` runs it."""
    return subprocess.run(["wine", program], cwd=folder, env=env, capture_output=True,
                          text=True, encoding="utf-8", errors="replace", timeout=1800,
                          stdin=subprocess.DEVNULL)


def check_package(exe, work, version):
    try:
        import bpy  # noqa: F401  (the builder comes with it)
    except ImportError:
        if os.environ.get("DCR_REQUIRE_BPY") == "1":
            check(False, "package: bpy is not installed (DCR_REQUIRE_BPY=1)")
        else:
            log("skip package: bpy is not installed (pip install bpy==4.5.7)")
        return
    out = os.path.join(work, "package")
    p = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "package_blender_addon.py"),
                        "--binary", exe, "--out", out], capture_output=True, text=True)
    zpath = p.stdout.strip().splitlines()[-1] if p.stdout.strip() else ""
    if not check(p.returncode == 0 and zpath.endswith(f"modal_bake-{version}-windows_x64.zip"),
                 f"package: built and validated by Blender's builder ({os.path.basename(zpath)})"):
        log((p.stdout + p.stderr)[-3000:])
        return
    with zipfile.ZipFile(zpath) as z:
        names = z.namelist()
        manifest = z.read("blender_manifest.toml").decode("utf-8")
        exe_bytes = z.read("bin/modal-bake.exe") if "bin/modal-bake.exe" in names else b""
    wheels = [n for n in names if n.startswith("wheels/")]
    check(exe_bytes[:2] == b"MZ" and "bin/modal-bake" not in names,
          "package: bin/modal-bake.exe is the Windows program")
    check(len(wheels) == 2 and all(w.endswith("win_amd64.whl") for w in wheels),
          f"package: Windows wheels ({', '.join(os.path.basename(w) for w in wheels)})")
    check('platforms = ["windows-x64"]' in manifest, "package: manifest platforms windows-x64")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n", 1)[1])
    ap.add_argument("--exe", default=os.path.join(TARGET_DIR, "x86_64-pc-windows-gnu", "release",
                                                  "modal-bake.exe"),
                    help="the Windows program (default: what scripts/build_windows.sh builds)")
    ap.add_argument("--linux", default=os.path.join(TARGET_DIR, "release", "modal-bake"),
                    help="the Linux program of the same sources (cargo build --release -p "
                         "modal-bake)")
    ap.add_argument("--linux-lib", default=None,
                    help="the Linux C library of the same sources, libdcr_capi.so (default: "
                         "beside --linux, where `cargo build --release -p dcr-capi` puts it; "
                         "`cargo test` leaves it in release/deps)")
    ap.add_argument("--no-tests", action="store_true",
                    help="skip the test programs under Wine (they are built first: minutes "
                         "on a cold target)")
    ap.add_argument("--no-package", action="store_true",
                    help="skip the Blender package check")
    a = ap.parse_args()
    for path, how in ((a.exe, "bash scripts/build_windows.sh"),
                      (a.linux, "cargo build --release -p modal-bake")):
        if not os.path.isfile(path):
            print(f"error: no {path}: build it with `{how}`", file=sys.stderr)
            return 2
    if a.linux_lib and os.path.basename(a.linux_lib) != "libdcr_capi.so":
        print(f"error: --linux-lib {a.linux_lib}: expected a file named libdcr_capi.so (the C "
              "example links it as -ldcr_capi)", file=sys.stderr)
        return 2
    ensure_tools()
    version = source_version()
    with tempfile.TemporaryDirectory(prefix="dcr_windows_") as work:
        check_imports(a.exe)
        wine = Wine(work, a.exe)
        try:
            p = wine.run(["--version"], cwd=work, timeout=300)
            check(p.stdout.strip() == f"modal-bake {version}",
                  f"--version answers `modal-bake {version}` ({p.stdout.strip() or p.stderr[-300:]})")
            check_bakes(wine, os.path.abspath(a.linux), work)
            check_interrupt(wine, work)
            check_hard_kill(wine, work)
            check_missing_python(wine, work)
            linux_lib = (os.path.dirname(os.path.abspath(a.linux_lib)) if a.linux_lib
                         else os.path.dirname(os.path.abspath(a.linux)))
            check_capi(wine, work, os.path.dirname(os.path.abspath(a.exe)), linux_lib,
                       os.path.abspath(a.linux))
            if not a.no_tests:
                check_tests(wine)
        finally:
            wine.close()
        if not a.no_package:
            check_package(os.path.abspath(a.exe), work, version)
    if failures:
        log(f"{len(failures)} check(s) failed")
        return 1
    log("every check passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
