"""Fixtures for the Python module's tests (run by ctest as test_python, from
the repository root, with LENSFIELD_LIBRARY, LF_BIN and PYTHONPATH set by
CMakeLists.txt).  Light fields are rendered here by lfrender from a small
camera-array scene, or synthesised in numpy: nothing from ../shared."""
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(os.environ.get("LF_BIN", ROOT / "build" / "bin"))


def run(tool, *args, check=True):
    """Runs build/bin/TOOL; returns the CompletedProcess (text)."""
    p = subprocess.run([str(BIN / tool), *map(str, args)], capture_output=True, text=True)
    if check and p.returncode:
        raise AssertionError(f"{tool} {' '.join(map(str, args))} exited {p.returncode}:\n{p.stderr}")
    return p


def read_pfm(path):
    """A PFM file as numpy, independently of the library: (h, w) or (h, w, 3),
    rows top first (PFM stores them bottom-up; a negative scale means
    little-endian)."""
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    shape = (h, w, 3) if kind == b"PF" else (h, w)
    return data.reshape(shape)[::-1].astype(np.float32)


CAMERA_ARRAY = """LookAt 0 0 0  0 0 1  0 1 0
Camera "lightfield" "float fov" [30] "integer camerasperdim" [5 5]
    "float cameragridbounds" [-0.04 0.04 -0.04 0.04]
Film "rgb" "integer xresolution" [240] "integer yresolution" [240] "bool savefp16" false
Sampler "zsobol" "integer pixelsamples" [2]
Integrator "path" "integer maxdepth" [2]
PixelFilter "box"
WorldBegin
Include "{world}"
"""


@pytest.fixture(scope="session")
def raw(tmp_path_factory):
    """A 5 x 5 camera array of 48 x 48 views (a 240 x 240 raw with its
    lensfield:* layout), rendered by lfrender."""
    d = tmp_path_factory.mktemp("raw")
    scene = d / "array.pbrt"
    scene.write_text(CAMERA_ARRAY.format(world=ROOT / "scenes" / "lightfield" / "world.pbrt"))
    out = d / "array.exr"
    run("lfrender", scene, "--seed", 3, "--quiet", "-o", out)
    return out


@pytest.fixture(scope="session")
def lf():
    import lensfield
    return lensfield
