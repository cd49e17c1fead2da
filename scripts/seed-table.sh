#!/usr/bin/env bash
# Renders the seven seed scenes at 1000×1000 (depth 5, the study's settings) with the
# release build and prints a Markdown table: median wall time of RUNS whole-process runs,
# peak resident memory, and the tracer's own ray rate and counters from --stats.
# Usage: scripts/seed-table.sh [RUNS] [extra scnc render flags…]
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-5}
shift || true
cargo build --release --quiet
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "| scene | wall (median of $runs) | peak RSS | rays/s | primary | shadow | reflection | SDF evals/ray | geometry bytes |"
echo "|---|---|---|---|---|---|---|---|---|"
for scene in examples/seed/0*.scn; do
  walls=()
  for _ in $(seq "$runs"); do
    /usr/bin/time -f "%e %M" -o "$out/time" ./target/release/scnc render "$scene" -o "$out/img.png" --stats "$@" 2> "$out/stats"
    walls+=("$(cut -d' ' -f1 "$out/time")")
  done
  median=$(printf '%s\n' "${walls[@]}" | sort -n | sed -n "$(( (runs + 1) / 2 ))p")
  rss=$(cut -d' ' -f2 "$out/time")
  rays=$(grep -oE '[0-9.]+ M rays/s' "$out/stats" | head -1)
  read -r primary shadow reflection < <(grep -E '^  rays ' "$out/stats" | grep -oE '[0-9]+ (primary|shadow|reflection)' | cut -d' ' -f1 | tr '\n' ' ') || true
  evals=$(grep -oE '\(([0-9.]+) per ray' "$out/stats" | head -1 | grep -oE '[0-9.]+')
  # The first figure of the memory line is the total; the others are parts of it.
  bytes=$(grep -E '^  memory' "$out/stats" | grep -oE '[0-9]+ bytes in total' | cut -d' ' -f1)
  echo "| $(basename "$scene" .scn) | ${median} s | $((rss / 1024)) MiB | $rays | $primary | $shadow | $reflection | $evals | $bytes |"
done
