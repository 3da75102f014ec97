#!/usr/bin/env bash
# Wall time and peak memory of `modal-bake mesh` + `bake` on a ~50k-triangle asset: gmsh's
# tutorial STL (PyPI gmsh package, mm) refined to ~50k triangles by gmsh and saved as binary
# STL, then meshed at the default size and at 5 mm (order 1 and 2) and baked (20 modes, the
# bottom 5% fixed). Prints /usr/bin/time -v's "Elapsed" and "Maximum resident set size".
# Usage: bash scripts/asset_bench.sh   (build first: cargo build --release -p modal-bake)
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN="$ROOT/target/release/modal-bake"
OUT="$ROOT/out/asset_bench"
mkdir -p "$OUT"
T13=$(python3 -c "import sys, gmsh; print(sys.prefix)")/share/doc/gmsh/tutorials/t13_data.stl
python3 - "$T13" "$OUT/t13_50k.stl" <<'PY'
import sys, gmsh
gmsh.initialize(["gmsh"], readConfigFiles=False)
gmsh.option.setNumber("General.Terminal", 0)
gmsh.option.setNumber("General.NumThreads", 1)
gmsh.option.setNumber("Mesh.RandomSeed", 1)
gmsh.merge(sys.argv[1])
gmsh.model.mesh.classifySurfaces(40 * 3.14159265 / 180, True, True, 3.14159265)
gmsh.model.mesh.createGeometry()
gmsh.option.setNumber("Mesh.MeshSizeMax", 1.6)
gmsh.option.setNumber("Mesh.Binary", 1)
gmsh.model.mesh.generate(2)
gmsh.write(sys.argv[2])
gmsh.finalize()
PY
echo "asset: $(python3 -c "import sys; d=open(sys.argv[1],'rb').read(); print(int.from_bytes(d[80:84],'little'))" "$OUT/t13_50k.stl") triangles; load $(cut -d' ' -f1 /proc/loadavg)"
measure() {
  local label=$1; shift
  /usr/bin/time -v "$@" >"$OUT/last.out" 2>"$OUT/last.err" || { cat "$OUT/last.err"; exit 1; }
  printf '%-44s %s  %s\n' "$label" \
    "$(grep 'Elapsed' "$OUT/last.err" | awk '{print $NF}')" \
    "$(grep 'Maximum resident' "$OUT/last.err" | awk '{print $NF " KB"}')"
  grep -E "mesh:|surface:|modes," "$OUT/last.out" | sed 's/^/    /' || true
}
for spec in "1:" "2:" "1:0.005" "2:0.005"; do
  order=${spec%%:*}; size=${spec#*:}
  args=(--units mm --order "$order"); [ -n "$size" ] && args+=(--size "$size")
  measure "mesh order $order size ${size:-default}" "$BIN" mesh "$OUT/t13_50k.stl" -o "$OUT/m.msh" "${args[@]}"
  measure "bake (20 modes, z ≤ -0.2064 m fixed)" "$BIN" bake "$OUT/m.msh" -o "$OUT/m.modes" \
    --youngs 2e11 --density 7800 --modes 20 --fixed-below z=-0.2064
done
