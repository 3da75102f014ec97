#!/bin/sh
# Regenerate docs/accuracy.md and docs/accuracy/*.svg (`dcr-lab accuracy --out docs`): every
# elastic object of the scenes and a thick slab, the runtime's methods (modal filters, the
# paper's attenuation, the default transfer table and variants) against the converged full-order
# truth at seeded pairs, with query cost, bake time and base size, and the Eq. 14 attenuation
# fit of each object. Extra arguments go to `dcr-lab accuracy` (`--only NAME`, repeatable;
# `--newmark-impacts N` for a cheaper truth on the objects above 6000 free dofs; `--quick`);
# the page states any reduction. Needs data/scenes/*.msh (scripts/gen_scene_meshes.sh).
set -e
cd "$(dirname "$0")/.."
cargo build --release -p dcr-lab
target/release/dcr-lab accuracy --out docs "$@"
