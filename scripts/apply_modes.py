#!/usr/bin/env python3
"""The six Table 1 scenes in both application modes: outcomes and cost side by side.

    python3 scripts/apply_modes.py [--runs N] [--bin PATH] [--out DIR]

Runs `dcr-scenes table1 --json` N times (default 3) in each of three configurations:
  after-step            the default: impulses right after the step, with the support event
  after-step, no recyc. the same with rapier's contact recycling off on the elastic objects,
                        as the in-solver path has it (separates the two causes of a difference)
  in-solver             the responses replayed by the next step's contact solver
The runs of one configuration are interleaved with the others' (run 1 of each, then run 2 ...)
so that the machine's load falls on all of them alike. Outcomes are deterministic (the first
run's are printed; the script checks the trajectory hashes agree across runs). Cost per
scene: the medians over the runs of rapier's total step time, the adapter's total time, their
ratio (`dcr_share_of_step`) and the per-object query median. Prints Markdown tables and the
load (`/proc/loadavg`) before and after; writes every run's JSON to DIR (default out/apply).
With --callgrind, also counts instructions (valgrind callgrind, independent of the load) of
rapier's `step_with_events` and the adapter (`DcrRapier::before_step` + `after_step`) in one
`dcr-scenes run SCENE` per scene and configuration.
"""

import argparse
import re
import shutil
import json
import os
import statistics
import subprocess
import sys
import time

CONFIGS = [
    ("after-step", ["--apply", "after-step"]),
    ("after-step, recycling off", ["--apply", "after-step", "--no-contact-recycling"]),
    ("in-solver", ["--apply", "in-solver"]),
]


def loadavg():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def fmt(x):
    if x == 0:
        return "0"
    a = abs(x)
    if a >= 100:
        return f"{x:.0f}"
    if a >= 10:
        return f"{x:.1f}"
    if a >= 0.01:
        return f"{x:.3g}"
    return f"{x:.2g}"


def change(x, ref):
    if ref == 0:
        return "" if x == 0 else ""
    d = (x - ref) / abs(ref) * 100
    return f" ({d:+.0f} %)" if abs(d) > 5 else ""


SCENES = ["dinner", "roof", "scaffold", "lowrider", "rockfall", "washing"]


def callgrind(binary, scene, args, out):
    """Inclusive instructions of rapier's step and the adapter's calls in one run."""
    f = os.path.join(out, "callgrind.out")
    subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={f}", binary, "run",
                    scene, *args, "--out", os.path.join(out, "cg_run")],
                   capture_output=True, check=True)
    text = subprocess.run(["callgrind_annotate", "--inclusive=yes", f], capture_output=True,
                          text=True, check=True).stdout

    def count(fn):
        m = re.search(r"^\s*([\d,]+) .*=> [^\n]*" + re.escape(fn) + r" \(", text, re.M)
        return int(m.group(1).replace(",", "")) if m else 0

    return (count("PhysicsWorld::step_with_events"),
            count("DcrRapier::after_step") + count("DcrRapier::before_step"))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--bin", default="target/release/dcr-scenes")
    ap.add_argument("--out", default="out/apply")
    ap.add_argument("--callgrind", action="store_true",
                    help="also count instructions with valgrind (about 2 minutes)")
    a = ap.parse_args()
    if a.runs < 1:
        sys.exit("apply_modes.py: --runs must be at least 1")
    if not os.access(a.bin, os.X_OK):
        sys.exit(f"apply_modes.py: {a.bin} is not an executable: build it with "
                 "`cargo build --release -p dcr-scenes` or pass --bin")
    os.makedirs(a.out, exist_ok=True)
    load_before = loadavg()
    started = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    runs = {name: [] for name, _ in CONFIGS}
    for i in range(a.runs):
        for name, args in CONFIGS:
            print(f"[apply_modes] run {i + 1}/{a.runs}: {name}", file=sys.stderr)
            p = subprocess.run([a.bin, "table1", "--json", *args], capture_output=True,
                               text=True)
            if p.returncode != 0:
                sys.exit(f"apply_modes.py: {a.bin} table1 {' '.join(args)} failed:\n{p.stderr}")
            slug = name.replace(", ", "_").replace(" ", "_")
            with open(os.path.join(a.out, f"{slug}_{i + 1}.json"), "w") as f:
                f.write(p.stdout)
            runs[name].append(json.loads(p.stdout)["scenes"])
    load_after = loadavg()

    for name, rs in runs.items():
        for r in rs[1:]:
            for s0, s in zip(rs[0], r):
                if s0["trajectory_hash_on"] != s["trajectory_hash_on"]:
                    sys.exit(f"apply_modes.py: {name}: {s['name']} is not deterministic")

    base = runs["after-step"][0]
    print(f"{started}, {a.runs} runs per configuration, load {load_before} before, "
          f"{load_after} after; `{a.bin}`\n")
    print("Outcomes (deterministic; changes above 5 % against after-step marked):\n")
    names = [n for n, _ in CONFIGS]
    print("| scene | outcome | " + " | ".join(names) + " | response off |")
    print("|---|---|" + "---|" * len(names) + "---|")
    seen = set()
    for j, s in enumerate(base):
        if s["name"] in seen:
            continue
        seen.add(s["name"])
        for k, o in s["outcomes"].items():
            ref = o["on"]
            cells = []
            for n in names:
                v = runs[n][0][j]["outcomes"][k]["on"]
                cells.append(fmt(v) + ("" if n == "after-step" else change(v, ref)))
            print(f"| {s['name']} | {k} ({o['unit']}) | " + " | ".join(cells)
                  + f" | {fmt(o['off'])} |")

    print("\nCost (medians over the runs; rapier and adapter: totals over the run, ms; "
          "share: adapter / rapier; query: per-object median, µs):\n")
    print("| scene / object | " + " | ".join(
        f"{n}: rapier / adapter / share / query" for n in names) + " |")
    print("|---|" + "---|" * len(names))
    for j, s in enumerate(base):
        cells = []
        for n in names:
            r = [x[j] for x in runs[n]]
            rap = statistics.median(x["rapier_ms"] for x in r)
            ad = statistics.median(x["adapter_ms"] for x in r)
            sh = statistics.median(x["dcr_share_of_step"] for x in r) * 100
            q = statistics.median(x["query_us_median"] for x in r)
            cells.append(f"{rap:.1f} / {ad:.2f} / {sh:.1f} % / {q:.1f}")
        print(f"| {s['name']} / {s['model']} | " + " | ".join(cells) + " |")

    if a.callgrind:
        if not shutil.which("valgrind"):
            sys.exit("apply_modes.py: --callgrind needs valgrind (apt-get install valgrind)")
        print("\nInstructions (callgrind, one `dcr-scenes run SCENE` each; rapier's step / "
              "the adapter, millions; share):\n")
        print("| scene | " + " | ".join(names) + " |")
        print("|---|" + "---|" * len(names))
        for scene in SCENES:
            cells = []
            for n, args in CONFIGS:
                print(f"[apply_modes] callgrind {scene}: {n}", file=sys.stderr)
                r, d = callgrind(a.bin, scene, args, a.out)
                cells.append(f"{r / 1e6:.1f} M / {d / 1e6:.2f} M ({100 * d / r:.1f} %)"
                             if r else "n/a")
            print(f"| {scene} | " + " | ".join(cells) + " |")

    print("\nImpacts, world steps, injected / dissipated energy (J), replays missed:\n")
    print("| scene / object | " + " | ".join(names) + " |")
    print("|---|" + "---|" * len(names))
    for j, s in enumerate(base):
        cells = []
        for n in names:
            x = runs[n][0][j]
            e = x["energy"]
            cells.append(f"{x['impacts']} imp., {x['world_steps']}/{x['steps']} steps, "
                         f"{fmt(e['injected_ke_j'])} / {fmt(e['dissipated_j'])} J, "
                         f"missed {x['replay_missed']}")
        print(f"| {s['name']} / {s['model']} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
