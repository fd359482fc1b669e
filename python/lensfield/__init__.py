"""lensfield: light fields, depth and renders as numpy arrays.

    import lensfield as lf
    L = lf.open("views/")                 # a folder of views, or a raw (+ layout keywords as lftool's flags)
    L.views                               # float32 (rows, cols, height, width, 3), linear, shared with C
    d = L.depth()                         # (height, width) float32, as `lftool depth`
    img = L.refocus(disparity=0.5)        # (height, width, 3), as `lftool refocus`
    img, meta = lf.render("scenes/demo.pbrt", spp=16, seed=1, threads=2)   # as `lfrender`
    lf.write("out.exr", img, meta)        # as the tools write files

The work is done by the same C libraries the tools use (liblensfield.so,
called through ctypes), so results equal the tools' outputs bit for bit.
Long calls release the GIL and return promptly on Ctrl-C (docs/python.md).
"""
import ctypes as C
import threading
import warnings

import numpy as np

from . import _capi

__all__ = ["LightField", "open", "render", "write", "read", "write_disparity", "Metadata", "Error", "FileError",
           "ParseError", "ParamError", "UnsupportedError", "NumericError", "Interrupted", "RefocusRangeWarning",
           "SceneWarning", "__version__"]

__version__ = _capi.version().decode()

# ---------------------------------------------------------------- errors


class Error(RuntimeError):
    """A lensfield library error; str(e) is the library's message (scenes:
    "file:line:col: message", one line per error).  e.code is the LF_ERR_* code."""

    code = 0

    def __init__(self, message, code=None):
        super().__init__(message)
        if code is not None:
            self.code = code


class FileError(Error):
    """LF_ERR_IO: a file missing, unreadable or unwritable."""
    code = 1


class ParseError(Error):
    """LF_ERR_PARSE: malformed input (the message names file:line:col)."""
    code = 2


class ParamError(Error, ValueError):
    """LF_ERR_PARAM: a bad, unknown or unused parameter."""
    code = 3


class UnsupportedError(Error):
    """LF_ERR_UNSUPPORTED."""
    code = 4


class NumericError(Error, ArithmeticError):
    """LF_ERR_NUMERIC: NaN/Inf or out-of-range numbers."""
    code = 6


class Interrupted(Error):
    """LF_ERR_INTERRUPTED."""
    code = 8


_ERRORS = {1: FileError, 2: ParseError, 3: ParamError, 4: UnsupportedError, 5: MemoryError, 6: NumericError,
           8: Interrupted}


class RefocusRangeWarning(UserWarning):
    """Refocusing outside Ng 2005's refocusable range (lftool refocus warns too)."""


class SceneWarning(UserWarning):
    """A renderer note ("file:line:col: warning: ..."), as lfrender prints it."""


def _raise(err, rc, text=None):
    msg = text if text else err.msg.decode(errors="replace")
    cls = _ERRORS.get(err.code or rc, Error)
    if cls is MemoryError:
        raise MemoryError(msg)
    raise cls(msg, err.code or rc)


# ---------------------------------------------------------------- calls and buffers


def _call(fn, *args, stop=None):
    """Runs the ctypes call fn(*args) on a worker thread and waits, so that
    Ctrl-C reaches Python at once.  With a stop flag (render) the library is
    asked to stop and the call ends after the tiles in flight; otherwise the
    computation finishes in the background and its result is dropped (the
    light-field functions have no stop hook)."""
    out = {}

    def work():
        try:
            out["rc"] = fn(*args)
        except BaseException as e:  # noqa: B902 - handed to the caller
            out["exc"] = e

    t = threading.Thread(target=work, name="lensfield", daemon=True)
    t.start()
    try:
        while t.is_alive():
            t.join(0.25)
    except KeyboardInterrupt:
        if stop is not None:
            stop.value = 1
            t.join()
        raise
    if "exc" in out:
        raise out["exc"]
    return out["rc"]


class _Buffer:
    """A C buffer as numpy sees it; holds its owner so the memory outlives
    every array over it."""

    def __init__(self, owner, addr, shape, typestr="<f4", readonly=False):
        self._owner = owner
        self.__array_interface__ = {"shape": tuple(shape), "typestr": typestr, "data": (addr, readonly),
                                    "version": 3}


def _array(owner, addr, shape, readonly=False):
    if not addr or 0 in shape:
        return np.zeros(shape, np.float32)
    return np.asarray(_Buffer(owner, addr, shape, readonly=readonly))


class _OutImage:
    """An lf_image the library fills; released when the last array over it goes."""

    def __init__(self):
        self.ptr = _capi.image_new()
        if not self.ptr:
            raise MemoryError("out of memory")

    def __del__(self, _release=_capi.image_release):
        if self.ptr:
            _release(self.ptr)
            self.ptr = None

    def array(self, squeeze=True):
        im = self.ptr.contents
        addr = C.cast(im.data, C.c_void_p).value
        shape = (im.height, im.width) if squeeze and im.channels == 1 else (im.height, im.width, im.channels)
        return _array(self, addr, shape)


def _in_image(a, name):
    """An lf_image over a numpy array (float32, C order: copied only when it is not)."""
    a = np.asarray(a)
    if a.ndim == 2:
        a = a[:, :, None]
    if a.ndim != 3 or a.shape[2] < 1:
        raise ValueError(f"{name}: want an array of shape (height, width) or (height, width, channels), "
                         f"got {a.shape}")
    a = np.ascontiguousarray(a, dtype=np.float32)
    im = _capi.Image(a.shape[1], a.shape[0], a.shape[2], a.ctypes.data_as(C.POINTER(C.c_float)))
    return im, a  # keep a alive while im is used


# ---------------------------------------------------------------- metadata


class Metadata(dict):
    """Header attributes (name -> value), e.g. lensfield:spp.  `types` keeps
    each attribute's EXR type ("string", "int", "float", "double", "floats",
    "m44d") so a render's header is written back as lfrender writes it;
    `savefp16` is the Film's "savefp16" (EXR channels as half floats)."""

    _TYPES = ("string", "int", "float", "double", "floats", "m44d")

    def __init__(self, *args, **kw):
        super().__init__(*args, **kw)
        self.types = {}
        self.savefp16 = False

    def _type_of(self, name, value):
        if name in self.types:
            return self.types[name]
        if isinstance(value, str):
            return "string"
        if isinstance(value, (bool, int, np.integer)):
            return "int"
        if isinstance(value, (float, np.floating)):
            return "double"
        a = np.asarray(value, dtype=np.float64)
        return "m44d" if a.shape == (4, 4) else "floats"


def _meta_from_attrs(attrs):
    meta = Metadata()
    for i in range(_capi.attrs_count(attrs)):
        a = _capi.attrs_item(attrs, i).contents
        name = a.name.decode()
        t = a.type
        if t == _capi.ATTR_STRING:
            v = a.s.decode(errors="replace") if a.s else ""
        elif t == _capi.ATTR_INT:
            v = a.i
        elif t in (_capi.ATTR_FLOAT, _capi.ATTR_DOUBLE):
            v = a.d
        elif t == _capi.ATTR_FLOATS:
            v = np.array([a.v[k] for k in range(a.n)], np.float32)
        else:
            v = np.array(list(a.m), np.float64).reshape(4, 4)
        meta[name] = v
        meta.types[name] = Metadata._TYPES[t]
    return meta


class _Attrs:
    def __init__(self, meta):
        self.ptr = _capi.attrs_new()
        if not self.ptr:
            raise MemoryError("out of memory")
        meta = meta or {}
        typed = meta if isinstance(meta, Metadata) else Metadata()
        for name, value in meta.items():
            t = typed._type_of(name, value)
            s, i, d, v, n, m = None, 0, 0.0, None, 0, None
            if t == "string":
                s = str(value).encode()
            elif t == "int":
                i = int(value)
            elif t in ("float", "double"):
                d = float(value)
            elif t == "floats":
                arr = np.ascontiguousarray(value, dtype=np.float32).ravel()
                v, n = arr.ctypes.data_as(C.POINTER(C.c_float)), arr.size
            else:
                arr = np.ascontiguousarray(value, dtype=np.float64).reshape(16)
                m = arr.ctypes.data_as(C.POINTER(C.c_double))
            if _capi.attrs_set(self.ptr, name.encode(), Metadata._TYPES.index(t), s, i, d, v, n, m):
                raise MemoryError("out of memory for attribute " + name)

    def __del__(self, _release=_capi.attrs_release):
        if self.ptr:
            _release(self.ptr)
            self.ptr = None


# ---------------------------------------------------------------- light fields


class _Handle:
    """Owns an lfpy_lightfield (and, for from_array, the numpy views it borrows)."""

    def __init__(self, ptr, keep=None):
        self.ptr = ptr
        self.keep = keep

    def __del__(self, _close=_capi.close):
        if self.ptr:
            _close(self.ptr)
            self.ptr = None


def _threads(threads):
    threads = int(threads)
    if not 0 <= threads <= 1024:
        raise ValueError("threads: 0 (all cores) .. 1024")
    return threads


def _focus(alpha, depth, disparity):
    f = _capi.Focus()
    if alpha is not None:
        if not alpha > 0:
            raise ValueError("alpha must be > 0")
        f.have_alpha, f.alpha = 1, float(alpha)
    if depth is not None:
        if not depth > 0:
            raise ValueError("depth must be > 0 (metres)")
        f.have_depth, f.depth = 1, float(depth)
    if disparity is not None:
        f.have_disp, f.disp = 1, float(disparity)
    return f


def _aperture(args, aperture, views):
    if aperture is not None:
        if not aperture >= 0:
            raise ValueError("aperture must be >= 0 (views from the centre)")
        args.have_aperture, args.aperture = 1, float(aperture)
    if views is not None:
        v = [int(x) for x in views]
        if len(v) != 4 or min(v) < 0:
            raise ValueError("views: (u0, u1, v0, v1), view indices >= 0")
        args.have_views = 1
        args.views[:] = v


class LightField:
    """A 4D light field L(u, v, s, t): rows x cols views of height x width RGB
    pixels, linear float32.  Make one with lensfield.open() or
    LightField.from_array()."""

    def __init__(self, handle):
        self._h = handle
        info = _capi.Info()
        _capi.info_get(handle.ptr, info)
        self._info = info

    # -- construction
    @classmethod
    def from_array(cls, views, positions=None):
        """A light field over views of shape (rows, cols, height, width, 3)
        (float32 in C order is used in place, anything else is converted
        once).  positions (rows, cols, 2): each view's (x, y) position, on a
        regular grid (x along columns, y along rows); its column step is
        the unit of disparity and the ratio of the steps is the light field's
        v/u disparity ratio.  None: unit steps."""
        v = np.asarray(views)
        if v.ndim != 5 or v.shape[4] != 3:
            raise ValueError(f"views: want shape (rows, cols, height, width, 3), got {v.shape}")
        v = np.ascontiguousarray(v, dtype=np.float32)
        rows, cols, h, w, _ = v.shape
        ratio = 1.0
        if positions is not None:
            ratio = _grid_ratio(np.asarray(positions, np.float64), rows, cols)
        ptr = C.c_void_p()
        err = _capi.Error()
        rc = _capi.wrap(v.ctypes.data, cols, rows, w, h, ratio, C.byref(ptr), C.byref(err))
        if rc:
            _raise(err, rc)
        return cls(_Handle(ptr, keep=v))

    # -- what it is
    @property
    def shape(self):
        """(rows, cols, height, width, 3)."""
        i = self._info
        return (i.nv, i.nu, i.nt, i.ns, 3)

    @property
    def views(self):
        """The views, float32 (rows, cols, height, width, 3), linear; the C
        library's own buffer (no copy), read-only unless made by from_array."""
        h = self._h
        if h.keep is not None:
            return h.keep
        return _array(h, self._info.data, self.shape, readonly=True)

    @property
    def valid(self):
        """None when every sample is valid, else (rows, cols, height, width)
        float32 1/0 (missing samples: vignetting, non-finite raw values)."""
        if not self._info.has_valid:
            return None
        return _array(self._h, self._info.valid, self.shape[:4], readonly=True)

    @property
    def positions(self):
        """(rows, cols, 2) float64: each view's (u, v) position in view steps
        from the grid's centre (u right, v down; v scaled by the light
        field's v/u disparity ratio)."""
        rows, cols = self.shape[:2]
        u = np.arange(cols) - (cols - 1) / 2.0
        v = (np.arange(rows) - (rows - 1) / 2.0) * self._info.disp_v_per_u
        p = np.empty((rows, cols, 2))
        p[..., 0] = u[None, :]
        p[..., 1] = v[:, None]
        return p

    @property
    def missing(self):
        """Samples marked missing."""
        return self._info.missing

    @property
    def nonfinite(self):
        """Raw values that were NaN/Inf (their samples are missing)."""
        return self._info.nonfinite

    def describe(self):
        """What `lftool info` prints about the source."""
        buf = C.create_string_buffer(4096)
        _capi.describe(self._h.ptr, buf, len(buf))
        return buf.value.decode(errors="replace")

    def __repr__(self):
        r, c, h, w, _ = self.shape
        return f"<lensfield.LightField {r} x {c} views of {w} x {h}>"

    # -- computations
    def depth(self, *, from_=None, to=None, steps=None, aperture=None, views=None, confidence=False,
              calibrate_views=False, noisy=False, plain_regions=False, prefilter=None, method="volume",
              threads=0, return_range=False):
        """Disparity map of the centre view, (height, width) float32, px per
        view step (lftool depth; docs/depth.md).  Keywords are lftool depth's
        flags: from_/to (--from/--to; neither: the source's stated range or
        one estimated from the data), steps, aperture and views (method
        "stack" only, as in lftool), calibrate_views, method ("volume" or
        "stack"), noisy (--noisy: views with sensor noise), plain_regions
        (--plain-regions: untextured regions from the evidence around them),
        prefilter (--prefilter: the views' Gaussian pre-smoothing in px, 0
        never; None: 0.7 where the views are noisy), threads (0: all cores).  confidence=True also returns the
        confidence map; return_range=True also the range searched (d0, d1)."""
        a = _capi.DepthArgs()
        if (from_ is None) != (to is None):
            raise ValueError("depth: give both from_ and to, or neither (range from the file or the data)")
        if from_ is not None:
            if not from_ < to:
                raise ValueError("depth: from_ must be below to")
            a.have_range, a.from_, a.to = 1, float(from_), float(to)
        if steps is not None:
            if not 3 <= int(steps) <= 4096:
                raise ValueError("steps: 3 .. 4096")
            a.have_steps, a.steps = 1, int(steps)
        if method not in ("volume", "stack"):
            raise ValueError('method: "volume" or "stack"')
        _aperture(a, aperture, views)
        a.threads = _threads(threads)
        a.calibrate_views = bool(calibrate_views)
        a.noisy = bool(noisy)
        a.plain = bool(plain_regions)
        if prefilter is not None:
            if not 0 <= float(prefilter) <= 4:
                raise ValueError("prefilter: 0 .. 4 px")
            a.have_prefilter, a.prefilter = 1, float(prefilter)
        a.stack = method == "stack"
        a.confidence = bool(confidence) and method == "volume"
        disp, conf = _OutImage(), _OutImage()
        rng = (C.c_double * 2)()
        src = C.c_char_p()
        err = _capi.Error()
        rc = _call(_capi.depth, self._h.ptr, C.byref(a), disp.ptr, conf.ptr, rng, C.byref(src), C.byref(err))
        if rc:
            _raise(err, rc)
        out = [disp.array()]
        if confidence:
            out.append(conf.array() if a.confidence else np.ones_like(out[0]))
        if return_range:
            out.append((rng[0], rng[1]))
        return out[0] if len(out) == 1 else tuple(out)

    def refocus(self, *, disparity=None, alpha=None, depth=None, aperture=None, views=None, method="shift",
                oversample=2.0, threads=0):
        """Refocused image (height, width, 3) float32 (lftool refocus): exactly
        one of disparity (px per view), alpha (Ng 2005) or depth (metres);
        aperture (radius in views), views (u0, u1, v0, v1), method "shift"
        (shift-and-add) or "fourier" (Fourier slice, with oversample)."""
        a = _capi.RefocusArgs()
        a.focus = _focus(alpha, depth, disparity)
        if a.focus.have_alpha + a.focus.have_depth + a.focus.have_disp != 1:
            raise ValueError("refocus needs exactly one of disparity=, alpha=, depth=")
        if method not in ("shift", "fourier"):
            raise ValueError('method: "shift" or "fourier"')
        if not 1 <= oversample <= 8:
            raise ValueError("oversample: 1 .. 8")
        _aperture(a, aperture, views)
        a.threads = _threads(threads)
        a.fourier = method == "fourier"
        a.oversample = float(oversample)
        out = _OutImage()
        d = C.c_double()
        warning = C.create_string_buffer(1024)
        err = _capi.Error()
        rc = _call(_capi.refocus, self._h.ptr, C.byref(a), out.ptr, C.byref(d), warning, len(warning), C.byref(err))
        if rc:
            _raise(err, rc)
        if warning.value:
            warnings.warn(warning.value.decode(), RefocusRangeWarning, stacklevel=2)
        return out.array()

    def view(self, u, v, *, disparity=None, alpha=None, depth=None, geometry=None, disparity_map=None,
             confidence=None, calibrate_views=False, threads=0):
        """The view from centred view coordinates (u, v) (view steps right of
        and below the centre), (height, width, 3) float32 (lftool view):
        geometry "depth" (per-pixel disparity, the default; disparity_map
        and its confidence may be given as (height, width) arrays) or
        "plane" (blend on the plane at disparity/alpha/depth)."""
        a = _capi.ViewArgs()
        a.u, a.v = float(u), float(v)
        a.focus = _focus(alpha, depth, disparity)
        if a.focus.have_alpha + a.focus.have_depth + a.focus.have_disp > 1:
            raise ValueError("give one of disparity=, alpha=, depth=")
        if geometry not in (None, "depth", "plane"):
            raise ValueError('geometry: "depth" or "plane"')
        a.geometry = -1 if geometry is None else int(geometry == "plane")
        keep = []
        if disparity_map is not None:
            im, arr = _in_image(disparity_map, "disparity_map")
            if not np.isfinite(arr).all():
                raise NumericError("disparity_map has NaN/Inf values")
            keep += [im, arr]
            a.disparity_map = C.pointer(im)
        if confidence is not None:
            im, arr = _in_image(confidence, "confidence")
            keep += [im, arr]
            a.confidence = C.pointer(im)
        a.calibrate_views = bool(calibrate_views)
        a.threads = _threads(threads)
        out = _OutImage()
        err = _capi.Error()
        rc = _call(_capi.view, self._h.ptr, C.byref(a), out.ptr, C.byref(err))
        del keep
        if rc:
            _raise(err, rc)
        return out.array()


def _grid_ratio(p, rows, cols):
    """The v/u step ratio of a regular grid of view positions (ValueError otherwise)."""
    if p.shape != (rows, cols, 2):
        raise ValueError(f"positions: want shape ({rows}, {cols}, 2), got {p.shape}")
    du = (p[0, -1, 0] - p[0, 0, 0]) / (cols - 1) if cols > 1 else 0.0
    dv = (p[-1, 0, 1] - p[0, 0, 1]) / (rows - 1) if rows > 1 else 0.0
    step = du if du else dv
    if not step:
        raise ValueError("positions: the views must not all sit at one place")
    ideal = np.empty_like(p)
    ideal[..., 0] = p[0, 0, 0] + du * np.arange(cols)[None, :]
    ideal[..., 1] = p[0, 0, 1] + dv * np.arange(rows)[:, None]
    if not np.allclose(p, ideal, rtol=0, atol=1e-6 * abs(step)):
        raise ValueError("positions: views must sit on a regular grid (x along columns, y along rows)")
    if du and dv and (du < 0 or dv < 0):
        raise ValueError("positions: x must grow along columns and y along rows (view (0, 0) top left)")
    return dv / du if du and dv else 1.0


# ---------------------------------------------------------------- module functions

_LAYOUT = {  # keyword: (bit, count)
    "kind": (_capi.LAYOUT_KIND, 1), "camsperdim": (_capi.LAYOUT_CAMS, 2), "griddim": (_capi.LAYOUT_GRIDDIM, 4),
    "inputfov": (_capi.LAYOUT_FOV, 1), "tilesize": (_capi.LAYOUT_TILE, 2), "grid": (_capi.LAYOUT_GRID, 1),
    "pitch": (_capi.LAYOUT_PITCH, 1), "rotation": (_capi.LAYOUT_ROTATION, 1), "offset": (_capi.LAYOUT_OFFSET, 2),
    "lenscount": (_capi.LAYOUT_LENSES, 2), "mainlens": (_capi.LAYOUT_MAINLENS, 4)}


def _seq(name, value, n, kind):
    v = [kind(x) for x in (value if n > 1 else [value])]
    if len(v) != n:
        raise ValueError(f"{name}: want {n} values")
    return v


def open(path, *, white=None, allow_nonfinite=False, **layout):  # noqa: A001 - lf.open reads as the issue asks
    """Opens a light-field raw (EXR with lensfield:* attributes, or any image
    plus layout keywords) or a folder of views (HCI layout, PREFIX_RR_CC),
    as lftool takes IN.  Layout keywords are lftool's flags: kind
    ("camera-array"|"plenoptic"), camsperdim (nx, ny), griddim (minx, maxx,
    miny, maxy), inputfov, tilesize (w, h), grid ("square"|"hex"), pitch,
    rotation, offset (x, y), lenscount (nx, ny), mainlens (focal_mm, fstop,
    mla_distance_mm, pitch_um); white: a white image to divide by."""
    k = _capi.Layout()
    for name, value in layout.items():
        if name not in _LAYOUT:
            raise TypeError(f"open() got an unexpected keyword argument '{name}' (layout keywords: "
                            + ", ".join(_LAYOUT) + ")")
        if value is None:
            continue
        bit, n = _LAYOUT[name]
        k.given |= bit
        if name == "kind":
            if value not in ("camera-array", "plenoptic"):
                raise ValueError('kind: "camera-array" or "plenoptic"')
            k.plenoptic = value == "plenoptic"
        elif name == "grid":
            if value not in ("square", "hex"):
                raise ValueError('grid: "square" or "hex"')
            k.hex = value == "hex"
        elif name in ("camsperdim", "tilesize", "lenscount"):
            v = _seq(name, value, 2, int)
            if min(v) < 1:
                raise ValueError(f"{name}: values >= 1")
            getattr(k, {"camsperdim": "cams", "tilesize": "tile", "lenscount": "lenses"}[name])[:] = v
        elif name in ("griddim", "offset", "mainlens"):
            v = _seq(name, value, n, float)
            if name == "mainlens" and min(v) <= 0:
                raise ValueError("mainlens: values > 0")
            getattr(k, name)[:] = v
        elif name == "inputfov":
            if not 0 < value < 180:
                raise ValueError("inputfov: 0 < degrees < 180")
            k.fov = float(value)
        elif name == "pitch":
            if not value > 0:
                raise ValueError("pitch must be > 0")
            k.pitch = float(value)
        else:
            k.rotation = float(value)
    ptr = C.c_void_p()
    err = _capi.Error()
    rc = _call(_capi.open_, str(path).encode(), C.byref(k), None if white is None else str(white).encode(),
               int(bool(allow_nonfinite)), C.byref(ptr), C.byref(err))
    if rc:
        _raise(err, rc)
    L = LightField(_Handle(ptr))
    if L.nonfinite and not L._info.is_folder:
        warnings.warn(f"{path}: {L.nonfinite} non-finite pixel values excluded as missing samples", stacklevel=2)
    return L


def render(scene, *, spp=None, seed=None, threads=0, crop=None, allow_unsupported=False, white=False):
    """Renders a pbrt-v4 scene as lfrender does: returns (image, meta), the
    film as float32 (height, width, channels), linear, and its lensfield:*
    header (Metadata).  spp: samples per pixel (None: the Sampler's);
    seed (None: the Sampler's); threads (0: all cores; never changes the
    result); crop (x0, x1, y0, y1); allow_unsupported, white as lfrender's
    flags.  Scene errors raise ParseError/ParamError with every
    "file:line:col: message"; Ctrl-C stops after the tiles in flight."""
    a = _capi.RenderArgs()
    if spp is not None:
        if not 1 <= int(spp) <= 1 << 24:
            raise ValueError("spp: 1 .. 2^24")
        a.spp = int(spp)
    if seed is not None:
        if not 0 <= int(seed) <= 4294967295:
            raise ValueError("seed: 0 .. 4294967295")
        a.has_seed, a.seed = 1, int(seed)
    a.threads = _threads(threads)
    if crop is not None:
        c = _seq("crop", crop, 4, int)
        if c[1] <= c[0] or c[3] <= c[2] or min(c) < 0:
            raise ValueError("crop (x0, x1, y0, y1) needs 0 <= x0 < x1 and 0 <= y0 < y1")
        a.have_crop = 1
        a.crop[:] = c
    a.allow_unsupported = bool(allow_unsupported)
    a.white = bool(white)
    img = _OutImage()
    attrs = _Attrs(None)
    stop, half = C.c_int(0), C.c_int(0)
    warn_p, errors_p = C.c_void_p(), C.c_void_p()
    err = _capi.Error()
    rc = _call(_capi.render, str(scene).encode(), C.byref(a), C.byref(stop), img.ptr, attrs.ptr, C.byref(half),
               C.byref(warn_p), C.byref(errors_p), C.byref(err), stop=stop)
    texts = []
    for p in (warn_p, errors_p):
        texts.append(C.string_at(p.value).decode(errors="replace") if p.value else "")
        _capi.free(p)
    if texts[0]:
        for line in texts[0].splitlines():
            warnings.warn(line, SceneWarning, stacklevel=2)
    if rc:
        _raise(err, rc, texts[1].rstrip("\n") or None)
    meta = _meta_from_attrs(attrs.ptr)
    meta.savefp16 = bool(half.value)
    n = meta.get("lensfield:nonfinite_samples", 0)
    if n:
        warnings.warn(f"{n} samples had NaN/Inf radiance and were dropped (lensfield:nonfinite_samples)",
                      stacklevel=2)
    return img.array(squeeze=False), meta


def write(path, img, meta=None, *, exposure=0.0, tonemap=None, half=None):
    """Writes an image as the tools do (format from the extension): EXR
    linear with meta as header attributes, PNG/JPEG tonemapped (exposure in
    stops, tonemap "clamp"|"filmic"|"aces"), PFM.  half: EXR channels as half
    floats; None: as lfrender would (meta.savefp16 of a render's Metadata)."""
    im, arr = _in_image(img, "img")
    if tonemap not in (None, "clamp", "filmic", "aces"):
        raise ValueError('tonemap: "clamp", "filmic" or "aces"')
    if half is None:
        half = bool(getattr(meta, "savefp16", False))
    attrs = _Attrs(meta)
    err = _capi.Error()
    rc = _call(_capi.write, str(path).encode(), C.byref(im), attrs.ptr, float(exposure),
               None if tonemap is None else tonemap.encode(), int(bool(half)), C.byref(err))
    del arr
    if rc:
        _raise(err, rc)


def write_disparity(path, disparity, d0, d1):
    """Writes a disparity map as lftool depth does: EXR/PFM values with
    lensfield:disparity_search_range [d0, d1]; PNG a colour map with its legend."""
    im, arr = _in_image(disparity, "disparity")
    err = _capi.Error()
    rc = _capi.write_disparity(str(path).encode(), C.byref(im), float(d0), float(d1), C.byref(err))
    del arr
    if rc:
        _raise(err, rc)


def read(path):
    """Reads an image (EXR, PFM, PNG, ... as the tools read them; 8-bit
    sRGB linearised): returns (image, meta), image (height, width) for one
    channel, else (height, width, channels), float32."""
    img = _OutImage()
    attrs = _Attrs(None)
    err = _capi.Error()
    rc = _call(_capi.read, str(path).encode(), img.ptr, attrs.ptr, C.byref(err))
    if rc:
        _raise(err, rc)
    return img.array(), _meta_from_attrs(attrs.ptr)
