#!/bin/sh
# Regenerate docs/outcomes.md and docs/outcomes/*_lift.svg (`dcr-lab scene-truth --page docs`):
# for each scene, the coupled elastic–rigid reference (every elastic mode of the object's mesh,
# penalty contacts implicit in the forces with the scene's rapier bodies, the step halved until
# the outcomes move by less than 2 %, then checked with the contact stiffness doubled and with
# half the modes) beside the rigid scene and the distant response at gain 1 (20 modes, the
# transfer table, attenuation). The dense eigensolves are cached in
# $CARGO_TARGET_DIR/scene-truth-cache (default target/); SKIP_BUILD=1 uses the built binary as
# it is. Scenes default to dinner and roof (the scaffold's 15k free dofs
# are above the dense limit of the reference); extra arguments go to `dcr-lab scene-truth`
# (`--seconds S`, `--dt S`, `--max-halvings N`, `--no-mode-check`). Exit status 3: a reference
# did not converge (the page is still written and says so). Needs data/scenes/*.msh
# (scripts/gen_scene_meshes.sh).
set -e
cd "$(dirname "$0")/.."
if [ -z "$SKIP_BUILD" ]; then cargo build --release -p dcr-lab; fi
TARGET=${CARGO_TARGET_DIR:-target}
SCENES=${SCENES:-"dinner roof"}
HEADER="Regenerate with \`scripts/outcomes.sh\` (\`SCENES=\"$SCENES\"\`; arguments: \`$*\`). Do not edit by hand. Generated $(date -u +%Y-%m-%d) on $(nproc) shared cores (load average at the start: $(cut -d' ' -f1-3 /proc/loadavg))."
# shellcheck disable=SC2086
exec "$TARGET/release/dcr-lab" scene-truth $SCENES --page docs --page-header "$HEADER" \
  --eigen-cache "$TARGET/scene-truth-cache" "$@"
