#!/usr/bin/env bash
# The meshing table (issue 22): every feature scene and the 1,000-sphere smooth chain
# rendered as meshes at `--detail high` and at `--tolerance pixel`, each at its own
# size, against the SDF render of the same scene. Wall times are medians of RUNS
# whole-process runs of the release build; lowering time, triangles, mesh bytes and the
# farthest isosurface vertex (in cells, from `|f|` at the vertices) come from --stats.
# Usage: scripts/mesh-table.sh [RUNS]
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
cargo build --release --quiet --bin scnc
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
digits=2
# shellcheck source=scripts/median.sh
. scripts/median.sh
# Median wall time of a render of ARGS…, its stats in $out/stats.
render() {
  median render "$@" -o "$out/img.png" --stats
}
# "wall lower triangles bytes farthest" of a mesh render.
mesh() {
  local wall lower tris bytes far
  wall=$(render "$@" --geometry mesh)
  lower=$(grep -oE 'lower [0-9.]+ s' "$out/stats" | grep -oE '[0-9.]+')
  tris=$(grep -E '^  meshes' "$out/stats" | grep -oE '[0-9]+ triangles' | grep -oE '[0-9]+' || echo 0)
  bytes=$(grep -E '^  meshes' "$out/stats" | grep -oE '[0-9]+ bytes \(' | grep -oE '[0-9]+' || echo 0)
  far=$(grep -oE '\(([0-9.]+) cell\)' "$out/stats" | grep -oE '[0-9.]+' | sort -g | tail -1 || true)
  echo "$wall $lower $tris $((bytes / 1024)) ${far:-–}"
}
echo "| scene | SDF | high: wall, lowering | triangles | KiB | farthest | pixel: wall, lowering | triangles | KiB | farthest |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for scene in examples/features/*.scn benches/scenes/chain-1000.scn; do
  # lights.scn is the lights the others include, with no object of its own.
  [ "$(basename "$scene")" = lights.scn ] && continue
  sdf=$(render "$scene")
  read -r hw hl ht hb hf < <(mesh "$scene" --detail high)
  read -r pw pl pt pb pf < <(mesh "$scene" --tolerance pixel)
  echo "| $(basename "$scene" .scn) | $sdf s | $hw s, $hl s | $ht | $hb | $hf | $pw s, $pl s | $pt | $pb | $pf |"
done
