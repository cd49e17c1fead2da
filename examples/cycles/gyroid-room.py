"""benches/scenes/gyroid-room.scn for Blender Cycles, the gyroid sheet as scnc's own mesh
of it (`scnc export benches/scenes/gyroid-sheet.scn -o g.ply --tolerance 0.001`, as
benches/light_error.py makes it), with cornell.py's settings (`pip install bpy==4.2.0`):

    python3 examples/cycles/gyroid-room.py --mesh g.ply --res 512 --spp 64 --seed 1 --out x.exr

The PLY holds scnc's (x, y, -z); Blender's PLY reader, reading y as up, turns a file's
(x, y, z) into its (x, -z, y), which is scnc's (x, z, y): cornell.py's map. The sheet is
shaded flat, as scnc shades a mesh file and as the Mitsuba scene does (the PLY has no
normals). The sphere of light `point(6, radius = 0.15)` is an emissive smooth UV sphere
of 256 × 128 faces and radiance 6 / (π 0.15²), which Cycles samples as a mesh light.
"""
import argparse
import math
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cornell  # noqa: E402  (the settings, materials and camera the two scenes share)


def build(res, spp, seed, mesh):
    scene = cornell.setup(res, spp, seed)
    white = cornell.material("white", (186, 186, 186))
    red = cornell.material("red", (160, 16, 16))
    green = cornell.material("green", (36, 140, 36))
    orange = cornell.material("orange", (230, 150, 60))
    lamp = cornell.material("lamp", emission=6 / (math.pi * 0.15**2))

    def box(half, at, m):
        bpy.ops.mesh.primitive_cube_add(size=2, location=cornell.scnc_at(*at))
        o = bpy.context.object
        o.scale = cornell.scnc_at(*half)
        cornell.place(o, m)

    box((2, 0.01, 2), (0, -0.01, 0), white)
    box((2, 0.01, 2), (0, 3.01, 0), white)
    box((2, 1.5, 0.01), (0, 1.5, 2.01), white)
    box((0.01, 1.5, 2), (-2.01, 1.5, 0), red)
    box((0.01, 1.5, 2), (2.01, 1.5, 0), green)
    bpy.ops.wm.ply_import(filepath=mesh, forward_axis="NEGATIVE_Z", up_axis="Y")
    sheet = bpy.context.selected_objects[0]
    sheet.location = cornell.scnc_at(0, 1.25, 0.3)
    for face in sheet.data.polygons:
        face.use_smooth = False
    cornell.place(sheet, orange)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=256, ring_count=128, radius=0.15,
                                         location=cornell.scnc_at(0, 2.75, -0.6))
    bpy.ops.object.shade_smooth()
    cornell.place(bpy.context.object, lamp)
    cornell.camera(scene, (0, 1.5, -5.2), (0, 1.4, 0), 42)
    return scene


if __name__ == "__main__":
    p = argparse.ArgumentParser(add_help=False)
    p.add_argument("--mesh", required=True)
    known, rest = p.parse_known_args()
    sys.argv = [sys.argv[0], *rest]
    cornell.main(lambda res, spp, seed: build(res, spp, seed, known.mesh))
