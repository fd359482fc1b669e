"""lf.render equals lfrender for the same seed, bit for bit; lf.write writes
the file lfrender writes."""
import numpy as np

from conftest import ROOT, run

SCENE = """LookAt 0 1 -4  0 0.5 0  0 1 0
Camera "perspective" "float fov" [40]
Film "rgb" "integer xresolution" [40] "integer yresolution" [30] "bool savefp16" {half}
Sampler "zsobol" "integer pixelsamples" [4]
Integrator "path" "integer maxdepth" [3]
WorldBegin
LightSource "distant" "point3 from" [-3 6 -4] "point3 to" [0 0 0] "rgb L" [3 3 3]
LightSource "infinite" "rgb L" [0.3 0.4 0.6]
AttributeBegin
  Material "diffuse" "rgb reflectance" [0.6 0.5 0.4]
  Shape "sphere" "float radius" [0.6]
AttributeEnd
Shape "bilinearmesh" "point3 P" [-5 -0.6 -5  5 -0.6 -5  -5 -0.6 5  5 -0.6 5]
"""

VARYING = {"lensfield:render_time_s", "lensfield:threads"}  # the run's own figures


def _scene(tmp_path, half):
    p = tmp_path / f"s{half}.pbrt"
    p.write_text(SCENE.format(half=half))
    return p


def test_render_equals_lfrender_float(lf, tmp_path):
    scene = _scene(tmp_path, "false")
    run("lfrender", scene, "--seed", 7, "--spp", 8, "--threads", 1, "--quiet", "-o", tmp_path / "cli.exr")
    cli, cli_meta = lf.read(tmp_path / "cli.exr")
    img, meta = lf.render(scene, spp=8, seed=7, threads=2)  # the thread count never changes a bit
    assert img.dtype == np.float32 and img.shape == (30, 40, 3)
    assert np.array_equal(img, cli)
    assert meta["lensfield:seed"] == 7 and meta["lensfield:spp"] == 8 and not meta.savefp16
    ours = {k for k in cli_meta if k.startswith("lensfield:")}
    assert set(meta) == ours and all(np.array_equal(meta[k], cli_meta[k]) for k in ours - VARYING)
    # physics, not program output: lit diffuse radiance is positive and finite
    assert np.isfinite(img).all() and img.min() >= 0 and img.mean() > 0.01


def test_render_and_write_as_lfrender_half(lf, tmp_path):
    """scenes/demo.pbrt, cropped: Film "savefp16" (pbrt's default) makes
    lfrender write half floats; lf.write(meta) does the same."""
    scene = ROOT / "scenes" / "demo.pbrt"
    crop = (300, 332, 200, 224)
    run("lfrender", scene, "--seed", 1, "--spp", 4, "--crop", *crop, "--quiet", "-o", tmp_path / "cli.exr")
    img, meta = lf.render(scene, spp=4, seed=1, crop=crop, threads=2)
    assert meta.savefp16
    lf.write(tmp_path / "py.exr", img, meta)
    a, ma = lf.read(tmp_path / "cli.exr")
    b, mb = lf.read(tmp_path / "py.exr")
    assert np.array_equal(a, b)
    assert np.array_equal(img.astype(np.float16).astype(np.float32), a)  # round to nearest half
    assert set(ma) == set(mb) and all(np.array_equal(ma[k], mb[k]) for k in ma if k not in VARYING)


def test_render_threads_and_seed(lf, tmp_path):
    scene = _scene(tmp_path, "false")
    a, _ = lf.render(scene, spp=2, seed=1, threads=1)
    b, _ = lf.render(scene, spp=2, seed=1, threads=2)
    c, _ = lf.render(scene, spp=2, seed=2, threads=2)
    assert np.array_equal(a, b) and not np.array_equal(a, c)


def test_write_read_roundtrip(lf, tmp_path):
    rng = np.random.default_rng(0)
    img = rng.random((5, 7, 3)).astype(np.float32)
    meta = {"lensfield:note": "x", "lensfield:count": 3, "lensfield:value": 0.25, "lensfield:v": [1.0, 2.0]}
    lf.write(tmp_path / "a.exr", img, meta)
    back, m = lf.read(tmp_path / "a.exr")
    assert np.array_equal(back, img)
    assert m["lensfield:note"] == "x" and m["lensfield:count"] == 3 and m["lensfield:value"] == 0.25
    assert np.array_equal(m["lensfield:v"], [1, 2])
    lf.write(tmp_path / "g.pfm", img[:, :, 0])
    assert np.array_equal(lf.read(tmp_path / "g.pfm")[0], img[:, :, 0])
