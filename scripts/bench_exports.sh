#!/usr/bin/env bash
# Cost of the export commands (wall time, file size) on the dinner scene (table base, 1,016
# surface vertices) and the rockfall scene (cliff base, 6,628 surface vertices): medians of
# REPS runs (default 5) of each command, the load (uptime) before and after. Writes
# target/bench/exports.json and prints a Markdown table. Usage: scripts/bench_exports.sh [REPS]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
reps="${1:-5}"
cargo build --release -q -p dcr-scenes -p modal-bake
out=out/bench_exports
mkdir -p "$out" target/bench
load_before="$(uptime)"
median() { sort -n | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
now() { date +%s.%N; }
rows=()
# measure NAME FILE CMD...: median wall time of CMD over $reps runs and FILE's size.
measure() {
  local name="$1" file="$2"; shift 2
  local ts=()
  for _ in $(seq "$reps"); do
    local t0; t0=$(now)
    "$@" >/dev/null 2>&1
    ts+=("$(awk -v a="$(now)" -v b="$t0" 'BEGIN { printf "%.4f", a - b }')")
  done
  local med; med=$(printf '%s\n' "${ts[@]}" | median)
  local size=0; [ -n "$file" ] && size=$(stat -c %s "$file")
  rows+=("{\"command\": \"$name\", \"median_s\": $med, \"bytes\": $size}")
  printf '| %s | %.3f | %s |\n' "$name" "$med" "$( [ "$size" = 0 ] && echo - || echo "$((size / 1024)) KiB")"
}
echo "| command | median wall (s) | file |"
echo "|---|---:|---:|"
for scene in dinner rockfall; do
  base=$([ "$scene" = dinner ] && echo table || echo cliff)
  # Bake (if needed) once so the runs below measure the runs alone.
  target/release/dcr-scenes run "$scene" --dcr off --seconds 0.01 --out "$out/warm" >/dev/null 2>&1
  b="out/bases/$base.modes"
  measure "modal-bake export $base.modes --vtu (20 modes)" "$out/$base.vtu" target/release/modal-bake export "$b" --vtu "$out/$base.vtu"
  measure "modal-bake export $base.modes --gltf (20 modes)" "$out/$base.glb" target/release/modal-bake export "$b" --gltf "$out/$base.glb"
  measure "modal-bake export $base.modes --png (8 modes)" "$out/$base.png" target/release/modal-bake export "$b" --png "$out/$base.png" --modes 8
  measure "modal-bake export $base.modes --png (20 modes)" "$out/${base}20.png" target/release/modal-bake export "$b" --png "$out/${base}20.png"
  measure "dcr-scenes run $scene --dcr both (no glTF; writes outcomes.svg)" "$out/$scene/outcomes.svg" target/release/dcr-scenes run "$scene" --dcr both --out "$out/$scene"
  measure "dcr-scenes run $scene --dcr both --gltf" "$out/$scene.glb" target/release/dcr-scenes run "$scene" --dcr both --out "$out/$scene" --gltf "$out/$scene.glb"
done
load_after="$(uptime)"
{
  echo "{\"reps\": $reps, \"load_before\": \"$load_before\", \"load_after\": \"$load_after\", \"rows\": ["
  (IFS=,; echo "${rows[*]}")
  echo "]}"
} > target/bench/exports.json
echo
echo "load before: $load_before"
echo "load after:  $load_after"
