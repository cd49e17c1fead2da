#!/usr/bin/env bash
# The CSG-at-scale table (issue 21): the same N jittered spheres as N objects, as one
# union and as one smooth union (benches/scenes/{objects,union,smooth}-N.scn, 400×400),
# and the 1,000-sphere smooth chain at 1000×1000, depth 5. Median of RUNS whole-process
# runs of the release build, and primitive evaluations per ray from --stats; the times
# are drawn log-log into docs/csg-scale.png (scripts/csg_plot.rs).
# Usage: scripts/csg-table.sh [RUNS]
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-5}
cargo build --release --quiet --bin scnc --example csg_plot
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
# shellcheck source=scripts/median.sh
. scripts/median.sh
# Median wall time of rendering, then the primitives per ray of the last run.
measure() {
  local median
  median=$(median render "$1" -o "$out/img.png" --stats)
  local leaves
  leaves=$(grep -E '^  primitives' "$out/stats" | grep -oE '\(([0-9.]+) per ray' | grep -oE '[0-9.]+')
  echo "$median $leaves"
}
echo "| N | objects | union | smooth union | union / objects | scene evaluation (check) | primitives per ray: objects, union, smooth |"
echo "|---|---|---|---|---|---|---|"
for n in 10 100 1000 10000; do
  read -r o ol < <(measure "benches/scenes/objects-$n.scn")
  read -r u ul < <(measure "benches/scenes/union-$n.scn")
  read -r s sl < <(measure "benches/scenes/smooth-$n.scn")
  e=$(median check "benches/scenes/union-$n.scn")
  ratio=$(awk -v u="$u" -v o="$o" 'BEGIN { printf "%.1f", (o > 0 ? u / o : 0) }')
  echo "| $n | $o s | $u s | $s s | ${ratio}× | $e s | $ol, $ul, $sl |"
  echo "$n $o $u $s $e" >> "$out/plot"
done
./target/release/examples/csg_plot docs/csg-scale.png < "$out/plot"
read -r c cl < <(measure benches/scenes/chain-1000.scn)
echo
echo "chain-1000 (1000×1000, depth 5): $c s, $cl primitives per ray"
