"""Automatic local fairing of cubic and quintic interpolating splines (seeds 000 and 001).

Methods registered with :func:`curvefair.fair`:

================  ===============  =============================================================
name              curve            step (see :mod:`curvefair.steps`)
================  ===============  =============================================================
``kjellander``    CubicHermite     Wang & Cao 2006 eq. (4) (uniform parameters only)
``poliakoff``     CubicHermite     eq. (8) as corrected in ERRATA (default for cubics)
``wang-cao``      CubicHermite     eqs. (11)-(12)
``wang-quintic``  QuinticHermite   Wang 2005 eqs. (3)-(5), 3x3 solve (default for quintics)
================  ===============  =============================================================

The loop (Wang & Cao 2006, "Algorithm", steps 1-6)
---------------------------------------------------
1. ``mode="spline"`` (default): the data are (re-)interpolated by the C2 cubic / C4 quintic
   spline with end conditions taken from the input (below), as the papers' examples do.
2. Rank every movable point by its measure (an indexed max tournament tree, ``O(log n)``):

   * cubic methods: the jump of the third derivative ``|r'''(t_k+) - r'''(t_k-)|`` (seed 001,
     "Bad points identification");
   * ``wang-quintic``: the exact drop of the strain energy ``int |r''|^2 dt`` that the Wang
     step achieves (``C^T H^-1 C / 2`` summed over coordinates). In ``mode="spline"`` only the
     part due to the position counts (``S |delta|^2 / 2``, ``S`` the Schur complement of the
     derivative block of ``H``), because the spline recomputes the derivatives. An energy
     ranks points by how much one step can gain, in the same units along the whole curve; the
     jump of the highest discontinuous derivative (``r^(5)`` of a C4 quintic) depends on the
     parameter scaling to the fifth power and ignores the derivative freedom of the step.
3. Fair the worst point with the method's step, clamped onto the tolerance ball around its
   ORIGINAL position (for every method here the clamped position is the exact minimiser of the
   step's energy on that ball, because after optimising the derivatives out the energy is
   isotropic around the unconstrained optimum; in hermite mode the derivatives are then
   re-optimised for the clamped position). A point whose move is ~0 is skipped (ranked out)
   until a neighbour's move changes its measure by more than ``1e-9`` relative: ~0 means at
   most 8 ulp of the data's scale (or ``1e-9 tol``), or -- when the tolerance clamps it -- less
   than ``1e-3`` of the move the step wants (the point sits on its tolerance sphere and could
   only creep along it; letting it creep costs thousands of steps for no visible gain).
4. Spline mode: re-interpolate. Moving one point changes every derivative of the spline, but the
   change decays geometrically away from it (by >= 2 per point for the cubic, ~0.27 on uniform
   parameters; ~0.43 for the quintic), so only a window is solved: the system with the current
   derivatives held outside the window, grown until the change at its edges is below
   ``2**-56`` of the largest change. Cost per step is independent of ``n``.
   Hermite mode: keep the step's own derivatives (Wang-Cao and Wang quintic change them;
   Kjellander and Poliakoff keep the tangents).
5. Repeat until the largest measure is below ``eps``, ``max_steps`` steps were made, or the
   tolerance/protection blocks every remaining move.
6. Tolerance on the whole curve, not only on the data points: the loop keeps every data point
   within ``tol`` of its original, but an interpolating spline can bulge between its points. If
   the certified deviation bound of :func:`curvefair.deviation` exceeds ``tol``, the loop is run
   again (at most twice) with the point tolerance shrunk by ``tol / deviation``, and if the
   curve still strays, every move is scaled back by the common factor that brings the bound to
   ``tol`` (the curve's change is linear in the moves; scaling back never raises the strain
   energy above the start's). The report's ``curve_tolerance`` entry says what was done.

Defaults: ``eps`` = 1e-2 x the initial largest measure for the linear measures (``jump``,
``sapidis``, ``move``) and 1e-4 x for the energies (``energy``, ``wang-quintic``'s default;
quadratic in the move: the same 1 % in amplitude); ``max_steps`` = 20 x the number of movable
points + 1000.

Bad-point measures (``measure=``)
---------------------------------
Step 2 ranks by one of:

* ``"jump"`` (cubic; the papers'): ``|r'''(t_k+) - r'''(t_k-)|`` (seed 001, eq. (7));
* ``"energy"``: the exact drop of ``int |r''|^2`` over the two segments at ``k`` that the
  method's unclamped step achieves on the current Hermite data (cubic: ``x^T H x / 2`` with the
  Hessian of the two segments' energy in ``(r_k, r'_k)``; Kjellander's step is not the
  minimiser, its drop is ``-(g . delta + Hpp |delta|^2 / 2)``); the quintic's published measure;
* ``"sapidis"`` (cubic): the jump of ``dkappa/ds`` at ``t_k`` (Sapidis & Farin 1990, the
  measure of the knot-removal method);
* ``"move"``: the length ``|delta|`` of the position change the method's unclamped step wants.

The third-derivative jump of noise of amplitude ``sigma`` grows like ``sigma / h^3`` with the
local spacing ``h`` and the jump of ``dkappa/ds`` with the curvature, so on data whose spacing
and curvature vary 1:100 (airfoils, clustered at the leading edge) both rank the densest, most
curved stretch first; the energy drop grows like ``sigma^2 / h^3``. The move is in the data's
own units, like ``tol``: the same noise ranks the same everywhere. Defaults
(:data:`DEFAULT_MEASURE`): ``"move"`` for ``poliakoff`` and ``wang-cao``; the published measure
for ``kjellander`` (on its uniform parameters its step is a fixed multiple of Poliakoff's, so
jump, move and energy rank alike) and ``wang-quintic`` (``"energy"``; ``"move"`` was not
fairer overall there). ``measure="jump"`` reproduces the papers' loop exactly.

End conditions (open curves, ``clamp`` per end)
-----------------------------------------------
Spline mode re-interpolates with conditions that the input satisfies, so an unfaired input is
reproduced exactly:

* cubic ``g0``: the input's end second derivative, ``(2, r''(t_0))`` (natural for a natural
  input); ``g1``: the input's end tangent ``(1, r'(t_0))``, kept exactly; ``g2``: ``(1, r'(t_0))``
  and the points next to that end are held (not moved) far enough that a move changes
  ``r''(t_0)`` by less than ``2**-56`` of the move's own effect. A C2 cubic spline cannot take
  both ``r'`` and ``r''`` at one end: moving any single point changes every tangent. The held
  zone is computed exactly from the parameters (about 30 points for uniform parameters); on a
  short curve it can hold every point. Use ``mode="hermite"`` or the quintic for an exact G2
  clamp on short curves.
* quintic (two conditions per end): ``g0``: the input's ``r'''`` and ``r''''`` at the end
  (natural for a natural input); ``g1``: ``r'`` and ``r'''``; ``g2``: ``r'`` and ``r''`` -- exact.

Hermite mode changes only the faired point's data, so the end tangent (and for the quintic the
end second derivative) are never touched; the cubic's end curvature also depends on point 1 and
its tangent, which ``g2`` therefore holds.

Closed curves: every point is eligible, the seam is point 0, ``clamp`` is ignored.
"""

from __future__ import annotations

import time
import warnings
from functools import partial
from typing import Any, cast

import numpy as np

from .._kernels import hermite as _k
from .._typing import FloatArray
from ..curves.hermite import CubicHermite, HermiteSpline, QuinticHermite
from ..curves.interpolate import cubic_slopes, quintic_hermite_data
from ..curves.piecewise import horner_rows
from ..errors import InputError
from .fair import MethodSpec, register_method
from .hermite_data import (
    distinct_data,
    distinct_derivatives,
    distinct_points,
    full_data,
    rebuild,
    uniform_spacing,
)
from .problem import FairingHistory, FairingProblem, Outcome, eps_threshold
from .stop import StopReason

__all__ = ["hermite_solve", "hermite_driver", "prepare", "hold_zone_cubic", "spline_derivatives"]

_THR = 2.0**-56
_W0 = {3: 32, 5: 48}  # 0.27**32, 0.43**48 < 2**-56 on uniform parameters
_WMAX = 4096
_DENSE_MAX = 300  # closed curves with nd * nb <= this use a precomputed dense inverse
_GRAM = {3: _k.hermite_gram(3, 2), 5: _k.hermite_gram(5, 3)}
_Q = {3: 2, 5: 3}

_METHOD_CODE = {"kjellander": _k.KJELLANDER, "poliakoff": _k.POLIAKOFF,
                "wang-cao": _k.WANG_CAO, "wang-quintic": _k.WANG_QUINTIC}


# ----------------------------------------------------------------------------------------------
# spline-mode set-up
# ----------------------------------------------------------------------------------------------
def _end_bc(curve: HermiteSpline, clamp: str, side: int) -> list[tuple[int, FloatArray]]:
    """Re-interpolation conditions at one end (side 0 = left, -1 = right), from the input."""
    t = curve.params[side]
    seg = np.array([0 if side == 0 else curve.n_points - 2])
    # the end segment's own power form (span_coefficients: bit for bit the whole form's row,
    # and Horner's rule as PiecewisePolynomial.evaluate applies it), not the whole curve's:
    # 72 bytes a segment of a planar cubic, alive through the whole loop before
    rows = curve.span_coefficients(seg)
    s = (np.array([t]) - np.asarray(curve.params)[seg])[:, None]
    ev = lambda nu: horner_rows(rows, s, nu)[0]  # noqa: E731
    if curve.degree == 3:
        return [(2, ev(2))] if clamp == "g0" else [(1, ev(1))]
    if clamp == "g0":
        return [(3, ev(3)), (4, ev(4))]
    if clamp == "g1":
        return [(1, ev(1)), (3, ev(3))]
    return [(1, ev(1)), (2, ev(2))]


def spline_derivatives(curve: HermiteSpline, P: FloatArray, clamp: tuple[str, str],
                       g2_segment: tuple[bool, bool] = (False, False)) -> FloatArray:
    """Derivative data ``(nd, nb, dim)`` of the C2 cubic / C4 quintic spline through the
    distinct points ``P`` at ``curve.params``, with the end conditions described in the module
    docstring (periodic for a closed curve).

    ``g2_segment`` (cubic, per end): keep the input's tangents at the end point AND its
    neighbour, so the end segment is the input's own (its end curvature exact) and the spline
    is C2 from the neighbour on (clamped there by the input's tangent)."""
    t = np.asarray(curve.params)
    pts = np.vstack([P, P[:1]]) if curve.closed else P
    if curve.degree == 3:
        if curve.closed:
            ders = [cubic_slopes(t, pts, "periodic")]
        else:
            T0 = np.asarray(cast(CubicHermite, curve).tangents, dtype=np.float64)
            lo = 1 if g2_segment[0] else 0
            hi = t.shape[0] - 2 if g2_segment[1] else t.shape[0] - 1
            d1 = np.array(T0)
            if hi > lo:
                left = (1, T0[1]) if g2_segment[0] else _end_bc(curve, clamp[0], 0)[0]
                right = (1, T0[-2]) if g2_segment[1] else _end_bc(curve, clamp[1], -1)[0]
                d1[lo:hi + 1] = cubic_slopes(t[lo:hi + 1], pts[lo:hi + 1], (left, right))
            ders = [d1]
    else:
        # the banded Hermite solve of interpolate_quintic (make_interp_spline(k=5) is far less
        # accurate: relative errors up to 1e-6 in r', r'' on nearly straight data)
        ends: tuple[Any, Any] = (None, None) if curve.closed else (_end_bc(curve, clamp[0], 0),
                                                  _end_bc(curve, clamp[1], -1))
        ders = list(quintic_hermite_data(pts, t, *ends, curve.closed))
    D = np.stack(ders, axis=1)
    if curve.closed:
        D = D[:-1]
    return np.ascontiguousarray(D)


def hold_zone_cubic(h: FloatArray, thr: float = _THR) -> int:
    """Number of points next to a G2-clamped end of a C2 cubic spline that must be held.

    With the end tangent fixed, the tangent change caused by moving point ``k`` reaches point
    1 multiplied by ``prod_{i=1}^{k-2} g_i``, where ``g_i = -c_i / (b_i + a_i g_{i-1})``
    (``g_0 = 0``) are the forward-elimination ratios of the spline's tridiagonal system
    (``a_i = 2/h_{i-1}``, ``b_i = 4/h_{i-1} + 4/h_i``, ``c_i = 2/h_i``, the Gram matrix of
    ``int |r''|^2``). Points ``1 .. K-1`` are held, ``K`` the first index whose product is
    ``<= thr``. ``h`` are the widths starting at the clamped end.
    """
    n = h.size + 1
    prod = 1.0
    g = 0.0
    k = 2
    while k <= n - 2:
        if prod <= thr:
            return k - 1
        i = k - 1  # row i = k-1 (1-based from the end)
        a = 2.0 / h[i - 1]
        b = 4.0 / h[i - 1] + 4.0 / h[i]
        c = 2.0 / h[i]
        g = -c / (b + a * g)
        prod *= abs(g)
        k += 1
    return max(n - 2, 0)


def _dense_inverse(nd: int, nb: int, h: FloatArray, degree: int) -> FloatArray:
    K0, pe = _GRAM[degree]
    q = _Q[degree]
    H = np.zeros((nd * nb, nd * nb))
    d0 = np.arange(1, nb + 1)
    d1 = np.arange(nb + 2, 2 * nb + 2)
    for j in range(nd):
        Kj = K0 * h[j] ** (1 - 2 * q + pe[:, None] + pe[None, :])
        rows = [j * nb + e for e in range(nb)]
        cols = [((j + 1) % nd) * nb + e for e in range(nb)]
        H[np.ix_(rows, rows)] += Kj[np.ix_(d0, d0)]
        H[np.ix_(cols, cols)] += Kj[np.ix_(d1, d1)]
        H[np.ix_(rows, cols)] += Kj[np.ix_(d0, d1)]
        H[np.ix_(cols, rows)] += Kj[np.ix_(d1, d0)]
    return np.ascontiguousarray(np.linalg.inv(H))


# ----------------------------------------------------------------------------------------------
# the driver
# ----------------------------------------------------------------------------------------------
def _end_second_derivative_kept(curve: HermiteSpline, clamp: tuple[str, str]) -> list[bool]:
    """Per end: does the C2 re-interpolation (end tangent clamped) keep the input's end
    second derivative ``r''(t_end)`` to 1e-12 of its size? True for an input that is already
    such a spline; only then can the hold zone keep a ``g2`` clamp.

    The end segment's ``r''`` at ``t_0`` is ``6 (P_1 - P_0) / h^2 - (4 D_0 + 2 D_1) / h``
    (the cubic Hermite basis), and symmetrically at the right end.
    """
    P, D, h = distinct_data(curve)
    Dn = spline_derivatives(curve, P, clamp)[:, 0]
    D = D[:, 0]

    def r2(Dv: FloatArray, side: int) -> FloatArray:
        if side == 0:
            return 6 * (P[1] - P[0]) / h[0] ** 2 - (4 * Dv[0] + 2 * Dv[1]) / h[0]
        return -6 * (P[-1] - P[-2]) / h[-1] ** 2 + (4 * Dv[-1] + 2 * Dv[-2]) / h[-1]

    out = []
    for side in (0, 1):
        a, b = r2(D, side), r2(Dn, side)
        size = max(float(np.abs(a).max()), float(np.abs(D).max()) / h[0 if side == 0 else -1])
        out.append(bool(np.abs(a - b).max() <= 1e-12 * max(size, 1e-300)))
    return out


_MEASURE_REPORT = {"jump": "third_derivative_jump", "energy": "energy_drop",
                   "sapidis": "dkappa_ds_jump", "move": "step_length"}
MEASURES = {3: ("jump", "energy", "sapidis", "move"), 5: ("energy", "move")}
"""``measure=`` values per degree; the first is the papers' (the default)."""
_MEASURE_CODE = {"jump": _k.M_DEFAULT, "energy": _k.M_ENERGY, "sapidis": _k.M_SAPIDIS,
                 "move": _k.M_MOVE}


#: ``measure=None``: the default measure per method (chosen on the quality benchmark, see
#: CHANGELOG); a method not listed uses its published one (the first of :data:`MEASURES`).
DEFAULT_MEASURE = {"poliakoff": "move", "wang-cao": "move"}


def measure_code(measure: str | None, degree: int, method: str) -> tuple[str, int]:
    """``(name, kernel code)`` of a ``measure=`` option (``None``: the method's default,
    :data:`DEFAULT_MEASURE`, else its published measure); InputError naming the valid
    values otherwise."""
    valid = MEASURES[degree]
    if measure is None:
        measure = DEFAULT_MEASURE.get(method, valid[0])
    if not isinstance(measure, str) or measure not in valid:
        raise InputError(f"unknown measure {measure!r} for method {method!r}; valid values "
                         "are: " + ", ".join(repr(m) for m in valid))
    if degree == 5 and measure == "energy":
        return measure, _k.M_DEFAULT
    return measure, _MEASURE_CODE[measure]


def prepare(curve: HermiteSpline, *, method: str, tol: float | None, eps: float | None,
            max_steps: int | None, clamp: tuple[str, str], protect: frozenset[int],
            mode: str = "spline", measure: str | None = None) -> dict[str, Any]:
    """Validate and set up everything the compiled loop needs (``O(n)``); see
    :func:`hermite_driver`. Returns a dict with the kernel arguments under ``"args"`` (in the
    order of :func:`curvefair._kernels.hermite.drive`) and bookkeeping entries."""
    degree = curve.degree
    code = _METHOD_CODE[method]
    mname, mcode = measure_code(measure, degree, method)
    spline = mode == "spline"
    # spline mode replaces the derivative data by the re-interpolation's (step 1): the input's
    # are read in place there, not copied beside the re-interpolation (2x the coordinates'
    # bytes of a quintic at its peak)
    D: FloatArray | None
    if spline:
        P, h = distinct_points(curve)
        D = None
    else:
        P, D, h = distinct_data(curve)
    nd, dim = P.shape
    nb = len(curve._derivs)
    closed = curve.closed
    if closed and nd < 3:
        raise InputError(f"method {method!r} needs at least 3 distinct points on a closed "
                         f"curve, got {nd}")
    if not closed and nd < 3:
        raise InputError(f"method {method!r} needs at least 3 points (one interior point), "
                         f"got {nd}")
    hstep = 0.0
    if code == _k.KJELLANDER:
        hs = uniform_spacing(np.asarray(curve.params))
        if hs is None:
            raise InputError("method 'kjellander' needs uniformly spaced params "
                             "(use 'poliakoff' for non-uniform params)")
        hstep = hs
    extra: dict[str, Any] = {}

    # -- who may move
    eligible = np.ones(nd, dtype=np.bool_)
    held: list[int] = []
    g2_segment = [False, False]
    if not closed:
        eligible[0] = eligible[-1] = False
        if degree == 3 and spline:
            kept = (_end_second_derivative_kept(curve, clamp) if "g2" in clamp
                    else [True, True])
            for side, cl in enumerate(clamp):
                if cl == "g2":
                    nh = hold_zone_cubic(h if side == 0 else h[::-1])
                    if 2 * nh <= nd - 2 and kept[side]:
                        zone = range(1, 1 + nh) if side == 0 else range(nd - 1 - nh, nd - 1)
                    else:
                        # not a C2 spline at this end, or the zone would hold most points:
                        # keep the end segment itself (tangents at the end and its neighbour)
                        g2_segment[side] = True
                        zone = range(1, 2) if side == 0 else range(nd - 2, nd - 1)
                    held.extend(zone)
            if "g2" in clamp:
                extra["g2_hold"] = ["segment" if g else ("zone" if cl == "g2" else None)
                                    for g, cl in zip(g2_segment, clamp, strict=True)]
        elif degree == 3 and not spline:
            if clamp[0] == "g2":
                held.append(1)
            if clamp[1] == "g2":
                held.append(nd - 2)
    held = sorted(set(held))
    for i in held:
        eligible[i] = False
    for i in protect:
        eligible[i] = False
    fixed = np.zeros((nd, nb), dtype=np.bool_)
    if spline and not closed:
        for side, cl in enumerate(clamp):
            i = 0 if side == 0 else nd - 1
            fixed[i, 0] = cl in ("g1", "g2")
            if degree == 5:
                fixed[i, 1] = cl == "g2"
            if g2_segment[side]:
                fixed[1 if side == 0 else nd - 2, 0] = True

    # -- step 1: (re-)interpolate (derivatives given by the end conditions stay bit-identical)
    if spline:
        D_new = spline_derivatives(curve, P, clamp, (g2_segment[0], g2_segment[1]))
        ders = distinct_derivatives(curve)
        for b in range(nb):
            D_new[fixed[:, b], b] = ders[b][fixed[:, b]]
        # max |.| per derivative as max(max, -min) of each coordinate's column (exact, as the
        # reduction of |.| over axes (0, 2) is, without its temporaries of the data's size)
        change = 0.0
        for b in range(nb):
            big = sml = 0.0
            for c in range(dim):
                col, dif = ders[b][:, c], D_new[:, b, c] - ders[b][:, c]
                big = max(big, float(col.max()), -float(col.min()))
                sml = max(sml, float(dif.max()), -float(dif.min()))
            change = max(change, sml / (big + 1e-300))
        extra["input_reinterpolation_change"] = change
        D = D_new
    assert D is not None

    # -- ranking and defaults
    meas, values, tv, ti, blocked, block_measure = _k.drive_setup(
        P, D, h, closed, degree, spline, eligible, code, hstep, mcode)
    m0 = float(meas[eligible].max()) if eligible.any() else 0.0
    # 1 % in amplitude: an energy is quadratic in the move, the other measures linear
    rel = 1e-4 if mname == "energy" else 1e-2
    eps_rel, eps_eff = eps_threshold(eps, m0, rel)
    n_elig = int(eligible.sum())
    max_eff = 20 * n_elig + 1000 if max_steps is None else int(max_steps)
    # max |P| + the largest extent of a coordinate, as 1-D reductions of each column (exact:
    # np.abs(P).max() + np.ptp(P, axis=0).max(), without a reduction across the short axis)
    cols = [(float(P[:, c].max()), float(P[:, c].min())) for c in range(P.shape[1])]
    scale = max(max(hi, -lo) for hi, lo in cols) + max(hi - lo for hi, lo in cols)
    floor: float = 8.0 * np.finfo(float).eps * scale
    if tol is not None:
        floor = max(floor, 1e-9 * tol)
    K0, pe = _GRAM[degree]
    q = _Q[degree]
    Hinv = np.zeros((0, 0))
    if spline and closed and nd * nb <= _DENSE_MAX:
        Hinv = _dense_inverse(nd, nb, h, degree)
    # the loop's tolerance centres and the start of a re-run: the input's own distinct points
    # (read only, never written; P's values before the loop), not a copy
    orig = np.asarray(curve.points, dtype=np.float64)[:nd]
    args = (P, D, h, orig, closed, degree, code, spline, hstep, eligible,
            np.inf if tol is None else float(tol), eps_eff, max_eff, floor,
            K0, pe, q, fixed, Hinv, _W0[degree], _WMAX, _THR, meas, values, tv, ti,
            blocked, block_measure, mcode)
    return {"args": args, "extra": extra, "held": held, "eligible": eligible, "m0": m0,
            "floor0": 8.0 * np.finfo(float).eps * scale,
            "measure_name": mname,
            "P0": orig, "D0": D.copy(),
            "eps": eps_eff, "eps_rel": eps_rel, "max_steps": max_eff, "n_elig": n_elig,
            "measure": meas,
            "P": P, "D": D, "spline": spline, "degree": degree, "nd": nd, "Hinv": Hinv}


_CURVE_TOL_RERUNS = 2
_SHRINK = 0.98
# the entries of prepare()'s "args" that drive() modifies in place: P, D, measure, values, tv,
# ti, blocked, block_measure
_DRIVE_STATE = (0, 1, 22, 23, 24, 25, 26, 27)


def _restart(st: dict[str, Any], tol: float) -> dict[str, Any]:
    """:func:`prepare`'s result for another point tolerance, after a run that changed ``st``'s
    loop state: the loop's start again from the pristine data ``st["P0"]``, ``st["D0"]``
    (copies) and the same compiled set-up :func:`prepare` ran on them
    (:func:`curvefair._kernels.hermite.drive_setup`: the same measures, tree and flags, bit
    for bit); only ``tol`` and the move floor differ. The run's state is dropped first.

    Rebuilding costs one measure pass and one tree build. The alternative, a copy of the
    first state kept for a re-run, holds about 125 bytes a point (8x a planar input's
    coordinates) through the whole call, and its copies took 1.4 s of a 1e7-point call."""
    args: list[Any] = list(st["args"])
    for k in _DRIVE_STATE:
        args[k] = None
    out = st  # the caller's, updated in place: nothing keeps the run's state alive
    out["args"] = None
    out["P"] = out["D"] = out["measure"] = None
    P, D = out["P0"].copy(), out["D0"].copy()
    h, closed, degree, code, spline, hstep, eligible = (args[2], args[4], args[5], args[6],
                                                       args[7], args[8], args[9])
    state = _k.drive_setup(P, D, h, closed, degree, spline, eligible, code, hstep, args[28])
    args[0], args[1] = P, D
    for k, a in zip(_DRIVE_STATE[2:], state, strict=True):
        args[k] = a
    args[10] = float(tol)
    args[13] = max(out["floor0"], 1e-9 * tol)
    out["args"] = tuple(args)
    out["P"], out["D"], out["measure"] = P, D, args[22]
    return out


def _curve_deviation(curve: HermiteSpline, P: FloatArray, D: FloatArray) -> float:
    """Certified upper bound of ``max_t |curve(t) - new(t)|`` (Bernstein hull bound), ``new``
    the curve with ``curve``'s parameters and distinct data ``P``, ``D``: measured on the
    difference curve, one piece at a time (:func:`curvefair.analysis.hermite_delta_deviation`;
    with a non-finite coefficient, on its whole power form,
    :func:`curvefair.fairing._tolerance.delta_deviation`, which reports it)."""
    from ..analysis import hermite_delta_deviation
    from ._tolerance import delta_deviation

    got = hermite_delta_deviation(curve, P, tuple(D[:, k] for k in range(D.shape[1])))
    if got is not None:
        return got[1]
    nd = P.shape[0]
    dP, dD = full_data(curve, P - np.asarray(curve.points)[:nd],
                       D - np.stack([np.asarray(d)[:nd] for d in curve._derivs], axis=1))
    if isinstance(curve, QuinticHermite):
        delta = {"points": dP, "d1": dD[:, 0], "d2": dD[:, 1]}
    else:
        delta = {"points": dP, "tangents": dD[:, 0]}
    return float(cast(float, delta_deviation(curve, delta).upper_bound))


def _enforce_curve_tol(curve: HermiteSpline, st: dict[str, Any], tol: float,
                       dev: float) -> tuple[float, float]:
    """Make the whole output curve, not only its data points, stay within ``tol``.

    The output differs from the (re-interpolated) start by ``s * (P - P0, D - D0)`` with
    ``s = 1``; both the spline re-interpolation and the Hermite form are linear in the data, so
    the curve's change scales with ``s`` exactly. If the certified deviation bound exceeds
    ``tol``, ``s`` is reduced (closed form, then bisection if the start itself differs from the
    input) until it does not. Scaling a move towards the start never raises the convex strain
    energy above the start's. Updates ``st["P"]``, ``st["D"]`` in place; returns ``(s, bound)``.
    """
    if dev <= tol:
        return 1.0, dev
    P, D, P0, D0 = st["P"], st["D"], st["P0"], st["D0"]
    dP, dD = P - P0, D - D0

    def at(s: float) -> float:
        return _curve_deviation(curve, P0 + s * dP, D0 + s * dD)

    d0 = at(0.0)
    if d0 > tol:
        raise InputError(
            f"re-interpolating the input already moves the curve by {d0:.6g} > tol = {tol:.6g}; "
            "use mode='hermite' or an input that is already an interpolating spline")
    s = (1.0 - 1e-9) * (tol - d0) / max(dev - d0, 1e-300)  # exact when d0 == 0
    d = at(s)
    if d > tol:  # the start differs from the input: bisect, keeping a feasible lower end
        lo, hi, d = 0.0, s, d0
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            dm = at(mid)
            if dm <= tol:
                lo, d = mid, dm
            else:
                hi = mid
            if hi - lo <= 1e-3 * hi:
                break
        s = lo
    P[...] = P0 + s * dP
    D[...] = D0 + s * dD
    return float(s), float(d)


def hermite_solve(problem: FairingProblem, *, method: str, tol_on: str = "curve",
                  measure: str | None = None, **options: Any) -> Outcome:
    """The four Hermite methods as solvers of ``problem`` (see the module docstring); called
    by :func:`fair`. ``problem.eps`` is relative to the largest initial bad-point measure
    (default ``1e-2``, ``1e-4`` for an energy measure: 1 % in amplitude).

    ``tol_on="curve"`` (default) keeps the whole output curve within ``tol`` of the input
    (step 6 of the module docstring); ``tol_on="points"`` bounds only the data points, as the
    papers' loop does, and the curve may then bulge past ``tol`` between them.

    ``measure`` chooses how the loop ranks the points (module docstring, "Bad-point
    measures"); ``None`` is the method's published measure, and ``"jump"`` (cubic) or
    ``"energy"`` (quintic) name it explicitly (bit-identical results).
    """
    if options:
        raise InputError(f"method {method!r} got unknown options {sorted(options)}")
    from .._validate import choice

    choice(tol_on, ("curve", "points"), "tol_on")
    t0 = time.perf_counter()
    curve = cast(HermiteSpline, problem.curve)
    tol, protect = problem.tol_or_none, problem.protect
    kw: dict[str, Any] = dict(method=method, eps=problem.eps, max_steps=problem.max_steps,
                              clamp=problem.clamp, protect=protect, mode=problem.mode,
                              measure=measure)
    point_tol = tol
    for attempt in range(_CURVE_TOL_RERUNS + 1):
        if attempt == 0:
            st = prepare(curve, tol=point_tol, **kw)
        else:
            st = _restart(st, cast(float, point_tol))  # from the same start
        (steps, stop, h_idx, h_meas, h_disp, blocked, n_trunc, n_skip,
         max_window) = _k.drive(*st["args"])
        if tol is None or tol_on == "points":
            break
        dev = _curve_deviation(curve, st["P"], st["D"])
        if dev <= tol or attempt == _CURVE_TOL_RERUNS:
            break
        # the curve between the data points strays farther than the points: fair again with
        # the points held proportionally closer (the curve change is linear in the moves)
        point_tol = cast(float, point_tol) * _SHRINK * tol / dev
    if tol is not None and tol_on == "curve":
        scale, dev = _enforce_curve_tol(curve, st, tol, dev)
        st["extra"]["curve_tolerance"] = {
            "point_tol_used": float(cast(float, point_tol)), "reruns": attempt, "scale": scale,
            "deviation_upper_bound": float(dev)}
    P, D, measure, eligible = st["P"], st["D"], st["measure"], st["eligible"]
    eps_eff, n_elig, spline, degree = st["eps"], st["n_elig"], st["spline"], st["degree"]
    extra, held, m0, Hinv, nd = st["extra"], st["held"], st["m0"], st["Hinv"], st["nd"]
    reason: StopReason
    if stop == _k.STOP_MAX_STEPS:
        reason = "max_steps"
    elif stop == _k.STOP_EPS:
        reason = "eps"
        if np.any((blocked != 0) & eligible & (measure >= eps_eff)):
            reason = "tolerance"
    elif n_elig == 0:
        reason = "no_movable_point"
    else:
        reason = "tolerance" if np.any(blocked == 1) else "converged"
    if n_elig == 0 and held and nd > 2 and \
            set(range(1, nd - 1)) <= set(held) | set(protect):
        # the G2 hold of a short C2 cubic spline covers every interior point: say why
        # nothing moved (the hold is exact, from hold_zone_cubic; see the module docstring)
        note = (f"clamp='g2' on this {nd}-point C2 cubic spline holds the points next to each "
                f"G2-clamped end ({len(held)} in all) so that no move can change the end "
                "curvature, and that covers every interior point: nothing was moved. For an "
                "exact G2 clamp on a short curve use mode='hermite' (CLI: --mode hermite) or "
                "a quintic spline (interpolate_quintic), or clamp='g1'")
        extra["g2_hold_covers_all"] = True
        extra["note"] = note
        warnings.warn(note, UserWarning, stacklevel=2)
    if not (np.isfinite(P).all() and np.isfinite(D).all()):  # pragma: no cover - safety net
        raise FloatingPointError(f"method {method!r} produced non-finite data")
    extra.update({
        "measure": _MEASURE_REPORT[st["measure_name"]] if degree == 3 or
                   st["measure_name"] != "energy" else
                   ("energy_drop_position" if spline else "energy_drop"),
        "measure_max_before": m0,
        "measure_max_after": float(cast(FloatArray, measure)[eligible].max()) if n_elig else 0.0,
        "held": sorted(held),
        "skipped": int(n_skip),
        "blocked_by_tol": int(np.sum(blocked == 1)),
    })
    # the loop's state is no longer read: freed before the result's copies are made
    eps_rel, max_eff = st["eps_rel"], st["max_steps"]
    st.clear()
    del measure, eligible, blocked
    # no step taken: the input is returned as it was (spline mode would otherwise hand back its
    # re-interpolation, a changed curve reported as "0 steps")
    new = curve if int(steps) == 0 else rebuild(curve, P, D)
    del P, D
    extra["driver_time_s"] = time.perf_counter() - t0
    if spline:
        extra["window_max_points"] = int(nd if Hinv.shape[0] else max_window)
        extra["window_truncations"] = int(n_trunc)
    return Outcome(new, int(steps), reason,
                   FairingHistory.from_arrays(h_idx, h_meas, h_disp, "data point"),
                   eps=eps_rel, max_steps=max_eff, extra=extra,
                   curve_within_tol=tol_on == "curve", eps_absolute=eps_eff)


#: The former name of :func:`hermite_solve` (keyword form, as ``MethodSpec.driver``).
def hermite_driver(curve: HermiteSpline, *, method: str, tol: float | None, eps: float | None,
                   max_steps: int | None, clamp: tuple[str, str], protect: frozenset[int],
                   mode: str = "spline", **options: Any) -> Outcome:
    """:func:`hermite_solve` with the shared options as keywords (already checked)."""
    prob = FairingProblem(curve, np.inf if tol is None else float(tol), eps, max_steps,
                          clamp, frozenset(protect), mode, dict(options))
    return hermite_solve(prob, method=method, **options)


_SPECS = [
    ("kjellander", (CubicHermite,), False,
     "Kjellander: new position zeroing the third-derivative jump (uniform parameters)",
     "Wang & Cao 2006 (seed 001), eq. (4)"),
    ("poliakoff", (CubicHermite,), True,
     "Poliakoff: energy-optimal new position, tangents held (non-uniform parameters)",
     "Wang & Cao 2006 (seed 001), eq. (8) corrected in ERRATA; Corollary 1"),
    ("wang-cao", (CubicHermite,), False,
     "Wang-Cao: energy-optimal new position and tangent",
     "Wang & Cao 2006 (seed 001), eqs. (11)-(14)"),
    ("wang-quintic", (QuinticHermite,), True,
     "Wang: energy-optimal new position, first and second derivative of a quintic spline",
     "Wang 2005 (seed 000), eqs. (3)-(5), H x = -C solved exactly (ERRATA)"),
]

_MEASURE_RUN = ("python benchmarks/quality/measures.py --only hermite --instances 2 "
                "--airfoils 120 --glyphs 40")
_DEFAULT_REASON = {
    "poliakoff": "ranked by measure=move: airfoil extrema ratio median 0.75 (the papers' jump "
                 "0.952, kjellander 1.14, wang-cao with move 0.73), glyph runs 0.58 [" +
                 _MEASURE_RUN + "]",
    "wang-quintic": "the only method for quintic Hermite splines; airfoil extrema ratio "
                    "median 1 (0.927 with eps=0), glyph runs 0.515 [" + _MEASURE_RUN + "]",
}

for _name, _types, _default, _summary, _source in _SPECS:
    register_method(MethodSpec(_name, _types, summary=_summary, source=_source,
                               solver=partial(hermite_solve, method=_name),
                               default=_default, modes=("spline", "hermite"),
                               default_reason=_DEFAULT_REASON.get(_name, "")))
