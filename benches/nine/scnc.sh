#!/bin/sh
# The nine bodies of issue 43 exported by scnc at each tolerance given (default 0.001):
# triangles, whether watertight, and the volume against exact.json. Run from this
# directory with scnc on the PATH (or SCNC=path/to/scnc).
SCNC=${SCNC:-scnc}
out=$(mktemp -d)
for t in "${@:-0.001}"; do
  echo "tolerance $t"
  for b in prism tube twist ellipsoid cone octahedron ring capsule plate; do
    "$SCNC" export "$b.scn" -o "$out/$b.stl" --tolerance "$t" --stats > "$out/$b.log" 2>&1
  done
  OUT=$out python3 - <<'P'
import json, os, re
exact = json.load(open('exact.json'))
for k, v in exact.items():
    log = open(os.path.join(os.environ['OUT'], k + '.log')).read()
    m = re.search(r'(\d+) triangles, (watertight and manifold|[^,]*), .*volume ([0-9.e+-]+)', log)
    # STL is written ten file units per scene unit: volumes are a thousand times larger.
    vol = float(m.group(3)) / 1000
    print(f"  {k:10s} {int(m.group(1)):9d} triangles, {m.group(2)}, volume {100 * (vol - v) / v:+.4f} %")
P
done
rm -rf "$out"
