"""Light fields through Python equal lftool's outputs bit for bit, views are
shared with the C library without a copy, and the numbers obey the physics
(docs/lightfield.md): disparity F_px * b / Z, refocusing averages views."""
import math

import numpy as np
import pytest

from conftest import read_pfm, run


def test_views_are_the_raw_tiles_without_a_copy(lf, raw):
    L = lf.open(raw)
    v = L.views
    assert v.shape == (5, 5, 48, 48, 3) and v.dtype == np.float32
    assert L.shape == v.shape
    # a camera-array raw tiles view (iu, iv) at (iu * w, iv * h): read the raw
    # itself and cut the tiles in numpy
    img, meta = lf.read(raw)
    tiles = img.reshape(5, 48, 5, 48, 3).transpose(0, 2, 1, 3, 4)
    assert np.array_equal(v, tiles)
    assert meta["lensfield:kind"] == "camera-array"
    # the library's buffer: every access is the same memory, nothing copied
    assert np.shares_memory(v, L.views)
    assert not v.flags.writeable and not v.flags.owndata
    p = L.positions
    assert p.shape == (5, 5, 2)
    assert np.array_equal(p[2, 2], [0, 0]) and np.array_equal(p[0, 4], [2, -2])
    assert "camera-array" in L.describe()


def test_views_outlive_the_light_field(lf, raw):
    v = lf.open(raw).views  # the LightField is gone; the array keeps its memory
    import gc
    gc.collect()
    assert np.isfinite(v).all() and v.max() > 0.05


def test_depth_equals_lftool(lf, raw, tmp_path):
    run("lftool", "depth", raw, "-o", tmp_path / "d.pfm", "--threads", 2)
    cli = read_pfm(tmp_path / "d.pfm")
    L = lf.open(raw)
    d, rng = L.depth(threads=1, return_range=True)  # the thread count never changes a bit
    assert d.shape == (48, 48) and d.dtype == np.float32
    assert np.array_equal(d, cli)
    # the range estimated from the data holds the scene: the near (1.5 m)
    # sphere's disparity F_px * b / Z, F_px = 24 / tan(15 deg), b = 2 cm, is
    # the largest; the wall's (6 m) the smallest
    f_px = 24 / math.tan(math.radians(15))
    assert rng[0] < f_px * 0.02 / 6 and f_px * 0.02 / 1.5 < rng[1]


def test_depth_options_and_confidence_equal_lftool(lf, raw, tmp_path):
    run("lftool", "depth", raw, "-o", tmp_path / "d.exr", "--from", 0, "--to", 2, "--steps", 24,
        "--confidence", tmp_path / "c.exr", "--threads", 2)
    d, c = lf.open(raw).depth(from_=0, to=2, steps=24, confidence=True, threads=2)
    cli_d, meta = lf.read(tmp_path / "d.exr")
    cli_c, _ = lf.read(tmp_path / "c.exr")
    assert np.array_equal(d, cli_d) and np.array_equal(c, cli_c)
    assert 0 <= c.min() and c.max() <= 1
    # written back as lftool writes it, header included
    lf.write_disparity(tmp_path / "py.exr", d, 0, 2)
    assert (tmp_path / "py.exr").read_bytes() == (tmp_path / "d.exr").read_bytes()


def test_depth_noisy_equals_lftool(lf, raw, tmp_path):
    # --noisy / noisy=True: the same map from both, and a different one from
    # the default (each view's difference is rescaled label by label).  The
    # pre-smoothing is off here: views it smooths are rescaled by default.
    run("lftool", "depth", raw, "-o", tmp_path / "n.pfm", "--from", 0, "--to", 2, "--noisy", "--prefilter", 0)
    L = lf.open(raw)
    d = L.depth(from_=0, to=2, noisy=True, prefilter=0)
    assert np.array_equal(d, read_pfm(tmp_path / "n.pfm"))
    assert not np.array_equal(d, L.depth(from_=0, to=2, prefilter=0))


def test_depth_plain_regions_equals_lftool(lf, raw, tmp_path):
    # --plain-regions / plain_regions=True: the same map from both, and a
    # different one from the default (the array's plain backdrop moves)
    run("lftool", "depth", raw, "-o", tmp_path / "p.pfm", "--from", 0, "--to", 2, "--plain-regions")
    L = lf.open(raw)
    d = L.depth(from_=0, to=2, plain_regions=True)
    assert np.array_equal(d, read_pfm(tmp_path / "p.pfm"))
    assert not np.array_equal(d, L.depth(from_=0, to=2))


def test_depth_prefilter_equals_lftool(lf, raw, tmp_path):
    # --prefilter SIGMA / prefilter=SIGMA, and 0 (never): the same maps
    # from both, and different ones from each other
    run("lftool", "depth", raw, "-o", tmp_path / "f.pfm", "--from", 0, "--to", 2, "--prefilter", 0.7)
    run("lftool", "depth", raw, "-o", tmp_path / "f0.pfm", "--from", 0, "--to", 2, "--prefilter", 0)
    L = lf.open(raw)
    d = L.depth(from_=0, to=2, prefilter=0.7)
    d0 = L.depth(from_=0, to=2, prefilter=0)
    assert np.array_equal(d, read_pfm(tmp_path / "f.pfm"))
    assert np.array_equal(d0, read_pfm(tmp_path / "f0.pfm"))
    assert not np.array_equal(d, d0)
    with pytest.raises(ValueError):
        L.depth(from_=0, to=2, prefilter=5)


def test_depth_stack_method_equals_lftool(lf, raw, tmp_path):
    run("lftool", "depth", raw, "-o", tmp_path / "s.pfm", "--method", "stack", "--from", 0, "--to", 2,
        "--steps", 5)
    d = lf.open(raw).depth(method="stack", from_=0, to=2, steps=5)
    assert np.array_equal(d, read_pfm(tmp_path / "s.pfm"))


def test_refocus_equals_lftool(lf, raw, tmp_path):
    L = lf.open(raw)
    for args, kw in [(["--disparity", 1.2], dict(disparity=1.2)),
                     (["--depth", 2.5, "--aperture", 1], dict(depth=2.5, aperture=1)),
                     (["--disparity", 0.3, "--method", "fourier"], dict(disparity=0.3, method="fourier"))]:
        out = tmp_path / "r.exr"
        run("lftool", "refocus", raw, *args, "-o", out)
        cli, meta = lf.read(out)
        img = L.refocus(**kw)
        assert img.shape == (48, 48, 3)
        assert np.array_equal(img, cli), args
    # disparity 0: the plain mean of the views (shift-and-add with no shift)
    mean = L.views.astype(np.float64).mean(axis=(0, 1))
    assert np.allclose(L.refocus(disparity=0), mean, rtol=0, atol=1e-6)


def test_view_equals_lftool(lf, raw, tmp_path):
    L = lf.open(raw)
    run("lftool", "view", raw, "--u", 0.5, "--v", -0.25, "-o", tmp_path / "v.exr")
    assert np.array_equal(L.view(u=0.5, v=-0.25), lf.read(tmp_path / "v.exr")[0])
    run("lftool", "view", raw, "--u", 0.5, "--v", 0.5, "--geometry", "plane", "--disparity", 1, "-o",
        tmp_path / "p.exr")
    assert np.array_equal(L.view(0.5, 0.5, geometry="plane", disparity=1), lf.read(tmp_path / "p.exr")[0])
    # at a view position the view itself (view (iu, iv) = (3, 2) is u = 1, v = 0)
    assert np.array_equal(L.view(u=1, v=0, geometry="plane"), L.views[2, 3])


def test_from_array_uses_the_array_and_matches_open(lf, raw):
    L = lf.open(raw)
    mine = L.views.copy()
    M = lf.LightField.from_array(mine, L.positions)
    assert M.views is mine  # float32 in C order: wrapped in place
    assert np.array_equal(M.depth(from_=0, to=2), L.depth(from_=0, to=2))
    assert np.array_equal(M.refocus(disparity=0.7), L.refocus(disparity=0.7))
    mine[2, 2] = 0  # the C side sees the caller's memory
    assert np.array_equal(M.view(u=0, v=0, geometry="plane"), np.zeros((48, 48, 3), np.float32))


def test_synthetic_plane_in_numpy(lf):
    """A textured plane at 2 px/view synthesised in numpy: refocusing at 2
    brings every view onto the centre view, and depth finds 2."""
    rng = np.random.default_rng(1)
    tex = rng.random((80, 80, 3)).astype(np.float32)
    n, size, d = 5, 48, 2
    views = np.empty((n, n, size, size, 3), np.float32)
    for iv in range(n):
        for iu in range(n):
            u, v = iu - 2, iv - 2  # a point moves by -d px when the viewpoint moves one view right
            views[iv, iu] = tex[16 + d * v:16 + d * v + size, 16 + d * u:16 + d * u + size]
    pos = np.stack(np.meshgrid(np.arange(n) * 0.01, np.arange(n) * 0.01), axis=-1)  # 1 cm grid
    L = lf.LightField.from_array(views, pos)
    r = L.refocus(disparity=d)
    inner = slice(2 * d, size - 2 * d)
    assert np.allclose(r[inner, inner], views[2, 2][inner, inner], rtol=0, atol=1e-6)
    disp = L.depth(from_=0, to=4)
    assert abs(np.median(disp[8:40, 8:40]) - d) < 0.02


def test_from_array_positions(lf):
    views = np.zeros((3, 4, 8, 8, 3))  # float64: converted once
    L = lf.LightField.from_array(views, np.stack(np.meshgrid(np.arange(4) * 2.0, np.arange(3) * 3.0), -1))
    assert L.views.dtype == np.float32
    assert np.array_equal(L.positions[0, 0], [-1.5, -1.5])  # v steps are 1.5 u steps
    with pytest.raises(ValueError, match="regular grid"):
        lf.LightField.from_array(views, np.random.default_rng(0).random((3, 4, 2)))
    with pytest.raises(ValueError, match="rows, cols, height, width, 3"):
        lf.LightField.from_array(np.zeros((3, 8, 8, 3)))


def test_write_png_as_lftool(lf, raw, tmp_path):
    run("lftool", "refocus", raw, "--disparity", 1, "--exposure", 1, "--tonemap", "filmic", "-o",
        tmp_path / "cli.png")
    img = lf.open(raw).refocus(disparity=1)
    lf.write(tmp_path / "py.png", img, exposure=1, tonemap="filmic")
    assert (tmp_path / "py.png").read_bytes() == (tmp_path / "cli.png").read_bytes()


def test_refocus_outside_range_warns(lf, raw):
    # a camera array has no refocusable-range limit: no warning
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lf.open(raw).refocus(disparity=5)


def test_calibrate_views_equals_lftool_and_lasts_one_call(lf, raw, tmp_path):
    run("lftool", "depth", raw, "-o", tmp_path / "cal.pfm", "--calibrate-views", "--from", 0, "--to", 2)
    run("lftool", "depth", raw, "-o", tmp_path / "plain.pfm", "--from", 0, "--to", 2)
    L = lf.open(raw)
    assert np.array_equal(L.depth(from_=0, to=2, calibrate_views=True), read_pfm(tmp_path / "cal.pfm"))
    # the fitted positions were for that call: the next is on the nominal grid, as a new lftool run
    assert np.array_equal(L.depth(from_=0, to=2), read_pfm(tmp_path / "plain.pfm"))
