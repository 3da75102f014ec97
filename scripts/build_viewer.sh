#!/usr/bin/env bash
# Rebuilds viewer/vendor/three.bundle.min.js (the parts of three.js the viewer imports,
# viewer/src/three-entry.js, bundled and minified by esbuild) and copies three.js's licence
# beside it. Versions are pinned by viewer/package-lock.json. The bundle is committed so the
# viewer works from a clone without npm; `--check` rebuilds into a temp dir and compares.
set -euo pipefail
cd "$(dirname "$0")/../viewer"
npm ci --no-audit --no-fund >/dev/null
out=vendor
if [ "${1:-}" = "--check" ]; then out="$(mktemp -d)"; fi
node_modules/.bin/esbuild src/three-entry.js --bundle --minify --format=esm --legal-comments=none \
  --log-level=warning --outfile="$out/three.bundle.min.js"
cp node_modules/three/LICENSE "$out/three.LICENSE"
if [ "${1:-}" = "--check" ]; then
  cmp "$out/three.bundle.min.js" vendor/three.bundle.min.js && cmp "$out/three.LICENSE" vendor/three.LICENSE
  echo "viewer/vendor is reproduced by scripts/build_viewer.sh"
fi
