"""Interpolating splines through data points: C2 cubic and C4 quintic.

Both return Hermite splines (:class:`~curvefair.CubicHermite`, :class:`~curvefair.QuinticHermite`)
whose per-point derivatives are those of the interpolating spline, so the local fairing steps of
seeds 000 and 001 apply directly.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.linalg.lapack import dgbsv, dpbsv

from .._kernels.cubic_spline import cubic_slopes_kernel, periodic_slopes_kernel
from .._typing import ArrayLike, FloatArray
from .._validate import as_points, as_vectors, choice, magnitude
from ..errors import InputError
from .hermite import CubicHermite, QuinticHermite
from .parameterize import _parameterize_valid

__all__ = ["interpolate_cubic", "interpolate_quintic", "BC_NAMES"]

BC_NAMES = ("natural", "clamped", "not-a-knot", "periodic")

# An end condition, as accepted in a (left, right) pair:
#   "natural", "not-a-knot", or (order, vector) with order 1 (given tangent) or 2 (given second
#   derivative) -- the same convention as scipy's ``bc_type``.
EndCondition = Any


def _close_points(pts: FloatArray) -> FloatArray:
    """Repeat the first point last unless it is already there."""
    scale = magnitude(pts)
    if np.allclose(pts[0], pts[-1], rtol=0.0, atol=1e-12 * scale):
        pts = pts.copy()
        pts[-1] = pts[0]
        return pts
    return np.vstack([pts, pts[:1]])


def _prepare(points: ArrayLike, param: Any, bc: Any, min_points: int
             ) -> tuple[FloatArray, FloatArray, bool]:
    periodic = isinstance(bc, str) and bc == "periodic"
    # no copy of a float64 array: the curve made from pts freezes its own copy (none of an
    # array already frozen, e.g. another curve's points), and nothing here writes pts
    pts = as_points(points, "points", min_points=min_points, copy=False)
    if periodic:
        pts = _close_points(pts)
        if pts.shape[0] < 4:
            raise InputError("a periodic (closed) curve needs at least 3 distinct points")
        if isinstance(param, str):
            t = _parameterize_valid(pts, param)
        else:
            t = np.asarray(param, dtype=float)
            if t.shape == (pts.shape[0] - 1,):
                raise InputError(
                    "param for a closed curve needs one value per point plus one for the closing "
                    f"point ({pts.shape[0]} values)")
            t = _parameterize_valid(pts, t)
    else:
        t = _parameterize_valid(pts, param)
    return pts, t, periodic


def _end_condition(spec: Any, which: str, dim: int, natural_orders: tuple[int, ...],
                   end_tangent: FloatArray | None) -> Any:
    """Translate one end's condition into scipy's (order, value) list form."""
    if isinstance(spec, str):
        choice(spec, ("natural", "clamped", "not-a-knot"), f"bc ({which} end)")
        if spec == "natural":
            return [(o, np.zeros(dim)) for o in natural_orders]
        if spec == "clamped":
            if end_tangent is None:
                raise InputError(f'bc="clamped" needs end_tangents=(left, right) ({which} end)')
            if len(natural_orders) == 1:
                return [(1, end_tangent)]
            return [(1, end_tangent), (3, np.zeros(dim))]
        return "not-a-knot"
    try:
        order, value = spec
        order = int(order)
    except (TypeError, ValueError):
        raise InputError(
            f"bc ({which} end) must be 'natural', 'clamped', 'not-a-knot' or (order, vector), "
            f"got {spec!r}") from None
    if order not in (1, 2):
        raise InputError(f"bc ({which} end): derivative order must be 1 or 2, got {order}")
    vec = as_vectors(value, (dim,), f"bc ({which} end) vector")
    if len(natural_orders) == 1:
        return [(order, vec)]
    # quintic: a given derivative plus the natural condition that completes it
    extra = {1: 3, 2: 4}[order]  # the natural complement of the given derivative
    return [(order, vec), (extra, np.zeros(dim))]


def _bc_pair(bc: Any, dim: int, natural_orders: tuple[int, ...],
             end_tangents: ArrayLike | None) -> tuple[Any, Any]:
    tangents: list[FloatArray | None] = [None, None]
    if end_tangents is not None:
        et = as_vectors(end_tangents, (2, dim), "end_tangents")
        tangents = [et[0], et[1]]
    if isinstance(bc, str):
        choice(bc, BC_NAMES, "bc")
        left = right = bc
    else:
        try:
            left, right = bc
        except (TypeError, ValueError):
            raise InputError(f"bc must be one of {BC_NAMES} or a (left, right) pair, got {bc!r}"
                             ) from None
    return (_end_condition(left, "left", dim, natural_orders, tangents[0]),
            _end_condition(right, "right", dim, natural_orders, tangents[1]))


def cubic_slopes(t: FloatArray, pts: FloatArray, bc: Any) -> FloatArray:
    """The slopes (first derivatives) at ``t`` of the C2 cubic spline through ``pts``.

    ``bc``: ``"periodic"`` (``pts[-1]`` repeats ``pts[0]``; at least 3 distinct points), or a
    pair of scipy-style ends, each ``(order, vector)`` with order 1 (given slope) or 2 (given
    second derivative; zero: natural) or ``"not-a-knot"``. Given slopes and second derivatives
    go through the compiled tridiagonal solve of :mod:`curvefair._kernels.cubic_spline` (its
    docstring has the equations); a not-a-knot end through scipy's ``CubicSpline``."""
    t = np.ascontiguousarray(t, dtype=np.float64)
    y = np.ascontiguousarray(pts, dtype=np.float64)
    n, dim = y.shape
    out = np.empty((n, dim))
    cp, pv = np.empty(n), np.empty(n)
    if isinstance(bc, str) and bc == "periodic":
        periodic_slopes_kernel(t, y, cp, pv, np.empty(n), out)
        return out
    left, right = bc
    if isinstance(left, str) or isinstance(right, str):
        # imported here: scipy.interpolate takes 0.3-0.5 s to import, which a points file's
        # reading (natural ends) never needs
        from scipy.interpolate import CubicSpline

        spl = CubicSpline(t, y, bc_type=(left, right), axis=0)
        return np.asarray(spl(t, 1))
    (lo, lv), (hi, hv) = left, right
    cubic_slopes_kernel(t, y, int(lo), np.ascontiguousarray(lv, dtype=np.float64).reshape(dim),
                        int(hi), np.ascontiguousarray(hv, dtype=np.float64).reshape(dim), cp,
                        pv, out)
    return out


def interpolate_cubic(points: ArrayLike, param: str | ArrayLike = "chord", bc: Any = "natural",
                      *, end_tangents: ArrayLike | None = None) -> CubicHermite:
    """C2 interpolating parametric cubic spline, returned as a :class:`CubicHermite`.

    Parameters
    ----------
    points : array_like, shape (n, dim)
        Data points, dim 2 or 3, no two consecutive points equal.
    param : {"uniform", "chord", "centripetal"} or array_like, shape (n,)
        Parameterisation (see :func:`curvefair.parameterize`).
    bc : str or (left, right)
        ``"natural"`` (zero second derivative at both ends, the papers' choice),
        ``"clamped"`` (given end tangents, ``end_tangents=(left, right)``), ``"not-a-knot"``,
        ``"periodic"`` (closed curve; the first point is repeated last unless it already is).
        A pair sets each end on its own: each is ``"natural"``, ``"not-a-knot"``, ``"clamped"``,
        ``(1, tangent)`` or ``(2, second_derivative)``.
    end_tangents : array_like, shape (2, dim), optional
        Tangents for ``"clamped"`` ends.

    Returns
    -------
    CubicHermite
        ``.tangents`` are the spline's first derivatives at the data points.

    Notes
    -----
    The tangents solve the usual tridiagonal C2 system (:func:`cubic_slopes`: compiled, the
    same system scipy's ``CubicSpline`` solves; a not-a-knot end goes through scipy); the
    Hermite form is then exactly the interpolating spline.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_cubic
    >>> pts = np.column_stack([np.arange(1.0, 8.0), np.ones(7)])
    >>> pts[3] = (4.3, 1.6)            # Wang & Cao 2006, Example 1
    >>> c = interpolate_cubic(pts)
    >>> c.degree, c.points.shape
    (3, (7, 2))
    """
    pts, t, periodic = _prepare(points, param, bc, min_points=2)
    if periodic:
        tangents = cubic_slopes(t, pts, "periodic")
    else:
        left, right = _bc_pair(bc, pts.shape[1], (2,), end_tangents)
        scipy_bc = tuple("not-a-knot" if c == "not-a-knot" else c[0] for c in (left, right))
        if pts.shape[0] < 4 and "not-a-knot" in scipy_bc and scipy_bc != ("not-a-knot",) * 2:
            raise InputError("a not-a-knot end needs at least 4 points unless both ends are "
                             "not-a-knot")
        tangents = cubic_slopes(t, pts, scipy_bc)
    # pts and t are _prepare's own validated arrays (given parameters were validated by
    # parameterize; computed ones, e.g. chord lengths, are checked by the constructor)
    out = CubicHermite.__new__(CubicHermite)
    out._init(pts, [tangents], t, periodic, _valid=(True, not isinstance(param, str)))
    if isinstance(param, str) and param == "chord" and isinstance(bc, str) \
            and bc in ("natural", "periodic"):
        # what a point file is read as: fair()'s guard need not rebuild it to recognise it
        # (curvefair.fairing._guard.is_chord_interpolant)
        out._chord_natural = True
    return out


# ----------------------------------------------------------------------------------------------
# C4 quintic: a direct banded solve for the Hermite data (m_i, s_i) = (r'(t_i), r''(t_i))
# ----------------------------------------------------------------------------------------------
# Jerk-energy stiffness of one quintic Hermite segment of width h, unknowns (m_j, s_j, m_j+1,
# s_j+1): entry [a, b] = _KE[a, b] / h**_KE_POW[a, b]. Its rows are the one-sided derivatives
# r''''(t_j+), -r'''(t_j+), -r''''(t_j+1-), r'''(t_j+1-) of the segment (seed 000 eq. (2)
# differentiated) without their position terms. Summed over the segments, the rows of point i
# are jump(r'''') and -jump(r''') (C4 and C3), at an end r'''' and -r''' (natural conditions).
_KE = np.array([[192.0, 36.0, 168.0, -24.0],
                [36.0, 9.0, 24.0, -3.0],
                [168.0, 24.0, 192.0, -36.0],
                [-24.0, -3.0, -36.0, 9.0]])
_KE_POW = np.array([[3, 2, 3, 2], [2, 1, 2, 1], [3, 2, 3, 2], [2, 1, 2, 1]])


def _one_sided(h: FloatArray, delta: FloatArray, m: FloatArray, s: FloatArray
               ) -> tuple[FloatArray, ...]:
    """``r'''``, ``r''''`` at the left and right end of every segment and ``r^(5)``, each
    ``(nseg, dim)``, of the quintic Hermite spline with data ``m``, ``s`` (``nseg + 1`` rows,
    segment j from row j to row j+1); seed 000 eq. (2) with ``D = h``:
    ``a_3 h^2 = 10 e1 - 4 e2 + e3 / 2``, ``a_4 h^3 = -15 e1 + 7 e2 - e3``,
    ``a_5 h^4 = 6 e1 - 3 e2 + e3 / 2`` with ``e1 = b1 / h``, ``e2 = b2``, ``e3 = b3 h``."""
    hh = h[:, None]
    ih = 1.0 / hh
    ih2 = ih * ih
    e1 = (delta - (m[:-1] + 0.5 * s[:-1] * hh) * hh) * ih
    e2 = m[1:] - m[:-1] - s[:-1] * hh
    e3 = (s[1:] - s[:-1]) * hh
    a3 = 10.0 * e1 - 4.0 * e2 + 0.5 * e3
    a4 = -15.0 * e1 + 7.0 * e2 - e3
    a5 = 6.0 * e1 - 3.0 * e2 + 0.5 * e3
    r3l = 6.0 * a3 * ih2
    r4l = 24.0 * a4 * (ih2 * ih)
    r3r = (6.0 * a3 + 24.0 * a4 + 60.0 * a5) * ih2
    r4r = (24.0 * a4 + 120.0 * a5) * (ih2 * ih)
    return r3l, r4l, r3r, r4r, 120.0 * a5 * (ih2 * ih2)


def _guess_rows(h: FloatArray, pts: FloatArray, a: int, b: int, periodic: bool
                ) -> tuple[FloatArray, FloatArray]:
    """Three-point (parabola) estimates ``m`` of ``r'`` and ``s`` of ``r''`` at points ``a ..
    b-1``: exact for data from a quadratic, in particular on a straight line. With ``sig_j =
    (p_{j+1} - p_j) / h_j``: ``m_i = (h_i sig_{i-1} + h_{i-1} sig_i) / (h_{i-1} + h_i)``,
    ``s_i = 2 (sig_i - sig_{i-1}) / (h_{i-1} + h_i)`` (indices mod ``npt`` on a periodic
    curve); an open curve's end points take their neighbour's ``s`` and ``m = sig -+ h s /
    2`` of their segment (two points: the chord's slope, ``s = 0``).

    Made a block of points at a time from the segments the block reads (every value one
    elementwise expression of its own operands: the same bits however the points are cut),
    so that the whole first guess and its temporaries, several arrays of the points' size,
    are never made at once. ``pts`` are the ``h.size + 1`` points (a periodic curve's last
    repeating the first: its point ``npt`` is point 0 again)."""
    dim = pts.shape[1]
    if periodic:
        nseg = h.size
        seg = np.arange(a - 1, b) % nseg  # segments i-1 and i of every point i (mod npt)
        hh = h[seg]
        sig = (pts[seg + 1] - pts[seg]) / hh[:, None]
        ha, hb = hh[:-1, None], hh[1:, None]
        sa, sb = sig[:-1], sig[1:]
        return (hb * sa + ha * sb) / (ha + hb), 2.0 * (sb - sa) / (ha + hb)
    n = h.size + 1
    m = np.empty((b - a, dim))
    s = np.zeros_like(m)
    if n == 2:
        m[:] = (pts[1] - pts[0]) / h[0]
        return m, s

    def inner(lo: int, hi: int) -> tuple[FloatArray, FloatArray]:
        """``m``, ``s`` of the interior points ``lo .. hi-1`` (``1 <= lo < hi <= n-1``)."""
        hh = h[lo - 1:hi]
        sig = (pts[lo:hi + 1] - pts[lo - 1:hi]) / hh[:, None]
        ha, hb = hh[:-1, None], hh[1:, None]
        return ((hb * sig[:-1] + ha * sig[1:]) / (ha + hb),
                2.0 * (sig[1:] - sig[:-1]) / (ha + hb))

    lo, hi = max(a, 1), min(b, n - 1)
    if hi > lo:
        m[lo - a:hi - a], s[lo - a:hi - a] = inner(lo, hi)
    if a == 0:  # s[0] = s[1], m[0] = sig[0] - h[0] s[0] / 2
        s1 = inner(1, 2)[1][0]
        s[0] = s1
        m[0] = (pts[1] - pts[0]) / h[0] - 0.5 * h[0] * s1
    if b == n:  # s[-1] = s[-2], m[-1] = sig[-1] + h[-1] s[-1] / 2
        s2 = inner(n - 2, n - 1)[1][0]
        s[-1] = s2
        m[-1] = (pts[n - 1] - pts[n - 2]) / h[-1] + 0.5 * h[-1] * s2
    return m, s


def _banded(h: FloatArray, npt: int, nseg_band: int, lo: int, up: int, sym: bool = False
            ) -> tuple[FloatArray, FloatArray]:
    """Jacobi scale ``dsc = diag(K)**-1/2`` (shape ``(2 npt,)``, all ``h.size`` segments; a
    periodic seam segment joins point ``npt-1`` to 0) and the scaled stiffness
    ``diag(dsc) K diag(dsc)`` of segments ``0 .. nseg_band-1`` in ``solve_banded`` layout
    (``ab[up + r - c, c] = K[r, c]``). ``ab`` is the view ``full[lo:]`` of a Fortran array
    ``full`` with ``lo`` zero rows on top: the layout LAPACK's ``dgbsv`` factors in place, so
    that :func:`_solve` hands it over without a copy (the copy was 80 bytes a point for every
    row of the band, at the peak of a quintic interpolation). ``sym``: the lower band alone,
    shape ``(4, 2 npt)`` (``ab[r - c, c] = K[r, c]``, ``r >= c``; ``lo = up = 3``), for
    :func:`_solve_spd`."""
    M = 2 * npt
    ih = 1.0 / h
    hp = {1: ih, 2: ih * ih}
    hp[3] = hp[2] * ih
    w = np.stack([192.0 * hp[3], 9.0 * ih], axis=1)
    if h.size == npt:  # periodic: point i ends segment i-1 (mod npt) and starts segment i
        diag = w + np.roll(w, 1, axis=0)
    else:
        diag = np.zeros((npt, 2))
        diag[:-1] += w
        diag[1:] += w
    dsc = diag.reshape(M) ** -0.5
    del w, diag  # (two arrays of 16 bytes a point, not read again: freed before the band)
    if sym:  # the lower band (LAPACK's dpbsv layout, kd = 3): ab[r - c, c] = K[r, c], r >= c
        ab = np.zeros((4, M), order="F")
    else:
        ab = np.zeros((2 * lo + up + 1, M), order="F")[lo:]
    nb = nseg_band
    ds = [dsc[e: e + 2 * nb: 2] for e in range(4)]  # unknown e of every band segment
    # each entry's products in one work array, in place (the same operations in the same
    # order as ``_KE[a, b] * hp[.] * ds[a] * ds[b]``, without two temporaries of the band's
    # length beside the band at a quintic interpolation's peak)
    val = np.empty(nb)
    for a in range(4):
        for b in range(a, 4):
            np.multiply(_KE[a, b], hp[int(_KE_POW[a, b])][:nb], out=val)
            val *= ds[a]
            val *= ds[b]
            if sym:  # (the same sums as the general band's entries below the diagonal)
                ab[b - a, a: a + 2 * nb: 2] += val
                continue
            ab[up + a - b, b: b + 2 * nb: 2] += val
            if b != a:
                ab[up + b - a, a: a + 2 * nb: 2] += val
    return dsc, ab


def _set_row(ab: FloatArray, F: FloatArray, lo: int, up: int, r: int, cols: np.ndarray,
             vals: FloatArray, rhs: FloatArray) -> None:
    """Replace row ``r`` of the banded matrix and right-hand side (row scaled to max 1)."""
    c = np.arange(max(r - lo, 0), min(r + up + 1, ab.shape[1]))
    ab[up + r - c, c] = 0.0
    scale = np.abs(vals).max()
    ab[up + r - cols, cols] = vals / scale
    F[r] = rhs / scale


def _nak_row(k: int, h: FloatArray, dsc: FloatArray) -> tuple[np.ndarray, FloatArray]:
    """Columns and scaled coefficients of ``jump(r^(5))`` at interior point ``k`` in the
    unknowns; ``r^(5) = (720 dp - 360 (m0 + m1) h + 60 (s1 - s0) h^2) / h^5`` per segment."""
    a, b = h[k - 1], h[k]
    cols = np.arange(2 * k - 2, 2 * k + 4)
    vals = np.array([-360.0 / a**4, -60.0 / a**3, 360.0 / b**4 - 360.0 / a**4,
                     60.0 / a**3 + 60.0 / b**3, 360.0 / b**4, -60.0 / b**3]) * dsc[cols]
    return cols, vals


def _end_sign(order: int, side: int) -> float:
    """Sign of a given ``r''''`` (``order`` 4) or ``r'''`` (3) in its end row's right-hand side:
    the rows hold ``+r''''``, ``-r'''`` at the left end (0) and the opposite at the right."""
    return (1.0 if order == 4 else -1.0) * (1.0 if side == 0 else -1.0)


def _solve_spd(ab: FloatArray, rhs: FloatArray) -> FloatArray | None:
    """The solution of ``A y = rhs`` for the symmetric positive definite band ``A`` given by its
    lower band ``ab`` (:func:`_banded` with ``sym=True``), by LAPACK's banded Cholesky
    ``dpbsv``; ``ab`` and a Fortran-ordered ``rhs`` are overwritten (no copy). None if the
    factorisation fails (``A`` not positive definite in floating point): the caller then
    solves the general system (:func:`_solve`)."""
    _, y, info = dpbsv(ab, np.asfortranarray(rhs), lower=1, overwrite_ab=1, overwrite_b=1)
    if info != 0 or not np.isfinite(y).all():
        return None
    return y


def _solve(ab: FloatArray, lo: int, up: int, rhs: FloatArray) -> FloatArray:
    """``solve_banded((lo, up), ab, rhs)``, calling its LAPACK driver ``dgbsv`` directly
    (saves scipy's checks and C-to-Fortran conversions). ``ab`` made by :func:`_banded` is
    factored in place (its values are lost); any other ``ab`` is copied first."""
    full = ab.base
    if not (isinstance(full, np.ndarray) and full.flags.f_contiguous
            and full.shape == (2 * lo + up + 1, ab.shape[1])
            and ab.__array_interface__["data"][0] == full[lo:].__array_interface__["data"][0]
            and not full[:lo].any()):
        full = np.empty((2 * lo + up + 1, ab.shape[1]), order="F")
        full[:lo] = 0.0
        full[lo:] = ab
    _, _, y, info = dgbsv(lo, up, full, np.asfortranarray(rhs), overwrite_ab=1, overwrite_b=1)
    if info != 0 or not np.isfinite(y).all():
        raise InputError("the quintic spline's end conditions do not determine it for these "
                         "points (singular system)")
    return y


#: segments per block of the one-sided derivatives in :func:`quintic_hermite_data`
ONE_SIDED_BLOCK = 65_536


def quintic_hermite_data(pts: FloatArray, t: FloatArray, left: Any, right: Any,
                          periodic: bool) -> tuple[FloatArray, FloatArray]:
    """First and second derivatives at ``t`` of the C4 quintic spline through ``pts``.

    ``left``, ``right``: ``"not-a-knot"`` or two ``(order, vector)`` pairs with distinct orders
    in 1..4 (given ``r'``, ``r''``, ``r'''``, ``r''''`` at that end; scipy's ``bc_type`` form);
    ignored if ``periodic`` (``pts[-1] == pts[0]``). Returns ``(d1, d2)``, shape ``(n, dim)``.

    Solved as a correction ``x = x0 + dx`` of the three-point estimate ``x0``: the right-hand
    side is the residual of ``x0`` (its C3/C4 jumps and end-condition defects, computed
    segment by segment), so the solve's rounding is relative to ``|dx|``, not ``|x|``; on a
    straight line ``dx`` is rounding noise.
    """
    n, dim = pts.shape
    hbar = (t[-1] - t[0]) / (n - 1)  # solve in t / hbar: no over/underflow of h**-5
    h = np.diff(t) / hbar
    nak_any = not periodic and (left == "not-a-knot" or right == "not-a-knot")

    npt = n if not periodic else n - 1
    M = 2 * npt

    def add_first_guess(x: FloatArray) -> FloatArray:
        """``x + x0`` in place (``x`` with ``m``, ``s`` interleaved, shape ``(2 npt, dim)``),
        the first guess made a block of points at a time (:func:`_guess_rows`; ``x + x0``
        and ``x0 + x`` are the same sums)."""
        for a in range(0, npt, ONE_SIDED_BLOCK):
            b = min(a + ONE_SIDED_BLOCK, npt)
            m0, s0 = _guess_rows(h, pts, a, b, periodic)
            x[2 * a:2 * b:2] += m0
            x[2 * a + 1:2 * b:2] += s0
        return x

    rp = np.r_[1:npt, 0] if periodic else np.arange(1, npt)
    r5 = np.empty((h.size, dim)) if nak_any else None
    # the first guess's end rows (m, s at the first and the last distinct point)
    (m_a, s_a), (m_b, s_b) = (_guess_rows(h, pts, 0, 1, periodic),
                              _guess_rows(h, pts, npt - 1, npt, periodic))
    x0_ends = {0: m_a[0], 1: s_a[0], M - 2: m_b[0], M - 1: s_b[0]}

    def residual() -> FloatArray:
        """``f - K x0`` per point (-jump(r''''), jump(r''')), shape ``(2 npt, dim)``,
        Fortran-ordered (filled through an ``(npt, 2, dim)`` view of coordinate-major memory):
        LAPACK solves it in place, no copy of it beside the band. The one-sided derivatives
        are made for a block of segments at a time (elementwise: the same values; an entry's
        two terms added to 0 in either order give the same sum), and so is the first guess
        of the block's points (:func:`_guess_rows`); ``r^(5)`` (into ``r5``) for a
        not-a-knot end only. The first guess is never whole: it is made again, block by
        block, after the solve."""
        res_t = np.zeros((dim, npt, 2))
        res: FloatArray = res_t.transpose(1, 2, 0)
        for a in range(0, h.size, ONE_SIDED_BLOCK):
            b = min(a + ONE_SIDED_BLOCK, h.size)
            delta = pts[a + 1:b + 1] - pts[a:b]  # (np.diff's rows a .. b-1)
            # points a .. b (a periodic curve's point npt is point 0)
            m0, s0 = _guess_rows(h, pts, a, b + 1, periodic)
            r3l, r4l, r3r, r4r, r5b = _one_sided(h[a:b], delta, m0, s0)
            res[a:b, 0] -= r4l
            res[rp[a:b], 0] += r4r
            res[a:b, 1] += r3l
            res[rp[a:b], 1] -= r3r
            if r5 is not None:
                r5[a:b] = r5b
        return res_t.reshape(dim, M).T

    if periodic:
        # A = B + E Ks E^T, B: the open chain without the seam segment (symmetric positive
        # definite for npt >= 3: banded Cholesky), Ks: the seam's scaled 4x4 stiffness on the
        # unknowns E = (m, s at npt-1; m, s at 0)
        res = residual()
        idx = np.array([M - 2, M - 1, 0, 1])

        def rhs(dsc: FloatArray) -> FloatArray:
            """``[res * dsc, E]``, made Fortran-ordered (LAPACK solves it in place)."""
            out = np.zeros((M, dim + 4), order="F")
            np.multiply(res, dsc[:, None], out=out[:, :dim])
            out[idx, dim + np.arange(4)] = 1.0
            return out

        dsc, ab = _banded(h, npt, npt - 1, 3, 3, sym=True)
        Y = _solve_spd(ab, rhs(dsc))
        del ab
        if Y is None:
            dsc, ab = _banded(h, npt, npt - 1, 3, 3)
            Y = _solve(ab, 3, 3, rhs(dsc))
            del ab
        del res
        Ks = _KE / h[-1] ** _KE_POW * dsc[idx][:, None] * dsc[idx][None, :]
        y0, Z = Y[:, :dim], Y[:, dim:]
        # Woodbury: A^-1 f = y0 - Z (I + Ks E^T Z)^-1 Ks E^T y0
        y = y0 - Z @ np.linalg.solve(np.eye(4) + Ks @ Z[idx], Ks @ y0[idx])
        del Y, y0, Z
        y *= dsc[:, None]
        x = add_first_guess(y)
        d1, d2 = np.empty((n, dim)), np.empty((n, dim))  # the last point repeats the first
        d1[:npt] = x[0::2] / hbar
        d2[:npt] = x[1::2] / hbar**2
        d1[npt], d2[npt] = d1[0], d2[0]
        return d1, d2
    nak = (left == "not-a-knot", right == "not-a-knot")
    # r''' and r'''' given at both ends (natural-type ends)
    natural = not (nak[0] or nak[1]) and all(o in (3, 4) for o, _ in [*left, *right])
    if n == 2 and natural:
        # r''' and r'''' given at both ends of one segment never determine it: with r(t)
        # any r + c (t - t0)(t - t1) satisfies them. Natural ends (zeros): the line, c = 0
        # (the first guess), the member that also minimises int |r''|^2.
        if any(np.any(np.asarray(v) != 0) for _, v in [*left, *right]):
            raise InputError("two points with r''' and r'''' given at both ends do not "
                             "determine a quintic")
        m0, s0 = _guess_rows(h, pts, 0, 2, False)
        return m0 / hbar, s0 / hbar**2
    lo = 6 if nak[1] else 3
    up = 6 if nak[0] else 3

    def system(sym: bool) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``(dsc, ab, F)``: the scaled band (the lower band if ``sym``) and right-hand side
        with the end conditions in the end points' rows."""
        dsc, ab = _banded(h, npt, npt - 1, lo, up, sym=sym)
        F = residual()
        F *= dsc[:, None]  # scaled in place: the same products as res * dsc
        for side, cond in enumerate((left, right)):
            pt = 0 if side == 0 else n - 1
            # rows of the end point: r'''' (+ left, - right), r''' (- left, + right)
            rows = (2 * pt, 2 * pt + 1)
            if nak[side]:
                assert r5 is not None
                ks = (1, 2) if side == 0 else (n - 3, n - 2)
                for r, k in zip(rows, ks, strict=True):
                    _set_row(ab, F, lo, up, r, *_nak_row(k, h, dsc), r5[k] - r5[k - 1])
                continue
            if sym:  # r''' and r'''' given: each keeps its own (symmetric) row
                for o, v in cond:
                    r = rows[0 if o == 4 else 1]
                    F[r] += _end_sign(o, side) * (np.asarray(v, dtype=float) * hbar**o) * dsc[r]
                continue
            c = np.arange(4) if side == 0 else np.arange(M - 4, M)  # the end segment's
            orig = [(c, ab[up + r - c, c].copy(), F[r].copy()) for r in rows]
            # a given r' or r'''' takes the r'''' row, r'' or r''' the r''' row
            target = [0 if o in (1, 4) else 1 for o, _ in cond]
            if target[0] == target[1]:
                target[1] = 1 - target[0]
            for (o, v), w in zip(cond, target, strict=True):
                vhat = np.asarray(v, dtype=float) * hbar**o
                if o in (1, 2):
                    u = 2 * pt + o - 1
                    _set_row(ab, F, lo, up, rows[w], np.array([u]), np.array([dsc[u]]),
                             vhat - x0_ends[u])
                else:
                    src = 0 if o == 4 else 1
                    c, vals, rhs = orig[src]
                    _set_row(ab, F, lo, up, rows[w], c, vals,
                             rhs + _end_sign(o, side) * vhat * dsc[rows[src]])
        return dsc, ab, F

    # natural-type ends: the matrix is the jerk energy's stiffness, symmetric positive
    # definite (n >= 3): banded Cholesky on its lower band (4 rows instead of the LU's 10);
    # the general LU otherwise, or if Cholesky fails
    dx: FloatArray | None = None
    if natural:
        dsc, ab, F = system(True)
        dx = _solve_spd(ab, F)
        del ab, F
    if dx is None:
        dsc, ab, F = system(False)
        dx = _solve(ab, lo, up, F)
        del ab, F  # (the band, before the correction is scaled and added)
    dx *= dsc[:, None]
    x = add_first_guess(dx)  # x0 + dx in place: the same sums
    return x[0::2] / hbar, x[1::2] / hbar**2


def interpolate_quintic(points: ArrayLike, param: str | ArrayLike = "chord", bc: Any = "natural",
                        *, end_tangents: ArrayLike | None = None) -> QuinticHermite:
    """C4 interpolating parametric quintic spline, returned as a :class:`QuinticHermite`.

    Parameters
    ----------
    points : array_like, shape (n, dim)
    param : as for :func:`interpolate_cubic`.
    bc : str or (left, right)
        ``"natural"``: ``r''' = r'''' = 0`` at both ends -- the natural end conditions of the
        quintic spline that minimises the jerk energy ``int |r'''|^2 dt`` among C2 interpolants.
        ``"clamped"``: given end tangent and ``r''' = 0`` (the natural complement).
        ``"not-a-knot"`` (needs n >= 6), ``"periodic"`` (closed; the first point is repeated last
        unless it already is). A pair per end: ``"natural"``, ``"clamped"``, ``"not-a-knot"``
        (n >= 4), ``(1, tangent)`` or ``(2, second_derivative)``. A given tangent is completed
        by ``r''' = 0`` and a given second derivative by ``r'''' = 0`` (the variational natural
        complements).
    end_tangents : array_like, shape (2, dim), optional

    Returns
    -------
    QuinticHermite
        With ``d1``, ``d2`` the spline's first and second derivatives at the data points.

    Notes
    -----
    The unknowns are the Hermite data ``m_i = r'(t_i)``, ``s_i = r''(t_i)``; each segment is the
    quintic Hermite interpolant of Wang 2005, eq. (2), so the spline interpolates and is C2 by
    construction. Every interior point adds ``jump(r'''') = 0`` and ``jump(r''') = 0`` (C4 and
    C3; one-sided values from eq. (2) differentiated). These two rows are, up to sign, the
    gradient of the jerk energy ``int |r'''|^2 dt`` with respect to ``(m_i, s_i)``: the matrix
    is the energy's Hessian (symmetric positive definite), and at an end the same rows read
    ``r'''' = 0`` and ``r''' = 0`` (the natural conditions). A given ``r'`` replaces the
    ``r''''`` row and keeps ``r''' = 0``; a given ``r''`` replaces the ``r'''`` row and keeps
    ``r'''' = 0``; a not-a-knot end replaces both by "no jump of ``r^(5)``" at the second and
    third points from that end, so the four end segments are one polynomial (the knots of
    scipy's ``make_interp_spline(k=5)``; one such end needs n >= 4, two need n >= 6).

    Solution: the unknowns are interleaved ``(m_0, s_0, m_1, s_1, ...)``, which makes the matrix
    banded (3 diagonals on each side, 6 beside a not-a-knot end), and scaled symmetrically by
    ``diag(K)**-1/2`` (about ``h**1.5`` for ``m`` and ``h**0.5`` for ``s``, ``h`` the local
    spacing), which keeps it well conditioned for non-uniform spacing. The system is solved for
    the correction to three-point (parabola) estimates of ``r'`` and ``r''`` -- exact on lines
    and parabolas -- with their C3/C4 jumps and end-condition defects as the right-hand side,
    so rounding in the solve is relative to the correction; the result is the spline of the
    given (rounded) data to about 1e-15 relative, and collinear points give the line itself.
    All coordinates are solved at once by LAPACK's banded ``dgbsv`` (what
    ``scipy.linalg.solve_banded`` calls), O(n). A closed curve's cyclic matrix is the open
    chain's band plus the seam segment's 4 x 4 block: Woodbury identity, 4 extra right-hand
    sides. Two points with natural ends: the conditions leave ``c (t - t0)(t - t1)`` free; the
    straight segment (the member that also minimises ``int |r''|^2``) is returned.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_quintic
    >>> q = interpolate_quintic(np.c_[np.cos(np.linspace(0, 3, 9)), np.sin(np.linspace(0, 3, 9))])
    >>> q.degree
    5
    >>> line = interpolate_quintic([[0, 0], [1, 1], [3, 3], [3.5, 3.5]])
    >>> bool(np.abs(line.d2).max() < 1e-14)
    True
    """
    pts, t, periodic = _prepare(points, param, bc, min_points=2)
    n, dim = pts.shape
    left = right = None
    if not periodic:
        left, right = _bc_pair(bc, dim, (3, 4), end_tangents)
        naks = (left == "not-a-knot") + (right == "not-a-knot")
        if naks == 2 and n < 6:
            raise InputError(f"a not-a-knot quintic spline needs at least 6 points, got {n}")
        if naks == 1 and n < 4:
            raise InputError(f"a quintic spline with one not-a-knot end needs at least 4 points, "
                             f"got {n}")
    d1, d2 = quintic_hermite_data(pts, t, left, right, periodic)
    if periodic:
        d1[-1] = d1[0]
        d2[-1] = d2[0]
    return QuinticHermite(pts, d1, d2, t, closed=periodic)
