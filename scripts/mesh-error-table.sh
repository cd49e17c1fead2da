#!/usr/bin/env bash
# Meshing by error (issue 62), each mesh file measured against its scene's field by
# examples/deviation (15 points a triangle). Wall time and peak resident memory are of
# the whole process (`/usr/bin/time`), one run each: compare within one run of this
# script. A tool that is missing is skipped.
# - `gyroid`: the sheet of benches/scenes/gyroid-sheet.scn meshed by `scnc export
#   --tolerance`, by fidget's dual contouring (benches/fidget-mesh, its VM evaluator:
#   faster than its JIT here) and by Manifold's level set (benches/manifold.py, with
#   `pip install manifold3d`).
# - `chain`: the 1,000-sphere molecule of benches/scenes/chain-1000.scn meshed by
#   `scnc export --tolerance` and by the uniform cells of `--detail` (the mesher the
#   error-driven one replaced: every cell near the surface the same size).
# Usage: scripts/mesh-error-table.sh [gyroid|chain] [PLOT_ROWS_FILE]
# prints a Markdown table; PLOT_ROWS_FILE gets `SERIES DEVIATION TRIANGLES SECONDS` lines
# for `cargo run --release --example mesh_plot -- chart.png < PLOT_ROWS_FILE`.
set -euo pipefail
cd "$(dirname "$0")/.."
which=${1:-gyroid}
rows=${2:-/dev/null}
case $which in
  gyroid) scene=benches/scenes/gyroid-sheet.scn ;;
  chain) scene=benches/scenes/chain-1000.scn ;;
  *) echo "usage: $0 [gyroid|chain] [PLOT_ROWS_FILE]" >&2; exit 2 ;;
esac
: > "$rows"
cargo build --release --quiet --bin scnc --example deviation
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# "wall peak_MB" of a command, its output in $out/log.
timed() {
  /usr/bin/time -f '%e %M' -o "$out/time" "$@" > "$out/log" 2>&1
  awk '{printf "%s %d\n", $1, $2 / 1024}' "$out/time"
}
# "triangles bad_edges max p999" of a mesh file.
measured() {
  local line
  line=$(target/release/examples/deviation "$scene" "$@" | tail -1)
  echo "$(sed -E 's/.*: ([0-9]+) triangles, ([0-9]+) open.*/\1 \2/' <<< "$line")" \
    "$(sed -E 's/.*deviation max ([^,]+),.* 99\.9 % ([^,]+),.*/\1 \2/' <<< "$line")"
}
row() {
  local series=$1 setting=$2 wall=$3 mb=$4 tris=$5 bad=$6 max=$7 p999=$8
  echo "| $series | $setting | $tris | $wall | $mb | $max | $p999 | $bad |"
  echo "$series $max $tris $wall" >> "$rows"
}

echo "| mesher | setting | triangles | wall s | peak MB | max deviation | 99.9 % | open or non-manifold edges |"
echo "|---|---|---|---|---|---|---|---|"
if [ "$which" = chain ]; then
  # The chain stands on a plane, which no mesh file holds.
  for t in 0.02 0.01 0.005 0.002 0.001; do
    read -r wall mb < <(timed target/release/scnc export "$scene" -o "$out/s.stl" --skip-unbounded --tolerance "$t")
    read -r tris bad max p999 < <(measured "$out/s.stl")
    row scnc-by-error "--tolerance $t" "$wall" "$mb" "$tris" "$bad" "$max" "$p999"
  done
  for d in 46 80 114 160; do
    read -r wall mb < <(timed target/release/scnc export "$scene" -o "$out/s.stl" --skip-unbounded --detail "$d")
    read -r tris bad max p999 < <(measured "$out/s.stl")
    row uniform-cells "--detail $d" "$wall" "$mb" "$tris" "$bad" "$max" "$p999"
  done
  exit 0
fi

for t in 0.01 0.005 0.003 0.002 0.001; do
  read -r wall mb < <(timed target/release/scnc export "$scene" -o "$out/s.stl" --tolerance "$t")
  read -r tris bad max p999 < <(measured "$out/s.stl")
  row scnc "--tolerance $t" "$wall" "$mb" "$tris" "$bad" "$max" "$p999"
done

if (cd benches/fidget-mesh && cargo build --release --quiet) 2> /dev/null; then
  for depth in 6 7 8 9; do
    read -r wall mb < <(timed benches/fidget-mesh/target/release/fidget-mesh-bench "$depth" "$out/f.stl" vm)
    read -r tris bad max p999 < <(measured "$out/f.stl" --scale 1 --up none)
    row fidget "depth $depth" "$wall" "$mb" "$tris" "$bad" "$max" "$p999"
  done
fi

if python3 -c 'import manifold3d' 2> /dev/null; then
  for edge in 0.04 0.02 0.01; do
    read -r wall mb < <(timed python3 benches/manifold.py "$edge" "$out/m.stl")
    read -r tris bad max p999 < <(measured "$out/m.stl" --scale 1 --up none)
    row Manifold "edge $edge" "$wall" "$mb" "$tris" "$bad" "$max" "$p999"
  done
fi
