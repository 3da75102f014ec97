#!/usr/bin/env python3
"""The stress scene's per-step cost against the number of resting contacts, with a line fit.

    python3 scripts/stress_linearity.py [--bin PATH] [--props 100,200,...] [--callgrind]

1. wall clock: `dcr-scenes bench-stress --props LIST` (scenes/stress.json cut to its first N
   boxes, four resting contacts each; 300 steps, a landing every 20 steps): the adapter's
   median world step and median quiet step, and rapier's median step, against the resting
   contacts;
2. with --callgrind, instructions (independent of the load): the adapter's calls
   (`DcrRapier::before_step` + `after_step`) and rapier's step over a whole run of each cut.
Each series is fitted by least squares to a + b·N (N resting contacts); printed: a, b and
the largest relative deviation of a point from the line, as Markdown, with the load.
"""

import argparse
import json
import os
import re
import subprocess
import sys
import time


def loadavg():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def fit(xs, ys):
    n = len(xs)
    mx, my = sum(xs) / n, sum(ys) / n
    sxx = sum((x - mx) ** 2 for x in xs)
    b = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx
    a = my - b * mx
    dev = max(abs(y - (a + b * x)) / y for x, y in zip(xs, ys))
    return a, b, dev


def callgrind(binary, scene, out):
    f = os.path.join(out, "callgrind.out")
    subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={f}", binary, "run",
                    scene, "--out", os.path.join(out, "cg_run")], capture_output=True,
                   check=True)
    text = subprocess.run(["callgrind_annotate", "--inclusive=yes", f], capture_output=True,
                          text=True, check=True).stdout

    def count(fn):
        m = re.search(r"^\s*([\d,]+) .*=> [^\n]*" + re.escape(fn) + r" \(", text, re.M)
        return int(m.group(1).replace(",", "")) if m else 0

    return (count("PhysicsWorld::step_with_events"),
            count("DcrRapier::after_step") + count("DcrRapier::before_step"))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default="target/release/dcr-scenes")
    ap.add_argument("--props", default="100,200,300,500,700,1000")
    ap.add_argument("--out", default="out/stress_linearity")
    ap.add_argument("--callgrind", action="store_true")
    a = ap.parse_args()
    if not os.access(a.bin, os.X_OK):
        sys.exit(f"stress_linearity.py: {a.bin} is not an executable: build it with "
                 "`cargo build --release -p dcr-scenes` or pass --bin")
    os.makedirs(a.out, exist_ok=True)
    print(f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, load {loadavg()} before; "
          f"`{a.bin} bench-stress --props {a.props}`\n")
    p = subprocess.run([a.bin, "bench-stress", "--props", a.props], capture_output=True,
                       text=True)
    if p.returncode != 0:
        sys.exit(f"stress_linearity.py: bench-stress failed:\n{p.stderr}")
    runs = json.loads(p.stdout)["runs"]
    print("| boxes | resting contacts | rapier step (µs) | adapter, world step (µs) | "
          "adapter, quiet step (µs) | world step per contact (ns) |")
    print("|---|---|---|---|---|---|")
    for r in runs:
        n = r["resting_contacts_max"]
        print(f"| {r['boxes']} | {n} | {r['rapier_us_median']:.0f} | "
              f"{r['adapter_us_median_world']:.0f} | {r['adapter_us_median_quiet']:.1f} | "
              f"{1e3 * r['adapter_us_median_world'] / n:.0f} |")
    xs = [r["resting_contacts_max"] for r in runs]
    print("\nFits a + b·N over N resting contacts (largest deviation of a point from the "
          "line):\n")
    for name, key in [("adapter, world step", "adapter_us_median_world"),
                      ("adapter, quiet step", "adapter_us_median_quiet"),
                      ("rapier step", "rapier_us_median")]:
        fa, fb, dev = fit(xs, [r[key] for r in runs])
        print(f"- {name}: a = {fa:.1f} µs, b = {1e3 * fb:.1f} ns per contact, "
              f"largest deviation {100 * dev:.0f} %")
    if a.callgrind:
        print("\nInstructions over a whole run (callgrind):\n")
        print("| boxes | resting contacts | rapier (M) | adapter (M) | adapter per contact "
              "per landing (k) |")
        print("|---|---|---|---|---|")
        ys = []
        for r in runs:
            boxes = r["boxes"]
            with open("scenes/stress.json") as f:
                d = json.load(f)
            for prop in d["props"]:
                if prop["name"] == "box":
                    prop["copies"] = prop["copies"][:boxes]
            scene = os.path.join(a.out, f"stress_{boxes}.json")
            with open(scene, "w") as f:
                json.dump(d, f)
            rap, ad = callgrind(a.bin, scene, a.out)
            ys.append(ad)
            n = r["resting_contacts_max"]
            print(f"| {boxes} | {n} | {rap / 1e6:.1f} | {ad / 1e6:.2f} | "
                  f"{ad / n / r['world_steps'] / 1e3:.2f} |")
        fa, fb, dev = fit(xs, ys)
        print(f"\nFit of the adapter's instructions: a = {fa / 1e6:.2f} M, b = {fb / 1e3:.1f} k "
              f"per contact over the run, largest deviation {100 * dev:.1f} %")
    print(f"\nload {loadavg()} after")


if __name__ == "__main__":
    main()
