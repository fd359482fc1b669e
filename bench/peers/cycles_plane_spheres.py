# Blender Cycles version of scenes/bench/plane-spheres.pbrt, for
# bench/peers/cycles_vs_lensfield.sh: 640x426, a 20x20 plane, 4 diffuse
# spheres (radius 0.6), a sun and a uniform sky, 8 bounces, 64 spp, box
# filter, CPU, 2 threads, fixed seed, no denoising, no adaptive sampling.
# pbrt's (x, y, z) (y up) maps to Blender's (x, z, y) (z up): a mirror image,
# the same work.
#   blender -b --factory-startup -P bench/peers/cycles_plane_spheres.py -- [SPP] [THREADS]
import math
import sys
import time

import bpy
from mathutils import Vector

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
spp = int(argv[0]) if len(argv) > 0 else 64
threads = int(argv[1]) if len(argv) > 1 else 2

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.engine = "CYCLES"
cy = scene.cycles
cy.device = "CPU"
cy.samples = spp
cy.use_adaptive_sampling = False
cy.use_denoising = False
cy.seed = 1
cy.max_bounces = 8
cy.diffuse_bounces = 8
cy.glossy_bounces = 8
cy.transmission_bounces = 8
cy.transparent_max_bounces = 8
cy.sample_clamp_direct = 0
cy.sample_clamp_indirect = 0
cy.pixel_filter_type = "BOX"
cy.filter_width = 1.0
scene.render.threads_mode = "FIXED"
scene.render.threads = threads
scene.render.resolution_x = 640
scene.render.resolution_y = 426
scene.render.resolution_percentage = 100
scene.render.use_persistent_data = False


def pbrt(x, y, z):
    return Vector((x, z, y))


def diffuse(name, rgb):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes.get("Principled BSDF")
    m.node_tree.nodes.remove(bsdf)
    d = m.node_tree.nodes.new("ShaderNodeBsdfDiffuse")
    d.inputs["Color"].default_value = (*rgb, 1.0)
    out = m.node_tree.nodes.get("Material Output")
    m.node_tree.links.new(d.outputs["BSDF"], out.inputs["Surface"])
    return m


bpy.ops.mesh.primitive_plane_add(size=20, location=pbrt(0, 0, 0))
bpy.context.object.data.materials.append(diffuse("ground", (0.8, 0.8, 0.8)))
for pos, rgb in [((-2.1, 0.6, 0.4), (0.8, 0.2, 0.15)), ((-0.7, 0.6, 0), (0.2, 0.8, 0.15)),
                 ((0.7, 0.6, -0.3), (0.15, 0.2, 0.8)), ((2.1, 0.6, 0.4), (0.7, 0.7, 0.2))]:
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.6, segments=64, ring_count=32, location=pbrt(*pos))
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(diffuse("sphere", rgb))

sun = bpy.data.lights.new("sun", "SUN")
sun.energy = 3.0
sun.angle = 0.0
sun_obj = bpy.data.objects.new("sun", sun)
scene.collection.objects.link(sun_obj)
direction = (pbrt(0, 0, 0) - pbrt(-3, 6, -4)).normalized()
sun_obj.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()

world = bpy.data.worlds.new("sky")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.35, 0.5, 0.8, 1.0)
scene.world = world

cam = bpy.data.cameras.new("cam")
cam.sensor_fit = "VERTICAL"
cam.angle_y = math.radians(32)
cam_obj = bpy.data.objects.new("cam", cam)
scene.collection.objects.link(cam_obj)
cam_obj.location = pbrt(0, 1.2, -6)
cam_obj.rotation_euler = (pbrt(0, 0.6, 0) - pbrt(0, 1.2, -6)).to_track_quat("-Z", "Y").to_euler()
scene.camera = cam_obj

scene.render.filepath = "/tmp/cycles_plane_spheres.exr"
scene.render.image_settings.file_format = "OPEN_EXR"
t0 = time.time()
bpy.ops.render.render(write_still=True)
dt = time.time() - t0
paths = 640 * 426 * spp
print(f"cycles: {paths} camera paths in {dt:.3f} s: {paths / dt / 1e6:.3f} M paths/s")
