#!/usr/bin/env bash
# Bakes data/bases/v1_beam.modes with modal-bake as it was before second-order support
# (commit 04149c0, `.modes` format version 1), so tests can check that bases written by that
# release still load. Builds the old commit in a temporary git worktree (the workspace's
# target folder caches the dependencies), then removes the worktree.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
COMMIT=04149c0
TMP=$(mktemp -d)
trap 'git -C "$ROOT" worktree remove --force "$TMP/src" >/dev/null 2>&1 || true; rm -rf "$TMP"' EXIT
git -C "$ROOT" worktree add --detach "$TMP/src" "$COMMIT" >/dev/null
CARGO_TARGET_DIR="$ROOT/target" cargo build --release -p modal-bake --manifest-path "$TMP/src/Cargo.toml"
cp "$ROOT/target/release/modal-bake" "$TMP/modal-bake-v1"
"$TMP/modal-bake-v1" bake "$ROOT/data/meshes/beam.msh" -o "$ROOT/data/bases/v1_beam.modes" \
  --youngs 2e9 --density 1200 --fixed clamp --modes 3 --f32
echo "wrote data/bases/v1_beam.modes"
