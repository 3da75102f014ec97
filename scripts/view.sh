#!/usr/bin/env bash
# Serves the browser viewer (viewer/) on 127.0.0.1 and prints the URL that opens FILE.glb in it.
# Usage: scripts/view.sh FILE.glb [PORT]     (Ctrl-C stops the server)
# The page needs no network: three.js is bundled in viewer/vendor/ (scripts/build_viewer.sh).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
if [ $# -lt 1 ] || [ ! -f "$1" ]; then
  echo "usage: scripts/view.sh FILE.glb [PORT]   (FILE.glb from 'dcr-scenes run SCENE --gltf' or 'modal-bake export BASE --gltf')" >&2
  exit 2
fi
port="${2:-8765}"
file="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"
# The file is served from a temporary folder beside the viewer's own files.
serve="$(mktemp -d)"
trap 'rm -rf "$serve"' EXIT
ln -s "$root/viewer/index.html" "$root/viewer/viewer.js" "$root/viewer/vendor" "$serve/"
ln -s "$file" "$serve/$(basename "$file")"
echo "dcr viewer: http://127.0.0.1:$port/index.html?file=$(basename "$file")"
echo "(serving $serve on 127.0.0.1:$port; Ctrl-C to stop)"
cd "$serve"
python3 -m http.server "$port" --bind 127.0.0.1
