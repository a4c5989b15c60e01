"""One validator per family of inputs (see STYLE.md item 4).

Each function converts to float64, checks finiteness and shape, and raises
:class:`curvefair.errors.InputError` naming the argument and the offending index.

Working range
-------------
Every number curvefair accepts lies in a fixed magnitude window, so that the powers its
formulas take stay finite and normal in float64 (``1e-308 .. 1e308``): on a polynomial piece of
parameter width ``D`` over coordinates ``x`` the derivative of order ``k`` is ``~ x / D^k``
(quintic power coefficient ``a_5 ~ x / D^5``, cubic Gram matrices of the 3rd derivative
``~ 1 / D^5``), and the energies square it before multiplying by ``D``. With

- coordinates: ``|x| <= MAX_MAGNITUDE = 1e30`` and, unless every point is the same, an extent
  (largest coordinate range) ``>= MIN_EXTENT = 1e-20`` (chord-length parameter steps of such
  data stay above ``MIN_STEP`` up to ~1e4 points; more need coarser units);
- parameters and knots: ``|t| <= 1e30`` and every non-zero step ``>= MIN_STEP = 1e-24``;
- derivative data (tangents, second derivatives): ``|v| <= MAX_DERIVATIVE = 1e60``;
- tolerances and other lengths (``window=True`` in :func:`as_positive`,
  :func:`as_nonnegative`): ``0`` (where allowed) or ``1e-24 .. 1e30``;

``x / D^5 <= 1e30 / 1e-120 = 1e150``, so even the 5th-derivative energy of a quintic
(``(x / D^5)^2 <= 1e300``) stays finite. Larger or smaller data are refused with an
:class:`~curvefair.errors.InputError` that says to rescale (change units): a rescaling by a
power of two is exact and changes no result but by that factor. What still overflows (the
power form or an energy of a high-degree B-spline near the smallest steps) is refused where it
is computed, never returned as inf or NaN.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Sequence
from typing import Literal, cast, overload

import numpy as np

from ._typing import ArrayLike, FloatArray
from .errors import InputError

__all__ = ["as_points", "as_vectors", "as_params", "as_positive", "choice", "check_finite",
           "as_nonnegative", "as_step_count", "as_count", "as_eval_params", "check_magnitude",
           "magnitude", "MAX_MAGNITUDE", "MIN_EXTENT", "MIN_STEP", "MAX_STEPS", "as_float"]

#: Largest accepted magnitude of a coordinate, parameter, knot or tolerance.
MAX_MAGNITUDE = 1e30
#: Largest accepted magnitude of given derivative data (tangents, second derivatives).
MAX_DERIVATIVE = MAX_MAGNITUDE**2
#: Smallest accepted extent (largest coordinate range) of a set of points that are not all equal.
MIN_EXTENT = 1e-20
#: Smallest accepted non-zero step between parameters or knots, and smallest positive scalar.
MIN_STEP = 1e-24
#: Step counts above this mean the same as this (no run can take 2**62 steps); it keeps every
#: count a valid int64 in the compiled loops, with room for ``max_steps + 1``.
MAX_STEPS = 2**62

_RESCALE = "rescale the data (change units; scaling by a power of 2 is exact)"


def check_finite(arr: FloatArray, name: str) -> None:
    """Raise if ``arr`` contains NaN or inf, naming the first bad index."""
    bad = ~np.isfinite(arr)
    if bad.any():
        idx = np.argwhere(bad)[0]
        where = tuple(int(i) for i in idx)
        if arr.ndim == 2:
            where_s = f"row {where[0]} (column {where[1]})"
        else:
            where_s = f"index {where[0] if len(where) == 1 else where}"
        raise InputError(f"{name} contains a non-finite value {arr[tuple(idx)]!r} at {where_s}")


def magnitude(arr: FloatArray) -> float:
    """``max |arr|``, at least the smallest normal float: the scale for relative closeness
    tests (``|a - b| <= rtol * magnitude``). No floor at 1: data of size 1e-20 compare at
    their own scale, not as if they were all one point."""
    if arr.size == 0:
        return float(np.finfo(float).tiny)
    return max(float(arr.max()), -float(arr.min()), float(np.finfo(float).tiny))


def check_magnitude(arr: FloatArray, name: str, limit: float = MAX_MAGNITUDE) -> None:
    """Raise if a finite ``arr`` has a value of magnitude above ``limit`` (the working range,
    see the module docstring), naming the first such index."""
    if arr.size == 0:
        return
    if max(float(arr.max()), -float(arr.min())) <= limit:
        return
    idx = np.argwhere(np.abs(arr) > limit)[0]
    where = tuple(int(i) for i in idx)
    where_s = (f"row {where[0]} (column {where[1]})" if arr.ndim == 2 else
               f"index {where[0] if len(where) == 1 else where}")
    raise InputError(f"{name} has the value {float(arr[tuple(idx)])!r} at {where_s}: curvefair "
                     f"works with magnitudes up to {limit:g} (float64 must hold the powers of "
                     f"the data its formulas take); {_RESCALE}")


def _refuse_kind(a: np.ndarray, name: str) -> None:
    kind = a.dtype.kind
    if kind == "c":
        raise InputError(f"{name} must be real numbers, got complex values (dtype {a.dtype}); "
                         "pass the real part (or the coordinates as columns) explicitly")
    if kind == "b":
        raise InputError(f"{name} must be numbers, got booleans (dtype {a.dtype})")
    if kind in "USVMm":
        raise InputError(f"{name} must be numbers, got dtype {a.dtype}")
    if kind == "O":
        for v in a.flat:
            if isinstance(v, (str, bytes, bool, np.bool_)) or np.iscomplexobj(v):
                raise InputError(f"{name} must be real numbers, got {v!r} "
                                 f"({type(v).__name__})")


def as_float(x: ArrayLike, name: str, *, copy: bool = True) -> FloatArray:
    """A float64 copy of ``x``; complex, boolean, string and date values are refused (a complex
    value would lose its imaginary part, a string would be parsed). ``copy=False``: ``x``
    itself when it is a float64 array (for a caller that only reads it, or freezes its own
    copy afterwards, as the curves do)."""
    try:
        a = np.asarray(x)
        _refuse_kind(a, name)
        arr = np.array(a, dtype=np.float64, copy=True) if copy else \
            np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError, OverflowError) as exc:
        if isinstance(exc, InputError):
            raise
        raise InputError(f"{name} cannot be converted to a float array: {exc}") from None
    return arr


def as_points(
    points: ArrayLike,
    name: str = "points",
    *,
    min_points: int = 2,
    dims: Sequence[int] = (2, 3),
    allow_coincident: bool = False,
    closed_ok: bool = True,
    copy: bool = True,
) -> FloatArray:
    """Validate an ``(n, dim)`` point array; return a float64 copy (``copy=False``: the
    array itself if it is float64, see :func:`as_float`).

    Parameters
    ----------
    points : array_like, shape (n, dim)
    name : str
        Argument name used in messages.
    min_points : int
        Smallest acceptable ``n``.
    dims : sequence of int
        Acceptable dimensions.
    allow_coincident : bool
        If False, two consecutive equal points raise (a zero chord breaks every parameterisation).
    closed_ok : bool
        Ignored for consecutive checks: first == last is never "consecutive".
    copy : bool
        False: no copy of a float64 array (the caller only reads it or copies it itself).
    """
    arr = as_float(points, name, copy=copy)
    if arr.ndim != 2:
        raise InputError(f"{name} must be a 2-D array of shape (n, dim), got shape {arr.shape}")
    n, dim = arr.shape
    if dim not in dims:
        raise InputError(
            f"{name} must have {' or '.join(map(str, dims))} columns (the dimension), got {dim}"
        )
    if n < min_points:
        raise InputError(f"{name} needs at least {min_points} points, got {n}")
    check_points_range(arr, name)
    if not allow_coincident and n > 1:
        # largest coordinate step per chord, one column at a time (a reduction across the
        # short axis of an (n, dim) array is much slower); the same maxima
        step = np.abs(arr[1:, 0] - arr[:-1, 0])
        for j in range(1, dim):
            np.maximum(step, np.abs(arr[1:, j] - arr[:-1, j]), out=step)
        scale = max(float(arr.max()), -float(arr.min()), np.finfo(float).tiny)
        bad = np.flatnonzero(step <= 4 * np.finfo(float).eps * scale)
        if bad.size:
            i = int(bad[0])
            raise InputError(
                f"{name} has coincident consecutive points at indices {i} and {i + 1} "
                f"({arr[i].tolist()}): remove the duplicate"
            )
    return arr


def check_points_range(arr: FloatArray, name: str) -> None:
    """Finite, magnitude ``<= MAX_MAGNITUDE`` and, unless all points are equal, an extent
    (largest per-coordinate range) ``>= MIN_EXTENT`` (see the module docstring). Whole-array
    and per-column minima and maxima (NaN propagates through them), no full-size temporaries
    (numpy's ``max(axis=0)`` on an ``(n, 2)`` array reduces across the short axis, which is
    much slower than a contiguous reduction per column)."""
    if arr.size == 0:
        return
    hi_all = float(arr.max())
    lo_all = float(arr.min())
    if not (np.isfinite(hi_all) and np.isfinite(lo_all)):
        check_finite(arr, name)
    if max(hi_all, -lo_all) > MAX_MAGNITUDE:
        check_magnitude(arr, name)
    if hi_all - lo_all >= MIN_EXTENT and arr.ndim == 2 and arr.shape[1] > 1:
        extent = max(float(arr[:, j].max()) - float(arr[:, j].min())
                     for j in range(arr.shape[1]))
    else:
        extent = hi_all - lo_all
    if 0.0 < extent < MIN_EXTENT:
        raise InputError(f"{name} spans only {extent!r} (the largest coordinate range): "
                         f"curvefair works with point sets at least {MIN_EXTENT:g} across "
                         f"(float64 must hold the powers of the data its formulas take); "
                         f"{_RESCALE}")


def check_steps(arr: FloatArray, name: str, *, strict: bool) -> None:
    """A finite, sorted 1-D ``arr`` (parameters, knots): magnitude ``<= MAX_MAGNITUDE``, steps
    ``> 0`` (``strict``) or ``>= 0``, every non-zero step ``>= MIN_STEP``."""
    check_finite(arr, name)
    check_magnitude(arr, name)
    if arr.shape[0] < 2:
        return
    dt = np.diff(arr)
    bad = np.flatnonzero(dt <= 0) if strict else np.flatnonzero(dt < 0)
    if bad.size:
        i = int(bad[0])
        rel = "strictly increasing" if strict else "non-decreasing"
        op = ">=" if strict else ">"
        raise InputError(f"{name} must be {rel}: {name}[{i}] = {float(arr[i])!r} {op} "
                         f"{name}[{i + 1}] = {float(arr[i + 1])!r}")
    small = np.flatnonzero((dt > 0) & (dt < MIN_STEP))
    if small.size:
        i = int(small[0])
        raise InputError(f"{name}[{i + 1}] - {name}[{i}] = {float(dt[i])!r} is below the "
                         f"smallest supported step {MIN_STEP:g} (float64 must hold the powers "
                         f"of the steps the formulas take); rescale the parameters")


def as_vectors(vectors: ArrayLike, shape: tuple[int, ...], name: str, *,
               copy: bool = True) -> FloatArray:
    """Validate an array of the exact ``shape`` (e.g. tangents matching points); float64 copy
    (``copy=False``: see :func:`as_float`).

    Derivative data are bounded by ``MAX_DERIVATIVE = 1e60`` (about a coordinate of ``1e30``
    over the smallest parameter step): the power coefficients and energies built from them
    stay finite (see the module docstring)."""
    arr = as_float(vectors, name, copy=copy)
    if arr.shape != tuple(shape):
        raise InputError(f"{name} must have shape {tuple(shape)}, got {arr.shape}")
    check_finite(arr, name)
    check_magnitude(arr, name, MAX_DERIVATIVE)
    return arr


def as_params(params: ArrayLike, n: int, name: str = "params", *,
              copy: bool = True) -> FloatArray:
    """Validate a strictly increasing parameter vector of length ``n``; float64 copy
    (``copy=False``: see :func:`as_float`)."""
    arr = as_float(params, name, copy=copy)
    if arr.ndim != 1:
        raise InputError(f"{name} must be 1-D, got shape {arr.shape}")
    if arr.shape[0] != n:
        raise InputError(f"{name} must have {n} values (one per point), got {arr.shape[0]}")
    check_steps(arr, name, strict=True)
    return arr


def as_eval_params(u: ArrayLike, name: str = "u") -> FloatArray:
    """Parameters at which to evaluate a curve (any shape): real, finite, float64."""
    if isinstance(u, np.ndarray) and u.dtype == np.float64:
        arr = u
    else:
        try:
            a = np.asarray(u)
            _refuse_kind(a, name)
            arr = np.asarray(a, dtype=np.float64)
        except (TypeError, ValueError, OverflowError) as exc:
            if isinstance(exc, InputError):
                raise
            raise InputError(f"{name} must be real numbers: {exc}") from None
    if not np.isfinite(arr).all():
        check_finite(arr if arr.ndim else arr.reshape(1), name)
    return arr


def as_count(value: object, name: str, *, minimum: int = 0, maximum: int | None = None) -> int:
    """A whole number in ``[minimum, maximum]``; bools and non-integers are refused."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InputError(f"{name} must be an integer >= {minimum}, got {value!r}")
    v = int(value)
    if v < minimum or (maximum is not None and v > maximum):
        rng = f">= {minimum}" if maximum is None else f"in [{minimum}, {maximum}]"
        raise InputError(f"{name} must be an integer {rng}, got {value!r}")
    return v


#: Highest supported B-spline degree (as OCCT's ``Geom_BSplineCurve::MaxDegree()``): the power
#: form and the basis derivatives take powers of the knot steps up to the degree, and Gram
#: matrices up to ``2 degree - 1``.
MAX_DEGREE = 25


def as_degree(degree: object) -> int:
    """A B-spline degree: an integer from 2 to :data:`MAX_DEGREE` (the check every builder and
    fitter of B-splines applies to its ``degree`` argument)."""
    return as_count(degree, "degree", minimum=2, maximum=MAX_DEGREE)


def physical_memory() -> int | None:
    """Bytes of physical memory of this machine, or None where the OS does not say."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError):
        return None


def check_fits(n_bytes: float, what: str) -> None:
    """Refuse an allocation of ``n_bytes`` (with its temporaries) that cannot fit in this
    machine's memory, with an InputError naming ``what`` (numpy would raise MemoryError after
    trying, or the OS would kill the process)."""
    mem = physical_memory()
    if mem is not None and n_bytes > mem:
        raise InputError(f"{what} needs about {n_bytes / 2**30:.3g} GiB, more than this "
                         f"machine's {mem / 2**30:.3g} GiB of memory")


def _as_scalar(value: object, name: str, what: str) -> float:
    if isinstance(value, (bool, np.bool_, str, bytes)) or np.iscomplexobj(cast(ArrayLike, value)):
        raise InputError(f"{name} must be {what}, got {value!r}")
    try:
        return float(value)  # type: ignore[arg-type]
    except OverflowError:
        raise InputError(f"{name} must be {what} within the float64 range (and curvefair's "
                         f"working range [{MIN_STEP:g}, {MAX_MAGNITUDE:g}]), got an integer "
                         f"with {len(str(abs(int(cast(int, value)))))} digits") from None
    except (TypeError, ValueError):
        raise InputError(f"{name} must be {what}, got {value!r}") from None


def _check_window(v: float, value: object, name: str) -> None:
    if v != 0.0 and not MIN_STEP <= v <= MAX_MAGNITUDE:
        raise InputError(f"{name} = {value!r} is outside the working range [{MIN_STEP:g}, "
                         f"{MAX_MAGNITUDE:g}] of curvefair (float64 must hold the powers its "
                         f"formulas take, e.g. {name}**2); {_RESCALE}")


@overload
def as_positive(value: object, name: str, *, allow_none: Literal[False] = False,
                window: bool = False) -> float: ...
@overload
def as_positive(value: object, name: str, *, allow_none: bool = False,
                window: bool = False) -> float | None: ...
def as_positive(value: object, name: str, *, allow_none: bool = False,
                window: bool = False) -> float | None:
    """A finite float > 0 (or None when allowed); ``window``: a length (tolerance, scale)
    within the working range ``[MIN_STEP, MAX_MAGNITUDE]`` (see the module docstring)."""
    if value is None:
        if allow_none:
            return None
        raise InputError(f"{name} is required")
    v = _as_scalar(value, name, "a number")
    if not np.isfinite(v) or v <= 0:
        raise InputError(f"{name} must be a finite number > 0, got {value!r}")
    if window:
        _check_window(v, value, name)
    return v


#: End conditions of ``clamp`` (case-insensitive; ``None`` is ``"none"``): ``"none"`` leaves the
#: end free, ``"g0"`` keeps the end point, ``"g1"`` also the end tangent, ``"g2"`` also the end
#: curvature.
CLAMP_VALUES = ("none", "g0", "g1", "g2")


def parse_clamp(clamp: object, name: str = "clamp") -> tuple[str, str]:
    """The one grammar of ``clamp``, for :func:`curvefair.fair` and every method function.

    ``clamp`` is one end condition for both ends or a ``(left, right)`` pair; each is ``None``
    or one of :data:`CLAMP_VALUES`, in any case (``"G1"`` is ``"g1"``). Returns the pair in
    lower case, ``None`` as ``"none"``.

    Raises
    ------
    InputError
        Naming ``name`` (and the end) for anything else.
    """
    if clamp is None or isinstance(clamp, str):
        pair: tuple[object, object] = (clamp, clamp)
    else:
        left: object
        right: object
        try:
            left, right = clamp  # type: ignore[misc]
        except (TypeError, ValueError):
            raise InputError(f"{name} must be one of {CLAMP_VALUES} (any case) or None, or a "
                             f"(left, right) pair of them, got {clamp!r}") from None
        pair = (left, right)
    out = []
    for side, v in zip(("left", "right"), pair, strict=True):
        key = "none" if v is None else (v.lower() if isinstance(v, str) else v)
        if key not in CLAMP_VALUES:
            raise InputError(f"unknown {name} {v!r} ({side} end); valid values are: None, "
                             + ", ".join(repr(c) for c in CLAMP_VALUES) + " (any case)")
        out.append(str(key))
    return out[0], out[1]


def choice(value: object, valid: Iterable[str], name: str) -> str:
    """Check a string option; the error lists the valid names."""
    valid = list(valid)
    if not isinstance(value, str) or value not in valid:
        raise InputError(
            f"unknown {name} {value!r}; valid values are: {', '.join(repr(v) for v in valid)}"
        )
    return value


def as_nonnegative(value: object, name: str, *, none_means: float | None = None,
                   window: bool = False) -> float:
    """A finite float >= 0; ``None`` returns ``none_means`` (an error if that is None too);
    ``window``: 0 or a length within the working range ``[MIN_STEP, MAX_MAGNITUDE]``."""
    if value is None:
        if none_means is None:
            raise InputError(f"{name} is required")
        return none_means
    alt = "" if none_means is None else " or None"
    v = _as_scalar(value, name, f"a number >= 0{alt}")
    if not np.isfinite(v) or v < 0:
        raise InputError(f"{name} must be a finite number >= 0{alt}, got {value!r}")
    if window:
        _check_window(v, value, name)
    return v


def as_step_count(value: object, name: str = "max_steps", *, default: int) -> int:
    """A whole number >= 0 (``None`` gives ``default``); bools are refused. Counts above
    :data:`MAX_STEPS` (``2**62``) mean the same as ``MAX_STEPS``: no run reaches it, and the
    compiled loops need an int64."""
    if value is None:
        return min(int(default), MAX_STEPS)
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
        raise InputError(f"{name} must be an integer >= 0, got {value!r}")
    return min(int(value), MAX_STEPS)
