"""The nine bodies of issue 43 in Manifold (`pip install manifold3d`): for each, the
coarsest setting whose volume is within 0.1 % of exact.json, and its triangle count.
Run from this directory: `python3 manifold.py`."""
import json, math, time
from manifold3d import Manifold, CrossSection, OpType

exact = json.load(open('exact.json'))


def body(k, n):
    if k == 'prism': return CrossSection([[(0, 0), (1, 0), (0, 1)]]).extrude(1.0)
    if k == 'tube': return CrossSection([[(0.5, -0.5), (0.6, -0.5), (0.4, 0.5), (0.3, 0.5)]]).revolve(n)
    if k == 'twist': return CrossSection.square((1, 1), True).extrude(2.0, n_divisions=n, twist_degrees=90)
    if k == 'ellipsoid': return Manifold.sphere(1, n).scale((1, 0.6, 0.4))
    if k == 'cone': return Manifold.cylinder(1.0, 0.6, 0.3, n)
    if k == 'octahedron': return Manifold.hull_points([(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)])
    if k == 'ring':
        return Manifold.batch_boolean(
            [Manifold.sphere(0.3, n).translate((math.cos(i * math.pi / 3), 0, math.sin(i * math.pi / 3))) for i in range(6)],
            OpType.Add)
    if k == 'capsule':
        return Manifold.batch_hull([Manifold.sphere(0.3, n).translate((0, -0.5, 0)), Manifold.sphere(0.3, n).translate((0, 0.5, 0))])
    if k == 'plate': return (CrossSection.square((2, 1.4), True) - CrossSection.circle(0.3, n)).extrude(0.2)


total, start = 0, time.time()
for k, v in exact.items():
    for n in list(range(3, 64)) + list(range(64, 2049, 8)):
        m = body(k, n)
        err = (m.volume() - v) / v
        if abs(err) < 1e-3 or k in ('prism', 'octahedron'):
            break
    total += m.num_tri()
    print(f"{k:10s} setting {n:5d} {m.num_tri():7d} triangles, volume {100 * err:+.4f} %")
print('total', total, 'triangles; search', round(time.time() - start, 1), 's')
