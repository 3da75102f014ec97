#!/bin/sh
# Regenerate docs/outcomes.md and docs/outcomes/*_lift.svg (`dcr-lab scene-truth --page docs`):
# for each scene, the coupled elastic–rigid reference (every elastic mode of the object's mesh,
# penalty contacts implicit in the forces with the scene's rapier bodies) as an ensemble of runs
# (member 0 the scene as written, the others with the projectile started 0.1 mm away: the
# outcomes are chaotic), the step halved until the ensemble means move by less than 2 % or
# than their noise, then checked with the contact stiffness doubled; beside it the rigid scene
# and the distant response at gain 1 (20 modes, the transfer table, attenuation), each as the
# same ensemble. The dense eigensolves are cached in $CARGO_TARGET_DIR/scene-truth-cache
# (default target/; the scaffold's 14,997-dof solve needs ~15 GB of memory and ~20 minutes
# once); SKIP_BUILD=1 uses the built binary as it is. Scenes default to dinner, roof, scaffold
# and lowrider (simulated 1.4 s from a first step of 1e-5 s: its truck lands 0.75 s in,
# `--scene-seconds lowrider=1.4 --scene-dt lowrider=1e-5`); extra arguments go to `dcr-lab
# scene-truth` (`--seconds S`, `--scene-seconds SCENE=S`, `--dt S`, `--scene-dt SCENE=S`,
# `--max-halvings N`, `--members N`, `--no-mode-check`). Exit status 3: a reference did not
# converge (the page is still written and says so). Needs data/scenes/*.msh
# (scripts/gen_scene_meshes.sh).
set -e
cd "$(dirname "$0")/.."
if [ -z "$SKIP_BUILD" ]; then cargo build --release --workspace --bins; fi
TARGET=${CARGO_TARGET_DIR:-target}
SCENES=${SCENES:-"dinner roof scaffold lowrider"}
# The lowrider's outcome comes after its truck lands, 1.4 s of a scene whose steps cost as much
# as the others' (a --scene-seconds or --scene-dt among the arguments overrides these).
LONG=""
case " $SCENES " in *" lowrider "*) LONG="--scene-seconds lowrider=1.4 --scene-dt lowrider=1e-5" ;; esac
HEADER="Regenerate with \`scripts/outcomes.sh\` (\`SCENES=\"$SCENES\"\`; arguments: \`$LONG $*\`). Do not edit by hand. Generated $(date -u +%Y-%m-%d) on $(nproc) shared cores (load average at the start: $(cut -d' ' -f1-3 /proc/loadavg))."
# shellcheck disable=SC2086
exec "$TARGET/release/dcr-lab" scene-truth $SCENES --page docs --page-header "$HEADER" \
  --eigen-cache "$TARGET/scene-truth-cache" --max-dense-dofs 16000 $LONG "$@"
