#!/usr/bin/env bash
# Regenerates the pictures the docs show (committed, the one kind of generated output that is):
#   docs/pictures/table_modes.png    the table's lowest 8 modes (modal-bake export --png)
#   docs/pictures/dinner_strip.jpg   the dinner scene, response on vs off, 4 frames (viewer)
#   docs/pictures/scene_NAME.jpg     one picture per Table 1 scene, on vs off (viewer)
# Needs a release build, `npm ci` in viewer/ and Debian's chromium. Runs and GLBs go to
# out/pictures/ (not committed). Usage: scripts/pictures.sh [SCENE...]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
cargo build --release -q -p dcr-scenes -p modal-bake
[ -d viewer/node_modules/playwright-core ] || (cd viewer && npm ci --no-audit --no-fund --loglevel=error)
mkdir -p docs/pictures out/pictures
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(dinner roof scaffold lowrider rockfall washing)
# Frames: seconds after the on run's first response (`end`: the run's last step).
declare -A frames=(
  [dinner]="0.06" [roof]="end" [scaffold]="0.08" [lowrider]="end" [rockfall]="1.2" [washing]="end"
)
# Viewer parameters (camera azimuth in degrees about +y).
declare -A query=(
  [dinner]="az=0" [roof]="az=0" [scaffold]="az=0" [lowrider]="az=20" [rockfall]="az=-120" [washing]="az=0"
)
for s in "${scenes[@]}"; do
  target/release/dcr-scenes run "$s" --dcr both --out "out/pictures/$s" --gltf "out/pictures/$s.glb" >/dev/null
  node scripts/frame_strip.mjs "out/pictures/$s.glb" "docs/pictures/scene_$s.jpg" \
    --after-response "${frames[$s]}" --query "${query[$s]}" --width 1200 --height 460 --scale 0.6
  if [ "$s" = dinner ]; then
    node scripts/frame_strip.mjs out/pictures/dinner.glb docs/pictures/dinner_strip.jpg \
      --after-response -0.01,0.03,0.08,0.15 --width 1200 --height 460 --scale 0.5
    target/release/modal-bake export out/bases/table.modes --modes 8 --png docs/pictures/table_modes.png
  fi
done
ls -l docs/pictures
