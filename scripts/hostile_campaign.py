#!/usr/bin/env python3
"""Hostile-input campaign against the `modal-bake` binary.

Runs mutated inputs of every kind (MSH 2.2/4.1 ASCII and binary, meshio JSON, `.modes`
archives) and abusive options through `bake`, `info`, `check`, `probe` and `geodesic`, each
under a memory cap (`ulimit -v 4000000`, 4 GB of address space) and a timeout, and classifies
every run:

  panic      exit 101
  abort      killed by a signal (SIGABRT on a failed allocation, SIGSEGV, ...) or timed out
  misread    exit 0 on a mesh mutation that must be refused (a repeated section, a
             permuted duplicate tetrahedron, an extra value, a negative tag) with node/tet
             counts or mass other than the unmutated mesh's
  leftover   a failed run left a file in its output folder
  unlocated  a refusal whose message does not name the file and a location in it (a line,
             byte, element / node / vertex number, archive entry, JSON index, section or
             option name; see LOCATED)
  refused    a clean refusal;  ok  exit 0 (a mutation that still reads)

Usage (from the repository root, after `cargo build --release -p modal-bake`):
    python3 scripts/hostile_campaign.py [--runs N] [--seed S] [--json out/campaign.json]
Exit status 1 when any run is a panic, abort, misread, leftover or unlocated refusal.
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
BIN = os.path.join(ROOT, "target", "release", "modal-bake")
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


def run(args, cwd):
    """Runs the binary under the memory cap and timeout: (returncode, stderr)."""
    cmd = "ulimit -v 4000000; exec " + " ".join("'%s'" % a for a in [BIN] + args)
    try:
        p = subprocess.run(["bash", "-c", cmd], cwd=cwd, capture_output=True, timeout=TIMEOUT)
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


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=300, help="mutated inputs per kind")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--json", help="write the totals and the bad cases here")
    a = ap.parse_args()
    if not os.path.exists(BIN):
        sys.exit("build first: cargo build --release -p modal-bake")
    rng = random.Random(a.seed)
    totals, bad = {}, []
    work = tempfile.mkdtemp(prefix="campaign-")

    def record(cls, what):
        totals[cls] = totals.get(cls, 0) + 1
        if cls not in ("ok", "refused"):
            bad.append({"class": cls, **what})

    def classify(code, err, name, outdir, expect_out, what, must_refuse=False, model_ok=True):
        left = [f for f in os.listdir(outdir) if f not in expect_out]
        if code == 101:
            return record("panic", what)
        if code == "timeout" or (isinstance(code, int) and (code < 0 or code > 128)):
            return record("abort", what)
        if code == 0:
            if must_refuse or not model_ok:
                return record("misread", what)
            return record("ok", what)
        if left:
            return record("leftover", dict(what, files=left))
        if name not in err or not LOCATED.search(err):
            return record("unlocated", dict(what, stderr=err[-300:]))
        return record("refused", what)

    # Reference counts of the unmutated meshes.
    ref = {}
    for m in MESHES:
        out = os.path.join(work, "ref.modes")
        code, so, se = run(["bake", os.path.join(ROOT, "data", "meshes", m), "-o", out,
                            "--modes", "4", "--json"], work)
        ref[m] = counts(so)
    base = os.path.join(work, "ref.modes")
    base_bytes = open(base, "rb").read()

    for i in range(a.runs):
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
        classify(code, se, os.path.basename(path), outdir, {"x.modes"} if code == 0 else set(),
                 what, model_ok=model_ok)
        code, so, se = run(["check", path, base, "--modes", "4"], case)
        if code not in (0, 1):
            classify(code, se, os.path.basename(path), outdir, set(os.listdir(outdir)),
                     dict(what, cmd="check"))
        else:
            record("ok", what)
        shutil.rmtree(case)

    for i in range(a.runs):
        mutated, kind = mutate_modes(rng, base_bytes)
        case = os.path.join(work, "m%d" % i)
        os.makedirs(case)
        path = os.path.join(case, "base.modes")
        open(path, "wb").write(mutated)
        sub = [["info", path, "--json"], ["geodesic", path, "--from-vertex", "3", "--json"],
               ["probe", path, "--impact", "0.5,0.5,1", "--impulse", "1", "--contact",
                "0.2,0.3,1", "--json"]][i % 3]
        code, so, se = run(sub, case)
        classify(code, se, "base.modes", case, set(os.listdir(case)),
                 {"input": "cube.modes", "mutation": kind, "cmd": sub[0]})
        shutil.rmtree(case)

    # Abusive options on a valid mesh and base.
    mesh = os.path.join(ROOT, "data", "meshes", "cube_v41.msh")
    abusive = [["--youngs", "1e308"], ["--density", "1e-300"], ["--modes", "100000"],
               ["--max-freq", "1e300"], ["--poisson", "0.5"], ["--rayleigh", "1e300,1e300"],
               ["--youngs", "nan"], ["--fixed", "nope"], ["--modes", "-1"]]
    for opts in abusive:
        outdir = os.path.join(work, "opt")
        os.makedirs(outdir, exist_ok=True)
        code, so, se = run(["bake", mesh, "-o", os.path.join(outdir, "o.modes")] + opts, work)
        classify(code, se, "", outdir, {"o.modes"} if code == 0 else set(),
                 {"input": "cube_v41.msh", "mutation": " ".join(opts), "cmd": "bake"})
        shutil.rmtree(outdir)
    shutil.rmtree(work)
    runs = sum(totals.values())
    print("hostile campaign: %d runs: %s" % (runs, ", ".join(
        "%s %d" % kv for kv in sorted(totals.items()))))
    for b in bad[:40]:
        print("  BAD", json.dumps(b))
    if a.json:
        os.makedirs(os.path.dirname(os.path.abspath(a.json)), exist_ok=True)
        json.dump({"runs": runs, "totals": totals, "bad": bad}, open(a.json, "w"), indent=1)
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
