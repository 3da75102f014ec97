#!/usr/bin/env bash
# Behaviour check for refactors: bakes the same set of bases (test meshes in every reader format,
# P1 and P2, f32/lumped, frequency caps, fixed selectors, transfer tables, --target-error, and
# the seven scene bases through `dcr-scenes table1`) with two builds of the binaries, then
# compares the .modes files byte for byte and the table1 trajectory hashes and outcomes.
#
# usage: scripts/compare_bakes.sh BEFORE_BIN_DIR AFTER_BIN_DIR [OUT_DIR]
#   *_BIN_DIR hold `modal-bake` and `dcr-scenes` (e.g. copies of target/release from two
#   commits); OUT_DIR (default out/compare_bakes) receives before/ and after/.
# Exit status: 0 identical, 1 some output differs, 2 a bake or run failed.
# Run from anywhere; it works from the repository root.
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 2 ] || { sed -n '2,11p' "$0" >&2; exit 2; }
before=$(cd "$1" && pwd)
after=$(cd "$2" && pwd)
out=${3:-out/compare_bakes}
for b in "$before" "$after"; do
  for exe in modal-bake dcr-scenes; do
    [ -x "$b/$exe" ] || { echo "error: $b/$exe is missing or not executable" >&2; exit 2; }
  done
done

bake_all() { # BIN_DIR OUT_DIR
  local B="$1/modal-bake" O="$2" M=data/meshes
  rm -rf "$O" && mkdir -p "$O/tests"
  {
    "$B" bake $M/beam.msh -o "$O/tests/beam.modes" --youngs 2e9 --density 1200 --fixed clamp --modes 10
    "$B" bake $M/beam.msh -o "$O/tests/beam_f32_lumped.modes" --fixed clamp --modes 6 --f32 --lumped
    "$B" bake $M/beam.msh -o "$O/tests/beam_maxfreq.modes" --fixed clamp --max-freq 2000
    "$B" bake $M/cube_v22.msh -o "$O/tests/cube_v22.modes" --modes 12
    "$B" bake $M/cube_v41_bin.msh -o "$O/tests/cube_v41_bin.modes" --fixed bottom --modes 8
    "$B" bake $M/cube_cell_sets.json -o "$O/tests/cube_json.modes" --fixed bottom --modes 8
    "$B" bake $M/cylinder_v41.msh -o "$O/tests/cylinder.modes" --fixed bottom --modes 8 --fixed-below z=0.05
    "$B" bake $M/cylinder_v22_bin.msh -o "$O/tests/cylinder_bin.modes" --fixed-box -1,-1,-0.01,1,1,0.02 --modes 5
    "$B" bake $M/fv32_p2_h1.msh -o "$O/tests/fv32_p2.modes" --modes 8
    "$B" bake $M/beam.msh -o "$O/tests/beam_transfer.modes" --fixed clamp --modes 10 --transfer-h 0.01 --transfer-modes 40 --transfer-order 2 --transfer-up 0,0,1
    "$B" bake $M/cube_v22.msh -o "$O/tests/cube_transfer.modes" --fixed bottom --modes 10 --transfer-h 0.005 --transfer-modes all
    "$B" bake $M/beam.msh -o "$O/tests/beam_target.modes" --fixed clamp --transfer-h 0.01 --transfer-up 0,0,1 --target-error 20
    "$1/dcr-scenes" table1 --json --bases "$O/bases" > "$O/table1.json"
  } > "$O/log.txt" 2>&1 || { echo "error: a bake or run with $1 failed; see $O/log.txt" >&2; exit 2; }
}

echo "baking with $before"
bake_all "$before" "$out/before"
echo "baking with $after"
bake_all "$after" "$out/after"

n=0 bad=0
for f in "$out"/before/tests/*.modes "$out"/before/bases/*.modes; do
  rel=${f#"$out"/before/}
  n=$((n + 1))
  cmp -s "$f" "$out/after/$rel" || { echo "differs: $rel"; bad=$((bad + 1)); }
done
echo "bases compared: $n, differing: $bad"
python3 - "$out" <<'PY' || bad=$((bad + 1))
import json, sys
out = sys.argv[1]
key = lambda s: (s["name"], s["trajectory_hash_on"], s["trajectory_hash_off"],
                 json.dumps(s["outcomes"], sort_keys=True))
b = [key(s) for s in json.load(open(f"{out}/before/table1.json"))["scenes"]]
a = [key(s) for s in json.load(open(f"{out}/after/table1.json"))["scenes"]]
same = a == b
print(f"table1 runs: {len(a)}, trajectory hashes and outcomes identical: {same}")
sys.exit(0 if same else 1)
PY
[ "$bad" -eq 0 ]
