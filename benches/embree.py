"""Issue 60's Embree anchor: closest hits of the same incoherent rays scnc casts in
`cargo run --release --example rays -- MESH.stl --write rays.bin`, through Embree 4
(`pip install embreex`: its `EmbreeScene.run` calls rtcIntersect1 once per ray, on one
thread), so both sides are rays per second per core.
`python3 benches/embree.py MESH.stl rays.bin`. The STL's triangles are read raw and their
corners shared (as scnc's reader shares them), so both build over the same triangles.
Prints the hit count and the mean distance to check against scnc's line, and the best of
three passes.
"""
import sys
import time

import numpy as np
from embreex import rtcore_scene as rtcs
from embreex.mesh_construction import TriangleMesh


def read_stl(path):
    """Binary STL as (vertices, faces) with equal corners shared."""
    raw = open(path, "rb").read()
    n = int.from_bytes(raw[80:84], "little")
    rec = np.frombuffer(raw, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]),
                        count=n, offset=84)
    corners = rec["v"].reshape(-1, 3)
    verts, index = np.unique(corners, axis=0, return_inverse=True)
    return verts.astype(np.float32), index.reshape(-1, 3).astype(np.int32)


def main():
    verts, faces = read_stl(sys.argv[1])
    rays = np.fromfile(sys.argv[2], dtype="<f4").reshape(-1, 6)
    origins = np.ascontiguousarray(rays[:, :3])
    dirs = np.ascontiguousarray(rays[:, 3:])
    scene = rtcs.EmbreeScene()
    start = time.perf_counter()
    TriangleMesh(scene, verts, faces)
    # The first query commits the scene (Embree builds its BVH then): one warm-up pass.
    scene.run(origins[:1], dirs[:1])
    build = time.perf_counter() - start
    best = float("inf")
    for _ in range(3):
        start = time.perf_counter()
        out = scene.run(origins, dirs, output=1)
        best = min(best, time.perf_counter() - start)
    hit = out["geomID"] >= 0
    t = out["tfar"][hit]
    print(f"embree: {len(faces)} triangles, BVH built in {build:.2f} s; {len(rays)} rays, {hit.sum()} hits, "
          f"mean t {t.mean():.6f}; best of 3 on one thread: {best:.3f} s = {len(rays) / best / 1e6:.2f} M rays/s")


if __name__ == "__main__":
    main()
