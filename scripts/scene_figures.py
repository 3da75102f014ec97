#!/usr/bin/env python3
"""The scene measurements quoted in docs/benchmarks.md and docs/design/exaggerated-scenes.md.

    python3 scripts/scene_figures.py [--bin PATH] [--out DIR] [SECTION ...]

Sections (default: all), each printed as Markdown with the commands it ran:
  energy     `dcr-scenes table1 --json --energy-sweep 1,0.5,0.1,0.05,0.02,0.01,0.005`:
             per scene, the first η that moves an outcome by more than 5 % and what moves
  kick       roof and scaffold with and without `--lateral-kick`, after the step and in the
             solver
  exaggerate lowrider and washing as committed, at the paper's C / gain 1, on the 20-mode
             modal base and on the transfer table, and truth-matched (copies of the scene
             files with only the named fields changed, in DIR)
  gain       `--method transfer --gain G` on lowrider and washing, G = 1 … 10
Every run is deterministic (rapier3d-f64, single thread); the outcomes do not depend on the
machine's load. Writes the runs' outputs under DIR (default out/scene_figures).
"""

import argparse
import copy
import json
import os
import subprocess
import sys

SWEEP = "1,0.5,0.1,0.05,0.02,0.01,0.005"


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


class Runner:
    def __init__(self, binary, out):
        self.bin = binary
        self.out = out

    def call(self, args):
        p = subprocess.run([self.bin, *args], capture_output=True, text=True)
        if p.returncode != 0:
            sys.exit(f"scene_figures.py: {self.bin} {' '.join(args)} failed:\n{p.stderr}")
        return p.stdout

    def run(self, scene, tag, *args):
        """`dcr-scenes run SCENE ARGS --out DIR/TAG`; returns its summary.json."""
        d = os.path.join(self.out, tag)
        self.call(["run", scene, *args, "--out", d])
        with open(os.path.join(d, "summary.json")) as f:
            return json.load(f)

    def scene_copy(self, scene, tag, edit):
        """A copy of scenes/SCENE.json with `edit(dict)` applied, written to DIR/TAG.json."""
        with open(f"scenes/{scene}.json") as f:
            d = json.load(f)
        d = copy.deepcopy(d)
        edit(d)
        path = os.path.join(self.out, f"{tag}.json")
        with open(path, "w") as f:
            json.dump(d, f, indent=1)
        return path


def outcomes(summary):
    """{name: value} of a run's summary.json."""
    return {k: v[0] for k, v in summary["outcomes"].items()}


def largest_dv(summary, prefix):
    """Largest Δv (m/s) received by the bodies whose name starts with prefix."""
    vals = [r["max_delta_v"] for name, r in summary["received"].items()
            if name.startswith(prefix)]
    return max(vals) if vals else 0.0


def energy(r):
    print(f"```sh\ndcr-scenes table1 --json --energy-sweep {SWEEP}\n```\n")
    d = json.loads(r.call(["table1", "--json", "--energy-sweep", SWEEP]))
    print("| scene | η first moving an outcome > 5 % (bounded object-steps) | "
          "at η = 1 / 0.5 / 0.1 | what moves first | injected / dissipated at η = 1 (J) |")
    print("|---|---|---|---|---|")
    seen = set()
    for s in d["scenes"]:
        if s["name"] in seen:
            continue
        seen.add(s["name"])
        sweep = s["energy_sweep"]
        free = sweep[0]
        first, what = None, "—"
        for e in sweep[1:]:
            moved = [k for k, v in e["outcomes"].items() if v["changed"]]
            if moved and first is None:
                first = e
                what = ", ".join(
                    f"{k} {fmt(free['outcomes'][k]['value'])} → {fmt(e['outcomes'][k]['value'])}"
                    for k in moved)
        at = []
        for eta in (1.0, 0.5, 0.1):
            e = next(x for x in sweep if x["energy_eta"] == eta)
            moved = [k for k, v in e["outcomes"].items() if v["changed"]]
            at.append("no change" if not moved else ", ".join(moved))
        one = next(x for x in sweep if x["energy_eta"] == 1.0)
        first_s = (f"{first['energy_eta']} ({first['energy_limited_steps']})"
                   if first else "none down to 0.005")
        print(f"| {s['name']} | {first_s} | {' / '.join(at)} | {what} | "
              f"{fmt(one['injected_ke_j'])} / {fmt(one['dissipated_j'])} |")
    print()


def kick(r):
    print("```sh\ndcr-scenes run roof|scaffold [--apply in-solver] [--lateral-kick]\n```\n")
    rows = {"roof": ["wrench_slide", "nailbox_slide"],
            "scaffold": ["hardhat_slide", "ladder_slide", "top_tools_max_lift",
                         "hardhat_max_lift", "ladder_max_lift"]}
    print("| scene | outcome (mm) | after step | after step, kick | in solver | "
          "in solver, kick |")
    print("|---|---|---|---|---|---|")
    for scene, names in rows.items():
        runs = []
        for apply in ("after-step", "in-solver"):
            for k in (False, True):
                args = ["--apply", apply] + (["--lateral-kick"] if k else [])
                tag = f"kick_{scene}_{apply}_{int(k)}"
                runs.append(outcomes(r.run(scene, tag, *args)))
        for n in names:
            print(f"| {scene} | {n} | " + " | ".join(fmt(x[n]) for x in runs) + " |")
    print()


def exaggerate(r):
    def ground(method):
        def edit(d):
            d["elastic"][0]["method"] = method
        return edit

    def gains(floor, fridge):
        def edit(d):
            d["elastic"][0]["gain"] = floor
            d["elastic"][1]["gain"] = fridge
        return edit

    low = [
        ("as committed (attenuation C = 9000, amplitude `top`)", "lowrider", []),
        ("paper's range: C = 2", r.scene_copy("lowrider", "lowrider_c2", ground(
            {"attenuation": {"c": 2.0, "beta": 1.0, "distance": "heat_table",
                             "amplitude": "top"}})), []),
        ("truth-matched: C = 2160, amplitude `per_vertex`", r.scene_copy(
            "lowrider", "lowrider_c2160", ground(
                {"attenuation": {"c": 2160.0, "beta": 1.0, "distance": "heat_table",
                                 "amplitude": "per_vertex"}})), []),
        ("modal, 20 modes, gain 1", "lowrider", ["--method", "modal", "--gain", "1"]),
        ("transfer table, gain 1", "lowrider", ["--method", "transfer", "--gain", "1"]),
    ]
    wash = [
        ("as committed (modal, floor and fridge gain 10)", "washing", []),
        ("modal, gain 1", "washing", ["--gain", "1"]),
        ("truth-matched: floor gain 1.24, fridge 3.4", r.scene_copy(
            "washing", "washing_truth", gains(1.24, 3.4)), []),
        ("transfer tables, gain 1", "washing", ["--method", "transfer", "--gain", "1"]),
    ]
    print("```sh\n"
          "dcr-scenes run lowrider|washing [--method modal|transfer] [--gain 1]\n"
          "dcr-scenes run out/scene_figures/{lowrider_c2,lowrider_c2160,washing_truth}.json\n"
          "```\n")
    print("| run | cones lift (mm) / tilt (°) | top post tilt (°) | posts fallen | "
          "largest Δv: cones / base posts (m/s) |")
    print("|---|---|---|---|---|")
    for i, (what, scene, args) in enumerate(low):
        s = r.run(scene, f"exaggerate_low_{i}", *args)
        o = outcomes(s)
        print(f"| {what} | {fmt(o['cones_max_lift'])} / {fmt(o['cones_max_tilt'])} | "
              f"{fmt(o['top_post_tilt'])} | {fmt(o['posts_fallen'])} | "
              f"{fmt(largest_dv(s, 'cone'))} / {fmt(largest_dv(s, 'post'))} |")
    print()
    print("| run | fridge / plant pot lift (mm) | leaves sway (°) | bottles tilt (°) | "
          "largest Δv: fridge / plant pot (m/s) |")
    print("|---|---|---|---|---|")
    for i, (what, scene, args) in enumerate(wash):
        s = r.run(scene, f"exaggerate_wash_{i}", *args)
        o = outcomes(s)
        print(f"| {what} | {fmt(o['fridge_max_lift'])} / {fmt(o['plant_pot_max_lift'])} | "
              f"{fmt(o['leaves_sway_range'])} | {fmt(o['bottles_max_tilt'])} | "
              f"{fmt(largest_dv(s, 'fridge'))} / {fmt(largest_dv(s, 'plant_pot'))} |")
    print()


def gain(r):
    print("```sh\ndcr-scenes run lowrider|washing --method transfer --gain G\n```\n")
    print("| gain | lowrider: cones lift / tilt, top post tilt, posts fallen | "
          "washing: fridge / plant lift, leaves sway |")
    print("|---|---|---|")
    for g in (1, 2, 3, 4, 5, 6, 7, 8, 10):
        lo = outcomes(r.run("lowrider", f"gain_low_{g}", "--method", "transfer", "--gain",
                            str(g)))
        wa = outcomes(r.run("washing", f"gain_wash_{g}", "--method", "transfer", "--gain",
                            str(g)))
        print(f"| {g} | {fmt(lo['cones_max_lift'])} mm / {fmt(lo['cones_max_tilt'])}°, "
              f"{fmt(lo['top_post_tilt'])}°, {fmt(lo['posts_fallen'])} | "
              f"{fmt(wa['fridge_max_lift'])} / {fmt(wa['plant_pot_max_lift'])} mm, "
              f"{fmt(wa['leaves_sway_range'])}° |")
    print()


SECTIONS = {"energy": energy, "kick": kick, "exaggerate": exaggerate, "gain": gain}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default="target/release/dcr-scenes")
    ap.add_argument("--out", default="out/scene_figures")
    ap.add_argument("sections", nargs="*", help="energy, kick, exaggerate, gain (default all)")
    a = ap.parse_args()
    for name in a.sections:
        if name not in SECTIONS:
            sys.exit(f"scene_figures.py: unknown section `{name}`: use {', '.join(SECTIONS)}")
    if not os.access(a.bin, os.X_OK):
        sys.exit(f"scene_figures.py: {a.bin} is not an executable: build it with "
                 "`cargo build --release -p dcr-scenes` or pass --bin")
    os.makedirs(a.out, exist_ok=True)
    r = Runner(a.bin, a.out)
    for name in a.sections or SECTIONS:
        print(f"### {name}\n")
        SECTIONS[name](r)


if __name__ == "__main__":
    main()
