#!/usr/bin/env bash
# gmsh's own tutorials as volume meshes through `modal-bake bake` (docs/benchmarks.md,
# "gmsh's tutorials as volume meshes"): inputs nobody here made, written by the real gmsh.
#
# Meshes each tutorial script t1.geo … t21.geo shipped with the PyPI gmsh package
# (share/doc/gmsh/tutorials) with `gmsh tN.geo -3 -format msh41`, as a gmsh user would, and
# bakes the result with `modal-bake bake tN.msh --material steel --modes 10`, recording the exit
# status, wall time, peak memory and the first line of the outcome (the mesh and modes, or the
# error); a mesh refused as curved is baked again with `--straighten`, and one refused as
# several disconnected pieces piece by piece (`--piece N`), one row each. Prints a markdown
# table. `--order 2` meshes with gmsh's `-order 2` (its default curved second order). Work
# files go to out/gmsh-tutorials/ (out/gmsh-tutorials-o2/; ignored by git).
#
# Usage: scripts/gmsh_tutorials.sh [--bin PATH-TO-modal-bake] [--order 1|2]
# Needs gmsh (`pip install gmsh`; its tutorials come with it) and /usr/bin/time.
set -euo pipefail

root="$(cd "$(dirname "$0")/.." && pwd)"
bin="$root/target/release/modal-bake"
order=1
while [ $# -gt 0 ]; do
  case "$1" in
    --bin) bin="$2"; shift 2 ;;
    --order) order="$2"; shift 2 ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "gmsh_tutorials.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
  esac
done
[ -x "$bin" ] || { echo "gmsh_tutorials.sh: no modal-bake at $bin: build it (cargo build --release -p modal-bake) or pass --bin" >&2; exit 2; }
command -v gmsh >/dev/null || { echo "gmsh_tutorials.sh: gmsh not found: pip install gmsh" >&2; exit 2; }

tutorials="$(python3 -c 'import sys, os; print(os.path.join(sys.prefix, "share/doc/gmsh/tutorials"))')"
[ -f "$tutorials/t1.geo" ] || { echo "gmsh_tutorials.sh: no tutorials at $tutorials (the PyPI gmsh package ships them)" >&2; exit 2; }
case "$order" in
  1) work="$root/out/gmsh-tutorials" ;;
  2) work="$root/out/gmsh-tutorials-o2" ;;
  *) echo "gmsh_tutorials.sh: --order must be 1 or 2, got $order" >&2; exit 2 ;;
esac
rm -rf "$work"
mkdir -p "$work"
cp -r "$tutorials"/. "$work"/
cd "$work"

echo "gmsh $(gmsh --version 2>&1 | tail -1) \`-order $order\`, $("$bin" --version); $(date -u +%Y-%m-%dT%H:%MZ), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo
# bake_row LABEL STEM VOLUME [EXTRA bake options]: bakes $t.msh into STEM.modes and prints a
# table row: exit status, wall time, peak memory and the outcome (mesh and modes, or the error).
bake_row() {
  local label="$1" stem="$2" volume="$3" rc wall kb outcome warnings
  shift 3
  set +e
  /usr/bin/time -f "%e %M" -o "$stem.time" "$bin" bake "$t.msh" -o "$stem.modes" --material steel --modes 10 "$@" \
    > "$stem.bake.out" 2> "$stem.bake.err"
  rc=$?
  set -e
  read -r wall kb < <(tail -1 "$stem.time") || true
  if [ "$rc" = 0 ]; then
    outcome="$(grep -E '^  mesh:' "$stem.bake.out" | sed 's/^ *//'); $(grep -E ' modes, ' "$stem.bake.out" | sed 's/^ *//')"
    warnings="$(grep -c '^warning: ' "$stem.bake.err" || true)"
    [ "$warnings" != 0 ] && outcome="$outcome; $warnings size/mass warning(s)"
  else
    outcome="$(grep -E '^error' "$stem.bake.err" | head -1 | cut -c1-220)"
  fi
  echo "| $label | $volume | $rc | $wall | $((kb / 1024)) | ${outcome//|/\\|} |"
}

echo "| tutorial | gmsh's elements (3-D) | bake exit | wall s | peak MiB | outcome |"
echo "|---|---|---|---|---|---|"
for n in $(seq 1 21); do
  t="t$n"
  gmsh "$t.geo" -3 -order "$order" -format msh41 -o "$t.msh" > "$t.gmsh.log" 2>&1 || true
  if [ ! -f "$t.msh" ]; then
    echo "| $t | gmsh wrote no mesh | – | – | – | – |"
    continue
  fi
  volume="$(python3 - "$t.msh" 2>/dev/null <<'EOF' | sed -n 's/^VOLUME //p' || true
import sys
try:
    import meshio
except ImportError:
    print("VOLUME (meshio not installed)"); sys.exit()
try:
    m = meshio.read(sys.argv[1])
except Exception as e:
    print("VOLUME (meshio cannot read it)"); sys.exit()
counts = {}
for c in m.cells:
    if c.dim == 3:
        counts[c.type] = counts.get(c.type, 0) + len(c.data)
print("VOLUME " + (", ".join(f"{n:,} {k}" for k, n in counts.items()) or "none"))
EOF
)"
  bake_row "$t" "$t" "${volume:-–}"
  # Curved second-order elements: baked again straightened, as the refusal says.
  extra=()
  err="$t.bake.err"
  if grep -q "curved 10-node tetrahedron" "$err"; then
    extra=(--straighten)
    bake_row "$t --straighten" "$t.s" "" "${extra[@]}"
    err="$t.s.bake.err"
  fi
  # A mesh of several pieces: each piece baked alone, as the refusal says.
  pieces="$(sed -n 's/.*the mesh has \([0-9]*\) disconnected pieces.*/\1/p' "$err" | head -1)"
  for k in $(seq 1 "${pieces:-0}"); do
    bake_row "$t${extra[*]:+ ${extra[*]}} --piece $k" "$t.p$k" "" "${extra[@]}" --piece "$k"
  done
done
