"""The one contract between :func:`curvefair.fair` and the fairing methods.

:func:`make_problem` is the only parser of the options every method shares. It turns them into
a :class:`FairingProblem`:

- ``tol``: a float, ``inf`` for "no tolerance" (``None`` at the surface); ``0`` is refused
  (nothing could move: use ``protect`` or ``max_steps=0``);
- ``eps``: one meaning for every method, *relative to the method's initial fairness measure*
  (see :func:`eps_threshold`), or None for the method's default;
- ``max_steps``: an int, or None for the method's default;
- ``clamp``: a ``(left, right)`` pair of ``"none" | "g0" | "g1" | "g2"``
  (:func:`curvefair._validate.parse_clamp`), ``protect`` a frozenset of data-point indices,
  and :attr:`FairingProblem.fixed`, the mask of data points that never move;
- the method's own options.

Each method is a *solver* of that problem: ``solve(problem, **options) -> Outcome``; the
public method functions (``eck_hadenfeld_fair``, ``knot_removal_fair``, ``global_fair``,
``cheng_yu_driver``) build the same problem and call the same solver.

The meaning of ``eps`` per method (the reference ``R`` in ``threshold = eps * R``):

=================  =============================================  ===============================
method             ranking measure compared with the threshold     ``R`` (initial measure)
=================  =============================================  ===============================
Hermite methods    the method's bad-point measure (jump, energy)   its largest value on the input
eck-hadenfeld      ranking number ``z_r`` (exact energy drop)      ``E_l`` of the input
knot-removal       the jump measure of the knots                    its largest value on the input
global             total complementarity ``sum lambda_i s_i``      ``E_l`` of the input
cheng-yu           ``z_i = D_i**2`` (second discrete curvature)    indicator ``x = sum D_i**2``
=================  =============================================  ===============================

The report of :func:`~curvefair.fair` gives both ``eps`` and ``eps_absolute`` (the threshold).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from .._validate import as_nonnegative, as_positive, as_step_count, parse_clamp
from ..curves.bspline import BSplineCurve
from ..curves.piecewise import PiecewiseCurve, readonly
from ..errors import InputError
from .stop import StopReason

__all__ = [
    "FairingProblem",
    "FairingHistory",
    "Outcome",
    "HistoryIndex",
    "make_problem",
    "normalize_protect",
    "fixed_mask",
    "eps_threshold",
    "CLAMP_POINTS",
    "check_bspline",
]

#: What :attr:`FairingHistory.index` counts.
HistoryIndex = Literal["data point", "control point", "knot"]

#: Control points a B-spline clamp fixes at an end: ``m + 1`` fixed points keep ``C^m``
#: contact (ERRATA, Eck & Hadenfeld).
CLAMP_POINTS = {"none": 0, "g0": 1, "g1": 2, "g2": 3}


def check_bspline(curve: object, name: str = "curve") -> BSplineCurve:
    """``curve`` if it is a :class:`~curvefair.BSplineCurve` (the B-spline methods' argument
    check), else an :class:`~curvefair.InputError` naming ``name``."""
    if not isinstance(curve, BSplineCurve):
        raise InputError(f"{name} must be a BSplineCurve, got {type(curve).__name__}")
    return curve


def _finite_or_none(v: Any) -> Any:
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


@dataclass(frozen=True, eq=False)
class FairingHistory:
    """What each step of a fairing loop did, as compact arrays (one entry per step).

    Attributes
    ----------
    step : ndarray of int64, shape (s,)
        Step number, 1-based (``1 .. s``: made when first read, not stored with the run; at
        ten million steps it is 80 MB).
    index : ndarray of int64, shape (s,)
        What the step worked on, 0-based; :attr:`counts` says what that is.
    measure : ndarray of float64, shape (s,)
        Its ranking measure just before the move (e.g. the third-derivative jump); 0 for a
        simultaneous solve (global, points-l1), which ranks nothing.
    displacement : ndarray of float64, shape (s,)
        Length of that move.
    counts : {"data point", "control point", "knot"}
        What ``index`` counts: a data point (Hermite methods), a control point (B-spline
        methods), or a knot ``j`` of the knot vector (knot removal).
    """

    index: np.ndarray
    measure: np.ndarray
    displacement: np.ndarray
    counts: HistoryIndex = "data point"

    @classmethod
    def from_arrays(cls, index: Iterable[int], measure: Iterable[float],
                    displacement: Iterable[float],
                    counts: HistoryIndex = "data point") -> "FairingHistory":
        """Build from per-step arrays; step numbers are ``1 .. len(index)``."""
        idx = np.asarray(index, dtype=np.int64).reshape(-1)
        meas = np.asarray(measure, dtype=np.float64).reshape(-1)
        disp = np.asarray(displacement, dtype=np.float64).reshape(-1)
        if not idx.shape == meas.shape == disp.shape:
            raise InputError("history arrays must have the same length, got "
                             f"{idx.shape[0]}, {meas.shape[0]}, {disp.shape[0]}")
        if counts not in ("data point", "control point", "knot"):
            raise InputError(f"history counts must be 'data point', 'control point' or 'knot', "
                             f"got {counts!r}")
        return cls(readonly(idx), readonly(meas), readonly(disp), counts)

    @functools.cached_property
    def step(self) -> np.ndarray:
        return readonly(np.arange(1, self.index.shape[0] + 1, dtype=np.int64))

    @classmethod
    def empty(cls, counts: HistoryIndex = "data point") -> "FairingHistory":
        return cls.from_arrays([], [], [], counts)

    def __len__(self) -> int:
        return int(self.index.shape[0])

    def to_dict(self) -> dict[str, Any]:
        """Plain lists (JSON-serialisable; non-finite measures become None)."""
        return {
            "counts": self.counts,
            "step": self.step.tolist(),
            "index": self.index.tolist(),
            "measure": [_finite_or_none(v) for v in self.measure.tolist()],
            "displacement": [_finite_or_none(v) for v in self.displacement.tolist()],
        }


@dataclass
class Outcome:
    """What a method's solver returns: the one outcome type of every method.

    Attributes
    ----------
    curve : PiecewiseCurve
        The faired curve (same type as the input).
    steps : int
        Steps taken (moves made; iterations for a simultaneous solve).
    stop_reason : StopReason
        Why it stopped (:mod:`curvefair.fairing.stop`).
    history : FairingHistory or None
    eps : float or None
        ``eps`` as :func:`~curvefair.fair` means it (relative to the method's initial fairness
        measure), the method's default when the problem had none.
    max_steps : int or None
        The step cap used.
    extra : dict
        Method-specific report entries (JSON-serialisable).
    curve_within_tol : bool
        The method promises the whole curve within ``tol`` (not only the data points):
        :func:`~curvefair.fair` then certifies the curve deviation and scales the moves back
        if needed.
    eps_absolute : float or None
        The threshold the method compared its measure with (``eps * R``, see
        :func:`eps_threshold`).
    """

    curve: PiecewiseCurve
    steps: int
    stop_reason: StopReason
    history: FairingHistory | None = None
    eps: float | None = None
    max_steps: int | None = None
    extra: dict[str, Any] = field(default_factory=dict)
    curve_within_tol: bool = True
    eps_absolute: float | None = None


def normalize_protect(protect: object, curve: PiecewiseCurve) -> frozenset[int]:
    """Validate protected data-point indices; a closed Hermite curve maps ``n-1`` to the seam 0."""
    n_stored = (int(curve.control_points.shape[0]) if hasattr(curve, "control_points")
                else int(np.asarray(curve.points).shape[0]))  # type: ignore[attr-defined]
    seam_alias = curve.closed and not hasattr(curve, "control_points")
    if protect is None:
        return frozenset()
    if isinstance(protect, (int, np.integer)) and not isinstance(protect, bool):
        items: list[object] = [protect]
    else:
        try:
            items = list(protect)  # type: ignore[call-overload]
        except TypeError:
            raise InputError(f"protect must be a sequence of point indices, got {protect!r}"
                             ) from None
    out = set()
    for v in items:
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
            raise InputError(f"protect must contain integer point indices, got {v!r}")
        i = int(v)
        if not 0 <= i < n_stored:
            raise InputError(f"protect index {i} is out of range: the curve has {n_stored} "
                             f"data points (valid: 0 .. {n_stored - 1})")
        out.add(0 if (seam_alias and i == n_stored - 1) else i)
    return frozenset(out)


def fixed_mask(curve: PiecewiseCurve, clamp: tuple[str, str],
               protect: Iterable[int]) -> np.ndarray:
    """Boolean mask of the data points that never move (True: fixed).

    B-splines (control points): ``clamp`` fixes 0, 1, 2, 3 end control points for
    ``"none"``, ``"g0"``, ``"g1"``, ``"g2"`` (:data:`CLAMP_POINTS`), which keeps position,
    tangent, curvature at that end of a clamped B-spline. Hermite curves (distinct data points):
    the end points of an open curve (their end tangent or curvature is a condition on the
    derivatives, not a fixed point). Closed curves have no ends. ``protect`` indices are fixed.
    """
    closed = bool(curve.closed)
    if hasattr(curve, "control_points"):
        n = int(curve.control_points.shape[0])
        mask = np.zeros(n, dtype=bool)
        if not closed:
            left, right = (CLAMP_POINTS[c] for c in clamp)
            mask[:left] = True
            if right:
                mask[n - right:] = True
    else:
        n = int(np.asarray(curve.points).shape[0]) - (1 if closed else 0)  # type: ignore[attr-defined]
        mask = np.zeros(n, dtype=bool)
        if not closed:
            mask[0] = mask[-1] = True
    for i in protect:
        mask[int(i)] = True
    return mask


@dataclass(frozen=True, eq=False)
class FairingProblem:
    """One fairing problem, as :func:`make_problem` normalised it.

    Attributes
    ----------
    curve : PiecewiseCurve
    tol : float
        Largest distance of any data point (and of the curve) from the input; ``inf``: none.
    eps : float or None
        Stopping threshold relative to the method's initial fairness measure
        (:func:`eps_threshold`); None: the method's default.
    max_steps : int or None
        Step cap; None: the method's default.
    clamp : (str, str)
        End conditions, each ``"none" | "g0" | "g1" | "g2"``.
    protect : frozenset of int
        Data points (B-splines: control points) that never move.
    mode : str
        ``"spline"`` or ``"hermite"`` (the Hermite methods).
    options : mapping
        The method's own options as the caller gave them.
    """

    curve: PiecewiseCurve
    tol: float = math.inf
    eps: float | None = None
    max_steps: int | None = None
    clamp: tuple[str, str] = ("g0", "g0")
    protect: frozenset[int] = frozenset()
    mode: str = "spline"
    options: Mapping[str, Any] = field(default_factory=dict)

    @property
    def tol_or_none(self) -> float | None:
        """``tol``, None for no tolerance."""
        return None if math.isinf(self.tol) else self.tol

    @property
    def fixed(self) -> np.ndarray:
        """Mask of the data points that never move (:func:`fixed_mask`)."""
        return fixed_mask(self.curve, self.clamp, self.protect)

    @property
    def movable(self) -> np.ndarray:
        """``~fixed``."""
        return ~self.fixed


def make_problem(curve: PiecewiseCurve, *, tol: object = None, eps: object = None,
                 max_steps: object = None, clamp: object = "g0", protect: object = (),
                 mode: str = "spline", options: Mapping[str, Any] | None = None
                 ) -> FairingProblem:
    """Parse the shared options into a :class:`FairingProblem` (the one place they are read).

    Raises
    ------
    InputError
        ``tol`` not a length > 0 in the working range (None: no tolerance), ``eps < 0``,
        ``max_steps`` not a whole number >= 0, an unknown ``clamp``, a ``protect`` index out
        of range.
    """
    tol_v = as_positive(tol, "tol", allow_none=True, window=True)
    eps_v = None if eps is None else as_nonnegative(eps, "eps")
    steps_v = None if max_steps is None else as_step_count(max_steps, default=0)
    return FairingProblem(curve, math.inf if tol_v is None else tol_v, eps_v, steps_v,
                          parse_clamp(clamp), normalize_protect(protect, curve), mode,
                          dict(options or {}))


def eps_threshold(eps: float | None, reference: float, default: float) -> tuple[float, float]:
    """``(eps, eps * reference)``: the relative ``eps`` (``default`` for None) and the absolute
    threshold a method compares its ranking measure with; ``reference`` is the method's initial
    fairness measure (table in the module docstring)."""
    e = float(default) if eps is None else float(eps)
    return e, e * float(reference)
