"""ctypes declarations of liblensfield.so (python/src/lensfield_capi.c).

The structures here mirror the C ones field for field; the C file is the
reference.  Nothing in this module is public API.
"""
import ctypes as C
import os
from pathlib import Path

_HERE = Path(__file__).resolve().parent


def _find_library():
    """$LENSFIELD_LIBRARY, else the copy installed beside this file, else a
    source checkout's build/lib (python/lensfield -> ../../build/lib)."""
    env = os.environ.get("LENSFIELD_LIBRARY")
    if env:
        return env
    for p in (_HERE / "liblensfield.so", _HERE.parent.parent / "build" / "lib" / "liblensfield.so"):
        if p.exists():
            return str(p)
    raise ImportError(
        "liblensfield.so not found: build it (cmake --build build --target lensfield) and reinstall "
        "(pip install --no-build-isolation --no-index ./python), or set LENSFIELD_LIBRARY to its path")


# The OpenImageIO module (formats other than EXR/PNG, image/oiio_loader.c) is
# looked for beside the executable, which here is python3: point the loader
# at the copy installed with the package when there is one.
if not os.environ.get("LF_OIIO_MODULE") and (_HERE / "liblf_oiio.so").exists():
    os.environ["LF_OIIO_MODULE"] = str(_HERE / "liblf_oiio.so")

lib = C.CDLL(_find_library())  # CDLL: every call releases the GIL


class Error(C.Structure):
    _fields_ = [("code", C.c_int), ("msg", C.c_char * 1024)]


class Image(C.Structure):
    _fields_ = [("width", C.c_int), ("height", C.c_int), ("channels", C.c_int), ("data", C.POINTER(C.c_float))]


class Attr(C.Structure):
    _fields_ = [("name", C.c_char_p), ("type", C.c_int), ("s", C.c_char_p), ("i", C.c_int), ("d", C.c_double),
                ("v", C.POINTER(C.c_float)), ("n", C.c_int), ("m", C.c_double * 16)]


ATTR_STRING, ATTR_INT, ATTR_FLOAT, ATTR_DOUBLE, ATTR_FLOATS, ATTR_M44D = range(6)

(LAYOUT_KIND, LAYOUT_CAMS, LAYOUT_GRIDDIM, LAYOUT_FOV, LAYOUT_TILE, LAYOUT_GRID, LAYOUT_PITCH, LAYOUT_ROTATION,
 LAYOUT_OFFSET, LAYOUT_LENSES, LAYOUT_MAINLENS) = (1 << i for i in range(11))


class Layout(C.Structure):
    _fields_ = [("given", C.c_uint), ("plenoptic", C.c_int), ("hex", C.c_int), ("cams", C.c_int * 2),
                ("tile", C.c_int * 2), ("lenses", C.c_int * 2), ("griddim", C.c_double * 4), ("fov", C.c_double),
                ("pitch", C.c_double), ("rotation", C.c_double), ("offset", C.c_double * 2),
                ("mainlens", C.c_double * 4)]


class Info(C.Structure):
    _fields_ = [("nu", C.c_int), ("nv", C.c_int), ("ns", C.c_int), ("nt", C.c_int), ("data", C.c_void_p),
                ("disp_v_per_u", C.c_double), ("disp_per_inv_m", C.c_double), ("disp_at_inf", C.c_double),
                ("disp_per_alpha", C.c_double), ("missing", C.c_size_t), ("nonfinite", C.c_size_t),
                ("is_folder", C.c_int), ("has_valid", C.c_int), ("valid", C.c_void_p)]


class DepthArgs(C.Structure):
    _fields_ = [("have_range", C.c_int), ("from_", C.c_double), ("to", C.c_double), ("have_steps", C.c_int),
                ("steps", C.c_int), ("have_aperture", C.c_int), ("aperture", C.c_double), ("have_views", C.c_int),
                ("views", C.c_int * 4), ("threads", C.c_int), ("calibrate_views", C.c_int), ("stack", C.c_int),
                ("confidence", C.c_int), ("noisy", C.c_int), ("plain", C.c_int),
                ("have_prefilter", C.c_int), ("prefilter", C.c_double)]


class Focus(C.Structure):
    _fields_ = [("have_alpha", C.c_int), ("have_depth", C.c_int), ("have_disp", C.c_int), ("alpha", C.c_double),
                ("depth", C.c_double), ("disp", C.c_double)]


class RefocusArgs(C.Structure):
    _fields_ = [("focus", Focus), ("have_aperture", C.c_int), ("aperture", C.c_double), ("have_views", C.c_int),
                ("views", C.c_int * 4), ("threads", C.c_int), ("fourier", C.c_int), ("oversample", C.c_double)]


class ViewArgs(C.Structure):
    _fields_ = [("u", C.c_double), ("v", C.c_double), ("focus", Focus), ("geometry", C.c_int),
                ("disparity_map", C.POINTER(Image)), ("confidence", C.POINTER(Image)),
                ("calibrate_views", C.c_int), ("threads", C.c_int)]


class RenderArgs(C.Structure):
    _fields_ = [("spp", C.c_int), ("threads", C.c_int), ("has_seed", C.c_int), ("seed", C.c_uint),
                ("have_crop", C.c_int), ("crop", C.c_int * 4), ("allow_unsupported", C.c_int), ("white", C.c_int)]


_P = C.POINTER
_H = C.c_void_p  # lfpy_lightfield *
_E = _P(Error)


def _sig(name, restype, *argtypes):
    f = getattr(lib, name)
    f.restype = restype
    f.argtypes = list(argtypes)
    return f


open_ = _sig("lfpy_open", C.c_int, C.c_char_p, _P(Layout), C.c_char_p, C.c_int, _P(_H), _E)
wrap = _sig("lfpy_wrap", C.c_int, C.c_void_p, C.c_int, C.c_int, C.c_int, C.c_int, C.c_double, _P(_H), _E)
close = _sig("lfpy_close", None, _H)
info_get = _sig("lfpy_info_get", None, _H, _P(Info))
describe = _sig("lfpy_describe", None, _H, C.c_char_p, C.c_size_t)
image_new = _sig("lfpy_image_new", _P(Image))
image_release = _sig("lfpy_image_release", None, _P(Image))
attrs_new = _sig("lfpy_attrs_new", C.c_void_p)
attrs_release = _sig("lfpy_attrs_release", None, C.c_void_p)
attrs_count = _sig("lfpy_attrs_count", C.c_size_t, C.c_void_p)
attrs_item = _sig("lfpy_attrs_item", _P(Attr), C.c_void_p, C.c_size_t)
attrs_set = _sig("lfpy_attrs_set", C.c_int, C.c_void_p, C.c_char_p, C.c_int, C.c_char_p, C.c_int, C.c_double,
                 _P(C.c_float), C.c_int, _P(C.c_double))
free = _sig("lfpy_free", None, C.c_void_p)
version = _sig("lfpy_version", C.c_char_p)
depth = _sig("lfpy_depth", C.c_int, _H, _P(DepthArgs), _P(Image), _P(Image), _P(C.c_double), _P(C.c_char_p), _E)
refocus = _sig("lfpy_refocus", C.c_int, _H, _P(RefocusArgs), _P(Image), _P(C.c_double), C.c_char_p, C.c_size_t,
               _E)
view = _sig("lfpy_view", C.c_int, _H, _P(ViewArgs), _P(Image), _E)
render = _sig("lfpy_render", C.c_int, C.c_char_p, _P(RenderArgs), _P(C.c_int), _P(Image), C.c_void_p,
              _P(C.c_int), _P(C.c_void_p), _P(C.c_void_p), _E)
write = _sig("lfpy_write", C.c_int, C.c_char_p, _P(Image), C.c_void_p, C.c_double, C.c_char_p, C.c_int, _E)
write_disparity = _sig("lfpy_write_disparity", C.c_int, C.c_char_p, _P(Image), C.c_double, C.c_double, _E)
read = _sig("lfpy_read", C.c_int, C.c_char_p, _P(Image), C.c_void_p, _E)
