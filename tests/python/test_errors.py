"""Errors come back as Python exceptions carrying the library's message,
with file:line:col for scenes, as the tools print them."""
import numpy as np
import pytest

from conftest import run

GOOD = """Camera "perspective" "float fov" [40]
Film "rgb" "integer xresolution" [8] "integer yresolution" [8]
WorldBegin
LightSource "infinite" "rgb L" [1 1 1]
"""


def test_missing_file(lf, tmp_path):
    with pytest.raises(lf.FileError) as e:
        lf.open(tmp_path / "nothing.exr")
    assert "nothing.exr" in str(e.value) and e.value.code == 1
    with pytest.raises(lf.Error, match="nothing.pbrt"):
        lf.render(tmp_path / "nothing.pbrt")


def test_scene_errors_carry_their_place_as_lfrender_prints_them(lf, tmp_path):
    scene = tmp_path / "typo.pbrt"
    scene.write_text(GOOD.replace('"float fov"', '"float fovv"'))
    p = run("lfrender", scene, "-o", tmp_path / "x.exr", check=False)
    assert p.returncode == 1
    with pytest.raises(lf.Error) as e:
        lf.render(scene)
    msg = str(e.value)
    assert msg.startswith(f"{scene}:1:") and "fovv" in msg
    assert p.stderr.strip() == "lfrender: " + msg  # the same text


def test_every_parse_error(lf, tmp_path):
    scene = tmp_path / "two.pbrt"
    scene.write_text(GOOD + 'Shape "sphere" "float radius" [oops]\nShape "sphere" "float radius" [nope]\n')
    with pytest.raises(lf.ParseError) as e:
        lf.render(scene)
    lines = str(e.value).splitlines()
    assert lines[0].startswith(f"{scene}:5:") and any(x.startswith(f"{scene}:6:") for x in lines)
    p = run("lfrender", scene, "-o", tmp_path / "x.exr", check=False)
    printed = [x.removeprefix("lfrender: ") for x in p.stderr.splitlines()]
    assert printed[:len(lines)] == lines  # lfrender adds only its summary line


def test_layout_errors_name_the_flag(lf, tmp_path):
    img = np.ones((20, 30, 3), np.float32)
    lf.write(tmp_path / "plain.exr", img)
    with pytest.raises(lf.ParamError) as e:
        lf.open(tmp_path / "plain.exr")
    p = run("lftool", "info", tmp_path / "plain.exr", check=False)
    assert p.returncode == 1 and str(e.value) in p.stderr
    L = lf.open(tmp_path / "plain.exr", camsperdim=(3, 2))  # layout keywords as lftool's flags
    assert L.shape == (2, 3, 10, 10, 3)


def test_argument_errors(lf, raw):
    L = lf.open(raw)
    with pytest.raises(ValueError, match="exactly one"):
        L.refocus()
    with pytest.raises(ValueError, match="both"):
        L.depth(from_=0)
    with pytest.raises(TypeError, match="unexpected keyword"):
        lf.open(raw, camsperdimm=(5, 5))
    with pytest.raises(lf.ParamError, match="alpha"):
        L.refocus(alpha=1.5)  # a camera array has no alpha
    with pytest.raises(lf.NumericError):
        lf.write("/tmp/never.exr", np.full((2, 2), np.nan, np.float32))
