# Blender Cycles version of scenes/bench/plane-spheres.pbrt, for
# bench/peers/cycles_vs_lensfield.sh: 640x426, a 20x20 plane, 4 diffuse
# spheres (radius 0.6), a sun and a uniform sky, 8 bounces, 64 spp, box
# filter, CPU, 2 threads, fixed seed, no denoising, no adaptive sampling.
# pbrt's (x, y, z) (y up) maps to Blender's (x, z, y) (z up): a mirror image,
# the same work.
#   blender -b --factory-startup -P bench/peers/cycles_plane_spheres.py -- [SPP] [THREADS] [CASE]
# CASE: pinhole (default), thinlens (lens radius 0.08, focus 6), motion (one
# sphere moves 0.5 units during the shutter), rolling (panning camera, rolling
# shutter over half the frame), fisheye (equisolid, 10 mm, 155.9 degrees) -
# the variants of scenes/bench/plane-spheres-CASE.pbrt.
import math
import sys
import time

import bpy
from mathutils import Vector

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
spp = int(argv[0]) if len(argv) > 0 else 64
threads = int(argv[1]) if len(argv) > 1 else 2
case = argv[2] if len(argv) > 2 else "pinhole"

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
scene.frame_start = scene.frame_current = 1
for i, (pos, rgb) in enumerate([((-2.1, 0.6, 0.4), (0.8, 0.2, 0.15)), ((-0.7, 0.6, 0), (0.2, 0.8, 0.15)),
                                ((0.7, 0.6, -0.3), (0.15, 0.2, 0.8)), ((2.1, 0.6, 0.4), (0.7, 0.7, 0.2))]):
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.6, segments=64, ring_count=32, location=pbrt(*pos))
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(diffuse("sphere", rgb))
    if case == "motion" and i == 1:
        ob = bpy.context.object
        ob.keyframe_insert("location", frame=1)
        ob.location = pbrt(pos[0] + 0.5, pos[1], pos[2])
        ob.keyframe_insert("location", frame=2)
        for fc in ob.animation_data.action.fcurves:
            for kp in fc.keyframe_points:
                kp.interpolation = "LINEAR"

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
if case == "thinlens":
    lens_mm = cam.sensor_height / 2 / math.tan(math.radians(16))
    cam.lens = lens_mm
    cam.dof.use_dof = True
    cam.dof.focus_distance = 6.0
    cam.dof.aperture_fstop = lens_mm / (2 * 80.0)  # aperture radius 0.08 m = 80 mm
if case in ("motion", "rolling"):
    scene.render.use_motion_blur = True
    cy.motion_blur_position = "START"
    scene.render.motion_blur_shutter = 1.0 if case == "motion" else 0.5
if case == "rolling":
    cy.rolling_shutter_type = "TOP"
    cy.rolling_shutter_duration = 0.5
    cam_obj.keyframe_insert("rotation_euler", frame=1)
    cam_obj.rotation_euler.z += math.radians(3)
    cam_obj.keyframe_insert("rotation_euler", frame=2)
if case == "fisheye":
    cam.type = "PANO"
    try:
        cam.panorama_type = "FISHEYE_EQUISOLID"
        cam.fisheye_lens = 10.0
        cam.fisheye_fov = math.radians(155.9)
    except AttributeError:  # Blender < 3.x keeps these under cam.cycles
        cam.cycles.panorama_type = "FISHEYE_EQUISOLID"
        cam.cycles.fisheye_lens = 10.0
        cam.cycles.fisheye_fov = math.radians(155.9)
    cam.sensor_fit = "AUTO"
    cam.sensor_width = 24.0

scene.render.filepath = "/tmp/cycles_plane_spheres.exr"
scene.render.image_settings.file_format = "OPEN_EXR"
t0 = time.time()
bpy.ops.render.render(write_still=True)
dt = time.time() - t0
paths = 640 * 426 * spp
print(f"cycles: {paths} camera paths in {dt:.3f} s: {paths / dt / 1e6:.3f} M paths/s")
