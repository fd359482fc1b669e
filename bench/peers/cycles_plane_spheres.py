# Blender Cycles version of scenes/bench/plane-spheres[-CASE].pbrt (and of
# scenes/bench/sky.pbrt and room.pbrt), for
# bench/peers/cycles_vs_lensfield.sh and bench/peers/equal_quality.sh: by
# default 640x426, a 20x20 plane, 4 diffuse spheres (radius 0.6), a sun and a
# uniform sky, 8 bounces, 64 spp, box filter 1 px, CPU, 2 threads, fixed seed,
# no denoising, no adaptive sampling, no clamping.  pbrt's (x, y, z) (y up)
# maps to Blender's (x, z, y) (z up); with pbrt's left-handed and Blender's
# right-handed frames the image comes out the same way round.
#   blender -b --factory-startup -P bench/peers/cycles_plane_spheres.py -- \
#       [SPP] [THREADS] [CASE] [--res W H] [--seed N] [--out FILE.exr]
#       [--fisheye-model equisolid|polynomial] [--bounces N (8: pbrt's maxdepth)]
# CASE: pinhole (default), thinlens (lens radius 0.08, focus 6), motion (one
# sphere moves 0.5 units during the shutter), rolling (panning camera, rolling
# shutter over half the frame), fisheye (equisolid 10.6 mm, 156 deg: the same
# ideal camera as lensfield's "fisheye"), fisheye-lens (equisolid, fitted to
# the traced 10 mm fisheye prescription, or with --fisheye-model polynomial
# Cycles' polynomial fisheye fitted to its whole mapping: see the fisheye-lens
# block below) - the variants of scenes/bench/plane-spheres-CASE.pbrt - and
# two other scenes: sky (scenes/bench/sky.pbrt, mostly sky, a small bright
# emitter) and room (scenes/bench/room.pbrt, a closed room under an area light).  There is no "realistic" case: Cycles
# has no traced lens.
# --out writes the render as a linear float RGB OpenEXR (scene-referred, no
# view transform); the time printed is that of bpy.ops.render.render alone
# (scene sync, BVH build and the samples), not of writing the file.
import math
import sys
import time

import bpy
from mathutils import Matrix, Vector

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
opts = {"--res": None, "--seed": "1", "--out": None, "--fisheye-model": "equisolid", "--bounces": "8"}
pos = []
i = 0
while i < len(argv):
    a = argv[i]
    if a == "--res":
        opts[a] = (int(argv[i + 1]), int(argv[i + 2]))
        i += 3
    elif a in opts:
        opts[a] = argv[i + 1]
        i += 2
    else:
        pos.append(a)
        i += 1
spp = int(pos[0]) if len(pos) > 0 else 64
threads = int(pos[1]) if len(pos) > 1 else 2
case = pos[2] if len(pos) > 2 else "pinhole"
width, height = opts["--res"] or (640, 426)
if case not in ("pinhole", "thinlens", "motion", "rolling", "fisheye", "fisheye-lens", "sky", "room"):
    sys.exit(f"cycles_plane_spheres.py: no Cycles equivalent of case '{case}'")

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.engine = "CYCLES"
cy = scene.cycles
cy.device = "CPU"
cy.samples = spp
cy.use_adaptive_sampling = False
cy.use_denoising = False
cy.seed = int(opts["--seed"])
cy.use_animated_seed = False
bounces = int(opts["--bounces"])  # pbrt's maxdepth (8 in every bench scene)
cy.max_bounces = bounces
cy.diffuse_bounces = bounces
cy.glossy_bounces = bounces
cy.transmission_bounces = bounces
cy.transparent_max_bounces = bounces
cy.sample_clamp_direct = 0
cy.sample_clamp_indirect = 0
cy.pixel_filter_type = "BOX"
cy.filter_width = 1.0
scene.render.threads_mode = "FIXED"
scene.render.threads = threads
scene.render.resolution_x = width
scene.render.resolution_y = height
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


def emission(name, rgb, one_sided=False):
    """pbrt's "diffuse" area light on a black surface: radiance rgb leaving
    the front; one_sided: nothing from the back (pbrt's default), through the
    Backfacing output of the Geometry node."""
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes.get("Principled BSDF"))
    e = nt.nodes.new("ShaderNodeEmission")
    e.inputs["Color"].default_value = (*rgb, 1.0)
    e.inputs["Strength"].default_value = 1.0
    out = nt.nodes.get("Material Output")
    if not one_sided:
        nt.links.new(e.outputs["Emission"], out.inputs["Surface"])
        return m
    black = nt.nodes.new("ShaderNodeBsdfDiffuse")
    black.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    geo = nt.nodes.new("ShaderNodeNewGeometry")
    mix = nt.nodes.new("ShaderNodeMixShader")
    nt.links.new(geo.outputs["Backfacing"], mix.inputs["Fac"])
    nt.links.new(e.outputs["Emission"], mix.inputs[1])
    nt.links.new(black.outputs["BSDF"], mix.inputs[2])
    nt.links.new(mix.outputs["Shader"], out.inputs["Surface"])
    return m


def quad(name, pts, mat, facing=None):
    """A quad from pbrt's bilinearmesh corner order p00 p10 p01 p11; facing
    (pbrt axes) orients its front side."""
    v = [pbrt(*p) for p in pts]
    me = bpy.data.meshes.new(name)
    me.from_pydata(v, [], [(0, 1, 3, 2)])
    me.update()
    if facing is not None and me.polygons[0].normal.dot(pbrt(*facing)) < 0:
        me.flip_normals()
        me.update()
    ob = bpy.data.objects.new(name, me)
    scene.collection.objects.link(ob)
    ob.data.materials.append(mat)
    return ob


def sphere(pos, radius, mat):
    bpy.ops.mesh.primitive_uv_sphere_add(radius=radius, segments=64, ring_count=32, location=pbrt(*pos))
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(mat)


def sun_and_sky(frm, irradiance, sky_rgb):
    sun = bpy.data.lights.new("sun", "SUN")
    sun.energy = irradiance
    sun.angle = 0.0
    sun_obj = bpy.data.objects.new("sun", sun)
    scene.collection.objects.link(sun_obj)
    direction = (pbrt(0, 0, 0) - pbrt(*frm)).normalized()
    sun_obj.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
    world = bpy.data.worlds.new("sky")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (*sky_rgb, 1.0)
    scene.world = world


def camera(eye, look, fov_deg):
    cam = bpy.data.cameras.new("cam")
    cam.sensor_fit = "VERTICAL"
    cam.angle_y = math.radians(fov_deg)
    cam_obj = bpy.data.objects.new("cam", cam)
    scene.collection.objects.link(cam_obj)
    cam_obj.location = pbrt(*eye)
    cam_obj.rotation_euler = (pbrt(*look) - pbrt(*eye)).to_track_quat("-Z", "Y").to_euler()
    scene.camera = cam_obj
    return cam, cam_obj


if case == "room":
    # scenes/bench/room.pbrt: a closed 4 x 3 x 5 room, one-sided ceiling panel
    grey = diffuse("grey", (0.7, 0.7, 0.7))
    quad("floor", [(-2, 0, -2), (2, 0, -2), (-2, 0, 3), (2, 0, 3)], grey)
    quad("ceiling", [(-2, 3, -2), (2, 3, -2), (-2, 3, 3), (2, 3, 3)], grey)
    quad("back", [(-2, 0, 3), (2, 0, 3), (-2, 3, 3), (2, 3, 3)], grey)
    quad("front", [(-2, 0, -2), (2, 0, -2), (-2, 3, -2), (2, 3, -2)], grey)
    quad("left", [(-2, 0, -2), (-2, 0, 3), (-2, 3, -2), (-2, 3, 3)], diffuse("red", (0.7, 0.15, 0.1)))
    quad("right", [(2, 0, -2), (2, 0, 3), (2, 3, -2), (2, 3, 3)], diffuse("green", (0.15, 0.6, 0.15)))
    quad("panel", [(-0.5, 2.99, 0.5), (0.5, 2.99, 0.5), (-0.5, 2.99, 1.5), (0.5, 2.99, 1.5)],
         emission("panel", (12.0, 12.0, 12.0), one_sided=True), facing=(0, -1, 0))
    sphere((-0.8, 0.5, 1.8), 0.5, diffuse("white", (0.75, 0.75, 0.75)))
    sphere((0.9, 0.4, 1.0), 0.4, diffuse("blue", (0.2, 0.3, 0.8)))
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    scene.world = world
    cam, cam_obj = camera((0, 1.5, -1.9), (0, 1.3, 3), 55)
elif case == "sky":
    # scenes/bench/sky.pbrt: about two thirds sky, a small bright emitter
    quad("ground", [(-100, 0, -100), (100, 0, -100), (-100, 0, 100), (100, 0, 100)],
         diffuse("ground", (0.5, 0.5, 0.5)))
    sphere((-2.5, 1, 2), 1.0, diffuse("s1", (0.7, 0.6, 0.5)))
    sphere((1.5, 0.7, 0), 0.7, diffuse("s2", (0.3, 0.5, 0.3)))
    sphere((3.5, 0.4, -2), 0.4, diffuse("s3", (0.6, 0.6, 0.65)))
    sphere((0.2, 1.6, 1), 0.15, emission("emitter", (40.0, 32.0, 20.0)))
    sun_and_sky((4, 8, -3), 3.0, (0.4, 0.55, 0.9))
    cam, cam_obj = camera((0, 1, -8), (0, 2.2, 0), 50)
else:
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
    # Frame 1 -> 2 is pbrt's time 0 -> 1 (its default transform times), and
    # the shutter spans it.
    scene.render.use_motion_blur = True
    cy.motion_blur_position = "START"
    scene.render.motion_blur_shutter = 1.0
if case == "rolling":
    # pbrt scene: shutter 0..0.5, readout 0.5 - row y of H is exposed over
    # [0.5 y/H, 0.5 y/H + 0.5].  Cycles maps the shutter's normalised time u
    # of row y (top first) to (u - 0.5) d + (y/H - 0.5)(1 - d) + 0.5, with
    # d = rolling_shutter_duration; over a 1-frame shutter, d = 0.5 gives the
    # same interval.  The pan: pbrt's "Rotate -3 0 1 0" at EndTime, applied
    # after the LookAt, turns the camera about its own up axis (tilted 5.7 deg
    # with the view) so the scene drifts left in the image: here -3 deg about
    # the camera's local Y, keyed as quaternions.
    cy.rolling_shutter_type = "TOP"
    cy.rolling_shutter_duration = 0.5
    r0 = cam_obj.rotation_euler.to_matrix()
    cam_obj.rotation_mode = "QUATERNION"
    cam_obj.rotation_quaternion = r0.to_quaternion()
    cam_obj.keyframe_insert("rotation_quaternion", frame=1)
    cam_obj.rotation_quaternion = (r0 @ Matrix.Rotation(math.radians(-3), 3, "Y")).to_quaternion()
    cam_obj.keyframe_insert("rotation_quaternion", frame=2)
    for fc in cam_obj.animation_data.action.fcurves:
        for kp in fc.keyframe_points:
            kp.interpolation = "LINEAR"
if case == "fisheye":
    # Like for like with lensfield's ideal "fisheye" camera in
    # scenes/bench/plane-spheres-fisheye.pbrt: equisolid, f = 10.6 mm, field
    # 156 deg, on the film of a 28 mm diagonal at this image's aspect.
    film_w = 28.0 * width / math.hypot(width, height)
    cam.type = "PANO"
    cam.sensor_fit = "HORIZONTAL"
    cam.sensor_width = film_w
    cam.sensor_height = film_w * height / width
    pano = cam if hasattr(cam, "panorama_type") else cam.cycles  # cam.cycles in Blender 3.x
    pano.panorama_type = "FISHEYE_EQUISOLID"
    pano.fisheye_lens = 10.6
    pano.fisheye_fov = math.radians(156.0)
    print(f"cycles: fisheye equisolid 10.6 mm, field 156 deg, sensor {film_w:.3f} mm wide")
if case == "fisheye-lens":
    # Fitted to what lensfield's fisheye scene frames (scenes/bench/
    # plane-spheres-fisheye-lens.pbrt: 10 mm prescription, 2 mm stop, focus 6 m,
    # film diagonal 28 mm).  `lflens info scenes/lenses/fisheye.10mm.dat
    # --aperture 2 --focus 6 --diagonal D` gives the traced field and the
    # image circle: 26.878 mm across, and 66.39 deg off axis at the film's
    # half width (11.654 mm).  The prescription maps nearly equidistantly
    # (r = 10.03 mm x theta, within 0.3%), which no equisolid lens
    # (r = 2 f sin(theta/2)) matches everywhere; this one is chosen to give the
    # same horizontal field (f from the half width) and the same image circle
    # (the field cut-off from the circle's radius).  The vertical field comes
    # out 85.5 deg against 88.6, and mid-field angles differ by up to 1.6 deg.
    # With --fisheye-model polynomial, Cycles' polynomial fisheye takes the
    # whole mapping instead: theta = k1 r + k2 r^2 + k3 r^3 + k4 r^4 (r in mm,
    # Cycles negates the coefficients), fitted by least squares to the traced
    # field angles at r = 0.5 .. 13.43 mm, within 0.05 deg
    # (`python3 bench/peers/fisheye_framing.py --fit` prints them), cut off
    # at the image circle's 76.89 deg.
    film_w = 28.0 * width / math.hypot(width, height)
    circle_r = 26.878 / 2
    half_w_angle = math.radians(66.39)
    lens_mm = (film_w / 2) / (2 * math.sin(half_w_angle / 2))
    fov = 4 * math.asin(circle_r / (2 * lens_mm))
    k = (0.0994777, 3.180818e-4, -6.381209e-5, 3.117570e-6)
    cam.type = "PANO"
    cam.sensor_fit = "HORIZONTAL"
    cam.sensor_width = film_w
    cam.sensor_height = film_w * height / width
    pano = cam if hasattr(cam, "panorama_type") else cam.cycles  # cam.cycles in Blender 3.x
    if opts["--fisheye-model"] == "polynomial":
        pano.panorama_type = "FISHEYE_LENS_POLYNOMIAL"
        pano.fisheye_polynomial_k0 = 0.0
        pano.fisheye_polynomial_k1, pano.fisheye_polynomial_k2, pano.fisheye_polynomial_k3, \
            pano.fisheye_polynomial_k4 = (-c for c in k)
        pano.fisheye_fov = math.radians(2 * 76.89)
        print(f"cycles: fisheye polynomial, field {2 * 76.89:.2f} deg, sensor {film_w:.3f} mm wide")
    else:
        pano.panorama_type = "FISHEYE_EQUISOLID"
        pano.fisheye_lens = lens_mm
        pano.fisheye_fov = fov
        print(f"cycles: fisheye equisolid {lens_mm:.3f} mm, field {math.degrees(fov):.2f} deg, "
              f"sensor {film_w:.3f} mm wide")

view = scene.view_settings
view.view_transform = "Standard"
view.look = "None"
view.exposure = 0.0
view.gamma = 1.0
t0 = time.time()
bpy.ops.render.render(write_still=False)
dt = time.time() - t0
if opts["--out"]:
    img = scene.render.image_settings
    img.file_format = "OPEN_EXR"
    img.color_mode = "RGB"
    img.color_depth = "32"
    img.exr_codec = "ZIP"
    bpy.data.images["Render Result"].save_render(opts["--out"], scene=scene)
paths = width * height * spp
print(f"cycles: {paths} camera paths in {dt:.3f} s: {paths / dt / 1e6:.3f} M paths/s")
