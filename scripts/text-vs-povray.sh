#!/bin/bash
# Lays out the same text in scnc (both back-ends) and in POV-Ray's `text` object, in the
# bundled DejaVu Sans, 256x256 without antialiasing, and counts the pixels whose
# coverage differs. Needs `povray` (Debian's package) and python3 with numpy.
# Usage: scripts/text-vs-povray.sh [SCNC]   (from the repository's root)
set -eu
scnc=${1:-target/release/scnc}
font=$(realpath assets/DejaVuSans.ttf)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cat > "$out/text.scn" <<'SCN'
camera(position = [1.25, 0.3, -6], look_at = [1.25, 0.3, 0], fov = 26)
render(width = 256, height = 256, background = rgb(0, 0, 0))
light ambient(1)
object extrude(text("Hello, Wörld!\ngyp @ 8", size = 0.5), 0.001) rotate [-90, 0, 0] with material(rgb(255, 255, 255))
SCN
# POV-Ray has no line breaks: the second line is its own text, one line height lower
# (DejaVu Sans: ascender 1901 - descender -483 + gap 0 = 2384 of 2048 units per em).
cat > "$out/text.pov" <<POV
#version 3.7;
global_settings { assumed_gamma 1 charset utf8 }
camera { perspective location <1.25, 0.3, -6> look_at <1.25, 0.3, 0> right x up y angle 26 }
background { rgb 0 }
union {
  text { ttf "$font" "Hello, Wörld!" 0.002, 0 scale 0.5 }
  text { ttf "$font" "gyp @ 8" 0.002, 0 scale 0.5 translate <0, -0.5 * 2384 / 2048, 0> }
  translate <0, 0, -0.001>
  pigment { rgb 1 } finish { ambient 1 diffuse 0 }
}
POV
"$scnc" render "$out/text.scn" -o "$out/sdf.png" > /dev/null
"$scnc" render "$out/text.scn" -o "$out/mesh.png" --geometry mesh --tolerance 0.0002 > /dev/null
povray "+I$out/text.pov" "+O$out/pov.ppm" +FP +W256 +H256 -D -A > /dev/null 2>&1
python3 - "$out" <<'PY'
import struct, sys, zlib
import numpy as np
out = sys.argv[1]

def png(path):
    d = open(path, 'rb').read()
    pos, idat = 8, b''
    while pos < len(d):
        n, = struct.unpack('>I', d[pos:pos + 4])
        kind, body = d[pos + 4:pos + 8], d[pos + 8:pos + 8 + n]
        pos += 12 + n
        if kind == b'IHDR':
            w, h, _, colour = struct.unpack('>IIBB', body[:10])
        if kind == b'IDAT':
            idat += body
    ch = {0: 1, 2: 3, 6: 4}[colour]
    raw, stride = zlib.decompress(idat), w * ch
    rows, prev = [], np.zeros(stride, np.int32)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = np.frombuffer(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)], np.uint8).astype(np.int32)
        cur = np.zeros(stride, np.int32)
        for x in range(stride):
            a = cur[x - ch] if x >= ch else 0
            b = prev[x]
            c = prev[x - ch] if x >= ch else 0
            p = a + b - c
            pred = [0, a, b, (a + b) // 2, a if abs(p - a) <= abs(p - b) and abs(p - a) <= abs(p - c) else (b if abs(p - b) <= abs(p - c) else c)][f]
            cur[x] = (line[x] + pred) & 255
        rows.append(cur)
        prev = cur
    return np.array(rows).reshape(h, w, ch)[:, :, :3].mean(axis=2) > 127

def ppm(path):
    d = open(path, 'rb').read()
    toks, pos = [], 0
    while len(toks) < 4:
        while d[pos:pos + 1].isspace():
            pos += 1
        if d[pos:pos + 1] == b'#':
            pos = d.index(b'\n', pos)
            continue
        end = pos
        while not d[end:end + 1].isspace():
            end += 1
        toks.append(d[pos:end])
        pos = end
    w, h = int(toks[1]), int(toks[2])
    return np.frombuffer(d[pos + 1:pos + 1 + w * h * 3], np.uint8).reshape(h, w, 3).mean(axis=2) > 127

pov = ppm(f'{out}/pov.ppm')
for name in ('sdf', 'mesh'):
    ours = png(f'{out}/{name}.png')
    differ = ours != pov
    # POV-Ray does not kern W with ö (DejaVu's kern table: -120 units; it kerns W with o).
    o = differ[110:160, 195:235].sum()
    print(f'{name:4}: {differ.sum()} of {differ.size} pixels differ from POV-Ray ({o} of them at the W-ö pair), '
          f'ink {ours.sum()} against {pov.sum()}')
PY
