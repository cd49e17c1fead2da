#!/usr/bin/env bash
# The study's table, redone: sweeps every seed scene at SIZE×SIZE (default 1000, the
# study's size) and prints, per scene, the SDF back-end at its default epsilon (1e-4),
# mesh low and high, and the lowest mesh detail that matches the SDF's mean geometric
# error, each with median wall time, geometry bytes and errors.
# Usage: scripts/study-table.sh [SIZE] [RUNS]
set -euo pipefail
cd "$(dirname "$0")/.."
size=${1:-1000}
runs=${2:-3}
cargo build --release --quiet
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "| scene | SDF (epsilon 1e-4) | mesh low | mesh high | mesh matching SDF accuracy |"
echo "|---|---|---|---|---|"
for scene in examples/seed/0*.scn; do
  ./target/release/scnc sweep "$scene" -o "$out" --width "$size" --height "$size" --runs "$runs" 2> /dev/null
  awk -F, -v name="$(basename "$scene" .scn)" '
    NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
    { setting[NR] = $col["setting"]; backend[NR] = $col["backend"]; wall[NR] = $col["wall_ms"];
      bytes[NR] = $col["geometry_bytes"]; geo[NR] = $col["geo_error_mean"]; n = NR }
    END {
      for (i = 2; i <= n; i++) if (setting[i] == "epsilon 1e-4 steps 512") sdf = i
      for (i = 2; i <= n; i++) if (setting[i] == "detail low") low = i
      for (i = 2; i <= n; i++) if (setting[i] == "detail high") high = i
      match_row = 0
      # Mesh rows come in increasing detail: the first within the SDF error is the match.
      for (i = 2; i <= n; i++) if (backend[i] == "mesh" && geo[i] + 0 <= geo[sdf] + 0 && match_row == 0) match_row = i
      cell = "%.1f ms, %d B, error %.1e"
      printf "| %s | ", name
      printf cell " | ", wall[sdf], bytes[sdf], geo[sdf]
      printf cell " | ", wall[low], bytes[low], geo[low]
      printf cell " | ", wall[high], bytes[high], geo[high]
      if (match_row) printf "%s: " cell " |\n", setting[match_row], wall[match_row], bytes[match_row], geo[match_row]
      else printf "none up to detail 112 |\n"
    }' "$out/sweep.csv"
done
