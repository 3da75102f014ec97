#!/bin/sh
# Regenerate docs/accuracy.md and docs/accuracy/*.svg: peak distant displacement of truncated
# modal bases (5 … 640 modes, four samplings, per-node vs per-contact), read and stepped through
# the runtime, vs the full-order truth on the table, the ground slab and the scaffold; a mesh
# resolution sweep on a structured plate; bake time, base size, query time; the bake-time
# peak-transfer table (Method::Transfer, issue #5 item 3) vs the 20-mode base; and the Eq. 14
# attenuation fit of each object (modal-bake fit-attenuation). For just the transfer study run
# the example directly: target/release/examples/accuracy --out /tmp/x --transfer-only.
# Needs data/scenes/*.msh (scripts/gen_scene_meshes.sh). About 10–15 min on 2 cores.
set -e
cd "$(dirname "$0")/.."
cargo build --release -p modal-bake --example accuracy
target/release/examples/accuracy --out docs "$@" > docs/accuracy.md.tmp
mv docs/accuracy.md.tmp docs/accuracy.md
echo "wrote docs/accuracy.md and docs/accuracy/*.svg"
