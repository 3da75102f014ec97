#!/usr/bin/env python3
"""Hostile-input campaign against the `modal-bake`, `dcr-scenes` and `dcr-lab` binaries.

Surfaces (`--surfaces`, all by default):
  volume   mutated MSH 2.2/4.1 ASCII and binary and meshio JSON through `bake` and `check`
  modes    mutated `.modes` archives through `info`, `geodesic` and `probe`
  options  abusive `bake` options
  export   `modal-bake export` to the input (three spellings), FIFOs, folders, one path twice,
           and abusive export options
  surface  mutated OBJ / STL / PLY assets (and files that must be refused: two STL solids,
           PLY faces beyond the header's count, FIFOs) through `bake` (gmsh meshes them)
  scenes   mutated scene files (every field given hostile values) and hostile outputs through
           `dcr-scenes run`
  lab      abusive `dcr-lab truth` / `fit-attenuation` options and `accuracy` with bad roots
  batch    mutated `modal-bake batch` manifests (JSON and TOML: missing, unknown and repeated
           keys, wrong types, absurd counts and values, outputs that are inputs, devices,
           FIFOs, folders or another entry's output, meshes that are devices or FIFOs, bad
           --shard / --jobs / --report), valid manifests run twice at once on one folder,
           and runs SIGKILLed mid-bake and resumed
Each run is under a memory cap (`ulimit -v 4000000`, 4 GB of address space) and a timeout,
and is classified:

  panic      exit 101
  abort      killed by a signal (SIGABRT on a failed allocation, SIGSEGV, ...) or timed out
  misread    exit 0 on a mesh mutation that must be refused (a repeated section, a
             permuted duplicate tetrahedron, an extra value, a negative tag) with node/tet
             counts or mass other than the unmutated mesh's
  leftover   a failed run left a file in its output folder
  clobber    an input, a FIFO or another output was replaced or changed
  unlocated  a refusal whose message does not name the file and a location in it (a line,
             byte, element / node / vertex number, archive entry, JSON index, section or
             option name; see LOCATED)
  refused    a clean refusal;  ok  exit 0 (a mutation that still reads)

Usage (from the repository root, after
`cargo build --release -p modal-bake -p dcr-scenes -p dcr-lab`):
    python3 scripts/hostile_campaign.py [--runs N] [--seed S] [--surfaces a,b] [--json FILE]
Exit status 1 when any run is a panic, abort, misread, clobber, leftover or unlocated refusal.
Totals are printed per surface.
"""

import argparse
import json
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TARGET = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
BIN = os.path.join(TARGET, "release", "modal-bake")
SCENES_BIN = os.path.join(TARGET, "release", "dcr-scenes")
LAB_BIN = os.path.join(TARGET, "release", "dcr-lab")
TIMEOUT = 60
# Where in the input a refusal points: a line (`file:12:` or `line 12`), a byte offset, an
# element / node / tetrahedron / triangle / vertex number, an archive entry or JSON key by
# name (`entry `modes``, `"points"[3]`), a section by name (`$Nodes`), or an option
# (`--modes`) or the library parameter it sets (`parameter `modes``). Every refusal must also name the file (checked separately).
LOCATED = re.compile(
    r"(:\d+:|\bline \d+|\bbyte \d+|\boffset \d+|\b(element|node|tetrahedron|tet|"
    r"triangle|vertex|edge|group|mode) `?[\w.-]+|\bentry `[^`]+`|\[\d+\]|\$[A-Z][A-Za-z]+|"
    r"--[a-z][a-z-]*|\bparameter `[\w.]+`)")

MESHES = ["cube_v22.msh", "cube_v41.msh", "cube_v22_bin.msh", "cube_v41_bin.msh",
          "cube_cell_sets.json"]
MUST_REFUSE = {"section duplicated", "permuted duplicate tet", "extra token", "negative tag"}


def run(args, cwd, binary=None):
    """Runs a binary (default `modal-bake`) under the memory cap and timeout:
    (returncode, stdout, stderr)."""
    cmd = "ulimit -v 4000000; exec " + " ".join(
        "'%s'" % a.replace("'", "'\\''") for a in [binary or BIN] + args)
    try:
        p = subprocess.run(["bash", "-c", cmd], cwd=cwd, capture_output=True, timeout=TIMEOUT,
                           env=dict(os.environ, DCR_ROOT=ROOT))
        return p.returncode, p.stdout.decode("utf8", "replace"), p.stderr.decode("utf8", "replace")
    except subprocess.TimeoutExpired:
        return "timeout", "", ""


def mutate_mesh(rng, data, name):
    """One mutation: (bytes, what)."""
    b = bytearray(data)
    ascii_ = name.endswith(".json") or b"\0" not in data[:4000]
    text = data.decode("latin1")
    kind = rng.choice(["flip", "truncate", "section duplicated", "huge number", "negative tag",
                       "extra token", "nan", "permuted duplicate tet"])
    if kind == "flip":
        for _ in range(rng.randint(1, 4)):
            i = rng.randrange(len(b))
            b[i] ^= rng.randint(1, 255)
        return bytes(b), kind
    if kind == "truncate":
        return bytes(b[:rng.randrange(len(b))]), kind
    if kind == "section duplicated" and name.endswith(".msh"):
        secs = [(m.start(), m.end()) for m in
                re.finditer(r"(?s)\n(\$(Nodes|Elements|Entities|PhysicalNames)\n.*?\$End\2\n)", text)]
        if secs:
            s, e = rng.choice(secs)
            return data + data[s + 1:e], kind
    toks = [m.span() for m in re.finditer(r"(?<![\w.])-?\d+(\.\d+)?(e-?\d+)?(?![\w.])", text)] \
        if ascii_ else []
    if kind == "negative tag" and name.endswith(".msh") and ascii_:
        # A tag: the first field of a node or element line, or an element's last (node) field.
        lines = text.split("\n")
        data_lines = []
        section = None
        for i, line in enumerate(lines):
            if line.startswith("$"):
                section = line
            elif section in ("$Nodes", "$Elements") and len(line.split()) >= 4:
                data_lines.append((i, section))
        if data_lines:
            i, section = rng.choice(data_lines)
            f = lines[i].split()
            k = rng.choice([0, len(f) - 1]) if section == "$Elements" else 0
            if f[k].lstrip("-").isdigit() and not f[k].startswith("-"):
                f[k] = "-" + f[k]
                lines[i] = " ".join(f)
                return "\n".join(lines).encode("latin1"), kind
        return data, "unchanged"
    if kind in ("huge number", "nan") and toks:
        s, e = rng.choice(toks)
        rep = {"huge number": rng.choice(["1e308", "18446744073709551616", "2147483648", "1e999"]),
               "nan": rng.choice(["nan", "inf", "-inf"]),
               "negative tag": "-" + text[s:e].lstrip("-")}[kind]
        if kind == "negative tag" and text[s:e].startswith("-"):
            return data, "unchanged"
        return (text[:s] + rep + text[e:]).encode("latin1"), kind
    if kind == "extra token" and ascii_ and name.endswith(".msh"):
        lines = text.split("\n")
        start = lines.index("$Elements") if "$Elements" in lines else -1
        cands = [i for i in range(start + 2, len(lines)) if lines[i] and not lines[i].startswith("$")]
        if start >= 0 and cands:
            i = rng.choice(cands)
            lines[i] += " 7"
            return "\n".join(lines).encode("latin1"), kind
    if kind == "permuted duplicate tet" and name == "cube_v22.msh":
        lines = text.split("\n")
        start = lines.index("$Elements")
        tets = [i for i in range(start + 2, len(lines)) if len(lines[i].split()) > 6
                and lines[i].split()[1] == "4"]
        i = rng.choice(tets)
        f = lines[i].split()
        f[-1], f[-2] = f[-2], f[-1]
        f[0] = "999999"
        lines.insert(i + 1, " ".join(f))
        lines[start + 1] = str(int(lines[start + 1]) + 1)
        return "\n".join(lines).encode("latin1"), kind
    i = rng.randrange(len(b))
    b[i] ^= 0x40
    return bytes(b), "flip"


def mutate_modes(rng, data):
    b = bytearray(data)
    heads = [m.start() for m in re.finditer(b"\x93NUMPY", data)]
    kind = rng.choice(["flip", "truncate", "npy header length", "npy shape", "nan word",
                       "zip count"])
    if kind == "npy header length" and heads:
        at = rng.choice(heads)
        b[at + 6] = 2
        b[at + 8:at + 12] = (0xFFFFFFF0).to_bytes(4, "little")
    elif kind == "npy shape" and heads:
        at = rng.choice(heads)
        p = data.find(b"(", at, at + 128)
        if p > 0:
            b[p + 1:p + 1] = b"100000000000"
    elif kind == "nan word":
        at = rng.randrange(len(b) - 8) & ~7
        b[at:at + 8] = rng.choice([b"\x00\x00\x00\x00\x00\x00\xf8\x7f", b"\x00" * 7 + b"\xf0"])
    elif kind == "zip count":
        e = data.rfind(b"PK\x05\x06")
        b[e + 8:e + 12] = b"\xff\xff\xff\xff"
    elif kind == "truncate":
        b = b[:rng.randrange(len(b))]
    else:
        for _ in range(rng.randint(1, 4)):
            i = rng.randrange(len(b))
            b[i] ^= rng.randint(1, 255)
    return bytes(b), kind


def counts(stdout):
    try:
        v = json.loads(stdout)
        return v.get("nodes"), v.get("tets"), round(v.get("mass_kg", 0), 9)
    except (ValueError, AttributeError):
        return None


class Campaign:
    """Totals per surface and class, and the bad runs."""

    def __init__(self):
        self.totals, self.bad, self.surface = {}, [], "volume"

    def record(self, cls, what):
        per = self.totals.setdefault(self.surface, {})
        per[cls] = per.get(cls, 0) + 1
        if cls not in ("ok", "refused"):
            self.bad.append({"surface": self.surface, "class": cls, **what})

    def classify(self, code, err, name, outdir, expect_out, what, must_refuse=False,
                 model_ok=True, need_location=True):
        left = [f for f in os.listdir(outdir) if f not in expect_out] if outdir else []
        if code == 101 or "panicked" in err:
            return self.record("panic", dict(what, stderr=err[-300:]))
        if code == "timeout":
            return self.record("hang", what)
        if isinstance(code, int) and (code < 0 or code > 128):
            return self.record("abort", what)
        if code == 0:
            if must_refuse or not model_ok:
                return self.record("misread", what)
            return self.record("ok", what)
        if left:
            return self.record("leftover", dict(what, files=left))
        whole_file = re.search(r"separate closed shells|holds no triangles|not a regular file", err)
        if need_location and (name not in err or not (LOCATED.search(err) or whole_file)):
            return self.record("unlocated", dict(what, stderr=err[-300:]))
        # (`error:` as a word: an option named `--target-error:` is not a second error.)
        if len(re.findall(r"(?<![\w-])error:", err)) > 1 or "{ " in err and " }" in err:
            # A cause printed twice, or Rust `Debug` text in the message.
            return self.record("unclear", dict(what, stderr=err[-300:]))
        return self.record("refused", what)


def volume_and_modes(c, rng, runs, work):
    """The original surfaces: mutated volume meshes, `.modes` archives, bake options."""
    ref = {}
    for m in MESHES:
        out = os.path.join(work, "ref.modes")
        code, so, se = run(["bake", os.path.join(ROOT, "data", "meshes", m), "-o", out,
                            "--modes", "4", "--json"], work)
        ref[m] = counts(so)
    base = os.path.join(work, "ref.modes")
    base_bytes = open(base, "rb").read()
    c.surface = "volume"
    for i in range(runs):
        m = MESHES[i % len(MESHES)]
        data = open(os.path.join(ROOT, "data", "meshes", m), "rb").read()
        mutated, kind = mutate_mesh(rng, data, m)
        case = os.path.join(work, "case%d" % i)
        os.makedirs(case)
        path = os.path.join(case, "mesh_" + m)
        open(path, "wb").write(mutated)
        outdir = os.path.join(case, "out")
        os.makedirs(outdir)
        out = os.path.join(outdir, "x.modes")
        what = {"input": m, "mutation": kind, "cmd": "bake"}
        code, so, se = run(["bake", path, "-o", out, "--modes", "4", "--json"], case)
        # A mutation that must be refused and was not is a misread when the model differs
        # from the unmutated one (a "-0" entity tag, say, leaves it the same).
        model_ok = code != 0 or kind not in MUST_REFUSE or counts(so) == ref[m]
        c.classify(code, se, os.path.basename(path), outdir,
                   {"x.modes"} if code == 0 else set(), what, model_ok=model_ok)
        code, so, se = run(["check", path, base, "--modes", "4"], case)
        if code not in (0, 1):
            c.classify(code, se, os.path.basename(path), outdir, set(os.listdir(outdir)),
                       dict(what, cmd="check"))
        else:
            c.record("ok", what)
        shutil.rmtree(case)

    c.surface = "modes"
    for i in range(runs):
        mutated, kind = mutate_modes(rng, base_bytes)
        case = os.path.join(work, "m%d" % i)
        os.makedirs(case)
        path = os.path.join(case, "base.modes")
        open(path, "wb").write(mutated)
        sub = [["info", path, "--json"], ["geodesic", path, "--from-vertex", "3", "--json"],
               ["probe", path, "--impact", "0.5,0.5,1", "--impulse", "1", "--contact",
                "0.2,0.3,1", "--json"]][i % 3]
        code, so, se = run(sub, case)
        c.classify(code, se, "base.modes", case, set(os.listdir(case)),
                   {"input": "cube.modes", "mutation": kind, "cmd": sub[0]})
        shutil.rmtree(case)

    c.surface = "options"
    mesh = os.path.join(ROOT, "data", "meshes", "cube_v41.msh")
    abusive = [["--youngs", "1e308"], ["--density", "1e-300"], ["--modes", "100000"],
               ["--max-freq", "1e300"], ["--poisson", "0.5"], ["--rayleigh", "1e300,1e300"],
               ["--youngs", "nan"], ["--fixed", "nope"], ["--modes", "-1"],
               ["--youngs", "-1e9"], ["--rayleigh", "-1,0"], ["--max-freq", "-5"]]
    for opts in abusive:
        outdir = os.path.join(work, "opt")
        os.makedirs(outdir, exist_ok=True)
        code, so, se = run(["bake", mesh, "-o", os.path.join(outdir, "o.modes")] + opts, work)
        c.classify(code, se, "", outdir, {"o.modes"} if code == 0 else set(),
                   {"input": "cube_v41.msh", "mutation": " ".join(opts), "cmd": "bake"})
        if "unexpected argument" in se:
            c.record("unclear", {"mutation": " ".join(opts), "stderr": se[-200:]})
        shutil.rmtree(outdir)
    return base


def snapshot(paths):
    """(kind, bytes) of each path: a FIFO, a link, a folder or the file's content."""
    out = {}
    for p in paths:
        if os.path.islink(p):
            out[p] = ("link", os.readlink(p))
        elif not os.path.exists(p):
            out[p] = ("missing", None)
        else:
            st = os.stat(p)
            import stat as st_
            if st_.S_ISFIFO(st.st_mode):
                out[p] = ("fifo", None)
            elif st_.S_ISDIR(st.st_mode):
                out[p] = ("dir", None)
            elif st_.S_ISCHR(st.st_mode):
                out[p] = ("chr", None)
            else:
                out[p] = ("file", open(p, "rb").read())
    return out


def export_surface(c, rng, runs, work, base):
    """`modal-bake export` against hostile outputs and options."""
    c.surface = "export"
    options = ["--vtu", "--gltf", "--png"]
    for i in range(runs):
        case = os.path.join(work, "e%d" % i)
        os.makedirs(os.path.join(case, "sub"))
        b = os.path.join(case, "b.modes")
        shutil.copy(base, b)
        os.symlink(b, os.path.join(case, "link.modes"))
        os.mkfifo(os.path.join(case, "fifo"))
        targets = {"input": "b.modes", "respelled input": "./sub/../b.modes",
                   "link to input": "link.modes", "fifo": "fifo", "folder": "sub",
                   "dot": ".", "under a file": "b.modes/x", "device": "/dev/null",
                   "fine": "out.x"}
        kind = rng.choice(sorted(targets))
        opt = rng.choice(options)
        args = ["export", "b.modes", opt, targets[kind]]
        if rng.random() < 0.3:
            # The same path for two outputs.
            other = rng.choice([o for o in options if o != opt])
            args += [other, rng.choice([targets[kind], "./" + targets[kind]])]
            kind += " twice"
        if rng.random() < 0.3:
            extra = rng.choice([["--scale", "1e308"], ["--scale", "-1"], ["--scale", "nan"],
                                ["--modes", "0"], ["--modes", "99999999999"],
                                ["--columns", "0"], ["--columns", "100000"],
                                ["--scale", "-1e-5"]])
            args += extra
            kind += " " + " ".join(extra)
        watched = [os.path.join(case, f) for f in ("b.modes", "link.modes", "fifo", "sub")]
        before = snapshot(watched)
        code, so, se = run(args, case)
        after = snapshot(watched)
        what = {"mutation": kind, "cmd": " ".join(args)}
        if before != after or not os.path.exists("/dev/null") or \
                not os.path.exists("/dev/null") or os.path.isfile("/dev/null"):
            c.record("clobber", what)
        else:
            must = kind.split()[0] != "fine" or "twice" in kind
            expect = set(os.listdir(case)) if code != 0 else set(os.listdir(case))
            left = [f for f in os.listdir(case) if f.startswith(".") and "tmp" in f]
            if left:
                c.record("leftover", dict(what, files=left))
            else:
                c.classify(code, se, "", None, expect, what, must_refuse=must and
                           "fine" not in kind, need_location=False)
                if code not in (0, 101) and not re.search(r"--(vtu|gltf|png|scale|modes|columns)", se):
                    c.record("unlocated", dict(what, stderr=se[-200:]))
        shutil.rmtree(case)


CUBE_V = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
CUBE_Q = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (2, 3, 7, 6), (1, 2, 6, 5), (0, 4, 7, 3)]


def cube_assets(scale=0.1, dx=0.0):
    tris = [t for q in CUBE_Q for t in ((q[0], q[1], q[2]), (q[0], q[2], q[3]))]
    v = [(scale * x + dx, scale * y, scale * z) for x, y, z in CUBE_V]
    obj = "o cube\n" + "".join("v %r %r %r\n" % p for p in v) + \
        "".join("f %d %d %d %d\n" % tuple(i + 1 for i in q) for q in CUBE_Q)
    stl = "solid cube\n"
    for t in tris:
        stl += "facet normal 0 0 0\nouter loop\n" + "".join(
            "vertex %r %r %r\n" % v[i] for i in t) + "endloop\nendfacet\n"
    stl += "endsolid cube\n"
    ply = ("ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
           "property float z\nelement face 6\nproperty list uchar int vertex_indices\n"
           "end_header\n" + "".join("%r %r %r\n" % p for p in v) +
           "".join("4 %d %d %d %d\n" % q for q in CUBE_Q))
    return {"cube.obj": obj, "cube.stl": stl, "cube.ply": ply}


def surface_surface(c, rng, runs, work):
    """Mutated surface assets through `bake` (gmsh meshes them)."""
    c.surface = "surface"
    assets = cube_assets()
    two = cube_assets()["cube.stl"] + cube_assets(0.2, 1.0)["cube.stl"]
    for i in range(runs):
        name = rng.choice(sorted(assets))
        text = assets[name]
        kind = rng.choice(["flip", "truncate", "huge", "nan", "two solids", "ply surplus",
                           "stl variant", "fifo", "zero link", "scale"])
        must = False
        case = os.path.join(work, "s%d" % i)
        os.makedirs(os.path.join(case, "out"))
        path = os.path.join(case, name)
        opts = []
        if kind == "two solids":
            name, text, must = "two.stl", two, True
            path = os.path.join(case, name)
        elif kind == "ply surplus":
            name = "cube.ply"
            text = assets[name].replace("element face 6", "element face %d" % rng.randint(1, 5))
            path, must = os.path.join(case, name), True
        elif kind == "stl variant":
            name = "cube.stl"
            text = rng.choice([assets[name].upper(), "\n\n" + assets[name],
                               assets[name].replace("solid cube", "solid")])
            path = os.path.join(case, name)
        elif kind == "huge":
            toks = [m.span() for m in re.finditer(r"(?<![\w.])\d+\.\d+", text)]
            if toks:
                s_, e_ = rng.choice(toks)
                text = text[:s_] + rng.choice(["1e39", "1e308", "1e-300", "1e9"]) + text[e_:]
        elif kind == "nan":
            toks = [m.span() for m in re.finditer(r"(?<![\w.])\d+\.\d+", text)]
            if toks:
                s_, e_ = rng.choice(toks)
                text = text[:s_] + rng.choice(["nan", "inf"]) + text[e_:]
        elif kind == "truncate":
            text = text[:rng.randrange(len(text))]
        elif kind == "scale":
            opts = rng.choice([["--scale", "1e150"], ["--scale", "1e308"], ["--scale", "-1"],
                               ["--scale", "0"], ["--size", "-1"], ["--size", "1e-300"],
                               ["--scale", "nan"]])
        else:
            b = bytearray(text.encode())
            for _ in range(rng.randint(1, 3)):
                j = rng.randrange(len(b))
                b[j] ^= rng.randint(1, 255)
            text = bytes(b).decode("latin1")
        if kind == "fifo":
            os.mkfifo(path)
            must = True
        elif kind == "zero link":
            os.symlink("/dev/zero", path)
            must = True
        else:
            open(path, "w", encoding="latin1").write(text)
        out = os.path.join(case, "out", "x.modes")
        code, so, se = run(["bake", path, "-o", out, "--modes", "4"] + opts, case)
        c.classify(code, se, name, os.path.join(case, "out"),
                   {"x.modes"} if code == 0 else set(),
                   {"input": name, "mutation": kind + " " + " ".join(opts), "cmd": "bake"},
                   must_refuse=must, need_location=not opts and kind not in ("fifo", "zero link"))
        shutil.rmtree(case)


# Hostile values for scene fields (every value here must be refused).
HOSTILE = [-1, 0, 1e300, -1e300, 1e-300, float("nan"), "x", None, [], {}]
SCENE_FIELDS = [  # (path, values that must be refused)
    (["restitution"], [5, -1, 1e300]),
    (["h"], [0, -1, 1e-300, 1e300]),
    (["seconds"], [-1, 0, 1e7, 1e300]),
    (["gravity"], [[0, -1e300, 0], [0, 0]]),
    (["name"], ["../../x", "", ".", "/tmp/abs", "a/b", ".hidden"]),
    (["elastic", 0, "name"], ["../x", "", ".", "/abs"]),
    (["elastic", 0, "material", "youngs"], [0, -1, 1e300]),
    (["elastic", 0, "material", "poisson"], [0.5, -1, 2]),
    (["elastic", 0, "material", "density"], [0, -1]),
    (["elastic", 0, "modes"], [0, 100000]),
    (["elastic", 0, "rayleigh"], [[-1, 0], [0, -1]]),
    (["elastic", 0, "friction"], [-1, 1e300]),
    (["elastic", 0, "gain"], [-1, 1e300]),
    (["elastic", 0, "impact_threshold"], [-1]),
    (["elastic", 0, "pose", "translation"], [[1e300, 0, 0]]),
    (["props", 0, "mass"], [0, -1, 1e300]),
    (["props", 0, "friction"], [-1]),
    (["props", 0, "linvel"], [[1e300, 0, 0]]),
    (["props", 0, "angvel"], [[0, 1e300, 0]]),
    (["props", 0, "pose", "translation"], [[0, 1e300, 0]]),
    (["props", 0, "colliders", 0, "shape"], [{"ball": {"radius": -1}}, {"ball": {"radius": 0}},
                                             {"cuboid": {"half_extents": [0, 1, 1]}}]),
    (["props", 0, "colliders"], [[]]),
    (["props", 1, "name"], ["@dup"]),
    (["outcomes", 0, "kind"], ["max_lfit"]),
    (["outcomes", 0, "bodies"], ["ghost*"]),
    (["outcomes", 0, "threshold"], [0, -1]),
    (["props", 0, "unknown_field"], [1]),
]


def set_path(v, path, x):
    for k in path[:-1]:
        v = v[k]
    v[path[-1]] = x


def scenes_surface(c, rng, runs, work):
    """Mutated scene files and hostile outputs through `dcr-scenes run`."""
    c.surface = "scenes"
    if not os.path.exists(SCENES_BIN):
        print("skipping scenes: no", SCENES_BIN)
        return
    bases = os.path.join(work, "bases")
    roof = json.load(open(os.path.join(ROOT, "scenes", "roof.json")))
    for i in range(runs):
        case = os.path.join(work, "sc%d" % i)
        os.makedirs(case)
        v = json.loads(json.dumps(roof))
        args_extra = []
        must = True
        r = rng.random()
        if r < 0.6:
            path, values = rng.choice(SCENE_FIELDS)
            x = rng.choice(values)
            if x == "@dup":
                x = v["props"][0]["name"]
            set_path(v, path, x)
            kind = "%s = %s" % (".".join(map(str, path)), json.dumps(x))
        elif r < 0.85:
            gl = rng.choice(["s.json", "./sub/../s.json", "fifo", ".", "/dev/null", "out",
                             "out/summary.json"])
            args_extra = ["--gltf", gl]
            kind = "--gltf " + gl
        else:
            opt = rng.choice([["--seconds", "1e300"], ["--seconds", "-1"], ["--seconds", "nan"],
                              ["--gain", "-1"], ["--energy-eta", "2"], ["--beta", "-1"],
                              ["--seconds", "1e7"]])
            args_extra = opt
            kind = " ".join(opt)
        os.makedirs(os.path.join(case, "sub"))
        os.mkfifo(os.path.join(case, "fifo"))
        p = os.path.join(case, "s.json")
        open(p, "w").write(json.dumps(v))
        watched = [p, os.path.join(case, "fifo"), os.path.join(case, "sub")]
        before = snapshot(watched)
        code, so, se = run(["run", p, "--out", os.path.join(case, "out"), "--bases", bases,
                            "--seconds", "0.05", "--dcr", "off"] + args_extra, case,
                           binary=SCENES_BIN) if "--seconds" not in args_extra else \
            run(["run", p, "--out", os.path.join(case, "out"), "--bases", bases, "--dcr", "off"]
                + args_extra, case, binary=SCENES_BIN)
        after = snapshot(watched)
        what = {"mutation": kind, "cmd": "dcr-scenes run"}
        if before != after or os.path.isfile("/dev/null"):
            c.record("clobber", what)
        else:
            outdir = os.path.join(case, "out")
            left = os.listdir(outdir) if code != 0 and os.path.isdir(outdir) else []
            tmps = [f for f in os.listdir(bases) if ".tmp-" in f] if os.path.isdir(bases) else []
            if left or tmps:
                c.record("leftover", dict(what, files=left + tmps))
            else:
                c.classify(code, se, "", None, set(), what, must_refuse=must,
                           need_location=False)
                if code not in (0, 101) and not re.search(r"--[a-z]+|\w+(\[\d+\])?\.\w+|\bname\b|s\.json", se):
                    c.record("unlocated", dict(what, stderr=se[-200:]))
        shutil.rmtree(case)


def lab_surface(c, rng, runs, work):
    """Abusive `dcr-lab` options and report roots."""
    c.surface = "lab"
    if not os.path.exists(LAB_BIN):
        print("skipping lab: no", LAB_BIN)
        return
    mesh = os.path.join(ROOT, "data", "meshes", "cube_v41.msh")
    cases = [
        ["truth", mesh, "--impact", "0.5,0.5,1", "--contact", "0.2,0.3,1", "--max-dense-dofs",
         "1000000000", "--method", "modal-all"],
        ["truth", mesh, "--impact", "0.5,0.5,1", "--contact", "0.2,0.3,1", "--dt", "-1e-5"],
        ["truth", mesh, "--impact", "0.5,0.5,1", "--contact", "0.2,0.3,1", "--h", "1e300"],
        ["truth", mesh, "--impact", "0.5,0.5,1", "--contact", "0.2,0.3,1", "--tol", "-1"],
        ["truth", mesh, "--impact", "1e300,0,0", "--contact", "0.2,0.3,1"],
        ["truth", mesh, "--impact", "0.5,0.5,1", "--contact", "0.2,0.3,1", "--rayleigh", "-1,0"],
        ["fit-attenuation", mesh, "--max-dense-dofs", "99999999"],
        ["fit-attenuation", mesh, "--h", "-1"],
        ["truth", "/dev/zero", "--impact", "0,0,0", "--contact", "0,0,0"],
        ["accuracy", "--root", "/nonexistent/root", "--out", "@out", "--quick"],
        ["accuracy", "--root", "@case", "--out", "@out", "--quick"],
        ["accuracy", "--out", "/dev/null", "--quick"],
    ]
    for i in range(min(runs, 3 * len(cases))):
        case = os.path.join(work, "l%d" % i)
        os.makedirs(case)
        args = [a.replace("@out", os.path.join(case, "out")).replace("@case", case)
                for a in cases[i % len(cases)]]
        code, so, se = run(args, case, binary=LAB_BIN)
        what = {"mutation": " ".join(args[1:]), "cmd": "dcr-lab " + args[0]}
        left = os.listdir(case)
        if code != 0 and left:
            c.record("leftover", dict(what, files=left))
        else:
            c.classify(code, se, "", None, set(), what, must_refuse=True, need_location=False)
            if "unexpected argument" in se:
                c.record("unclear", dict(what, stderr=se[-200:]))
        shutil.rmtree(case)


def toml_of(v):
    """A manifest tree as TOML (the subset manifests use), or None when it has no TOML form."""
    def val(x):
        if isinstance(x, bool):
            return "true" if x else "false"
        if isinstance(x, (int, float)):
            return repr(x) if x == x and abs(x) != float("inf") else None
        if isinstance(x, str):
            return json.dumps(x)
        if isinstance(x, list):
            items = [val(i) for i in x]
            return None if None in items else "[" + ", ".join(items) + "]"
        return None
    if not isinstance(v, dict):
        return None
    out = []
    for k, x in v.items():
        if k == "entries" and isinstance(x, list) and all(isinstance(e, dict) for e in x):
            continue
        t = val(x)
        if t is None:
            return None
        out.append("%s = %s" % (json.dumps(k), t))
    for e in v.get("entries", []) if isinstance(v.get("entries"), list) else []:
        if not isinstance(e, dict):
            return None
        out.append("\n[[entries]]")
        opts = None
        for k, x in e.items():
            if k == "options" and isinstance(x, dict):
                opts = x
                continue
            t = val(x)
            if t is None:
                return None
            out.append("%s = %s" % (json.dumps(k), t))
        if opts is not None:
            out.append("[entries.options]")
            for k, x in opts.items():
                t = val(x)
                if t is None:
                    return None
                out.append("%s = %s" % (json.dumps(k), t))
    return "\n".join(out) + "\n"


# Manifest mutations: (name, function of (manifest, rng) -> (manifest or bytes, extra args)).
BATCH_FIELD = [
    ("missing mesh", lambda e: e.pop("mesh")),
    ("missing out", lambda e: e.pop("out")),
    ("unknown key", lambda e: e.__setitem__("outt", "x.modes")),
    ("mesh not a string", lambda e: e.__setitem__("mesh", 5)),
    ("out empty", lambda e: e.__setitem__("out", "")),
    ("options not a table", lambda e: e.__setitem__("options", "--modes 4")),
]
BATCH_OPTIONS = [
    {"modez": 4}, {"fixed_box": [0, 0, 0, 1, 1, 1]}, {"max-memory": 1000}, {"out": "y.modes"},
    {"target-error": 5}, {"modes": None}, {"modes": {"n": 3}}, {"modes": -1}, {"modes": 10.5},
    {"modes": 1e12}, {"modes": 0}, {"youngs": -5}, {"youngs": 1e308}, {"poisson": 0.5},
    {"density": 1e-300}, {"material": "cheese"}, {"modes": 3, "max-freq": 100},
    {"size": 0.1}, {"rayleigh": [1, 2, 3]}, {"rayleigh": [-1, 0]}, {"max-freq": -5},
    {"fixed-below": "w=3"}, {"fixed-box": [1, 1, 1, 0, 0, 0]}, {"transfer-h": -1},
    {"transfer-modes": 3}, {"units": "furlong"}, {"modes": "1e999"}, {"lumped": "yes"},
]
BATCH_PATHS = {  # out paths (relative to the case folder) that must be refused
    "out is the mesh": ("out", "mesh.msh"), "out respells the mesh": ("out", "./sub/../mesh.msh"),
    "out links the mesh": ("out", "link.msh"), "out is the manifest": ("out", "@manifest"),
    "out is a device": ("out", "/dev/null"), "out is a FIFO": ("out", "fifo"),
    "out is a folder": ("out", "sub"), "out under a file": ("out", "mesh.msh/x.modes"),
    "mesh is a device": ("mesh", "/dev/zero"), "mesh is a FIFO": ("mesh", "fifo"),
    "mesh links a device": ("mesh", "zero"), "mesh is a folder": ("mesh", "sub"),
    "mesh missing": ("mesh", "missing.msh"),
}
BATCH_ARGS = [["--shard", "3/3"], ["--shard", "0/0"], ["--shard", "-1/2"], ["--shard", "x"],
              ["--shard", "env:DCR_CAMPAIGN_UNSET/2"], ["--jobs", "0"], ["--jobs", "1000000"],
              ["--report", "@manifest"], ["--report", "mesh.msh"], ["--report", "fifo"],
              ["--report", "/dev/null"], ["--report", "sub"], ["--max-memory", "-1"],
              ["--max-time", "nan"]]


def batch_surface(c, rng, runs, work):
    """Mutated `modal-bake batch` manifests and options; valid ones run twice at once on one
    folder, or SIGKILLed mid-bake and resumed."""
    c.surface = "batch"
    src = os.path.join(ROOT, "data", "meshes", "cube_v41.msh")
    located = re.compile(r"entries\[\d+\]|--[a-z][a-z-]*|\bline \d+|\boffset \d+|\bentries\b|"
                         r"\bversion\b|\bkey `|MiB|\bmanifest\b")
    for i in range(runs):
        case = os.path.join(work, "b%d" % i)
        os.makedirs(os.path.join(case, "sub"))
        shutil.copy(src, os.path.join(case, "mesh.msh"))
        os.symlink(os.path.join(case, "mesh.msh"), os.path.join(case, "link.msh"))
        os.symlink("/dev/zero", os.path.join(case, "zero"))
        os.mkfifo(os.path.join(case, "fifo"))
        man = {"version": 1, "entries": [
            {"mesh": "mesh.msh", "out": "bases/a.modes", "options": {"modes": 4}},
            {"mesh": "mesh.msh", "out": "bases/b.modes", "options": {"modes": 3, "fixed": ["bottom"]}},
            {"mesh": "mesh.msh", "out": "bases/c.modes", "options": {"modes": 2, "material": "steel"}}]}
        extra, must, raw = [], True, None
        r = rng.random()
        if r < 0.2:
            name, f = rng.choice(BATCH_FIELD)
            f(rng.choice(man["entries"]))
            kind = name
        elif r < 0.45:
            o = rng.choice(BATCH_OPTIONS)
            rng.choice(man["entries"])["options"] = dict(o)
            kind = "options " + json.dumps(o)
        elif r < 0.65:
            kind = rng.choice(sorted(BATCH_PATHS))
            field, value = BATCH_PATHS[kind]
            rng.choice(man["entries"])[field] = value
        elif r < 0.72:
            kind = rng.choice(["duplicate out", "respelled duplicate out", "version 2",
                               "empty entries", "entries not an array", "top unknown key",
                               "absurd entry count", "top array"])
            if kind == "duplicate out":
                man["entries"][2]["out"] = man["entries"][0]["out"]
            elif kind == "respelled duplicate out":
                man["entries"][2]["out"] = "./sub/../" + man["entries"][0]["out"]
            elif kind == "version 2":
                man["version"] = 2
            elif kind == "empty entries":
                man["entries"] = []
            elif kind == "entries not an array":
                man["entries"] = man["entries"][0]
            elif kind == "top unknown key":
                man["jobs"] = 4
            elif kind == "absurd entry count":
                man["entries"] = [{"mesh": "mesh.msh", "out": "x%d.modes" % k}
                                  for k in range(100001)]
            else:
                man = man["entries"]
        elif r < 0.8:
            kind = rng.choice(["flip", "truncate", "duplicate key", "not utf-8", "huge file"])
            text = json.dumps(man).encode()
            if kind == "flip":
                b = bytearray(text)
                for _ in range(rng.randint(1, 3)):
                    j = rng.randrange(len(b))
                    b[j] ^= rng.randint(1, 255)
                raw = bytes(b)
                must = False  # a flip may leave valid JSON (a path or a value changed)
            elif kind == "truncate":
                raw = text[:rng.randrange(len(text))]
            elif kind == "duplicate key":
                raw = text.replace(b'"out": "bases/a.modes"',
                                   b'"out": "bases/a.modes", "out": "bases/z.modes"')
            elif kind == "not utf-8":
                raw = b"\xff\xfe" + text
            else:
                raw = text + b" " * (17 << 20)
        elif r < 0.9:
            extra = list(rng.choice(BATCH_ARGS))
            kind = " ".join(extra)
        else:
            kind = rng.choice(["fine", "fine twice at once", "fine killed and resumed"])
            must = False
        toml_form = raw is None and rng.random() < 0.3 and toml_of(man) is not None
        mpath = os.path.join(case, "m.toml" if toml_form else "m.json")
        for e in man.get("entries", []) if isinstance(man, dict) and \
                isinstance(man.get("entries"), list) else []:
            if isinstance(e, dict) and e.get("out") == "@manifest":
                e["out"] = os.path.basename(mpath)
        extra = [mpath if a == "@manifest" else a for a in extra]
        if raw is not None:
            open(mpath, "wb").write(raw)
        elif toml_form:
            open(mpath, "w").write(toml_of(man))
            kind += " (TOML)"
        else:
            open(mpath, "w").write(json.dumps(man))
        watched = [os.path.join(case, f) for f in ("mesh.msh", "link.msh", "zero", "fifo", "sub",
                                                   os.path.basename(mpath))]
        before = snapshot(watched)
        args = ["batch", mpath, "--json"] + extra
        what = {"mutation": kind, "cmd": " ".join(args[:1] + args[2:])}
        if kind.startswith("fine twice"):
            procs = [subprocess.Popen(["bash", "-c", "ulimit -v 4000000; exec '%s' %s" % (
                BIN, " ".join("'%s'" % a for a in args))], cwd=case, stdout=subprocess.PIPE,
                stderr=subprocess.PIPE) for _ in range(2)]
            outs = [p.communicate(timeout=TIMEOUT) for p in procs]
            codes = [p.returncode for p in procs]
            code, se = max(codes, key=lambda x: abs(x)), "".join(o[1].decode() for o in outs)
        elif kind.startswith("fine killed"):
            p = subprocess.Popen([BIN] + args, cwd=case, stdout=subprocess.DEVNULL,
                                 stderr=subprocess.PIPE)
            for line_ in p.stderr:
                if b": baked in" in line_:
                    break
            p.kill()
            p.wait()
            code, so, se = run(args, case)
            if code == 0:
                rep = json.loads(so)
                if not any(e["action"] == "skipped" for e in rep["entries"]) and \
                        rep["totals"]["entries"] > 1:
                    c.record("misread", dict(what, why="nothing was skipped on resume"))
        else:
            code, so, se = run(args, case)
        after = snapshot(watched)
        tmps = [os.path.join(d, f) for d, _, fs in os.walk(case) for f in fs if ".tmp-" in f]
        bases = os.path.join(case, "bases")
        if before != after or os.path.isfile("/dev/null"):
            c.record("clobber", what)
        elif tmps:
            c.record("leftover", dict(what, files=tmps))
        elif code != 0 and os.path.isdir(bases) and os.listdir(bases) and \
                not kind.startswith("fine"):
            c.record("leftover", dict(what, files=os.listdir(bases)))
        else:
            if code == 0 and kind.startswith("fine"):
                # Every base written is whole and a second run finds them up to date.
                c2, so2, se2 = run(["batch", mpath, "--json"], case)
                if c2 != 0 or any(e["action"] != "skipped" for e in json.loads(so2)["entries"]):
                    c.record("misread", dict(what, why="a second run rebaked", stderr=se2[-300:]))
                    shutil.rmtree(case)
                    continue
            c.classify(code, se, "", None, set(), what, must_refuse=must, need_location=False)
            if code not in (0, 101, "timeout") and isinstance(code, int) and 0 < code < 128:
                named = os.path.basename(mpath) in se or re.search(r"--[a-z]", se)
                if not (named and located.search(se)):
                    c.record("unlocated", dict(what, stderr=se[-300:]))
        shutil.rmtree(case)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=300, help="mutated inputs per kind")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--surfaces", default="volume,export,surface,scenes,lab,batch",
                    help="comma-separated: volume (with modes and options), export, surface, "
                         "scenes, lab, batch")
    ap.add_argument("--json", help="write the totals and the bad cases here")
    a = ap.parse_args()
    if not os.path.exists(BIN):
        sys.exit("build first: cargo build --release -p modal-bake -p dcr-scenes -p dcr-lab")
    rng = random.Random(a.seed)
    c = Campaign()
    work = tempfile.mkdtemp(prefix="campaign-")
    surfaces = a.surfaces.split(",")
    base = os.path.join(work, "ref.modes")
    if "volume" in surfaces:
        base = volume_and_modes(c, rng, a.runs, work)
    else:
        run(["bake", os.path.join(ROOT, "data", "meshes", "cube_v41.msh"), "-o", base,
             "--modes", "4"], work)
    if "export" in surfaces:
        export_surface(c, rng, a.runs, work, base)
    if "surface" in surfaces:
        surface_surface(c, rng, a.runs, work)
    if "scenes" in surfaces:
        scenes_surface(c, rng, a.runs, work)
    if "lab" in surfaces:
        lab_surface(c, rng, a.runs, work)
    if "batch" in surfaces:
        batch_surface(c, rng, a.runs, work)
    shutil.rmtree(work)
    runs = sum(sum(t.values()) for t in c.totals.values())
    print("hostile campaign: %d runs" % runs)
    for surface, t in c.totals.items():
        print("  %-8s %s" % (surface, ", ".join("%s %d" % kv for kv in sorted(t.items()))))
    for b in c.bad[:40]:
        print("  BAD", json.dumps(b))
    if a.json:
        os.makedirs(os.path.dirname(os.path.abspath(a.json)), exist_ok=True)
        json.dump({"runs": runs, "totals": c.totals, "bad": c.bad}, open(a.json, "w"), indent=1)
    sys.exit(1 if c.bad else 0)


if __name__ == "__main__":
    main()
