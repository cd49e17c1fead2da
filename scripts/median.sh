# Sourced by the table scripts. `median ARGS…`: the median wall time, in seconds with
# $digits decimals (default 3), of $runs whole-process runs of `./target/release/scnc
# ARGS…`; the last run's standard error stays in $out/stats.
median() {
  local walls=()
  for _ in $(seq "$runs"); do
    local start end
    start=$(date +%s.%N)
    ./target/release/scnc "$@" 2> "$out/stats"
    end=$(date +%s.%N)
    walls+=("$(awk -v a="$start" -v b="$end" -v d="${digits:-3}" 'BEGIN { printf "%.*f", d, b - a }')")
  done
  printf '%s\n' "${walls[@]}" | sort -n | sed -n "$(( (runs + 1) / 2 ))p"
}
