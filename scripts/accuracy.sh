#!/bin/sh
# Regenerate docs/accuracy.md and docs/accuracy/*.svg (`dcr-lab accuracy --out docs`): every
# elastic object of the scenes (and the fridge's whole surface) and a thick slab, the runtime's
# methods (modal filters, the paper's attenuation, the default transfer table and variants)
# against the converged full-order truth at seeded pairs, with query cost, bake time and base
# size; the Eq. 14 attenuation fit of each object; and the energy bound (every Table 1 scene
# unbounded and at η = 1, 0.5, 0.1). Converged truths are cached in out/truth-cache/ (a rerun
# reuses them; `--no-truth-cache` recomputes). Extra arguments go to `dcr-lab accuracy`
# (`--only NAME`, repeatable; `--newmark-impacts N` for a cheaper truth on the objects above
# 6000 free dofs; `--no-energy`; `--quick`); the page states any reduction. Needs
# data/scenes/*.msh (scripts/gen_scene_meshes.sh). A full run from an empty cache takes about
# an hour and a half on 2 cores (the scaffold's and the cliff's Newmark truths are most of it).
set -e
cd "$(dirname "$0")/.."
cargo build --release -p dcr-lab
target/release/dcr-lab accuracy --out docs "$@"
