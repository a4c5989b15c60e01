"""Shared pieces of the file formats: the record, atomic writes, lazy imports, corners.

Nothing here is format specific; the format modules (``points``, ``airfoil``, ``jsonfmt``,
``dxf``, ``rhino``, ``svg``, ``occ``) build on it.
"""

from __future__ import annotations

import contextlib
import dataclasses
import importlib
import os
import shutil
import signal
import stat
import tempfile
import threading
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from .._kernels import corners as _k
from .._threads import THREADS, ranges
from .._typing import ArrayLike, FloatArray
from .._validate import MAX_MAGNITUDE, MIN_EXTENT
from ..curves.bspline import BSplineCurve
from ..curves.hermite import CubicHermite, QuinticHermite
from ..curves.interpolate import interpolate_cubic
from ..curves.piecewise import PiecewiseCurve, readonly
from ..errors import FileFormatError, InputError, MissingDependencyError

__all__ = [
    "CurveRecord",
    "KINDS",
    "atomic_write",
    "atomic_path",
    "lazy_import",
    "turning_angles",
    "corner_turning",
    "noise_scale",
    "DEFAULT_CORNER_ANGLE",
    "split_at_corners",
    "points_curve",
    "check_points",
    "drop_duplicates",
]

#: What a record's ``kind`` can say the file held.
KINDS = ("points", "airfoil", "polyline", "fit_points", "bspline", "cubic_hermite",
         "quintic_hermite")


@dataclass(frozen=True, eq=False)
class CurveRecord:
    """One curve read from a file, with what is needed to write it back faithfully.

    Attributes
    ----------
    curve : PiecewiseCurve
        The curve to fair: a :class:`~curvefair.BSplineCurve` for spline entities, a
        :class:`~curvefair.CubicHermite` (``interpolate_cubic(points, "chord", "natural")``, or
        ``"periodic"`` for closed point loops) for point data, or whatever a JSON file held.
    name : str or None
        Name line of an airfoil, DXF layer + handle, 3dm object name, SVG path id, JSON name.
    kind : str
        What the file held (one of :data:`KINDS`): ``"points"`` (a text point list),
        ``"airfoil"`` (a Selig/Lednicer ``.dat``), ``"polyline"`` (DXF/3dm/SVG polyline
        vertices), ``"fit_points"`` (a DXF spline defined by fit points only), ``"bspline"``
        (control points + knots), ``"cubic_hermite"``/``"quintic_hermite"`` (JSON).
    source : mapping
        Read-only, format specific; always ``"format"``, ``"path"`` (absolute, or None for
        curves not read from a file) and ``"index"`` (0-based position of the record in the
        file). See :doc:`docs/formats.md </formats>` for the keys of each format.
    points : ndarray, shape (m, dim), or None
        The raw data points of point kinds (``points``, ``airfoil``, ``polyline``,
        ``fit_points``), in file order; ``curve.points`` starts as exactly these (plus the first
        point repeated last for a closed loop).
    corners : tuple of int
        0-based indices into ``points`` (and ``curve.points``) that are sharp corners or fixed
        ends (an airfoil's trailing edge): pass them to the fairing as ``protect``. A point list
        with interior corners is split there into several records, so a corner is always the
        first or last point of a record.

    Notes
    -----
    Records are immutable; :meth:`with_curve` gives a copy holding the faired curve, which is
    what :func:`curvefair.write_curves` takes.
    """

    curve: PiecewiseCurve
    name: str | None = None
    kind: str = "bspline"
    source: Mapping[str, Any] = field(default_factory=dict)
    points: FloatArray | None = None
    corners: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.curve, PiecewiseCurve):
            raise InputError(f"curve must be a curvefair curve, got {type(self.curve).__name__}")
        if self.kind not in KINDS:
            raise InputError(f"kind must be one of {KINDS}, got {self.kind!r}")
        if not isinstance(self.source, MappingProxyType):
            object.__setattr__(self, "source", MappingProxyType(dict(self.source)))
        if self.points is not None:
            pts = np.array(self.points, dtype=np.float64)
            object.__setattr__(self, "points", readonly(pts))
        object.__setattr__(self, "corners", tuple(int(i) for i in self.corners))

    @property
    def format(self) -> str | None:
        """The format the record was read from (``source["format"]``)."""
        return self.source.get("format")

    @property
    def path(self) -> str | None:
        """The file the record was read from (``source["path"]``)."""
        return self.source.get("path")

    def with_curve(self, curve: PiecewiseCurve) -> CurveRecord:
        """A copy holding ``curve`` (e.g. the faired one); everything else unchanged."""
        return dataclasses.replace(self, curve=curve)

    def __repr__(self) -> str:
        return (f"CurveRecord(name={self.name!r}, kind={self.kind!r}, format={self.format!r}, "
                f"curve={self.curve!r}, corners={self.corners})")


# ------------------------------------------------------------------------------------------
# atomic writes
# ------------------------------------------------------------------------------------------
def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


#: temporary files being written (cleaned up by the SIGTERM / SIGHUP handler)
_LIVE_TEMPS: set[str] = set()
_CLEANUP_SIGNALS = tuple(getattr(signal, n) for n in ("SIGTERM", "SIGHUP") if hasattr(signal, n))


def _on_signal(signum: int, frame: Any) -> None:
    """Delete the live temporary files, then die of the signal as the previous handler would."""
    for tmp in list(_LIVE_TEMPS):
        with contextlib.suppress(OSError):
            _remove(tmp)
        _LIVE_TEMPS.discard(tmp)
    prev = _PREVIOUS_HANDLERS.get(signum, signal.SIG_DFL)
    _restore_handlers()
    if callable(prev):
        prev(signum, frame)
    elif prev != signal.SIG_IGN:
        signal.signal(signum, signal.SIG_DFL)
        os.kill(os.getpid(), signum)


_PREVIOUS_HANDLERS: dict[int, Any] = {}


def _install_handlers() -> None:
    if _PREVIOUS_HANDLERS or threading.current_thread() is not threading.main_thread():
        return
    for sig in _CLEANUP_SIGNALS:
        with contextlib.suppress(ValueError, OSError):
            prev = signal.getsignal(sig)
            if prev == signal.SIG_IGN:
                continue
            signal.signal(sig, _on_signal)
            _PREVIOUS_HANDLERS[sig] = prev


def _restore_handlers() -> None:
    for sig, prev in list(_PREVIOUS_HANDLERS.items()):
        with contextlib.suppress(ValueError, OSError, TypeError):
            signal.signal(sig, prev if prev is not None else signal.SIG_DFL)
    _PREVIOUS_HANDLERS.clear()


#: destinations that are folders (a UFO font)
FOLDER_SUFFIXES = (".ufo",)


def _remove(path: str | os.PathLike[str]) -> None:
    """Delete a temporary file, or a temporary folder (a UFO font is a folder)."""
    if os.path.isdir(path) and not os.path.islink(path):
        shutil.rmtree(path)
    else:
        os.unlink(path)


def _replace(tmp: Path, dest: Path) -> None:
    """``os.replace(tmp, dest)``; a folder replaces a folder by moving the old one aside first
    (``rename`` cannot replace a non-empty folder), which is put back if the move fails."""
    if not (tmp.is_dir() and dest.is_dir() and not dest.is_symlink()):
        os.replace(tmp, dest)
        return
    aside = Path(tempfile.mkdtemp(prefix="." + dest.name + ".old.", dir=dest.parent))
    os.rmdir(aside)
    os.replace(dest, aside)
    try:
        os.replace(tmp, dest)
    except BaseException:
        os.replace(aside, dest)
        raise
    shutil.rmtree(aside, ignore_errors=True)


def write_target(path: str | os.PathLike[str]) -> Path:
    """The file a write to ``path`` replaces: ``path`` itself, or the final target when
    ``path`` is a symbolic link (a write goes *through* the link, which stays a link).

    Raises
    ------
    InputError
        ``path`` is empty or names a folder.
    """
    raw = os.fspath(path)
    if not str(raw).strip():
        raise InputError("the output path is empty")
    if os.path.isdir(raw) and Path(raw).suffix.lower() not in FOLDER_SUFFIXES:
        raise InputError(f"{raw!r} is a folder, not a file name")
    dest = Path(os.path.realpath(raw)) if os.path.islink(raw) else Path(raw)
    if dest.is_dir() and dest.suffix.lower() not in FOLDER_SUFFIXES:
        raise InputError(f"{raw!r} is a link to the folder {str(dest)!r}, not to a file")
    return dest


def _user_os_error(exc: OSError, user: str, tmp: str | None, always: bool = False) -> OSError:
    """``exc`` naming the user's path instead of a temporary file (or no file); ``always``:
    whatever file it names (an error creating the temporary file names only that)."""
    if always or exc.filename in (None, tmp) or (
            tmp is not None and exc.filename == os.path.basename(tmp)):
        new = OSError(exc.errno, exc.strerror or str(exc), user)
        if type(exc) is not OSError:
            with contextlib.suppress(TypeError):
                new = type(exc)(exc.errno, exc.strerror or str(exc), user)
        return new
    return exc


def copy_input(src: str | os.PathLike[str], tmp: Path) -> None:
    """Copy the input ``src`` as it is onto the temporary path ``tmp`` of :func:`atomic_path`:
    a file byte for byte, a folder (a UFO font) as a tree, its symbolic links kept."""
    if os.path.isdir(src):
        _remove(tmp)
        shutil.copytree(src, tmp, symlinks=True)
    else:
        shutil.copyfile(src, tmp)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str], suffix: str | None = None) -> Iterator[Path]:
    """Yield a temporary path in the destination folder; on success ``os.replace`` it onto
    ``path``, on error delete it. The destination keeps its permissions if it existed.

    For libraries that save to a file name (ezdxf, rhino3dm, OCC, fontTools). ``suffix``
    defaults to the destination's (some libraries choose the format by the extension). The
    writer may replace the temporary file by a folder of the same name (a UFO font): it then
    replaces the destination folder.

    A symbolic link is written through: the temporary file goes next to the link's final
    target, which is replaced, and the link stays a link. The temporary file is removed on any
    error, on KeyboardInterrupt, and on SIGTERM / SIGHUP (a handler is installed in the main
    thread while a temporary file exists). OS errors name ``path``, never the temporary file.
    """
    user = os.fspath(path)
    dest = write_target(path)
    folder = dest.parent if str(dest.parent) else Path(".")
    if not folder.is_dir():
        raise InputError(f"{user!r}: the folder {str(folder)!r} does not exist")
    _install_handlers()
    try:
        fd, tmp = tempfile.mkstemp(prefix="." + dest.name + ".",
                                   suffix=dest.suffix if suffix is None else suffix, dir=folder)
    except OSError as exc:
        if not _LIVE_TEMPS:
            _restore_handlers()
        raise _user_os_error(exc, user, None, always=True) from None
    _LIVE_TEMPS.add(tmp)
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        yield tmp_path
        if dest.exists() and dest.is_dir() == tmp_path.is_dir():
            mode = stat.S_IMODE(dest.stat().st_mode)
        else:
            mode = (0o777 if tmp_path.is_dir() else 0o666) & ~_umask()
        os.chmod(tmp_path, mode)
        _replace(tmp_path, dest)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            _remove(tmp_path)
        if isinstance(exc, OSError):
            new = _user_os_error(exc, user, tmp)
            if new is not exc:
                raise new from None
        raise
    finally:
        _LIVE_TEMPS.discard(tmp)
        if not _LIVE_TEMPS:
            _restore_handlers()


def atomic_write(path: str | os.PathLike[str], data: str | bytes | Callable[[Any], None],
                 *, encoding: str = "utf-8", newline: str | None = "") -> None:
    """Write ``data`` to ``path`` atomically: temp file in the same folder, fsync, os.replace.

    Parameters
    ----------
    path : path-like
    data : str, bytes, or callable
        Text, bytes, or a function called with the open (text) file object.
    encoding : str
        For text.
    newline : str or None
        As for :func:`open`; the default ``""`` writes line endings exactly as given.

    Examples
    --------
    >>> import tempfile, os
    >>> d = tempfile.mkdtemp()
    >>> atomic_write(os.path.join(d, "a.txt"), "hello\\n")
    >>> open(os.path.join(d, "a.txt")).read()
    'hello\\n'
    """
    with atomic_path(path) as tmp:
        if isinstance(data, bytes):
            with open(tmp, "wb") as fb:
                fb.write(data)
                fb.flush()
                os.fsync(fb.fileno())
        else:
            with open(tmp, "w", encoding=encoding, newline=newline) as ft:
                if callable(data):
                    data(ft)
                else:
                    ft.write(data)
                ft.flush()
                os.fsync(ft.fileno())


# ------------------------------------------------------------------------------------------
# optional dependencies
# ------------------------------------------------------------------------------------------
class Unsupported(Exception):
    """A curve entity curvefair cannot represent exactly (reported or skipped by the reader)."""


#: What a format's straight-line shapes are called in :class:`DrawnShapesOnly`'s message.
_DRAWN_WHAT = {
    "svg": ("straight-line shape", "polygons, polylines, lines, rectangles, subpaths of lines "
                                   "only"),
    "dxf": ("polyline", "LWPOLYLINE, 2-D and 3-D POLYLINE"),
    "3dm": ("polyline", "PolylineCurve, degree-1 NurbsCurve"),
    "font": ("contour", "straight lines only"),
}
#: How to read them anyway (fonts: no way -- a straight contour has no curve to fair).
_DRAWN_HINT = {
    "font": "a contour of straight lines has no curve to fair",
}
_POLYLINES_HINT = ("read_curves(..., polylines=True) (CLI --polylines) reads them as point "
                   "lists")


class ReadNote(UserWarning):
    """Something a reader did that the user should know but that is not a problem (a note,
    not a warning): the command line prints it as a ``Note:`` line."""


class ColumnsKept(ReadNote):
    """A points file's reader read some of its columns as coordinates and keeps the others
    (``kept``, 0-based column indices: point numbers, arc lengths, labels) as they are,
    written back character for character."""

    def __init__(self, message: str, kept: tuple[int, ...] = ()) -> None:
        super().__init__(message)
        self.kept = kept


class DrawnShapesLeft(ReadNote):
    """A drawing's reader left ``n_drawn`` straight-line shapes as drawn (not read, kept
    byte for byte on write-back) beside the curves it read: a note, so that they are not
    missed; ``polylines=True`` reads them. The command line prints it as a ``Note:``."""

    def __init__(self, message: str, n_drawn: int = 0) -> None:
        super().__init__(message)
        self.n_drawn = n_drawn


def warn_drawn(path: str | os.PathLike[str], n_drawn: int, fmt: str) -> None:
    """The :class:`DrawnShapesLeft` note of a reader that read curves and left ``n_drawn``
    straight-line shapes (nothing when there are none)."""
    if not n_drawn:
        return
    import warnings

    noun, detail = _DRAWN_WHAT[fmt]
    warnings.warn(DrawnShapesLeft(
        f"{os.fspath(path)}: {n_drawn} {noun}{'s' if n_drawn > 1 else ''} ({detail}) left as "
        f"drawn; {_POLYLINES_HINT}", n_drawn), stacklevel=4)


class DrawnShapesOnly(FileFormatError):
    """A drawing (SVG, DXF, 3dm) holding no curve but ``n_drawn`` straight-line shapes, which
    are left as drawn unless ``polylines=True``, or a font whose contours are all straight
    lines (nothing to fair); the command line writes such a file back unchanged."""

    def __init__(self, n_drawn: int, path: object, fmt: str) -> None:
        kind = "font" if fmt in ("ufo", "glyphs", "opentype") else fmt
        noun, detail = _DRAWN_WHAT[kind]
        super().__init__(
            f"no curves in the {fmt} file: its {n_drawn} {noun}"
            f"{'s are' if n_drawn > 1 else ' is'} ({detail}) left as drawn; "
            f"{_DRAWN_HINT.get(kind, _POLYLINES_HINT)}", path)
        self.n_drawn = n_drawn
        #: whether ``polylines=True`` would read the shapes (drawings; not fonts)
        self.polylines_option = kind not in _DRAWN_HINT


def planar(xyz: FloatArray) -> tuple[FloatArray, float | None]:
    """2-D points and their common z when all z are equal, else the 3-D points and None."""
    if xyz.shape[0] and np.all(xyz[:, 2] == xyz[0, 2]):
        return np.ascontiguousarray(xyz[:, :2]), float(xyz[0, 2])
    return xyz, None


def lazy_import(module: str, package: str, extra: str, what: str) -> Any:
    """Import ``module`` or raise :class:`MissingDependencyError` naming the extra."""
    try:
        return importlib.import_module(module)
    except ImportError:
        raise MissingDependencyError(package, extra, what) from None


# ------------------------------------------------------------------------------------------
# points, corners
# ------------------------------------------------------------------------------------------
def frozen_index(values: Any) -> np.ndarray:
    """An index map of a record's ``source`` (e.g. ``row_map``: file data row -> point) as a
    read-only int64 array: one machine word per row, not a Python int object each (a
    million-row file's map was 36 MB of ints and 0.15 s to build)."""
    out = np.array(values, dtype=np.int64).reshape(-1)
    out.setflags(write=False)
    return out


def check_points(pts: FloatArray, path: object,
                 lines: Sequence[int | None] | np.ndarray | None = None,
                 what: str = "point") -> None:
    """FileFormatError for NaN/inf coordinates and duplicate consecutive points.

    ``lines`` (1-based line numbers per point) makes the message name the line.
    """
    q = np.ascontiguousarray(pts, dtype=np.float64)
    if q.ndim == 1:
        q = q[:, None]
    if not q.size:
        return
    # one compiled scan (:func:`curvefair._kernels.corners.point_checks`): the first bad row
    # of each kind, the extent
    bad, big, extent, dup = _k.point_checks(q, MAX_MAGNITUDE, 4 * np.finfo(float).eps)
    if bad >= 0:
        i = int(bad)
        ln = None if lines is None else lines[i]
        raise FileFormatError(f"{what} {i} has a non-finite coordinate {pts[i].tolist()}",
                              path, ln)
    if big >= 0:
        i = int(big)
        ln = None if lines is None else lines[i]
        raise FileFormatError(f"{what} {i} has the coordinate {pts[i].tolist()}: curvefair works "
                              f"with magnitudes up to {MAX_MAGNITUDE:g} (float64 must hold the "
                              f"powers of the data its formulas take); rescale the data", path, ln)
    if pts.shape[0] > 1:
        if 0.0 < extent < MIN_EXTENT:
            raise FileFormatError(f"the {what}s span only {extent!r}: curvefair works with "
                                  f"point sets at least {MIN_EXTENT:g} across (float64 must hold "
                                  f"the powers of the data its formulas take); rescale the data",
                                  path)
        if dup >= 0:
            i = int(dup)
            ln = None if lines is None else lines[i + 1]
            where = "" if lines is None or lines[i] is None else f" (lines {lines[i]} and {ln})"
            raise FileFormatError(
                f"duplicate consecutive {what}s {i} and {i + 1}{where}: {pts[i].tolist()}",
                path, ln)


def drop_duplicates(pts: FloatArray, path: object,
                    lines: Sequence[int | None] | np.ndarray | None = None,
                    what: str = "point", tiny: float = 0.0) -> tuple[FloatArray, np.ndarray]:
    """Drop exactly-duplicate consecutive points, with a warning naming them.

    A point equal in every coordinate to the one before it carries no geometry (exporters
    write them at the joins of pieces) but makes the chord-length parameterisation singular.
    Points that are merely close stay and are refused by :func:`check_points` -- unless they
    differ by no more than ``tiny`` in every coordinate (a reader's rounding level, e.g. SVG
    relative coordinates summed in floating point): those are dropped too, and the warning
    says "equal up to rounding".

    Returns
    -------
    kept : ndarray, shape (k, dim)
        The points without the repeats.
    where : int ndarray, shape (m,)
        For every input point, the index in ``kept`` of the point it is (a dropped repeat maps
        to its twin), to write the repeat back with its twin's value.
    """
    pts = np.asarray(pts, dtype=float)
    m = pts.shape[0]
    if m < 2:
        return pts, np.arange(m)
    rep = np.r_[False, np.all(np.abs(pts[1:] - pts[:-1]) <= tiny, axis=1)]
    if not rep.any():
        return pts, np.arange(m)
    exact = bool(np.all(pts[1:][rep[1:]] == pts[:-1][rep[1:]]))
    where = np.cumsum(~rep) - 1
    drop = np.flatnonzero(rep)
    if lines is not None and lines[int(drop[0])] is not None:
        at = ", ".join(f"line {lines[int(i)]}" for i in drop[:5])
    else:
        at = ", ".join(f"{what} {int(i)}" for i in drop[:5])
    more = f" and {drop.size - 5} more" if drop.size > 5 else ""
    import warnings

    warnings.warn(f"{os.fspath(path) if path is not None else '<data>'}: dropped "  # type: ignore[call-overload]
                  f"{drop.size} {'exactly ' if exact else ''}repeated consecutive {what}(s) "
                  f"{'' if exact else '(equal up to rounding) '}({at}{more}); they are "
                  "written back with the value of the point they repeat", UserWarning,
                  stacklevel=3)
    return pts[~rep], where


def turning_angles(points: FloatArray, closed: bool) -> FloatArray:
    """Turning angle in degrees at every point, shape ``(n,)``.

    The angle between the incoming chord ``p_i - p_{i-1}`` and the outgoing chord
    ``p_{i+1} - p_i`` (0 = straight on, 180 = reversal). Open curves get 0 at both ends; a
    closed loop (first point NOT repeated) wraps around.
    """
    p = np.asarray(points, dtype=float)
    n = p.shape[0]
    out = np.zeros(n)
    if n < 3:
        return out
    if closed:
        a = p - np.roll(p, 1, axis=0)
        b = np.roll(p, -1, axis=0) - p
    else:
        a = p[1:-1] - p[:-2]
        b = p[2:] - p[1:-1]
    na = np.linalg.norm(a, axis=1)
    nb = np.linalg.norm(b, axis=1)
    cos = np.einsum("ij,ij->i", a, b) / np.maximum(na * nb, np.finfo(float).tiny)
    ang = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
    if closed:
        out[:] = ang
    else:
        out[1:-1] = ang
    return out


#: Default corner angle (degrees) of the readers: a point list turning by this much or more at
#: a point (at the scale of its noise, see :func:`corner_turning`) is split there.
DEFAULT_CORNER_ANGLE = 60.0
_NOISE_MIN_POINTS = 10
_NOISE_ALTERNATION = 0.3
_NOISE_MAX_REL = 0.01
_NOISE_CHORDS = 6.0
_NOISE_SCALES = (1.0, 2.0, 4.0)
_CORNER_PAR_MIN = 100_000  # points from which the corner search runs on two threads


_RAYLEIGH_MEDIAN = float(np.sqrt(2.0 * np.log(2.0)))  # median of a Rayleigh distribution


def noise_scale(points: FloatArray, closed: bool) -> float:
    """Estimated noise amplitude of a point list, or 0 when it does not look noisy.

    ``r_i`` is the distance of ``p_i`` from the chord ``p_{i-1} p_{i+1}``; the estimate is
    ``median(r) / 0.6745`` in the plane (the median absolute deviation of a normal
    distribution) and ``median(r) / 1.1774`` in space, where ``r`` is the length of a normal
    vector across the chord, two components (the median of a Rayleigh distribution,
    ``sqrt(2 ln 2)``): the same figure for the same noise per coordinate, about ``1.22 sigma``
    (the residual's own spread, ``sqrt(1.5) sigma`` for evenly spaced neighbours). The list
    is taken as noisy only if it has at least 10 points, the sign of the turning flips between
    at least 30 % of consecutive points (a smooth sampling flips only at its inflections, a
    convex polygon never) and the estimate is at most 1 % of the list's extent (a zigzag
    polyline drawn on purpose, e.g. a gear or a staircase outline, has larger offsets).
    """
    p = np.asarray(points, dtype=float)
    m = p.shape[0]
    if m < _NOISE_MIN_POINTS:
        return 0.0
    if p.shape[1] == 2:  # one compiled pass, the same figures bit for bit
        q = np.ascontiguousarray(p)
        ratio = np.empty(m)
        nr, flips = _k.noise_terms_2d(q, bool(closed), ratio)
        if nr == 0:
            return 0.0
        alt = flips / ((m if closed else m - 2) - 1)
        if alt < _NOISE_ALTERNATION:  # (not noisy: no median or extent needed)
            return 0.0
        sigma = float(np.median(ratio[:nr])) / 0.6745
        size = float(_k.coord_extent(q))
        if not sigma <= _NOISE_MAX_REL * size:
            return 0.0
        return sigma
    # in space: the same figures with cross products (the normal vector across the chord)
    if closed:
        a, b, c = np.roll(p, 1, 0), p, np.roll(p, -1, 0)
    else:
        a, b, c = p[:-2], p[1:-1], p[2:]
    d = c - a
    L = np.linalg.norm(d, axis=1)
    v = b - a
    cr = np.linalg.norm(np.cross(v, d), axis=1)
    ok = L > 0
    if not ok.any():
        return 0.0
    bn = np.cross(v, c - b)
    alt = float(np.mean(np.einsum("ij,ij->i", bn[1:], bn[:-1]) < 0))
    sigma = float(np.median(cr[ok] / L[ok])) / _RAYLEIGH_MEDIAN
    size = float(np.ptp(p, axis=0).max())
    if alt < _NOISE_ALTERNATION or not sigma <= _NOISE_MAX_REL * size:
        return 0.0
    return sigma


def _chord_turns(p: FloatArray, closed: bool, Lmin: float) -> FloatArray:
    """Turning angle (degrees) at every point between the chords to the nearest points before
    and after it at least ``Lmin`` away; NaN where a chord cannot reach that length before an
    end of an open list (or half-way round a closed one). Compiled
    (:func:`curvefair._kernels.corners.chord_turns_kernel`);
    :func:`curvefair._kernels.corners.chord_turns_reference` is the same search written
    plainly."""
    q = np.ascontiguousarray(p, dtype=np.float64)
    out = np.full(q.shape[0], np.nan)
    _k.chord_turns_kernel(q, bool(closed), float(Lmin), out)
    return out


def corner_turning(points: FloatArray, closed: bool) -> FloatArray:
    """Turning angle in degrees at every point, measured at the scale of the data's noise.

    Without noise (:func:`noise_scale` is 0) this is :func:`turning_angles`: the angle between
    the chords to the two neighbours. On a noisy list the two chords run from ``p_i`` to the
    nearest points before and after it that are at least ``L`` away, for ``L = 6, 12`` and
    ``24 sigma``, and the turn is the smallest of those: a turn between samples closer than
    the noise is not a corner, and the noise's share of the turn falls as ``sigma / L``, while
    a real tangent break persists at every scale. A point whose chords reach fewer than two of
    those lengths before an end of an open list gets 0 (a corner that close to an end cannot
    be told from noise), and of a run of neighbours turning by the same corner only the one
    turning most keeps its angle.
    """
    p = np.asarray(points, dtype=float)
    m = p.shape[0]
    sigma = noise_scale(p, closed)
    if sigma == 0.0:
        return turning_angles(p, closed)
    # the three lengths' turns (as _chord_turns gives them) and their minimum in one compiled
    # pass (point ranges on two threads), then the local maxima (corner_turning_reference:
    # the same by numpy, bit for bit)
    lengths = np.array([mult * _NOISE_CHORDS * sigma for mult in _NOISE_SCALES])
    q = np.ascontiguousarray(p)
    out = np.empty(m)
    ranges(partial(_k.corner_turns_range, q, bool(closed), lengths, out), 0, m, THREADS,
           _CORNER_PAR_MIN)
    _k.keep_local_maxima(out, bool(closed))
    return out


def corner_turning_reference(points: FloatArray, closed: bool) -> FloatArray:
    """:func:`corner_turning` composed in numpy from :func:`_chord_turns` at each length (the
    code :func:`curvefair._kernels.corners.corner_turns_range` and ``keep_local_maxima``
    replaced; the tests' reference)."""
    p = np.asarray(points, dtype=float)
    m = p.shape[0]
    sigma = noise_scale(p, closed)
    if sigma == 0.0:
        return turning_angles(p, closed)
    out = np.full(m, np.inf)
    reached = np.zeros(m, dtype=int)
    for mult in _NOISE_SCALES:
        ang = _chord_turns(p, closed, mult * _NOISE_CHORDS * sigma)
        ok = ~np.isnan(ang)
        out[ok] = np.minimum(out[ok], ang[ok])
        reached += ok
    out = np.where(reached >= 2, out, 0.0)
    # one corner per run of turning neighbours: keep the local maxima
    keep = np.ones(m, dtype=bool)
    prev, nxt = np.roll(out, 1), np.roll(out, -1)
    if not closed:
        prev[0], nxt[-1] = -1.0, -1.0
    keep &= (out >= prev) & (out >= nxt)
    return np.where(keep, out, 0.0)


def split_at_corners(points: FloatArray, closed: bool, corner_angle: float | None,
                     extra_corners: Sequence[int] = (),
                     min_angles: Mapping[int, float] | None = None
                     ) -> tuple[list[np.ndarray], FloatArray]:
    """Cut a point list at its corners.

    Parameters
    ----------
    points : ndarray, shape (m, dim)
        Distinct points (a closed loop does NOT repeat its first point).
    closed : bool
    corner_angle : float or None
        A point whose turning angle (:func:`corner_turning`: at the scale of the data's noise)
        is ``>= corner_angle`` degrees is a corner; None: no detection.
    extra_corners : sequence of int
        Points that are corners whatever their angle.
    min_angles : mapping of int to float, optional
        Points that are corners only from this angle on (or ``corner_angle`` if larger), e.g.
        an airfoil's leading edge.

    Returns
    -------
    pieces : list of int ndarray
        Indices into ``points`` of each piece, in order. A closed loop without corners is one
        piece ``[0, 1, ..., m-1, 0]`` (its first point repeated last, as a closed curve stores
        it); otherwise every piece runs from a corner (or end) to the next, sharing corners.
    angles : ndarray, shape (m,)
    """
    m = points.shape[0]
    angles = corner_turning(points, closed)
    is_c = np.zeros(m, dtype=bool)
    if corner_angle is not None:
        limit = np.full(m, float(corner_angle))
        for i, a in (min_angles or {}).items():
            limit[int(i) % m] = max(float(corner_angle), float(a))
        is_c |= angles >= limit
    if len(extra_corners):
        is_c[np.asarray(extra_corners, dtype=int) % m] = True
    if not closed:
        is_c[0] = is_c[-1] = False
        cuts = np.r_[0, np.flatnonzero(is_c), m - 1]
        return [np.arange(a, b + 1) for a, b in zip(cuts[:-1], cuts[1:], strict=False)], angles
    c = np.flatnonzero(is_c)
    if c.size == 0:
        return [np.r_[np.arange(m), 0]], angles
    ext = np.r_[c, c[0] + m]
    return [np.arange(a, b + 1) % m for a, b in zip(ext[:-1], ext[1:], strict=False)], angles


def points_curve(pts: FloatArray, closed_loop: bool) -> CubicHermite:
    """The curve through data points: C2 cubic, chord parameters, natural (open) or periodic.

    ``closed_loop``: ``pts`` repeats its first point last and the curve is periodic.
    """
    if closed_loop:
        return interpolate_cubic(pts, "chord", "periodic")
    return interpolate_cubic(pts, "chord", "natural")


def data_points(curve: PiecewiseCurve, what: str) -> FloatArray:
    """The data points of a Hermite curve (what a points format writes back)."""
    pts = getattr(curve, "points", None)
    if pts is None:
        raise InputError(
            f"{what}: a {type(curve).__name__} has no data points to write to a points format; "
            "write it to JSON, DXF, 3dm or SVG, or evaluate it at the parameters you want")
    return np.asarray(pts, dtype=float)


def piece_values(n_points: int, dim: int, records: Sequence[CurveRecord], what: str,
                 closed_loop_dup: bool = False) -> FloatArray:
    """Assemble the written points of a split point list from its records.

    Every record has ``source["indices"]`` (indices into the assembled list of ``n_points``
    points) and a curve with matching data points. Points shared by two pieces (corners) take
    the value of the first piece that has them.
    """
    out = np.full((n_points, dim), np.nan)
    for rec in records:
        idx = np.asarray(rec.source["indices"], dtype=int)
        pts = data_points(rec.curve, what)
        if pts.shape != (idx.shape[0], dim):
            raise InputError(
                f"{what}: record {rec.source.get('index')} ({rec.name!r}) must have "
                f"{idx.shape[0]} data points of dimension {dim} (the number read), got "
                f"{pts.shape[0]} of dimension {pts.shape[1]}")
        fresh = np.isnan(out[idx, 0])
        out[idx[fresh]] = pts[fresh]
    missing = np.flatnonzero(np.isnan(out[:, 0]))
    if missing.size:
        raise InputError(f"{what}: no record gives point {int(missing[0])} of the source; pass "
                         "every record read from the file")
    return out


def bspline_from_data(control_points: ArrayLike, knots: ArrayLike, degree: int,
                      closed: bool) -> BSplineCurve:
    return BSplineCurve(control_points, knots, degree, closed=closed)


def curve_kind(curve: PiecewiseCurve) -> str:
    """The record kind of a bare curve."""
    if isinstance(curve, BSplineCurve):
        return "bspline"
    if isinstance(curve, QuinticHermite):
        return "quintic_hermite"
    if isinstance(curve, CubicHermite):
        return "cubic_hermite"
    raise InputError(f"unsupported curve type {type(curve).__name__}")


def bezier_pieces(curve: PiecewiseCurve, what: str, max_degree: int | None = None
                  ) -> FloatArray:
    """Bezier control points of every polynomial piece, shape ``(m, p+1, dim)``.

    ``p`` is the curve's degree, or ``max_degree`` when given (lower degrees are elevated;
    a higher degree raises :class:`InputError`).

    Notes
    -----
    From the local power form ``r = sum_j a_j s^j`` on ``s in [0, h]``, with ``c_j = a_j h^j``:
    ``b_k = sum_{j<=k} C(k, j) / C(p, j) c_j`` (the power-to-Bernstein change of basis).
    """
    from math import comb

    pp = curve.piecewise
    p = pp.degree if max_degree is None else int(max_degree)
    if pp.degree > p:
        raise InputError(f"{what}: a degree-{pp.degree} curve has no exact degree-{p} Bezier "
                         "form; fair a cubic curve, or write it to JSON/DXF/3dm")
    c = np.zeros((pp.n_segments, p + 1, pp.dim))
    c[:, : pp.degree + 1] = pp.coeffs
    c *= (pp.widths[:, None] ** np.arange(p + 1)[None, :])[:, :, None]
    M = np.array([[comb(k, j) / comb(p, j) if j <= k else 0.0 for j in range(p + 1)]
                  for k in range(p + 1)])
    return np.einsum("kj,mjd->mkd", M, c)


def bspline_of(curve: PiecewiseCurve, what: str) -> BSplineCurve:
    """``curve`` as a B-spline: itself, or (Hermite curves) the same curve exactly with a knot
    at every break of multiplicity ``degree - 1 - continuity`` + 1 (cubic Hermite: C1, double
    knots; quintic Hermite: C2, triple knots), falling back to Bezier knots (multiplicity
    ``degree``) if the curve is not that smooth."""
    if isinstance(curve, BSplineCurve):
        return curve
    b = bezier_pieces(curve, what)
    m, p1, _ = b.shape
    p = p1 - 1
    if p < 2:
        raise InputError(f"{what}: a degree-{p} curve is not a B-spline of degree >= 2")
    br = np.asarray(curve.piecewise.breaks, dtype=float)
    cont = {3: 1, 5: 2}.get(p, 0)
    if cont and m > 1:
        smooth = _smooth_bspline(curve, br, p, p - cont)
        if smooth is not None:
            return smooth
    ctrl = np.vstack([b[0, :1]] + [b[i, 1:] for i in range(m)])
    knots = np.r_[[br[0]] * (p + 1), np.repeat(br[1:-1], p), [br[-1]] * (p + 1)]
    return BSplineCurve(ctrl, knots, p, closed=False)


def _smooth_bspline(curve: PiecewiseCurve, br: FloatArray, p: int,
                    mult: int) -> BSplineCurve | None:
    """The clamped B-spline with interior knots ``br[1:-1]`` of multiplicity ``mult`` equal
    to ``curve`` (least squares on p+1 points per span, checked), or None."""
    from scipy.interpolate import BSpline

    knots = np.r_[[br[0]] * (p + 1), np.repeat(br[1:-1], mult), [br[-1]] * (p + 1)]
    s = (np.arange(p + 1) + 0.5) / (p + 1)
    x = (br[:-1, None] + np.diff(br)[:, None] * s[None, :]).reshape(-1)
    x = np.r_[br[0], x, br[-1]]
    y = curve(x)
    A = BSpline.design_matrix(x, knots, p).toarray()
    c, *_ = np.linalg.lstsq(A, y, rcond=None)
    c[0], c[-1] = y[0], y[-1]
    out = BSplineCurve(c, knots, p)
    u = np.linspace(br[0], br[-1], 8 * (br.shape[0] - 1) + 1)
    scale = max(float(np.abs(y).max()), 1.0)
    if float(np.abs(out(u) - curve(u)).max()) <= 1e-10 * scale:
        return out
    return None


def is_clamped(knots: FloatArray, degree: int) -> bool:
    p = degree
    return bool(np.all(knots[: p + 1] == knots[0]) and np.all(knots[-p - 1:] == knots[-1]))


def same_path(a: object, b: object) -> bool:
    """True when two paths name the same existing file."""
    try:
        return os.path.samefile(os.fspath(a), os.fspath(b))  # type: ignore[call-overload]
    except (OSError, TypeError):
        return False


def point_records(points: FloatArray, *, closed: bool, corner_angle: float | None,
                  kind: str, name: str | None, source: Mapping[str, Any],
                  end_corners: bool = False, first_index: int = 0,
                  min_angles: Mapping[int, float] | None = None) -> list[CurveRecord]:
    """Records of one point list: split at corners, each piece a curve through its points.

    Parameters
    ----------
    points : ndarray, shape (m, dim)
        Distinct points in order (a closed loop does not repeat its first point).
    closed : bool
        The list is a closed loop.
    end_corners : bool
        The first and last points are corners too (an airfoil's trailing edge).
    min_angles : mapping of int to float, optional
        Points split only from this corner angle on (:func:`split_at_corners`).
    source : mapping
        Common source keys; each record adds ``"indices"`` (into ``points``; a read-only
        int64 array), ``"n_points"``
        (``m``), ``"closed"``, ``"piece"``, ``"n_pieces"``, ``"index"``.
    first_index : int
        ``source["index"]`` of the first record.
    """
    m = points.shape[0]
    pieces, _ = split_at_corners(points, closed, corner_angle, min_angles=min_angles)
    loop = closed and len(pieces) == 1
    is_corner = np.zeros(m, dtype=bool)
    if len(pieces) > 1:
        for idx in pieces:
            is_corner[idx[0]] = is_corner[idx[-1]] = True
        if not closed:
            is_corner[0] = is_corner[-1] = False
    if end_corners and not closed:
        is_corner[0] = is_corner[-1] = True
    records = []
    for k, idx in enumerate(pieces):
        pts = points[idx]
        curve = points_curve(pts, loop)
        corners = tuple(int(j) for j in np.flatnonzero(is_corner[idx]) if not loop)
        src = dict(source)
        src.update(index=first_index + k, n_points=m,
                   indices=readonly(np.asarray(idx, dtype=np.int64)),  # not a million ints
                   closed=bool(closed), piece=k, n_pieces=len(pieces))
        pname = name if len(pieces) == 1 or name is None else f"{name} [{k}]"
        records.append(CurveRecord(curve, pname, kind, src, pts, corners))
    return records


def joined_points(records: Sequence[CurveRecord], what: str) -> FloatArray:
    """The points of one point list, from its records (pieces joined again) or one curve.

    Records that were split from one list (``source["indices"]``) are joined; a closed loop
    comes back with its first point repeated last.
    """
    paths = {(r.path, r.format) for r in records}
    if len(paths) == 1 and all("indices" in r.source for r in records):
        n = int(records[0].source["n_points"])
        dim = data_points(records[0].curve, what).shape[1]
        pts = piece_values(n, dim, records, what)
        if records[0].source.get("closed"):
            pts = np.vstack([pts, pts[:1]])
        return pts
    if len(records) != 1:
        raise InputError(f"{what}: a point file holds one point list, got {len(records)} "
                         "curves (write each to its own file, or use JSON)")
    return data_points(records[0].curve, what)
