"""One local fairing step per published method (pure functions: each returns a new curve).

Indices are 0-based: the papers' ``P_k`` (1-based) is our ``k - 1``. On an open curve a step
needs both neighbours, so ``0 < k < n - 1``; on a closed curve every distinct point can be faired
and ``k = 0`` is the seam (both stored copies are updated; ``k = n - 1`` is accepted as the same
point).

Each step is the exact minimiser of the strain energy ``int |r''(t)|^2 dt`` of the two segments
next to the point, over the data it changes, with every other datum held:

=====================  ===============  ==========================================================
function               curve            changes
=====================  ===============  ==========================================================
:func:`kjellander`     CubicHermite     ``r_k`` (uniform parameters only)
:func:`poliakoff`      CubicHermite     ``r_k``
:func:`wang_cao`       CubicHermite     ``r_k`` and ``r'_k``
:func:`wang_quintic`   QuinticHermite   ``r_k``, ``r'_k`` and ``r''_k``
=====================  ===============  ==========================================================

The automatic loop that ranks points and repeats the steps is :func:`curvefair.fair`.
"""

from __future__ import annotations

import numpy as np

from ._kernels import hermite as _k
from .curves.hermite import CubicHermite, HermiteSpline, QuinticHermite
from .errors import InputError
from .fairing.cheng_yu import cheng_yu  # (Cheng & Yu, cubic B-splines)
from .fairing.eck_hadenfeld import eck_hadenfeld  # (Eck & Hadenfeld, B-splines)
from .fairing.hermite_data import distinct_data, rebuild, uniform_spacing
from .fairing.knot_removal import knot_removal  # (Farin, B-splines)

__all__ = ["kjellander", "poliakoff", "wang_cao", "wang_quintic", "uniform_spacing",
           "bad_point_measure", "eck_hadenfeld", "knot_removal", "cheng_yu"]


# ----------------------------------------------------------------------------------------------
# helpers
# ----------------------------------------------------------------------------------------------
def check_step_index(curve: HermiteSpline, k: object) -> int:
    """Validate a step index (see the module docstring); return the distinct-point index."""
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)):
        raise InputError(f"k must be an integer point index, got {k!r}")
    k = int(k)
    n = curve.n_points
    if curve.closed:
        if not 0 <= k <= n - 1:
            raise InputError(f"k = {k} is out of range for a closed curve with {n} stored points "
                             f"(valid: 0 .. {n - 1}, where {n - 1} is the seam again)")
        return k % (n - 1)
    if n < 3:
        raise InputError(f"a local step needs at least 3 points, the curve has {n}")
    if not 0 < k < n - 1:
        kind = "an end point" if k in (0, n - 1) else "out of range"
        raise InputError(f"k = {k} is {kind}: an open curve's steps need 0 < k < {n - 1} "
                         "(both neighbours)")
    return k


def _need(curve: object, cls: type, fn: str) -> None:
    if not isinstance(curve, cls):
        raise InputError(f"{fn}() needs a {cls.__name__}, got {type(curve).__name__}"
                         + (" (use wang_quintic for quintic curves)" if cls is CubicHermite
                            and isinstance(curve, QuinticHermite) else ""))


def _cubic(curve: CubicHermite, k: object, method: int, fn: str, hstep: float = 0.0
           ) -> CubicHermite:
    _need(curve, CubicHermite, fn)
    kd = check_step_index(curve, k)
    P, D, h = distinct_data(curve)
    delta = np.empty(P.shape[1])
    eta = np.empty(P.shape[1])
    _k.cubic_step(P, D, h, kd, method, hstep, delta, eta)
    P[kd] += delta
    if method == _k.WANG_CAO:
        D[kd, 0] += eta
    return rebuild(curve, P, D)  # type: ignore[return-value]


# ----------------------------------------------------------------------------------------------
# public steps
# ----------------------------------------------------------------------------------------------
def kjellander(curve: CubicHermite, k: int) -> CubicHermite:
    """Kjellander's step on a uniformly parameterised cubic spline: new position of point ``k``.

    Parameters
    ----------
    curve : CubicHermite
        Parameters must be uniformly spaced (any spacing ``h``).
    k : int
        0-based point index (paper's ``k`` minus one); ``0 < k < n-1`` for open curves.

    Returns
    -------
    CubicHermite
        Same tangents, point ``k`` moved.

    Raises
    ------
    InputError
        Non-uniform parameters, wrong curve type, bad index.

    Notes
    -----
    Wang & Cao 2006, eq. (4), generalised to spacing ``h``:
    ``r_k,new = (r_{k-1} + r_{k+1}) / 2 + h (r'_{k-1} - r'_{k+1}) / 4``. It zeroes the jump of
    ``r'''`` at ``t_k`` (eq. (3)) with all tangents held, which is also the exact minimiser of the
    strain energy over ``r_k`` (the same as :func:`poliakoff` on uniform parameters).

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_cubic, steps
    >>> pts = np.column_stack([np.arange(1.0, 8.0), np.ones(7)])
    >>> pts[3] = (4.3, 1.6)
    >>> c = steps.kjellander(interpolate_cubic(pts, "uniform"), 3)
    >>> bool(abs(c.points[3, 1] - 1.0) < abs(1.6 - 1.0))
    True
    """
    _need(curve, CubicHermite, "kjellander")
    hs = uniform_spacing(curve.params)
    if hs is None:
        d = np.diff(curve.params)
        raise InputError("kjellander needs uniformly spaced params; parameter steps range from "
                         f"{d.min()!r} to {d.max()!r} (use poliakoff for non-uniform params)")
    return _cubic(curve, k, _k.KJELLANDER, "kjellander", hs)


def poliakoff(curve: CubicHermite, k: int) -> CubicHermite:
    """Poliakoff's step: new position of point ``k`` of a non-uniform cubic spline.

    Parameters
    ----------
    curve : CubicHermite
    k : int
        0-based point index; ``0 < k < n-1`` for open curves, any point of a closed one.

    Returns
    -------
    CubicHermite
        Same tangents, point ``k`` moved.

    Notes
    -----
    Wang & Cao 2006, eq. (8) as corrected in ERRATA (the printed equation is garbled):
    ``r_k,new = r_k + delta``, ``delta = -(a_{k,3} - a_{k-1,3}) / (2/D_k^3 + 2/D_{k-1}^3)``
    with ``D_i = t_{i+1} - t_i`` (paper indices), i.e. Corollary 1: the exact minimiser of the
    strain energy of the C1 Hermite spline over ``r_k`` with every tangent held. It makes
    ``r'''`` continuous at ``t_k``.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_cubic, steps
    >>> pts = np.column_stack([np.arange(1.0, 8.0), np.ones(7)])
    >>> pts[3] = (4.3, 1.6)
    >>> c = steps.poliakoff(interpolate_cubic(pts), 3)
    >>> c.points[3].round(3).tolist() != [4.3, 1.6]
    True
    """
    return _cubic(curve, k, _k.POLIAKOFF, "poliakoff")


def wang_cao(curve: CubicHermite, k: int) -> CubicHermite:
    """Wang & Cao's step: new position AND tangent of point ``k`` of a cubic spline.

    Parameters
    ----------
    curve : CubicHermite
    k : int
        0-based point index; ``0 < k < n-1`` for open curves, any point of a closed one.

    Returns
    -------
    CubicHermite
        Point ``k`` and its tangent changed.

    Notes
    -----
    Wang & Cao 2006, eqs. (11)-(12), with ``D1 = Delta_k``, ``D0 = Delta_{k-1}``:

    ``delta* = D1^2 D0^2 / (D1 + D0)^3 [2 D1 D0 (a_{k-1,3} - a_{k,3})
    + (D1 - D0)(a_{k,2} - a_{k-1,2} - 3 a_{k-1,3} D0)]``,

    ``eta* = D1 D0 / (D1 + D0)^3 [3 D1 D0 (D1 - D0)(a_{k-1,3} - a_{k,3})
    + 2 (D1^2 - D1 D0 + D0^2)(a_{k,2} - a_{k-1,2} - 3 a_{k-1,3} D0)]``.

    ``(r_k + delta*, r'_k + eta*)`` is the exact minimiser of the strain energy of the two
    segments over ``(r_k, r'_k)`` (Theorem 1); geometrically it is the value and derivative at
    ``t_k`` of the single cubic Hermite segment over ``[t_{k-1}, t_{k+1}]`` with the end data of
    the neighbours (ERRATA). Holding the tangent gives :func:`poliakoff` (Corollary 1).

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_cubic, steps
    >>> pts = np.column_stack([np.arange(1.0, 8.0), np.ones(7)])
    >>> pts[3] = (4.3, 1.6)
    >>> c = steps.wang_cao(interpolate_cubic(pts), 3)
    >>> c.tangents.shape
    (7, 2)
    """
    return _cubic(curve, k, _k.WANG_CAO, "wang_cao")


def wang_quintic(curve: QuinticHermite, k: int) -> QuinticHermite:
    """Wang's quintic step: new position, first and second derivative of point ``k``.

    Parameters
    ----------
    curve : QuinticHermite
    k : int
        0-based point index; ``0 < k < n-1`` for open curves, any point of a closed one.

    Returns
    -------
    QuinticHermite
        Point ``k`` and both its derivatives changed.

    Notes
    -----
    Wang 2005, eqs. (3)-(5) and the Theorem: the change of strain energy is
    ``I = C . x + x^T H x / 2`` per coordinate with ``x = (delta, eta, xi)`` and ``C1, C2, C3``,
    ``H`` as printed (ERRATA: those are right; eta and xi of the printed eq. (4) are not). The
    step solves ``H x = -C`` exactly; ``H_12 = 0`` lets ``eta`` and ``xi`` be eliminated:
    ``delta = -(C1 - H01 C2/H11 - H02 C3/H22) / (H00 - H01^2/H11 - H02^2/H22)``,
    ``eta = -(C2 + H01 delta)/H11``, ``xi = -(C3 + H02 delta)/H22``.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_quintic, steps
    >>> pts = np.column_stack([np.arange(1.0, 8.0), np.ones(7)])
    >>> pts[3] = (4.3, 1.6)
    >>> q = steps.wang_quintic(interpolate_quintic(pts), 3)
    >>> q.d2.shape
    (7, 2)
    """
    _need(curve, QuinticHermite, "wang_quintic")
    kd = check_step_index(curve, k)
    P, D, h = distinct_data(curve)
    dim = P.shape[1]
    delta, eta, xi = np.empty(dim), np.empty(dim), np.empty(dim)
    _k.quintic_step(P, D, h, kd, delta, eta, xi, False)
    P[kd] += delta
    D[kd, 0] += eta
    D[kd, 1] += xi
    return rebuild(curve, P, D)  # type: ignore[return-value]


# ----------------------------------------------------------------------------------------------
# bad-point measures
# ----------------------------------------------------------------------------------------------
_MEASURE_METHODS = {"kjellander": _k.KJELLANDER, "poliakoff": _k.POLIAKOFF,
                    "wang-cao": _k.WANG_CAO, "wang-quintic": _k.WANG_QUINTIC}


def bad_point_measure(curve: HermiteSpline, k: int, method: str = "poliakoff",
                      measure: str | None = None, mode: str = "hermite") -> float:
    """The value by which ``fair(curve, method, measure=measure)`` ranks point ``k``.

    ``measure``: ``"jump"`` (cubic; the papers', ``|r'''(t_k+) - r'''(t_k-)|``, seed 001),
    ``"energy"`` (the exact drop of ``int |r''|^2`` the method's unclamped step achieves on the
    current Hermite data; the quintic's is Wang 2005's ``C^T H^-1 C / 2``, position part only
    in ``mode="spline"``), ``"sapidis"`` (cubic; the jump of ``dkappa/ds``, Sapidis & Farin),
    ``"move"`` (the length of the position change of the method's unclamped step); ``None``:
    the method's published measure. Index rules as for the steps (module docstring).
    """
    from .fairing.local_hermite import measure_code

    if method not in _MEASURE_METHODS:
        raise InputError(f"unknown method {method!r}; valid methods are: "
                         + ", ".join(repr(m) for m in _MEASURE_METHODS))
    cls = QuinticHermite if method == "wang-quintic" else CubicHermite
    _need(curve, cls, "bad_point_measure")
    if mode not in ("spline", "hermite"):
        raise InputError(f"unknown mode {mode!r}; valid values are: 'spline', 'hermite'")
    kd = check_step_index(curve, k)
    _, code = measure_code(measure, curve.degree, method)
    P, D, h = distinct_data(curve)
    hstep = 0.0
    if method == "kjellander":
        hs = uniform_spacing(np.asarray(curve.params))
        if hs is None:
            raise InputError("method 'kjellander' needs uniformly spaced params")
        hstep = hs
    return float(_k.measure_at(P, D, h, kd, curve.degree, mode == "spline",
                               _MEASURE_METHODS[method], hstep, code))
