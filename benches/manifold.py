"""Issue 62's Manifold anchor: the gyroid sheet of benches/scenes/gyroid-sheet.scn
(period 0.8, |g| < 0.3, cut by a ball of radius 1.2) meshed by Manifold's level set
(`pip install manifold3d`), written as binary STL in the field's own coordinates for
scnc's deviation measurement (`cargo run --release --example deviation -- SCENE out.stl
--scale 1 --up none`). `python3 benches/manifold.py EDGE out.stl [TOLERANCE]`: EDGE is
Manifold's largest edge length, TOLERANCE its vertex tolerance (-1, its default,
interpolates). Manifold calls the Python function once per grid point, on one thread.
"""
import math
import struct
import sys
import time

from manifold3d import Manifold

K = math.radians(450)


def inside(x, y, z):
    """Manifold's sign: positive inside."""
    g = (math.sin(K * x) * math.cos(K * y) + math.sin(K * y) * math.cos(K * z)
         + math.sin(K * z) * math.cos(K * x))
    return -max(abs(g) - 0.3, math.sqrt(x * x + y * y + z * z) - 1.2)


def main():
    edge, out = float(sys.argv[1]), sys.argv[2]
    tolerance = float(sys.argv[3]) if len(sys.argv) > 3 else -1
    start = time.perf_counter()
    m = Manifold.level_set(inside, [-1.21, -1.21, -1.21, 1.21, 1.21, 1.21], edge, 0.0, tolerance)
    secs = time.perf_counter() - start
    mesh = m.to_mesh()
    verts, tris = mesh.vert_properties, mesh.tri_verts
    with open(out, "wb") as f:
        f.write(b"\0" * 80 + struct.pack("<I", len(tris)))
        for t in tris:
            f.write(struct.pack("<3f", 0, 0, 0))
            for i in t:
                f.write(struct.pack("<3f", *verts[i][:3]))
            f.write(b"\0\0")
    print(f"manifold level set edge {edge}: {len(tris)} triangles in {secs:.3f} s, volume {m.volume():.4f}")


main()
