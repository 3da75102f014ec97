#!/usr/bin/env bash
# The adapter's cost against rapier's step on the six scenes and the stress scene.
#
#   scripts/bench_adapter.sh [REPEATS]        (default 3)
#
# 1. wall clock: `dcr-scenes table1 --json` REPEATS times (under `nice -n -20` when allowed, to
#    shield the runs from other load); per scene the best-of (smallest) rapier and adapter totals
#    and the median of the per-run shares (`dcr_share_of_step`);
# 2. instructions (valgrind callgrind, independent of the machine's load): rapier's
#    `step_with_events` and `DcrRapier::after_step` (+ `before_step`) per scene, for the default
#    impact-step gate and for reading every step; the same for the stress scene cut to 100, 300
#    and 1000 boxes (default gate only);
# 3. `dcr-scenes bench-stress --props 100,300,1000`.
# Writes out/bench/{table1_*.json,callgrind.txt,stress.json,summary.txt}; prints the summary.
set -euo pipefail
cd "$(dirname "$0")/.."
REPEATS="${1:-3}"
OUT=out/bench
mkdir -p "$OUT"
cargo build --release -p dcr-scenes >&2
BIN=target/release/dcr-scenes
NICE=""
if nice -n -20 true 2>/dev/null; then NICE="nice -n -20"; fi
{
  echo "date: $(date -u +%Y-%m-%dT%H:%MZ)  host load before: $(cut -d' ' -f1-3 /proc/loadavg)  nice: ${NICE:-none}"
} > "$OUT/summary.txt"

for i in $(seq 1 "$REPEATS"); do
  $NICE "$BIN" table1 --json > "$OUT/table1_$i.json" 2>/dev/null
done
python3 - "$OUT" "$REPEATS" >> "$OUT/summary.txt" <<'EOF'
import json, statistics, sys
out, n = sys.argv[1], int(sys.argv[2])
runs = [json.load(open(f"{out}/table1_{i}.json")) for i in range(1, n + 1)]
print("wall clock (table1, best-of rapier / adapter totals, median share over runs):")
for j, s in enumerate(runs[0]["scenes"]):
    r = [x["scenes"][j] for x in runs]
    rap = min(x["rapier_ms"] for x in r)
    ad = min(x["adapter_ms"] for x in r)
    med = statistics.median(x["dcr_share_of_step"] for x in r) * 100
    q = [x["query_us_median"] for x in r if x["query_us_median"] is not None]
    print(f"  {s['name']:9} {s['model']:9} rapier {rap:8.2f} ms  adapter {ad:7.3f} ms  "
          f"best-of share {100 * ad / rap:5.2f} %  median share {med:6.2f} %  "
          f"query median {statistics.median(q) if q else float('nan'):8.1f} µs  "
          f"world steps {s['world_steps']}/{s['steps']}")
EOF

# One callgrind run: `callgrind NAME GATE SCENE` appends "NAME GATE rapier after before world"
# (inclusive instruction counts at the call sites, "=> … (Nx)"; a function inlined everywhere
# has none) to callgrind.txt.
callgrind() {
  local name="$1" gate="$2" scene="$3"
  local f="$OUT/cg.$name.$gate.out"
  valgrind --tool=callgrind --callgrind-out-file="$f" "$BIN" run "$scene" --gate "$gate" \
    --out "$OUT/run_$name" >/dev/null 2>&1
  callgrind_annotate --inclusive=yes "$f" 2>/dev/null > "$f.txt"
  count() { { grep -E "=> .*$1 \(" "$f.txt" || true; } | head -1 | awk '{print $1}' | tr -d ,; }
  local r a b w
  r=$(count "PhysicsWorld::step_with_events")
  a=$(count "DcrRapier::after_step")
  b=$(count "DcrRapier::before_step")
  w=$(count "DcrWorld::step")
  echo "$name $gate ${r:-0} ${a:-0} ${b:-0} ${w:-0}" >> "$OUT/callgrind.txt"
}

if command -v valgrind >/dev/null; then
  : > "$OUT/callgrind.txt"
  for s in dinner roof scaffold lowrider rockfall washing; do
    for g in impact-steps every-step; do
      callgrind "$s" "$g" "$s"
    done
  done
  # The stress scene cut to N boxes (as bench-stress does), default gate.
  for n in 100 300 1000; do
    python3 - "$n" "$OUT/stress_$n.json" <<'EOF'
import json, sys
d = json.load(open("scenes/stress.json"))
for p in d["props"]:
    if p["name"] == "box":
        p["copies"] = p["copies"][: int(sys.argv[1])]
json.dump(d, open(sys.argv[2], "w"))
EOF
    callgrind "stress_$n" impact-steps "$OUT/stress_$n.json"
  done
  python3 - "$OUT" >> "$OUT/summary.txt" <<'EOF'
import sys
out = sys.argv[1]
print("instructions (callgrind; adapter = before_step + after_step, of which the world's step):")
for line in open(f"{out}/callgrind.txt"):
    s, g, r, a, b, w = line.split()
    r, a, b, w = int(r), int(a), int(b), int(w)
    share = 100 * (a + b) / r if r else float("nan")
    print(f"  {s:9} {g:12} rapier {r/1e6:9.2f} M  adapter {(a+b)/1e6:7.2f} M ({share:5.2f} %)  "
          f"world step {w/1e6:7.2f} M ({100*w/r if r else float('nan'):5.2f} %)")
EOF
fi

$NICE "$BIN" bench-stress --props 100,300,1000 > "$OUT/stress.json" 2>/dev/null
python3 - "$OUT" >> "$OUT/summary.txt" <<'EOF'
import json, sys
d = json.load(open(f"{sys.argv[1]}/stress.json"))
print("stress scene (bench-stress; medians per step, µs):")
for r in d["runs"]:
    print(f"  {r['boxes']:5} boxes  resting contacts {r['resting_contacts_max']:5}  rapier {r['rapier_us_median']:8.1f}  "
          f"adapter quiet {r['adapter_us_median_quiet']:7.2f}  world step {r['adapter_us_median_world']:8.1f}  "
          f"world steps {r['world_steps']}/{r['steps']}  share {100*r['dcr_share_of_step']:5.2f} %")
EOF
echo "host load after: $(cut -d' ' -f1-3 /proc/loadavg)" >> "$OUT/summary.txt"
cat "$OUT/summary.txt"
