#!/usr/bin/env bash
# Measurements behind modal_bake::transfer::TablePlan's cost model: `modal-bake bake
# --transfer-h 0.01 --json` on the committed scene meshes (and the npm Stanford bunny when
# scripts/asset_scene.py has made out/asset-scene/bunny.msh) at several table mode counts,
# orders and regions, under /usr/bin/time. Prints one CSV row per run: case, order, points,
# region vertices, bent points, modes, samples per step, the table's measured build (s), its
# estimate (s), the process's peak memory (MB), the table's memory estimate (MB) and the load;
# then the least-squares coefficients of the time model (relative residuals) and the
# estimate's error on every run. Takes ~10 minutes on 2 cores.
# Usage: bash scripts/calibrate_table_cost.sh [BIN]   (build first: cargo build --release -p modal-bake)
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=${1:-"${CARGO_TARGET_DIR:-$ROOT/target}/release/modal-bake"}
OUT="$ROOT/out/calibrate_table_cost"
mkdir -p "$OUT"
CSV="$OUT/runs.csv"
echo "case,order,points,vertices,bent,modes,samples,build_s,estimated_s,peak_mb,estimated_mb,load" >"$CSV"
run() { # case mesh args...
  local name=$1 mesh=$2
  shift 2
  /usr/bin/time -f "%M" -o "$OUT/time.txt" "$BIN" bake "$mesh" -o "$OUT/t.modes" --force --json \
    --transfer-h 0.01 "$@" >"$OUT/report.json" 2>"$OUT/last.err" || { cat "$OUT/last.err" >&2; return 1; }
  python3 - "$name" "$OUT/report.json" "$(cat "$OUT/time.txt")" "$(cut -d' ' -f1 /proc/loadavg)" >>"$CSV" <<'PY'
import json, sys
name, rep, rss_kb, load = sys.argv[1], json.load(open(sys.argv[2])), float(sys.argv[3]), sys.argv[4]
t = rep["transfer"]
print(",".join(str(x) for x in [name, t["order"], t["points"], t["vertices"], t["bent"], t["modes"],
      t["samples"], round(t["build_s"], 3), round(t["estimated_s"], 3), round(rss_kb / 1024),
      round(t["estimated_bytes"] / 1e6), load]))
PY
  tail -1 "$CSV"
}
TABLE=(data/scenes/table.msh --fixed feet --youngs 1.1e9 --poisson 0.3 --density 770)
SCAFFOLD=(data/scenes/scaffold.msh --fixed feet --youngs 1e10 --poisson 0.3 --density 100)
cd "$ROOT"
for order in 1 2 3; do
  run "table-up-200-o$order" "${TABLE[@]}" --transfer-up 0,1,0 --transfer-modes 200 --transfer-order "$order"
done
run table-up-600-o2 "${TABLE[@]}" --transfer-up 0,1,0 --transfer-modes 600 --transfer-order 2
run table-up-all "${TABLE[@]}" --transfer-up 0,1,0
run table-all-200-o1 "${TABLE[@]}" --transfer-modes 200 --transfer-order 1
run scaffold-up-640 "${SCAFFOLD[@]}" --transfer-up 0,1,0
run floor-all data/scenes/floor.msh --fixed bottom --fixed edges --youngs 1e10 --poisson 0.3 --density 540
BUNNY=out/asset-scene/bunny.msh
if [ -f "$BUNNY" ]; then
  B=("$BUNNY" --youngs 2.3e9 --poisson 0.35 --density 1050 --fixed-below y=0.0099)
  run bunny-300-o1 "${B[@]}" --transfer-modes 300 --transfer-order 1
  run bunny-300-o2 "${B[@]}" --transfer-modes 300 --transfer-order 2
  run bunny-1000-o1 "${B[@]}" --transfer-modes 1000 --transfer-order 1
fi
python3 - "$CSV" <<'PY'
import csv, sys
import numpy as np
rows = list(csv.DictReader(open(sys.argv[1])))
P = 2.0
X, y = [], []
for r in rows:
    s, m, nc, n = (float(r[k]) for k in ("samples", "modes", "vertices", "points"))
    nc += float(r["bent"])
    X.append([s * m * nc * nc / P, s * n * n / 2 / P, s * n * nc / 2 / P])
    y.append(float(r["build_s"]))
X, y = np.array(X), np.array(y)
w = 1 / y  # relative residuals
coef, *_ = np.linalg.lstsq(X * w[:, None], y * w, rcond=None)
print("least squares (relative): GEMM s/flop %.3e, peak s/sample-pair %.3e, blend s/sample %.3e" % tuple(coef))
coef = np.maximum(coef, 0)
for r, xi in zip(rows, X):
    fit = xi @ coef
    print("%-18s measured %7.2f s  estimate %7.2f s (%+4.0f %%)  refit %7.2f s (%+4.0f %%)  peak %5s MB  estimate %5s MB" % (
        r["case"], float(r["build_s"]), float(r["estimated_s"]),
        100 * (float(r["estimated_s"]) / float(r["build_s"]) - 1), fit,
        100 * (fit / float(r["build_s"]) - 1), r["peak_mb"], r["estimated_mb"]))
PY
