#!/usr/bin/env bash
# Bakes the small base the C examples and the C/C++ guide use: a 1 × 0.6 × 0.05 m steel plate,
# x ∈ [0, 1], y ∈ [0, 0.6], top face at z = 0 (+z up), held at its four corners (5 × 5 cm
# columns through the plate, like a table top on legs), 20 modes. Not committed: run this.
#
#   scripts/gen_plate_base.sh [OUT.modes]        (default out/bases/plate.modes)
#
# The plate's surface is written as an OBJ into a temporary folder and meshed and baked by
# `modal-bake bake` (gmsh, as for any surface asset). MODAL_BAKE names the binary (default
# target/release/modal-bake, built when missing).
set -euo pipefail
cd "$(dirname "$0")/.."
OUT="${1:-out/bases/plate.modes}"
BIN="${MODAL_BAKE:-target/release/modal-bake}"
if [ ! -x "$BIN" ]; then
  cargo build --release --bin modal-bake >&2
fi
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT
# Outward-facing (counter-clockwise seen from outside) triangles of the box.
cat > "$TMP/plate.obj" <<'OBJ'
v 0 0 -0.05
v 1 0 -0.05
v 1 0.6 -0.05
v 0 0.6 -0.05
v 0 0 0
v 1 0 0
v 1 0.6 0
v 0 0.6 0
f 1 4 3
f 1 3 2
f 5 6 7
f 5 7 8
f 1 2 6
f 1 6 5
f 4 8 7
f 4 7 3
f 1 5 8
f 1 8 4
f 2 3 7
f 2 7 6
OBJ
mkdir -p "$(dirname "$OUT")"
"$BIN" bake "$TMP/plate.obj" -o "$OUT" --material steel --size 0.03 --order 1 --modes 20 \
  --fixed-box 0,0,-0.05,0.05,0.05,0 --fixed-box 0.95,0,-0.05,1,0.05,0 \
  --fixed-box 0,0.55,-0.05,0.05,0.6,0 --fixed-box 0.95,0.55,-0.05,1,0.6,0
echo "wrote $OUT" >&2
