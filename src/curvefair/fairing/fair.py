"""The automatic fairing loop :func:`fair` and its method registry.

Every fairing method (local Hermite steps, Eck-Hadenfeld, knot removal, ...) registers a
:class:`MethodSpec` whose *driver* runs the method's loop. :func:`fair` validates the arguments
common to all methods, calls the driver, and writes the report (before/after analysis, which
points moved and how far, the largest deviation of the curve).
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
import math
import time
import weakref
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from .. import _threads
from .._typing import FloatArray
from ..curves.hermite import CubicHermite
from ..curves.piecewise import PiecewiseCurve, readonly
from ..errors import InputError
from ..interop import as_curve as _as_curve
from .problem import FairingHistory, FairingProblem, Outcome, make_problem

if TYPE_CHECKING:
    from ..curves.bspline import BSplineCurve

__all__ = [
    "MethodSpec",
    "DriverOutput",
    "Outcome",
    "FairingProblem",
    "FairingHistory",
    "FairingResult",
    "FairingReport",
    "METHODS",
    "register_method",
    "available_methods",
    "method_options",
    "fair",
    "CLAMPS",
    "MODES",
]

CLAMPS = ("none", "g0", "g1", "g2")
#: Phases of one :func:`fair` call reported to its ``progress`` callback.
PHASES = 4
MODES = ("spline", "hermite")


# ----------------------------------------------------------------------------------------------
# data classes
# ----------------------------------------------------------------------------------------------
#: What a method returns to :func:`fair`: the one outcome type (:class:`.problem.Outcome`).
DriverOutput = Outcome


@dataclass(frozen=True)
class MethodSpec:
    """A fairing method as :func:`fair` knows it.

    Attributes
    ----------
    name : str
        The ``method=`` name.
    curve_types : tuple of type
        Curve classes the method accepts.
    driver : callable or None
        ``driver(curve, *, tol, eps, max_steps, clamp, protect, **options) -> Outcome``, the
        keyword form (``tol=None`` for no tolerance, ``clamp`` a ``(left, right)`` pair,
        ``protect`` a frozenset of 0-based data-point indices: control points for B-splines;
        a closed Hermite curve's seam is index 0). With a ``solver`` it is derived from it.
    solver : callable or None
        ``solver(problem, **options) -> Outcome``: the method as a solver of a
        :class:`~curvefair.fairing.problem.FairingProblem`, its keyword parameters its options.
        :func:`fair` calls the solver when there is one, else the driver.
    summary : str
        One line for listings.
    source : str
        Paper and equations.
    default : bool
        The default method for its curve types.
    modes : tuple of str
        Values of ``fair(mode=...)`` the method accepts. A method declaring more than the plain
        ``("spline",)`` receives ``mode=`` as a keyword.
    accepts : callable or None
        ``accepts(curve) -> bool``: a further condition on curves of ``curve_types`` (e.g.
        cubic B-splines only); :func:`available_methods` lists the method for a curve only if
        it holds. ``fair`` still calls the driver, which explains a refusal.
    prefer : callable or None
        ``prefer(curve) -> bool``, for a ``default`` method: the curves it is the default for
        (e.g. open point data up to a size); where it does not hold, the default of the curve
        type without such a condition is used. None: ``accepts`` decides.
    clamps : tuple of str or None
        The end conditions the method can keep (``"g0"`` ...); None: all. A default method
        is not chosen for a call whose ``clamp`` it cannot keep (the next default is).
    default_options : dict or callable
        Options :func:`fair` passes when it chooses this method as the default (``method``
        not given), or ``default_options(curve) -> dict``; options the caller gives win.
        E.g. ``{"l": 3}`` for ``global`` on curves of degree >= 3.
    default_reason : str
        Why it is the default: one line with the benchmark figure (``curvefair methods``).
    two_threads : bool
        The method's own passes keep both threads (:mod:`curvefair._threads`) busy for most
        of its run: :func:`fair` then analyses a long input before the method, not beside it
        on the worker thread (which would leave the method's passes one thread).
    """

    name: str
    curve_types: tuple[type, ...]
    driver: Callable[..., Outcome] = field(default_factory=lambda: _no_driver)
    summary: str = ""
    source: str = ""
    default: bool = False
    modes: tuple[str, ...] = ("spline",)
    accepts: Callable[[Any], bool] | None = None
    prefer: Callable[[Any], bool] | None = None
    clamps: tuple[str, ...] | None = None
    default_options: dict[str, Any] | Callable[[Any], dict[str, Any]] = field(
        default_factory=dict)
    default_reason: str = ""
    solver: Callable[..., Outcome] | None = None
    two_threads: bool = False

    def __post_init__(self) -> None:
        if self.driver is None:  # spelled out by a caller
            object.__setattr__(self, "driver", _no_driver)
        if self.solver is None and self.driver is _no_driver:
            raise InputError(f"method {self.name!r} needs a solver or a driver")
        if self.driver is _no_driver:
            object.__setattr__(self, "driver", functools.partial(
                _solver_as_driver, cast("Callable[..., Outcome]", self.solver)))

    def run(self, problem: FairingProblem, options: dict[str, Any]) -> Outcome:
        """Solve ``problem`` with this method (its solver, else its driver)."""
        if self.solver is not None:
            return self.solver(problem, **options)
        kw = dict(options)
        if self.modes != ("spline",):
            kw["mode"] = problem.mode
        return self.driver(problem.curve, tol=problem.tol_or_none, eps=problem.eps,
                           max_steps=problem.max_steps, clamp=problem.clamp,
                           protect=problem.protect, **kw)


def _no_driver(*args: Any, **kwargs: Any) -> Outcome:  # placeholder until __post_init__
    raise TypeError("MethodSpec without a driver")


def _solver_as_driver(solver: Callable[..., Outcome], curve: PiecewiseCurve, *,
                      tol: float | None, eps: float | None, max_steps: int | None,
                      clamp: tuple[str, str], protect: frozenset[int], mode: str = "spline",
                      **options: Any) -> Outcome:
    """The keyword (driver) form of a solver: the problem built from already checked values."""
    prob = FairingProblem(curve, math.inf if tol is None else float(tol), eps, max_steps,
                          tuple(clamp), frozenset(protect), mode, dict(options))  # type: ignore[arg-type]
    return solver(prob, **options)


class FairingReport(dict):
    """The report of :func:`fair`: a ``dict`` whose per-point entries stay numpy arrays.

    Every entry is a plain Python value (``float``, ``int``, ``str``, ``bool``, ``None``,
    lists and dicts of them; non-finite floats are ``None``) except ``report["moved"]``,
    whose ``"indices"`` (int64) and ``"displacement"`` (float64) are read-only arrays with one
    entry per moved data point: on a curve of a million points, a million Python objects would
    cost more than the fairing itself. :meth:`to_dict` gives the whole report as plain Python
    values (what ``json.dumps`` needs).
    """

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready copy: arrays become lists, non-finite floats ``None``."""
        return jsonable(self)


@dataclass(frozen=True, eq=False)
class FairingResult:
    """Result of :func:`fair`.

    Attributes
    ----------
    curve : PiecewiseCurve
        The faired curve.
    report : FairingReport
        Summary (see :func:`fair`): a ``dict`` of plain values whose per-point ``"moved"``
        entries are numpy arrays; :meth:`FairingReport.to_dict` makes it JSON-ready.
    history : FairingHistory
        One entry per step.
    original : PiecewiseCurve or None
        The curve that was faired (the input, after :func:`curvefair.as_curve`), for the
        before/after display; None when the result was built without it.
    """

    curve: PiecewiseCurve
    report: FairingReport
    history: FairingHistory
    original: PiecewiseCurve | None = None

    def _repr_html_(self) -> str:  # notebook display: curvefair.view.result_repr_html
        from ..view import result_repr_html
        return result_repr_html(self)

    def __repr__(self) -> str:
        r = self.report
        return (f"FairingResult(method={r.get('method')!r}, steps={r.get('steps')}, "
                f"stop_reason={r.get('stop_reason')!r}, curve={self.curve!r})")


METHODS: dict[str, MethodSpec] = {}


def register_method(spec: MethodSpec) -> MethodSpec:
    """Add (or replace) a method in :data:`METHODS`; returns ``spec``."""
    if not isinstance(spec, MethodSpec):
        raise InputError(f"register_method needs a MethodSpec, got {type(spec).__name__}")
    METHODS[spec.name] = spec
    return spec


def available_methods(curve: object = None) -> list[str]:
    """Names of the registered methods (those accepting ``curve``'s type, if given)."""
    if curve is None:
        return list(METHODS)
    return [n for n, s in METHODS.items() if isinstance(curve, s.curve_types)
            and (s.accepts is None or s.accepts(curve))]


# arguments of every driver that fair() passes itself: not "options" of a method
_STANDARD_ARGS = frozenset({"tol", "eps", "max_steps", "clamp", "protect", "mode"})


def _driver_options(spec: MethodSpec) -> tuple[dict[str, Any], bool]:
    """The driver's own keyword options ``{name: default}`` and whether it takes ``**kwargs``.

    The first positional parameter (the curve), the arguments :func:`fair` passes itself
    (:data:`_STANDARD_ARGS`) and keywords bound by a :func:`functools.partial` driver are not
    options. A driver whose signature cannot be read is taken to accept anything.
    """
    fn = spec.solver if spec.solver is not None else spec.driver
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):
        return {}, True
    bound = set(fn.keywords) if isinstance(fn, functools.partial) else set()
    opts: dict[str, Any] = {}
    var_kw = False
    for k, p in enumerate(sig.parameters.values()):
        if p.kind is p.VAR_KEYWORD:
            var_kw = True
            continue
        if p.kind not in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY):
            continue
        if k == 0 and p.kind is p.POSITIONAL_OR_KEYWORD:
            continue  # the curve
        if p.name in _STANDARD_ARGS or p.name in bound:
            continue
        opts[p.name] = p.default
    return opts, var_kw


def _method_spec(name: object) -> MethodSpec:
    if not isinstance(name, str) or name not in METHODS:
        raise InputError(f"unknown method {name!r}; valid methods are: "
                         + ", ".join(repr(m) for m in METHODS))
    return METHODS[name]


def method_options(name: str) -> dict[str, Any]:
    """The options ``fair(curve, name, **options)`` accepts, each with its default.

    Options are the method driver's keyword parameters other than ``tol``, ``eps``,
    ``max_steps``, ``clamp``, ``protect`` and ``mode`` (which :func:`fair` takes itself), in
    the driver's order; an option without a default maps to :data:`inspect.Parameter.empty`.
    A driver that also takes ``**kwargs`` (the Hermite methods) may accept or check further
    names itself; only its named options are listed.

    Raises
    ------
    InputError
        Unknown method name.

    Examples
    --------
    >>> from curvefair.fairing.fair import method_options
    >>> method_options("eck-hadenfeld")["schedule"]
    'sweep'
    """
    return dict(_driver_options(_method_spec(name))[0])


def _check_options(spec: MethodSpec, options: dict[str, Any]) -> None:
    """Refuse option names the method's driver does not take (InputError naming them)."""
    known, var_kw = _driver_options(spec)
    if var_kw:
        return
    unknown = sorted(k for k in options if k not in known)
    if not unknown:
        return
    names = ", ".join(repr(k) for k in unknown)
    what = f"no option {names}" if len(unknown) == 1 else f"no options {names}"
    valid = ("its options are: " + ", ".join(sorted(known)) if known
             else "it takes no options")
    raise InputError(f"method {spec.name!r} has {what}; {valid}")


# ----------------------------------------------------------------------------------------------
# helpers
# ----------------------------------------------------------------------------------------------
def _finite_or_none(v: Any) -> Any:
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def jsonable(obj: Any) -> Any:
    """Convert numpy scalars/arrays to plain Python; non-finite floats to None."""
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind in "iub":
            return obj.tolist()  # plain ints / bools: no per-element conversion needed
        if obj.dtype.kind == "f" and obj.ndim == 1:
            vals = obj.astype(np.float64, copy=False).tolist()
            if bool(np.isfinite(obj).all()):
                return vals
            return [_finite_or_none(v) for v in vals]
        return jsonable(obj.tolist())
    if isinstance(obj, (np.bool_, bool)):
        return bool(obj)
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (np.floating, float)):
        return _finite_or_none(float(obj))
    if obj is None or isinstance(obj, (int, str)):
        return obj
    if isinstance(obj, (set, frozenset)):
        return sorted(jsonable(v) for v in obj)
    return str(obj)


def data_points(curve: PiecewiseCurve) -> FloatArray:
    """The data a fairing method moves: ``control_points`` of a B-spline, else ``points``.

    A closed Hermite curve's repeated last point is dropped (distinct points only).
    """
    if hasattr(curve, "control_points"):
        return np.asarray(curve.control_points)
    pts = np.asarray(curve.points)  # type: ignore[attr-defined]
    if curve.closed and not hasattr(curve, "control_points"):
        return pts[:-1]
    return pts


def normalize_clamp(clamp: object) -> tuple[str, str]:
    """``"G1"`` -> ``("g1", "g1")``: :func:`curvefair._validate.parse_clamp`, the grammar every
    method function shares."""
    from .._validate import parse_clamp

    return parse_clamp(clamp)


def _default_method(curve: PiecewiseCurve, clamp: object = "g0") -> MethodSpec:
    # a default with an ``accepts`` condition that holds is more specific than one without
    # (e.g. 'points-l1' for open cubic Hermite point data, 'poliakoff' for the closed ones),
    # if it can keep the ends the call asks for
    try:
        ends = normalize_clamp(clamp)
    except InputError:
        ends = ("g0", "g0")   # fair() reports the bad clamp itself
    for spec in METHODS.values():
        cond = spec.prefer if spec.prefer is not None else spec.accepts
        if (spec.default and isinstance(curve, spec.curve_types) and cond is not None
                and cond(curve)
                and (spec.clamps is None or bool(curve.closed)
                     or all(e in spec.clamps for e in ends))):
            return spec
    for spec in METHODS.values():
        if (spec.default and isinstance(curve, spec.curve_types) and spec.accepts is None
                and spec.prefer is None):
            return spec
    for spec in METHODS.values():
        if spec.default and isinstance(curve, spec.curve_types):
            return spec
    for spec in METHODS.values():
        if isinstance(curve, spec.curve_types):
            return spec
    raise InputError(f"no fairing method is registered for {type(curve).__name__}")


#: the keys of :func:`analysis_block`
ANALYSIS_FIGURES = ("energy", "energy3", "max_jump", "max_top_jump", "sapidis_sum",
                    "dkds_energy", "inflections", "extrema")


class _CacheState:
    """Which lazily built figures a curve held when :func:`fair` was called with it: its
    power form (:attr:`~curvefair.PiecewiseCurve.piecewise`) and, for a B-spline, the keys of
    its Gram bands (shared by every curve on the same knots). :func:`fair` drops what it
    built itself once it is done with it, so that the caller's curve leaves the call as it
    came in and the call's peak memory does not hold them (a power form is 72 bytes per span
    of a planar cubic, a Gram band 56 bytes per control point)."""

    def __init__(self, curve: PiecewiseCurve) -> None:
        self.had_form = "piecewise" in curve.__dict__
        cache = getattr(curve, "_gram_cache", None)
        self.gram_keys = frozenset(cache) if isinstance(cache, dict) else frozenset()

    def drop_power_form(self, curve: PiecewiseCurve, *, method_done: bool) -> None:
        """The input's power form, once nothing reads it: a B-spline's after its analysis and
        join plan (the B-spline methods work on the control points), any curve's after the
        method (the Hermite loops take end derivatives from it); the rest of the call reads
        the input's data (the certificate works on the difference curve)."""
        if not self.had_form and (method_done or hasattr(curve, "control_points")):
            curve.__dict__.pop("piecewise", None)

    def drop_gram_bands(self, curve: PiecewiseCurve, new: PiecewiseCurve) -> None:
        """After the method: the Gram bands it built, on the input and on the result (the
        two share one cache when their knots are the same)."""
        for c in (curve, new):
            cache = getattr(c, "_gram_cache", None)
            if isinstance(cache, dict):
                keep = self.gram_keys if cache is getattr(curve, "_gram_cache", None) else ()
                for k in [k for k in cache if k not in keep]:
                    del cache[k]


#: the analysis blocks of cubic Hermite curves already analysed, by curve (their data are
#: read-only): one fair() call on point data asks for the same curve's figures several times
#: (the input before and in the method's back-off; the result in the method, after it and in
#: the guard; the rebuilt curves of the method's choice and of the guard)
_ANALYSIS_MEMO: weakref.WeakKeyDictionary[Any, dict[str, Any]] = weakref.WeakKeyDictionary()


#: the analyses of inputs that fair() runs on the worker thread (:func:`_start_analysis`), by
#: curve: a method that asks for its input's figures meanwhile waits for that job instead of
#: analysing the curve a second time
_ANALYSIS_PENDING: weakref.WeakKeyDictionary[Any, _threads.Background] = (
    weakref.WeakKeyDictionary())


def analysis_block(curve: PiecewiseCurve) -> dict[str, Any]:
    """The report's figures of one curve (:func:`curvefair.analyze`): energies, largest jumps,
    Sapidis sum, ``int (dkappa/ds)^2 ds``, inflection and curvature-extremum counts (a fresh
    dict; a :class:`CubicHermite`'s are computed once per curve object)."""
    job = _ANALYSIS_PENDING.get(curve)
    if job is not None:
        return dict(job.result())
    return _memo_analysis_block(curve)


def _memo_analysis_block(curve: PiecewiseCurve, lean: bool | None = None) -> dict[str, Any]:
    memo = type(curve) is CubicHermite
    if memo:
        got = _ANALYSIS_MEMO.get(curve)
        if got is not None:
            return dict(got)
    block = _analysis_block_of(curve, lean)
    if memo:
        _ANALYSIS_MEMO[curve] = dict(block)
    return block


#: points (B-splines: control points) from which :func:`fair` analyses its input on the
#: worker thread while the join plan and the method run on the calling thread (with two
#: threads, ``curvefair._threads``)
OVERLAP_MIN = 50_000


def _start_analysis(curve: PiecewiseCurve, beside: bool = True
                    ) -> Callable[[], dict[str, Any]]:
    """The input's :func:`analysis_block`, started on the worker thread when the curve is long
    (:data:`OVERLAP_MIN` points, two threads) and ``beside`` (the method's passes leave the
    worker thread free, :attr:`MethodSpec.two_threads`); else computed now. The returned
    function gives the figures (the same bits either way: every pass of the analysis gives
    the same results on one thread or two). The job keeps no samples (``lean``: 52-60 bytes a
    segment instead of 128-228, the method's memory and the analysis' add up while both
    run). Analysed first, as before: a 3-D
    B-spline (its analysis builds the whole power form, which the call drops before the
    method) and a curve of ``RESCAN_MIN`` segments or more, where the analysis is lean anyway
    because memory is what limits the call: beside the method its 3.3-3.8 times the
    coordinates' bytes raise the method's peak (measured at 1e7 points: docs/benchmarks.md)."""
    from ..analysis import lean_by_default

    n = data_points(curve).shape[0]
    if (not beside or _threads.THREADS < 2 or n < OVERLAP_MIN or lean_by_default(n)
            or (curve.dim == 3 and hasattr(curve, "control_points"))):
        block = analysis_block(curve)
        return lambda: block
    job = _threads.Background(functools.partial(_memo_analysis_block, curve, True))
    _ANALYSIS_PENDING[curve] = job

    def result() -> dict[str, Any]:
        try:
            return cast("dict[str, Any]", job.result())
        finally:
            if _ANALYSIS_PENDING.get(curve) is job:
                del _ANALYSIS_PENDING[curve]
    return result


def _analysis_block_of(curve: PiecewiseCurve, lean: bool | None = None) -> dict[str, Any]:
    from ..analysis import fairness_figures

    a = fairness_figures(curve, lean=lean)  # analyze()'s figures, without per-knot arrays
    return {
        "energy": a["energy2"],
        "energy3": a["energy3"],
        "max_jump": a["max_jump"],
        "max_top_jump": a["max_top_jump"],
        "sapidis_sum": a["sapidis_sum"],
        "dkds_energy": a["dkds_energy"],
        "inflections": a["inflections"],
        "extrema": a["extrema"],
    }


_analysis_block = analysis_block  # the former name (used inside the fairing package)


# ----------------------------------------------------------------------------------------------
# fair
# ----------------------------------------------------------------------------------------------
def fair(curve: PiecewiseCurve, method: str | None = None, *, tol: float | None = None,
         eps: float | None = None, max_steps: int | None = None, clamp: Any = "g0",
         protect: Iterable[int] = (), mode: str = "spline", joins: str = "keep",
         g1_angle: float | None = None, corner_turn: float | None = None,
         guard: bool = True, structure: str = "keep",
         progress: Callable[[int, int], None] | None = None,
         **options: Any) -> FairingResult:
    """Fair a curve automatically: repeatedly apply a local step at the worst point.

    Parameters
    ----------
    curve : PiecewiseCurve
        :class:`~curvefair.CubicHermite`, :class:`~curvefair.QuinticHermite`, or a B-spline
        (with a B-spline method registered).
    method : str, optional
        A name from :func:`available_methods`; default: the curve type's default
        (``"points-l1"`` for point data up to 20,000 points, i.e. chord-length natural cubics,
        open or closed (periodic), ``"poliakoff"`` for other cubic, ``"wang-quintic"`` for
        quintic Hermite splines, ``"global"`` with ``l=3`` for B-splines: the fairest method of
        the quality benchmark that keeps the B-spline's degree, knots and number of control
        points), with that method's ``default_options`` under the caller's own options.
    tol : float > 0, optional
        Neither the output curve nor any data point ends farther than ``tol`` from the input.
        Each step is clamped onto the ball of radius ``tol`` around the ORIGINAL point (ERRATA,
        Eck & Hadenfeld); a point whose clamped move is ~0 is skipped. B-spline methods bound
        control points, so the curve follows by the convex hull property; the Hermite methods
        also check the whole curve with the certified bound of :func:`curvefair.deviation` and
        shrink the moves where an interpolant bulges between its points (their option
        ``tol_on="points"`` bounds only the data points, as the papers do). The promise holds
        in float64 as the report prints it: every result passes through
        :func:`curvefair.fairing._tolerance.enforce_tolerance`, which pulls a point that rounding
        left outside ``np.linalg.norm(moved - original) <= tol`` back along its move and
        certifies the curve deviation on the difference curve.
    eps : float >= 0, optional
        Stop when the method's ranking measure falls below ``eps`` times its initial fairness
        measure ``R`` (the same meaning for every method: the largest initial bad-point measure
        for the Hermite methods and knot removal, ``E_l(input)`` for eck-hadenfeld and global,
        the indicator ``sum D_i**2`` for cheng-yu; table in :mod:`curvefair.fairing.problem`).
        ``0`` runs until ``max_steps`` or until the tolerance blocks every move. Default:
        method-specific. The report gives ``eps`` and the threshold ``eps_absolute``.
    max_steps : int >= 0, optional
        Step cap (default method-specific).
    clamp : {"none", "g0", "g1", "g2"} (any case) or (left, right)
        End conditions kept exactly: ``"g0"`` end points fixed, ``"g1"`` also the end tangent,
        ``"g2"`` also the end second derivative (curvature); ``"none"`` (or None): the B-spline
        methods may move the end control points (the Hermite methods refuse it: they always
        keep the end points). Ignored for closed curves.
    protect : iterable of int
        Data-point indices that never move (0-based; B-splines: control points).
    mode : {"spline", "hermite"}
        For the Hermite methods: ``"spline"`` re-interpolates after every step (the papers'
        examples), ``"hermite"`` keeps the step's own derivatives.
    joins : {"keep", "free"}
        ``"keep"`` (default): G1 joins stay G1 (to rounding) and G2 joins G2, corners (C0 knots
        whose tangents differ by more than ``g1_angle``) and straight pieces stay where they
        are, a smooth seam of an open curve whose ends coincide stays smooth
        (:mod:`curvefair.fairing.joins`). ``"free"``: the method alone decides.
    g1_angle : float, optional
        Degrees; a C0 knot whose two tangents differ by at most this is a G1 join (default
        :data:`curvefair.fairing.joins.DEFAULT_G1_ANGLE`, 0.5).
    corner_turn : float, optional
        Degrees; the most the angle of a corner of a B-spline (a C0 knot that is not G1), and
        each of its two tangents, may turn (default
        :data:`curvefair.fairing.joins.DEFAULT_CORNER_TURN`, 1). Where the
        method turns one more, the curve is faired again with the control points that fix
        that corner's angle held (``report["joins"]["corner_points_held"]``); ``math.inf``:
        no limit (only the corner's point is held).
    guard : bool
        Default True: if the faired curve has more inflections or curvature extrema than the
        input (curvefair's own counts, :func:`curvefair.analyze`), the largest fraction of the
        move (1/2, 1/4, 1/8) that does not is returned instead, or else the input itself;
        ``report["guard"]`` says what was kept and why. Point data (the input is the
        chord-length natural or periodic cubic through its points, as a point file is read,
        and the result a cubic Hermite curve on its parameters): the curve a reader rebuilds
        from the result's points (the same interpolant at their own chord lengths) is judged
        too: ``report["guard"]["rebuilt"]`` holds its figures (those of :func:`analyze`:
        energies, jumps, counts) for the curve returned; False: the method's result as it
        is.
    structure : {"keep", "free"}
        B-splines: ``"keep"`` (default) keeps the degree, knot vector and number of control
        points; ``"free"`` accepts fewer knots (:mod:`curvefair.fairing.structure`: the fewest
        knots whose least-squares refit stays within ``tol / 2``, then the method under the
        rest of the tolerance; ``report["structure"]``). Other curves: no effect.
    progress : callable, optional
        ``progress(done, total)`` after each phase of the call, ``total`` = ``PHASES``
        (4): the analysis before, the method's fairing, the analysis after (and the
        never-worse guard), the tolerance certificate. (A long input's analysis runs beside
        the method, on the worker thread: its ``1`` then comes just before the ``2``.) For
        progress within one long curve; the method itself is not interrupted.
    **options
        Passed to the method's driver; :func:`method_options` lists each method's options and
        their defaults (e.g. ``schedule="sweep"`` for ``"eck-hadenfeld"``). An unknown name
        raises :class:`InputError` before any work is done.

    Returns
    -------
    FairingResult
        ``.curve``, ``.report`` (a :class:`FairingReport`: a dict without NaN whose
        per-point ``"moved"`` entries are numpy arrays; ``.report.to_dict()`` is JSON-ready)
        and ``.history``.

    Raises
    ------
    InputError
        Unknown method/mode/clamp/option, ``tol <= 0``, ``eps < 0``, negative ``max_steps``, protect
        index out of range, a curve the method does not handle, too few points.

    Notes
    -----
    The loop is Wang & Cao 2006's steps 1-6: rank the points, fair the worst, re-interpolate,
    repeat. The report holds ``method``, ``steps``, ``stop_reason``, ``moved`` (arrays of the
    indices and their final displacement from the original), ``energy_before/after``
    (``int |r''|^2``), ``max_jump_before/after`` (third derivative, seed 001),
    ``max_top_jump_before/after`` (jump of the ``degree``-th derivative: the meaningful one for
    a C4 quintic),
    ``energy3_before/after``, ``sapidis_sum_before/after``, ``dkds_energy_before/after``
    (``int (dkappa/ds)^2 ds``), ``inflections_before/after``, ``extrema_before/after``,
    ``max_point_displacement`` (+ ``max_point_index``; ``np.linalg.norm(moved - original)``),
    ``tolerance_guard`` (points pulled back inside ``tol`` at rounding level, and the factor the
    moves were scaled by to certify the curve), ``max_deviation`` (at equal parameter, on the
    difference curve; + where:
    ``max_deviation_param``, ``max_deviation_point``), ``tol``, ``eps``, ``max_steps``,
    ``clamp``, ``protect``, ``mode``, ``time_s`` and method-specific entries.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_cubic, fair
    >>> pts = np.column_stack([np.arange(1.0, 8.0), np.ones(7)])
    >>> pts[3] = (4.3, 1.6)
    >>> res = fair(interpolate_cubic(pts), "poliakoff", tol=0.5)
    >>> res.report["energy_after"] < res.report["energy_before"]
    True
    """
    t_start = time.perf_counter()
    curve = _as_curve(curve, "curve")  # scipy splines too (curvefair.interop.as_curve)
    if not isinstance(curve, PiecewiseCurve):
        raise InputError(f"curve must be a curvefair curve, got {type(curve).__name__}")
    if progress is not None and not callable(progress):
        raise InputError(f"progress must be a callable progress(done, total), got "
                         f"{type(progress).__name__}")
    if structure not in ("keep", "free"):
        raise InputError(f"unknown structure {structure!r}; valid values are: 'keep', 'free'")
    if structure == "free" and hasattr(curve, "control_points"):
        from .._validate import as_positive as _pos
        from .structure import fair_new_structure

        res = fair_new_structure(
            cast("BSplineCurve", curve), method,
            _pos(tol, "tol", allow_none=True, window=True), fair, eps=eps,
            max_steps=max_steps, clamp=clamp, protect=protect, mode=mode, joins=joins,
            g1_angle=g1_angle, corner_turn=corner_turn, guard=guard, **options)
        if progress is not None:
            progress(PHASES, PHASES)
        return res
    if method is None:
        spec = _default_method(curve, clamp)
        dflt = spec.default_options
        options = {**(dflt(curve) if callable(dflt) else dflt), **options}
    else:
        spec = _method_spec(method)
    if not isinstance(curve, spec.curve_types):
        raise InputError(
            f"method {spec.name!r} needs a {' or '.join(t.__name__ for t in spec.curve_types)}, "
            f"got {type(curve).__name__}; methods for this curve: "
            + ", ".join(repr(m) for m in available_methods(curve)))
    from .._validate import as_nonnegative

    # the one parse of the shared options (curvefair.fairing.problem)
    problem = make_problem(curve, tol=tol, eps=eps, max_steps=max_steps, clamp=clamp,
                           protect=protect, mode=mode, options=options)
    tol_v = problem.tol_or_none
    eps_v, clamp_pair, prot = problem.eps, problem.clamp, problem.protect
    max_steps = problem.max_steps
    from ..curves.bspline import BSplineCurve

    if ("none" in clamp_pair and not isinstance(curve, BSplineCurve)
            and not getattr(curve, "closed", False)):
        raise InputError(f"clamp 'none' is not available for method {spec.name!r}: the methods "
                         "for point data always keep the end points; use 'g0', 'g1' or 'g2'")
    if not isinstance(mode, str) or mode not in MODES:
        raise InputError(f"unknown mode {mode!r}; valid values are: "
                         + ", ".join(repr(m) for m in MODES))
    if mode not in spec.modes:
        raise InputError(f"method {spec.name!r} supports mode "
                         + " or ".join(repr(m) for m in spec.modes) + f", got {mode!r}")
    _check_options(spec, options)

    from . import joins as _joins

    if joins not in ("keep", "free"):
        raise InputError(f"unknown joins {joins!r}; valid values are: 'keep', 'free'")
    g1_deg = _joins.DEFAULT_G1_ANGLE if g1_angle is None else as_nonnegative(g1_angle,
                                                                            "g1_angle")
    turn_deg = (_joins.DEFAULT_CORNER_TURN if corner_turn is None
                else math.inf if isinstance(corner_turn, (int, float)) and corner_turn == math.inf
                else as_nonnegative(corner_turn, "corner_turn"))
    # what the call adds to the input's caches (its power form, Gram bands) is dropped as soon
    # as the call no longer needs it: at a million points they are 72 and 56 bytes per span,
    # held by the caller's curve after the call, and at the call's peak (the result's analysis)
    cached_at_entry = _CacheState(curve)

    def solve(plan: Any, tol_w: float | None) -> Outcome:
        # the method solves the problem on the join plan's curve (joins held, tol shared)
        sub = dataclasses.replace(problem, curve=plan.curve,
                                  tol=math.inf if tol_w is None else tol_w,
                                  clamp=plan.clamp, protect=frozenset(plan.protect))
        res = spec.run(sub, dict(options))
        if not isinstance(res, Outcome):
            raise TypeError(f"driver of {spec.name!r} returned {type(res).__name__}, "
                            "expected DriverOutput")
        return res

    def run(jp: Any, held: frozenset[int]) -> tuple[Any, Outcome, PiecewiseCurve]:
        out = solve(jp, None if tol_v is None else tol_v - jp.margin)
        if not jp.restorable(out.curve):  # the method changed the knots: hold the joins
            jp = _joins.plan(curve, clamp_pair, frozenset(prot) | held, g1_deg, tol_v,
                             allow_reduce=False)
            out = solve(jp, tol_v)
        return jp, out, jp.restore(out.curve)

    # (a long curve's: beside the join plan and the method)
    before_figures = _start_analysis(curve, not spec.two_threads)
    try:
        jp = (_joins.plan(curve, clamp_pair, prot, g1_deg, tol_v) if joins == "keep"
              else _joins.JoinPlan(curve, prot, clamp_pair))
        cached_at_entry.drop_power_form(curve, method_done=False)
        jp, out, new = run(jp, frozenset())
    except Exception:
        before_figures()  # (the input's analysis raises first, as when it ran first)
        raise
    before = before_figures()
    if progress is not None:
        progress(1, PHASES)
    if jp.corners and isinstance(curve, BSplineCurve) and math.isfinite(turn_deg):
        # a corner keeps its angle to DEFAULT_CORNER_TURN: where one turned more, fair again
        # with what fixes it held; if another turns then, with every corner's held
        corners = list(jp.corners)
        held: frozenset[int] = frozenset()
        for attempt in range(2):
            turned = _joins.corner_turns(cast("BSplineCurve", new), corners, turn_deg)
            if not turned:
                break
            held |= turned if attempt == 0 else frozenset().union(*(c.support for c in corners))
            jp, out, new = run(_joins.plan(curve, clamp_pair, frozenset(prot) | held, g1_deg,
                                           tol_v), held)
        if held:
            jp.report["corner_points_held"] = len(held)
    cached_at_entry.drop_power_form(curve, method_done=True)
    cached_at_entry.drop_gram_bands(curve, new)
    if progress is not None:
        progress(2, PHASES)
    if jp.reduced and out.history is not None and len(out.history):
        h = out.history
        out.history = FairingHistory.from_arrays(jp.original_index(h.index), h.measure,
                                                 h.displacement, h.counts)
    from ._tolerance import enforce_tolerance, point_report, prime_power_forms, same_curve

    if same_curve(curve, new):  # the method moved nothing: the input's figures are the result's
        primed, after = None, dict(before)
    else:
        # a 3-D B-spline result on the input's knots: its power form (for the analysis) and
        # the difference curve's (for the certificate below) share one pass over the spans;
        # a planar one's analysis reads its spans' forms range by range (never the whole
        # form), and the certificate makes the difference form after it, not beside it
        primed = prime_power_forms(curve, new) if new.dim == 3 else None
        after = analysis_block(new)
    guard_info: dict[str, Any] = {"kept": "output"}
    from ._guard import _adds, is_chord_interpolant, rebuilt_analysis

    worse = bool(_adds(after, before))
    rebuilt = rb_after = None
    if guard:
        if (type(new) is CubicHermite and type(curve) is CubicHermite
                and np.array_equal(new.params, curve.params)
                and not np.array_equal(new.points, curve.points)
                and is_chord_interpolant(curve)):
            # point data: also judge the curve a reader rebuilds from the written points
            def rebuilt(c: PiecewiseCurve) -> dict[str, Any] | None:
                return rebuilt_analysis(c, analysis_block)

            rb_after = rebuilt(new)
            worse = worse or rb_after is None or bool(_adds(rb_after, before))
            if rb_after is not None:
                guard_info["rebuilt"] = dict(rb_after)
    if guard and worse:
        from ._guard import never_worse

        new, after, guard_info = never_worse(curve, new, before, after, jp, out.curve,
                                             analysis_block, rebuilt, rb_after)
    if progress is not None:
        progress(3, PHASES)
    # the one final guarantee every result passes through (after the joins are restored and
    # the never-worse guard chose): data points within tol in float64 (pulled back if rounding
    # put one outside), curve deviation certified on the difference curve
    checked, cert = enforce_tolerance(curve, new, tol_v, curve_bound=out.curve_within_tol,
                                      primed=primed)
    if checked is not new:
        new, after = checked, analysis_block(checked)
        if rebuilt is not None and "rebuilt" in guard_info:
            # the pulled-back points make their own rebuilt curve
            rb_final = rebuilt(new)
            guard_info["rebuilt"] = None if rb_final is None else dict(rb_final)
    if progress is not None:
        progress(4, PHASES)

    p0 = data_points(curve)
    moved_idx, disp, max_disp, max_idx = point_report(curve, new)
    dev_point = None
    if math.isfinite(cert.param):
        a0, a1 = curve.domain
        dev_point = np.asarray(curve(min(max(cert.param, a0), a1)), dtype=float).reshape(-1)
    history = out.history if out.history is not None else FairingHistory.empty()
    report: dict[str, Any] = {
        "method": spec.name,
        "curve_type": type(curve).__name__,
        "closed": bool(curve.closed),
        "n_points": int(p0.shape[0]),
        "mode": mode if spec.modes != ("spline",) else None,
        "steps": int(out.steps),
        "stop_reason": out.stop_reason,
        "moved": {"indices": moved_idx, "displacement": disp},
        "n_moved": int(moved_idx.size),
        "energy_before": before["energy"],
        "energy_after": after["energy"],
        "max_jump_before": before["max_jump"],
        "max_jump_after": after["max_jump"],
        "energy3_before": before["energy3"],
        "energy3_after": after["energy3"],
        "max_top_jump_before": before["max_top_jump"],
        "max_top_jump_after": after["max_top_jump"],
        "sapidis_sum_before": before["sapidis_sum"],
        "sapidis_sum_after": after["sapidis_sum"],
        "dkds_energy_before": before["dkds_energy"],
        "dkds_energy_after": after["dkds_energy"],
        "inflections_before": before["inflections"],
        "inflections_after": after["inflections"],
        "extrema_before": before["extrema"],
        "extrema_after": after["extrema"],
        "max_point_displacement": max_disp,
        "max_point_index": max_idx,
        "max_deviation": cert.max_distance,
        "max_deviation_upper_bound": _finite_or_none(cert.upper_bound),
        "max_deviation_param": _finite_or_none(cert.param),
        "max_deviation_point": dev_point,
        "tolerance_guard": {"pulled_back": cert.pulled_back, "scale": cert.scale},
        "tol": tol_v,
        "eps": out.eps if out.eps is not None else eps_v,
        "eps_absolute": out.eps_absolute,
        "max_steps": out.max_steps if out.max_steps is not None else max_steps,
        "clamp": list(clamp_pair),
        "protect": sorted(prot),
    }
    if joins == "keep":
        report["joins"] = jp.report
    report["guard"] = guard_info
    for k, v in out.extra.items():
        report.setdefault(k, v)
    report["time_s"] = time.perf_counter() - t_start
    # everything plain Python except the per-point arrays (FairingReport): converting a
    # million of them is what to_dict() does when a JSON file is asked for
    report["moved"] = None
    rep = FairingReport(jsonable(report))
    rep["moved"] = {"indices": readonly(np.asarray(moved_idx, dtype=np.int64)),
                    "displacement": readonly(np.asarray(disp, dtype=np.float64))}
    return FairingResult(new, rep, history, curve)
