"""One validator per family of inputs (see STYLE.md item 4).

Each function converts to float64, checks finiteness and shape, and raises
:class:`curvefair.errors.InputError` naming the argument and the offending index.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np

from ._typing import ArrayLike, FloatArray
from .errors import InputError

__all__ = ["as_points", "as_vectors", "as_params", "as_positive", "choice", "check_finite"]


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


def _as_float(x: ArrayLike, name: str) -> FloatArray:
    try:
        arr = np.array(x, dtype=np.float64, copy=True)
    except (TypeError, ValueError) as exc:
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
) -> FloatArray:
    """Validate an ``(n, dim)`` point array; return a float64 copy.

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
    """
    arr = _as_float(points, name)
    if arr.ndim != 2:
        raise InputError(f"{name} must be a 2-D array of shape (n, dim), got shape {arr.shape}")
    n, dim = arr.shape
    if dim not in dims:
        raise InputError(
            f"{name} must have {' or '.join(map(str, dims))} columns (the dimension), got {dim}"
        )
    if n < min_points:
        raise InputError(f"{name} needs at least {min_points} points, got {n}")
    check_finite(arr, name)
    if not allow_coincident and n > 1:
        d = np.abs(np.diff(arr, axis=0)).max(axis=1)
        scale = max(float(np.abs(arr).max()), np.finfo(float).tiny)
        bad = np.flatnonzero(d <= 4 * np.finfo(float).eps * scale)
        if bad.size:
            i = int(bad[0])
            raise InputError(
                f"{name} has coincident consecutive points at indices {i} and {i + 1} "
                f"({arr[i].tolist()}): remove the duplicate"
            )
    return arr


def as_vectors(vectors: ArrayLike, shape: tuple[int, ...], name: str) -> FloatArray:
    """Validate an array of the exact ``shape`` (e.g. tangents matching points); float64 copy."""
    arr = _as_float(vectors, name)
    if arr.shape != tuple(shape):
        raise InputError(f"{name} must have shape {tuple(shape)}, got {arr.shape}")
    check_finite(arr, name)
    return arr


def as_params(params: ArrayLike, n: int, name: str = "params") -> FloatArray:
    """Validate a strictly increasing parameter vector of length ``n``; float64 copy."""
    arr = _as_float(params, name)
    if arr.ndim != 1:
        raise InputError(f"{name} must be 1-D, got shape {arr.shape}")
    if arr.shape[0] != n:
        raise InputError(f"{name} must have {n} values (one per point), got {arr.shape[0]}")
    check_finite(arr, name)
    if n > 1:
        dt = np.diff(arr)
        bad = np.flatnonzero(dt <= 0)
        if bad.size:
            i = int(bad[0])
            raise InputError(
                f"{name} must be strictly increasing: {name}[{i}] = {arr[i]!r} "
                f">= {name}[{i + 1}] = {arr[i + 1]!r}"
            )
    return arr


def as_positive(value: object, name: str, *, allow_none: bool = False) -> float | None:
    """A finite float > 0 (or None when allowed)."""
    if value is None:
        if allow_none:
            return None
        raise InputError(f"{name} is required")
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number, got {value!r}") from None
    if not np.isfinite(v) or v <= 0:
        raise InputError(f"{name} must be a finite number > 0, got {value!r}")
    return v


def choice(value: object, valid: Iterable[str], name: str) -> str:
    """Check a string option; the error lists the valid names."""
    valid = list(valid)
    if not isinstance(value, str) or value not in valid:
        raise InputError(
            f"unknown {name} {value!r}; valid values are: {', '.join(repr(v) for v in valid)}"
        )
    return value


def as_nonnegative(value: object, name: str, *, none_means: float | None = None) -> float:
    """A finite float >= 0; ``None`` returns ``none_means`` (an error if that is None too)."""
    if value is None:
        if none_means is None:
            raise InputError(f"{name} is required")
        return none_means
    alt = "" if none_means is None else " or None"
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number >= 0{alt}, got {value!r}") from None
    if not np.isfinite(v) or v < 0:
        raise InputError(f"{name} must be a finite number >= 0{alt}, got {value!r}")
    return v


def as_step_count(value: object, name: str = "max_steps", *, default: int) -> int:
    """A whole number >= 0 (``None`` gives ``default``); bools are refused."""
    if value is None:
        return int(default)
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
        raise InputError(f"{name} must be an integer >= 0, got {value!r}")
    return int(value)
