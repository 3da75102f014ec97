#!/usr/bin/env bash
# Measurements behind modal_bake::bake::SizeEstimate: `modal-bake mesh` and `bake` (20 modes,
# free-free) under /usr/bin/time -v on gmsh's tutorial STL (PyPI gmsh package, mm) and on a
# 0.1 m box, at several sizes and both orders. Prints one CSV row per run: asset, order, size,
# surface triangles, volume (m³), area (m²), tets, nodes, dofs, mesh wall/cpu s, mesh peak
# MB, bake wall/cpu s, bake peak MB, and the machine's load. The CPU time (user + sys) is
# what the model is fitted to (wall time on a busy machine is inflated by the load).
# Usage: bash scripts/calibrate_estimate.sh [BIN]   (build first: cargo build --release -p modal-bake)
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=${1:-"${CARGO_TARGET_DIR:-$ROOT/target}/release/modal-bake"}
OUT="$ROOT/out/calibrate_estimate"
mkdir -p "$OUT"
T13=$(python3 -c "import sys, gmsh; print(sys.prefix)")/share/doc/gmsh/tutorials/t13_data.stl
python3 - "$OUT/box.obj" <<'PY'
import sys
a, n = 0.1, 4
faces = [((0,0,0),(0,1,0),(1,0,0)), ((0,0,1),(1,0,0),(0,1,0)), ((0,0,0),(1,0,0),(0,0,1)),
         ((0,1,0),(0,0,1),(1,0,0)), ((0,0,0),(0,0,1),(0,1,0)), ((1,0,0),(0,1,0),(0,0,1))]
out, nv = [], 0
for o, u, v in faces:
    for i in range(n + 1):
        for j in range(n + 1):
            p = [a * (o[k] + i / n * u[k] + j / n * v[k]) for k in range(3)]
            out.append("v %r %r %r" % tuple(p))
    idx = lambda i, j: nv + i * (n + 1) + j + 1
    for i in range(n):
        for j in range(n):
            A, B, C, D = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
            out.append("f %d %d %d\nf %d %d %d" % (A, B, C, A, C, D))
    nv += (n + 1) ** 2
open(sys.argv[1], "w").write("\n".join(out) + "\n")
PY
timed() { # label, command...: prints wall_s,cpu_s,peak_MB of the command
  /usr/bin/time -f "%e %U %S %M" -o "$OUT/time.txt" "$@" >"$OUT/last.out" 2>"$OUT/last.err" || { cat "$OUT/last.err" >&2; return 1; }
  awk '{printf "%s,%.2f,%.1f", $1, $2 + $3, $4 / 1024}' "$OUT/time.txt"
}
echo "asset,order,size_m,triangles,tets,nodes,dofs,mesh_wall_s,mesh_cpu_s,mesh_mb,bake_wall_s,bake_cpu_s,bake_mb,load"
run() { # asset units order size
  local asset=$1 units=$2 order=$3 size=$4
  local args=(--units "$units" --order "$order" --force)
  [ "$size" != default ] && args+=(--size "$size")
  local m; m=$(timed "$BIN" mesh "$asset" -o "$OUT/m.msh" "${args[@]}" --json)
  local tets nodes dofs tris
  tets=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['tets'])" "$OUT/last.out")
  nodes=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['nodes'])" "$OUT/last.out")
  dofs=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['dofs'])" "$OUT/last.out")
  tris=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['surface']['triangles'])" "$OUT/last.out")
  local b; b=$(timed "$BIN" bake "$OUT/m.msh" -o "$OUT/m.modes" --material steel --modes 20 --force --json)
  echo "$(basename "$asset"),$order,$size,$tris,$tets,$nodes,$dofs,$m,$b,$(cut -d' ' -f1 /proc/loadavg)"
}
for spec in "1:default" "2:default" "1:0.005" "2:0.006" "2:0.004"; do
  run "$T13" mm "${spec%%:*}" "${spec#*:}"
done
for spec in "1:0.004" "2:0.01" "2:0.006" "2:0.0045"; do
  run "$OUT/box.obj" m "${spec%%:*}" "${spec#*:}"
done
