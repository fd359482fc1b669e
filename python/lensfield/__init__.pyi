"""Type hints for lensfield (python/lensfield/__init__.py holds the code and
the long docstrings; docs/python.md the guide)."""
import os
from typing import Any, Literal, Mapping, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str
__all__: list[str]

PathLike = Union[str, "os.PathLike[str]"]
F32 = npt.NDArray[np.float32]

class Error(RuntimeError):
    """A lensfield library error: str(e) is the library's message
    ("file:line:col: message" for scenes, one line each); code the LF_ERR_* code."""
    code: int
    def __init__(self, message: str, code: Optional[int] = ...) -> None: ...

class FileError(Error):
    """A file missing, unreadable or unwritable (LF_ERR_IO)."""

class ParseError(Error):
    """Malformed input, naming file:line:col (LF_ERR_PARSE)."""

class ParamError(Error, ValueError):
    """A bad, unknown or unused parameter (LF_ERR_PARAM)."""

class UnsupportedError(Error):
    """LF_ERR_UNSUPPORTED."""

class NumericError(Error, ArithmeticError):
    """NaN/Inf or out-of-range numbers (LF_ERR_NUMERIC)."""

class Interrupted(Error):
    """LF_ERR_INTERRUPTED."""

class RefocusRangeWarning(UserWarning):
    """Refocusing outside Ng 2005's refocusable range."""

class SceneWarning(UserWarning):
    """A renderer note, "file:line:col: warning: ..."."""

class Metadata(dict[str, Any]):
    """Header attributes (name -> str, int, float, float32 vector or 4x4
    float64 matrix); types: each attribute's EXR type; savefp16: write the
    EXR as half floats (a render's Film "savefp16")."""
    types: dict[str, Literal["string", "int", "float", "double", "floats", "m44d"]]
    savefp16: bool

class LightField:
    """A 4D light field: rows x cols views of height x width linear RGB float32."""

    @classmethod
    def from_array(cls, views: npt.ArrayLike, positions: Optional[npt.ArrayLike] = ...) -> "LightField":
        """Wraps views (rows, cols, height, width, 3) in place when float32 in C
        order (else converted once); positions (rows, cols, 2) on a regular grid."""
    @property
    def shape(self) -> Tuple[int, int, int, int, int]:
        """(rows, cols, height, width, 3)."""
    @property
    def views(self) -> F32:
        """(rows, cols, height, width, 3), the library's buffer (no copy)."""
    @property
    def valid(self) -> Optional[F32]:
        """(rows, cols, height, width) 1/0, or None when every sample is valid."""
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """(rows, cols, 2): (u, v) in view steps from the centre."""
    @property
    def missing(self) -> int: ...
    @property
    def nonfinite(self) -> int: ...
    def describe(self) -> str:
        """What `lftool info` prints."""
    @overload
    def depth(self, *, from_: Optional[float] = ..., to: Optional[float] = ..., steps: Optional[int] = ...,
              aperture: Optional[float] = ..., views: Optional[Sequence[int]] = ...,
              confidence: Literal[False] = ..., calibrate_views: bool = ..., noisy: bool = ...,
              plain_regions: bool = ..., prefilter: Optional[float] = ...,
              method: Literal["volume", "stack"] = ..., threads: int = ...,
              return_range: Literal[False] = ...) -> F32: ...
    @overload
    def depth(self, *, from_: Optional[float] = ..., to: Optional[float] = ..., steps: Optional[int] = ...,
              aperture: Optional[float] = ..., views: Optional[Sequence[int]] = ..., confidence: bool = ...,
              calibrate_views: bool = ..., noisy: bool = ..., plain_regions: bool = ...,
              prefilter: Optional[float] = ...,
              method: Literal["volume", "stack"] = ..., threads: int = ..., return_range: bool = ...) -> Union[F32, Tuple[Any, ...]]:
        """Disparity of the centre view (height, width), px per view step, as
        `lftool depth`; (disp, conf) with confidence, + (d0, d1) with return_range."""
    def refocus(self, *, disparity: Optional[float] = ..., alpha: Optional[float] = ...,
                depth: Optional[float] = ..., aperture: Optional[float] = ...,
                views: Optional[Sequence[int]] = ..., method: Literal["shift", "fourier"] = ...,
                oversample: float = ..., threads: int = ...) -> F32:
        """(height, width, 3) refocused as `lftool refocus`: exactly one of
        disparity, alpha, depth."""
    def view(self, u: float, v: float, *, disparity: Optional[float] = ..., alpha: Optional[float] = ...,
             depth: Optional[float] = ..., geometry: Optional[Literal["depth", "plane"]] = ...,
             disparity_map: Optional[npt.ArrayLike] = ..., confidence: Optional[npt.ArrayLike] = ...,
             calibrate_views: bool = ..., threads: int = ...) -> F32:
        """(height, width, 3) seen from centred view coordinates (u, v), as `lftool view`."""

def open(path: PathLike, *, white: Optional[PathLike] = ..., allow_nonfinite: bool = ...,
         kind: Optional[Literal["camera-array", "plenoptic"]] = ..., camsperdim: Optional[Sequence[int]] = ...,
         griddim: Optional[Sequence[float]] = ..., inputfov: Optional[float] = ...,
         tilesize: Optional[Sequence[int]] = ..., grid: Optional[Literal["square", "hex"]] = ...,
         pitch: Optional[float] = ..., rotation: Optional[float] = ..., offset: Optional[Sequence[float]] = ...,
         lenscount: Optional[Sequence[int]] = ..., mainlens: Optional[Sequence[float]] = ...) -> LightField:
    """A raw (+ layout keywords as lftool's flags) or a folder of views."""

def render(scene: PathLike, *, spp: Optional[int] = ..., seed: Optional[int] = ..., threads: int = ...,
           crop: Optional[Sequence[int]] = ..., allow_unsupported: bool = ...,
           white: bool = ...) -> Tuple[F32, Metadata]:
    """(film (height, width, channels) float32 linear, lensfield:* header), as lfrender."""

def write(path: PathLike, img: npt.ArrayLike, meta: Optional[Mapping[str, Any]] = ..., *, exposure: float = ...,
          tonemap: Optional[Literal["clamp", "filmic", "aces"]] = ..., half: Optional[bool] = ...) -> None:
    """EXR (linear, meta as attributes), PNG/JPEG (tonemapped), PFM, as the tools write them."""

def write_disparity(path: PathLike, disparity: npt.ArrayLike, d0: float, d1: float) -> None:
    """A disparity map as `lftool depth` writes it."""

def read(path: PathLike) -> Tuple[F32, Metadata]:
    """(image, header): (height, width) for one channel, else (height, width, channels)."""
