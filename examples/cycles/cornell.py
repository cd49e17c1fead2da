"""examples/light/cornell.scn for Blender Cycles, built through `bpy` (`pip install
bpy==4.2.0`, Blender 4.2 as a Python module) and rendered on the CPU:

    python3 examples/cycles/cornell.py --res 512 --spp 64 --seed 1 --out x.exr

Prints the render call's wall time (BVH build included, scene set-up not). scnc's world is
left-handed with y up; Blender's right-handed with z up: scnc's (x, y, z) is Blender's
(x, z, y), a swap of two axes, which turns one handedness into the other, so nothing is
mirrored. Colours are scnc's divided by 255 (its linear colour mode). The area light is
an emissive rectangle of strength 40 (Cycles' emission strength is radiance), sampled by
Cycles' light tree with MIS as scnc and Mitsuba sample theirs. Spheres are smooth UV
spheres of 256 × 128 faces (Cycles has no analytic sphere). Unbiased settings: no light
clamp, no glossy filter, no adaptive sampling (unless `--adaptive-threshold`), no
denoising; 8 bounces of every kind (scnc's default `bounces`), two threads.
"""
import argparse
import math
import sys
import time

import bpy
import mathutils


def material(name, colour=None, glass=False, emission=None):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nodes, links = m.node_tree.nodes, m.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    if emission is not None:
        bsdf = nodes.new("ShaderNodeEmission")
        bsdf.inputs["Strength"].default_value = emission
        bsdf.inputs["Color"].default_value = (1, 1, 1, 1)
    elif glass:
        bsdf = nodes.new("ShaderNodeBsdfGlass")
        # Roughness 0 is a smooth dielectric (Blender 4 has no separate "sharp" mode).
        bsdf.distribution = "GGX"
        bsdf.inputs["Roughness"].default_value = 0.0
        bsdf.inputs["IOR"].default_value = 1.5
        bsdf.inputs["Color"].default_value = (1, 1, 1, 1)
    else:
        bsdf = nodes.new("ShaderNodeBsdfDiffuse")
        bsdf.inputs["Color"].default_value = (*[c / 255 for c in colour], 1)
        bsdf.inputs["Roughness"].default_value = 0.0
    links.new(bsdf.outputs[0], out.inputs["Surface"])
    return m


def place(obj, m):
    obj.data.materials.append(m)


def scnc_at(x, y, z):
    """scnc's coordinates in Blender's."""
    return (x, z, y)


def setup(res, spp, seed):
    """A new Cycles scene: the renderer's settings, the image and a black world."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = spp
    cy.seed = seed
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    cy.blur_glossy = 0.0
    cy.max_bounces = 8
    cy.diffuse_bounces = 8
    cy.glossy_bounces = 8
    cy.transmission_bounces = 8
    cy.transparent_max_bounces = 8
    cy.caustics_reflective = True
    cy.caustics_refractive = True
    cy.pixel_filter_type = "BLACKMAN_HARRIS"
    scene.render.threads_mode = "FIXED"
    scene.render.threads = 2
    scene.render.resolution_x = res
    scene.render.resolution_y = res
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.image_settings.color_mode = "RGB"
    scene.view_settings.view_transform = "Standard"
    scene.display_settings.display_device = "sRGB"
    scene.render.film_transparent = False
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world
    return scene


def camera(scene, at, look_at, fov):
    """A camera at scnc's `at` looking at `look_at`, `fov` degrees vertically."""
    cam = bpy.data.cameras.new("camera")
    cam.sensor_fit = "VERTICAL"
    cam.angle = math.radians(fov)
    cam_obj = bpy.data.objects.new("camera", cam)
    scene.collection.objects.link(cam_obj)
    cam_obj.location = scnc_at(*at)
    # Blender's camera looks down its -z with +y up: turned so that -z points at the
    # target and +y is up (Blender's +z, scnc's +y).
    direction = mathutils.Vector(scnc_at(*look_at)) - mathutils.Vector(scnc_at(*at))
    cam_obj.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
    scene.camera = cam_obj


def build(res, spp, seed):
    scene = setup(res, spp, seed)
    white = material("white", (186, 186, 186))
    red = material("red", (160, 16, 16))
    green = material("green", (36, 140, 36))
    glass = material("glass", glass=True)
    lamp = material("lamp", emission=40.0)

    def box(half, at, m):
        bpy.ops.mesh.primitive_cube_add(size=2, location=scnc_at(*at))
        o = bpy.context.object
        o.scale = scnc_at(*half)
        place(o, m)

    box((1, 0.01, 1), (0, -0.01, 0), white)
    box((1, 0.01, 1), (0, 2.01, 0), white)
    box((1, 1, 0.01), (0, 1, 1.01), white)
    box((0.01, 1, 1), (-1.01, 1, 0), red)
    box((0.01, 1, 1), (1.01, 1, 0), green)
    for at, m in (((-0.4, 0.35, 0.3), white), ((0.45, 0.35, -0.2), glass)):
        bpy.ops.mesh.primitive_uv_sphere_add(segments=256, ring_count=128, radius=0.35, location=scnc_at(*at))
        o = bpy.context.object
        bpy.ops.object.shade_smooth()
        place(o, m)
    # A 0.5 × 0.4 rectangle at y = 1.999; Blender's plane faces +z, so turned over to face
    # down (-z), as scnc's faces -y.
    bpy.ops.mesh.primitive_plane_add(size=1, location=scnc_at(0, 1.999, 0), rotation=(math.pi, 0, 0))
    o = bpy.context.object
    o.scale = (0.5, 0.4, 1)
    place(o, lamp)

    camera(scene, (0, 1, -3.4), (0, 1, 0), 40)
    return scene


def main(build=build):
    """Renders the scene `build` makes, as the command line asks."""
    p = argparse.ArgumentParser()
    p.add_argument("--res", type=int, default=128)
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", required=True)
    p.add_argument("--adaptive-threshold", type=float, default=0.0,
                   help="Cycles' adaptive sampling to this noise threshold, --spp the most (0: off)")
    a = p.parse_args()
    scene = build(a.res, a.spp, a.seed)
    if a.adaptive_threshold > 0:
        scene.cycles.use_adaptive_sampling = True
        scene.cycles.adaptive_threshold = a.adaptive_threshold
    scene.render.filepath = a.out
    start = time.time()
    bpy.ops.render.render(write_still=True)
    print(f"cycles: {time.time() - start:.3f} s", file=sys.stderr)


if __name__ == "__main__":
    main()
