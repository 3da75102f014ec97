#!/bin/sh
# Regenerate data/scenes/*.msh from scenes/meshes/*.py (see scripts/gen_scene_meshes.py).
set -e
cd "$(dirname "$0")/.."
exec python3 scripts/gen_scene_meshes.py "$@"
