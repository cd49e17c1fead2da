#!/bin/bash
# Renders every example and bench scene with two scnc binaries, at 96x96 on both
# back-ends, and says which images differ by a byte (or exit differently).
# Usage: scripts/same-images.sh OLD_SCNC NEW_SCNC
# For a restructuring that must not change a pixel: build the old commit's binary,
# copy it aside, build the new one, and run this from the repository's root.
set -u
old=$1 new=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
compared=0 rendered=0 differ=0
for f in $(find examples benches/scenes -name '*.scn' | sort); do
  for g in sdf mesh; do
    k=$(echo "$f" | tr / _)-$g
    "$old" render "$f" -o "$out/a-$k.png" --width 96 --height 96 --geometry $g >/dev/null 2>&1; ra=$?
    "$new" render "$f" -o "$out/b-$k.png" --width 96 --height 96 --geometry $g >/dev/null 2>&1; rb=$?
    compared=$((compared + 1))
    if [ $ra != $rb ]; then echo "exit differs: $f ($g): $ra, $rb"; differ=$((differ + 1)); continue; fi
    [ $ra != 0 ] && continue
    rendered=$((rendered + 1))
    cmp -s "$out/a-$k.png" "$out/b-$k.png" || { echo "differs: $f ($g)"; differ=$((differ + 1)); }
  done
done
echo "$compared runs, $rendered images compared, $differ differ"
[ $differ = 0 ]
