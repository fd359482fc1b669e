"""Copies the CMake build's liblensfield.so (and the OpenImageIO module it
loads, liblf_oiio.so) into the package; nothing is compiled here, so the
wheel holds exactly the library the tools' build made (docs/python.md).

The build folder is $LENSFIELD_BUILD_DIR, else ../build (the README's).
"""
import os
import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.dist import Distribution

HERE = Path(__file__).resolve().parent


class BuildPy(build_py):
    def run(self):
        super().run()
        build = Path(os.environ.get("LENSFIELD_BUILD_DIR", HERE.parent / "build"))
        wanted = [build / "lib" / "liblensfield.so", build / "bin" / "liblf_oiio.so"]
        missing = [str(p) for p in wanted if not p.exists()]
        if missing:
            raise SystemExit(f"lensfield: {', '.join(missing)} not found: build lensfield first "
                             "(cmake -S . -B build -G Ninja && cmake --build build), or set LENSFIELD_BUILD_DIR")
        dest = Path(self.build_lib) / "lensfield"
        dest.mkdir(parents=True, exist_ok=True)
        for p in wanted:
            shutil.copy2(p, dest / p.name)


class BinaryDistribution(Distribution):
    """The package carries a platform library: a platform wheel, not a pure one."""

    def has_ext_modules(self):
        return True


setup(cmdclass={"build_py": BuildPy}, distclass=BinaryDistribution)
