#!/bin/sh
# Regenerate docs/accuracy.md: peak distant displacement of truncated modal bases (5 … 640 modes)
# vs the full-order truth (all-mode sum, cross-checked with full-order Newmark) on the table.
# Needs data/scenes/table.msh (scripts/gen_scene_meshes.sh). ~1 min on 2 cores.
set -e
cd "$(dirname "$0")/.."
cargo build --release -p modal-bake --example accuracy
target/release/examples/accuracy data/scenes/table.msh --fixed feet "$@" > docs/accuracy.md.tmp
mv docs/accuracy.md.tmp docs/accuracy.md
echo "wrote docs/accuracy.md"
