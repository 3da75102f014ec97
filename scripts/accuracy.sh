#!/bin/sh
# Regenerate docs/accuracy.md and docs/accuracy/*.svg (`dcr-lab accuracy --out docs`): peak
# distant displacement of truncated modal bases and transfer tables, read and stepped through the
# runtime, vs the full-order truth; a mesh resolution sweep; bake time, base size, query time;
# and the Eq. 14 attenuation fit of each object. Extra arguments go to `dcr-lab accuracy`
# (e.g. --transfer-only, --quick). Needs data/scenes/*.msh (scripts/gen_scene_meshes.sh).
set -e
cd "$(dirname "$0")/.."
cargo build --release -p dcr-lab
target/release/dcr-lab accuracy --out docs "$@"
