"""Compiled kernels of B-spline curves (:mod:`curvefair.curves.bspline`) and of the energies
that the B-spline fairing methods minimise.

* basis functions and their derivatives (Piegl & Tiller, *The NURBS Book*, algorithm A2.3):
  :func:`ders_kernel`, behind :func:`curvefair.curves.bspline.basis_derivatives`;
* the piecewise power form of a B-spline, :func:`power_form_kernel` (of the curve itself, and of
  a difference curve in :mod:`curvefair.fairing._tolerance`), and :func:`power_form_pair_kernel`
  (a curve and its difference to another in one pass);
* the banded Gram matrix of the energy ``int |r^(l)|^2``, :func:`gram_kernel`
  (:meth:`curvefair.BSplineCurve.gram_band`), and, in difference form, its product
  :func:`band_residual` and quadratic form :func:`band_energy`, each written once as one row
  (:func:`residual_row`, :func:`energy_row`, inlined by the Eck-Hadenfeld and global fairing
  kernels);
* the natural cubic interpolant's elimination, :func:`natural_cubic_kernel`, and the
  coincident-points check of its input, :func:`first_coincident`
  (:func:`curvefair.interpolate_bspline`).

Indices are 0-based; control indices wrap modulo ``n`` on closed curves (the layout of
:class:`curvefair.BSplineCurve`).
"""

from __future__ import annotations

import numpy as np

from .._jit import njit

# ------------------------------------------------------------------------------------------
# basis functions, power form, Gram band, energy and residual
# ------------------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def _ders_one(knots, p, s, u, base, nder, ndu, left, right, a, out, q):
    """Basis derivatives at one parameter into ``out[q]`` (Piegl & Tiller A2.3); work arrays
    ``ndu`` (p+1, p+1), ``left``/``right`` (p+1,), ``a`` (2, p+1)."""
    ndu[0, 0] = 1.0
    for j in range(1, p + 1):
        left[j] = u - (knots[s + 1 - j] - base)
        right[j] = (knots[s + j] - base) - u
        saved = 0.0
        for r in range(j):
            ndu[j, r] = right[r + 1] + left[j - r]
            temp = ndu[r, j - 1] / ndu[j, r]
            ndu[r, j] = saved + right[r + 1] * temp
            saved = left[j - r] * temp
        ndu[j, j] = saved
    for j in range(p + 1):
        out[q, 0, j] = ndu[j, p]
    for r in range(p + 1):
        s1 = 0
        s2 = 1
        a[0, 0] = 1.0
        for k in range(1, nder + 1):
            d = 0.0
            rk = r - k
            pk = p - k
            if r >= k:
                a[s2, 0] = a[s1, 0] / ndu[pk + 1, rk]
                d = a[s2, 0] * ndu[rk, pk]
            j1 = 1 if rk >= -1 else -rk
            j2 = k - 1 if r - 1 <= pk else p - r
            for j in range(j1, j2 + 1):
                a[s2, j] = (a[s1, j] - a[s1, j - 1]) / ndu[pk + 1, rk + j]
                d += a[s2, j] * ndu[rk + j, pk]
            if r <= pk:
                a[s2, k] = -a[s1, k - 1] / ndu[pk + 1, r]
                d += a[s2, k] * ndu[r, pk]
            out[q, k, r] = d
            s1, s2 = s2, s1
    fac = float(p)
    for k in range(1, nder + 1):
        for j in range(p + 1):
            out[q, k, j] *= fac
        fac *= p - k


@njit(cache=True, readonly=('knots',))
def ders_kernel(knots, p, span, x, nder, local, out):
    ndu = np.empty((p + 1, p + 1))
    left = np.empty(p + 1)
    right = np.empty(p + 1)
    a = np.empty((2, p + 1))
    for q in range(x.shape[0]):
        s = span[q]
        _ders_one(knots, p, s, x[q], knots[s] if local else 0.0, nder, ndu, left, right, a,
                  out, q)


def basis_reference(t, p, i, x):
    """Slow reference of :func:`ders_kernel`'s basis values: ``N_{i,p}(x)`` by recursion.

    The Cox-de Boor recursion, right-continuous, for one basis function at one scalar ``x``:
    the textbook definition, exponential in ``p`` and with no shared triangle, against which
    the kernel's order-0 output is tested (``tests/test_bspline_curve.py``).

    Parameters
    ----------
    t : numpy.ndarray
        Knot vector.
    p : int
        Degree.
    i : int
        Index of the basis function.
    x : float
        Parameter.

    Returns
    -------
    float
        ``N_{i,p}(x)``.
    """
    if p == 0:
        return 1.0 if t[i] <= x < t[i + 1] else 0.0
    a = (0.0 if t[i + p] == t[i] else
         (x - t[i]) / (t[i + p] - t[i]) * basis_reference(t, p - 1, i, x))
    b = (0.0 if t[i + p + 1] == t[i + 1] else
         (t[i + p + 1] - x) / (t[i + p + 1] - t[i + 1]) * basis_reference(t, p - 1, i + 1, x))
    return a + b


@njit(cache=True)
def _factorials(p):
    fact = np.empty(p + 1)
    fact[0] = 1.0
    for k in range(1, p + 1):
        fact[k] = fact[k - 1] * k
    return fact


@njit(cache=True, inline="always")
def _span_basis(knots, p, s, prev, have, ndu, left, right, a, d):
    """Basis derivatives of span ``s`` into ``d[0]`` (local offsets), unless its local knot
    pattern equals the previous span's (kept in ``prev``): then ``d`` already holds bitwise the
    same values. Returns whether ``d`` is valid (``have`` for the next span)."""
    ts = knots[s]
    same = have  # the basis derivatives depend on the local knot pattern only
    for k in range(2 * p):
        v = knots[s - p + 1 + k] - ts
        same = same and v == prev[k]
        prev[k] = v
    if not same:
        _ders_one(knots, p, s, 0.0, ts, p, ndu, left, right, a, d, np.intp(0))
    return True


@njit(cache=True, inline="always")
def _basis_work(p):  # pragma: no cover - compiled
    """The work arrays of :func:`_span_basis` for degree ``p`` (``ndu``, ``left``, ``right``,
    ``a``, the derivatives ``d`` of one parameter), the factorials ``0! .. p!``, the previous
    span's knot pattern and ``have = False``: what a pass over spans starts from."""
    return (np.empty((p + 1, p + 1)), np.empty(p + 1), np.empty(p + 1), np.empty((2, p + 1)),
            np.empty((1, p + 1, p + 1)), _factorials(p), np.empty(2 * p), np.bool_(False))


@njit(cache=True, inline="always")
def _power_form_body(knots, p, spans, ctrl, base, closed, out, out_diff, pair):
    """The loop of :func:`power_form_kernel` (``pair`` False; ``base`` and ``out_diff`` unused)
    and of :func:`power_form_pair_kernel` (``pair`` True). Inlined into both with ``p`` and
    ``pair`` as they are passed, so a call with a constant degree is compiled for that degree
    (its loops unrolled, the work arrays in registers) and performs the same operations in
    the same order as the general one: bitwise the same results."""
    n = ctrl.shape[0]
    dim = ctrl.shape[1]
    ndu, left, right, a, d, fact, prev, have = _basis_work(p)
    for m in range(spans.shape[0]):
        s = spans[m]
        have = _span_basis(knots, p, s, prev, have, ndu, left, right, a, d)
        for k in range(p + 1):
            for e in range(dim):
                acc = 0.0
                acc2 = 0.0
                for b in range(p + 1):
                    i = s - p + b
                    if closed:
                        i = i % n
                    acc += d[0, k, b] * ctrl[i, e]
                    if pair:
                        acc2 += d[0, k, b] * (ctrl[i, e] - base[i, e])
                out[m, k, e] = acc / fact[k]
                if pair:
                    out_diff[m, k, e] = acc2 / fact[k]


@njit(cache=True, nogil=True, readonly=('knots', 'spans', 'ctrl'))
def power_form_kernel(knots, p, spans, ctrl, closed, out):
    """``out[m, k, :] = sum_a N_{s-p+a}^(k)(t_s) d_{s-p+a} / k!`` for ``s = spans[m]`` (control
    indices mod ``n`` for a closed curve): the piecewise power form of the B-spline. A span
    whose local knot pattern equals the previous span's reuses its basis derivatives. Cubics
    (most B-splines) run a copy compiled for degree 3: the same operations, with its loops
    unrolled and its work arrays in registers, which the general loop (trip counts known only
    at run time) cannot have."""
    if p == 3:
        _power_form_body(knots, 3, spans, ctrl, ctrl, closed, out, out, False)
    else:
        _power_form_body(knots, p, spans, ctrl, ctrl, closed, out, out, False)


@njit(cache=True, nogil=True, readonly=('knots', 'spans', 'ctrl', 'base'))
def power_form_pair_kernel(knots, p, spans, ctrl, base, closed, out, out_diff):
    """:func:`power_form_kernel` of ``ctrl`` into ``out`` and of ``ctrl - base`` into
    ``out_diff`` in one pass: the basis derivatives of each span (most of the work) are
    computed once for both. The same operations in the same order as two calls of
    :func:`power_form_kernel` (the second on the array ``ctrl - base``): bitwise the same."""
    if p == 3:
        _power_form_body(knots, 3, spans, ctrl, base, closed, out, out_diff, True)
    else:
        _power_form_body(knots, p, spans, ctrl, base, closed, out, out_diff, True)


@njit(cache=True, nogil=True)
def gram_kernel(knots, p, spans, l, xq, wq, n, closed, W, row0):  # noqa: E741
    """Banded Gram matrix ``W`` (n, 2p+1) of ``int N_i^(l) N_j^(l)`` (see
    :meth:`curvefair.BSplineCurve.gram_band`), accumulated into ``W`` (zeros on entry,
    allocated by numpy: huge pages, see :func:`natural_cubic_kernel`).

    One Gauss-Legendre rule per knot span, on local offsets ``x - knots[s]``; a span whose
    local knot pattern (``knots[s-p+1 .. s+p] - knots[s]``) equals the previous span's reuses
    its element matrix bitwise (uniform knots: a handful of evaluations in all).

    ``row0`` (open curves): ``W`` holds rows ``row0 ..`` of the band, and the rows before it
    are skipped, so that the spans from ``s >= row0`` on accumulate every row from ``row0``
    on completely, in the order of one pass (a row ``r`` sums the spans ``r .. r + p``):
    :meth:`curvefair.BSplineCurve.gram_band` runs the second half of a long curve's spans so
    on a second thread, bitwise the one pass. ``0`` for the whole band.
    """
    nq = xq.shape[0]
    ndu = np.empty((p + 1, p + 1))
    left = np.empty(p + 1)
    right = np.empty(p + 1)
    a = np.empty((2, p + 1))
    d = np.empty((nq, l + 1, p + 1))
    M = np.empty((p + 1, p + 1))
    prev = np.empty(2 * p)
    have = False
    w2 = 2 * p + 1
    Wf = W.reshape(-1)  # W[r, c] = Wf[r w2 + c]
    for m in range(spans.shape[0]):
        s = spans[m]
        ts = knots[s]
        same = have
        for k in range(2 * p):
            v = knots[s - p + 1 + k] - ts
            same = same and v == prev[k]
            prev[k] = v
        if not same:
            h = knots[s + 1] - ts
            for q in range(nq):
                _ders_one(knots, p, s, h * xq[q], ts, l, ndu, left, right, a, d, q)
            for i in range(p + 1):
                for j in range(p + 1):
                    acc = 0.0
                    for q in range(nq):
                        acc += wq[q] * d[q, l, i] * d[q, l, j]
                    M[i, j] = acc * h
            have = True
        if closed and s >= n:  # rows s - p .. s wrap past n - 1
            for i in range(p + 1):
                row = (s - p + i) % n
                for j in range(p + 1):
                    W[row, p + j - i] += M[i, j]
        else:  # the same additions in the same order, flat indices
            base = (s - p - row0) * w2 + p
            for i in range(p + 1):
                if s - p + i < row0:
                    continue
                b = base + i * (w2 - 1)
                for j in range(p + 1):
                    Wf[b + j] += M[i, j]
    return W


@njit(cache=True, inline="always")
def residual_row(W, ks, p, closed, x, i, a, interior):
    """``((W ks) x)_{i, a}`` in the difference form of :func:`band_residual`,
    ``sum_{o != 0} (W[i, p + o] ks) (x_{i+o} - x_i)``; ``ks = 1.0`` gives ``(G x)_{i, a}``
    exactly (a product by 1 is exact), another ``ks`` the residual of the scaled band of the
    global fairing. ``interior`` (``p <= i < n - p``) skips the wrap tests. Inlined at numba IR
    level (no call with array arguments in the callers' loops); the one place this sum is
    written."""
    n = x.shape[0]
    xi = x[i, a]
    acc = 0.0
    for o in range(-p, p + 1):
        if o == 0:
            continue
        j = i + o
        if not interior and (j < 0 or j >= n):
            if not closed:
                continue
            j = j + n if j < 0 else j - n
        acc += (W[i, p + o] * ks) * (x[j, a] - xi)
    return acc


@njit(cache=True, readonly=('W', 'x'))
def band_residual(W, p, closed, x, out):
    """``out = G x`` (per coordinate) for the Gram band ``W`` of
    :meth:`curvefair.BSplineCurve.gram_band`, in difference form
    ``(G x)_i = sum_{o != 0} W[i, p + o] (x_{i+o} - x_i)``.

    Exact for ``l >= 1`` because the rows of ``G`` sum to zero (the basis functions sum to 1,
    their derivatives to 0); unlike ``W @ x`` it does not lose the digits of large coordinates
    (1e6-sized coordinates cost ``W @ x`` about 1e-9 relative).
    """
    n, dim = x.shape
    for i in range(n):
        interior = i >= p and i + p < n
        for a in range(dim):
            out[i, a] = residual_row(W, 1.0, p, closed, x, i, a, interior)


@njit(cache=True, inline="always")
def energy_row(W, p, closed, x, i, e):
    """``e`` less row ``i``'s terms of :func:`band_energy`, ``sum_{o=1..p} W[i, p + o]
    |x_{i+o} - x_i|^2``, subtracted one by one (the caller's sum keeps its order of
    operations). Inlined at numba IR level; the one place this sum is written."""
    n, dim = x.shape
    for o in range(1, p + 1):
        j = i + o
        if j >= n:
            if not closed:
                break
            j -= n
        w = W[i, p + o]
        if w != 0.0:
            d2 = 0.0
            for a in range(dim):
                t = x[j, a] - x[i, a]
                d2 += t * t
            e -= w * d2
    return e


@njit(cache=True, readonly=('W', 'x'))
def band_energy(W, p, closed, x):
    """``x^T G x`` summed over the coordinates, in difference form
    ``-sum_i sum_{o=1..p} W[i, p + o] |x_{i+o} - x_i|^2`` (see :func:`band_residual`): exact
    for ``l >= 1`` and free of the cancellation of large coordinates."""
    e = 0.0
    for i in range(x.shape[0]):
        e = energy_row(W, p, closed, x, i, e)
    return e


# ------------------------------------------------------------------------------------------
# the natural cubic interpolant
# ------------------------------------------------------------------------------------------
@njit(cache=True)
def natural_cubic_kernel(u, pts, T, d, cp):
    """Fill the clamped knot vector ``T`` (m + 6) and the control points ``d`` (m + 2, dim) of
    the natural cubic interpolant (see :func:`curvefair.curves.bspline._natural_cubic`): the
    tridiagonal system solved for every coordinate at once by elimination without pivoting
    (Thomas). Returns False (and leaves ``d`` partly written) when a pivot is tiny against its
    row, for the caller's pivoting fallback; the interior rows are collocation rows of a totally
    positive matrix and the end rows are diagonally dominant, so this does not happen for
    increasing ``u``.

    ``cp`` (m,) is work space. Every large array is allocated by the numpy caller: numpy asks
    for transparent huge pages on large arrays, numba's allocator does not, and first-touch
    page faults on 4 KiB pages are a measurable part of an O(n) kernel."""
    m = u.shape[0]
    dim = pts.shape[1]
    for i in range(3):
        T[i] = u[0]
        T[m + 3 + i] = u[m - 1]
    for i in range(m):
        T[i + 3] = u[i]
    rp = d[1:]  # eliminated right-hand sides, rp[i] = d[i + 1] (overwritten in place)
    # row 0: -(a0 + b0) x_0 + a0 x_1 = -b0 p_0
    a0 = 1.0 / (u[2] - u[0])
    b0 = 1.0 / (u[1] - u[0])
    diag = -(a0 + b0)
    cp[0] = a0 / diag
    for a in range(dim):
        rp[0, a] = -b0 * pts[0, a] / diag
    for i in range(1, m - 1):  # data point i: x_{i-1}, x_i, x_{i+1} at the knot t_k, k = i + 3
        k = i + 3
        tk = T[k]
        den = T[k + 1] - T[k - 1]
        lo = (T[k + 1] - tk) ** 2 / (den * (T[k + 1] - T[k - 2]))
        up = (tk - T[k - 1]) ** 2 / (den * (T[k + 2] - T[k - 1]))
        piv = (1.0 - lo - up) - lo * cp[i - 1]
        if not abs(piv) > 1e-12 * (abs(1.0 - lo - up) + abs(lo * cp[i - 1])):
            return False
        inv = 1.0 / piv
        cp[i] = up * inv
        for a in range(dim):
            rp[i, a] = (pts[i, a] - lo * rp[i - 1, a]) * inv
    # row m - 1: a1 x_{m-2} - (a1 + b1) x_{m-1} = -b1 p_{m-1}
    a1 = 1.0 / (u[m - 1] - u[m - 3])
    b1 = 1.0 / (u[m - 1] - u[m - 2])
    piv = -(a1 + b1) - a1 * cp[m - 2]
    if not abs(piv) > 1e-12 * (abs(a1 + b1) + abs(a1 * cp[m - 2])):
        return False
    for a in range(dim):
        d[m, a] = (-b1 * pts[m - 1, a] - a1 * rp[m - 2, a]) / piv
    for i in range(m - 2, -1, -1):
        for a in range(dim):
            d[i + 1, a] = rp[i, a] - cp[i] * d[i + 2, a]
    for a in range(dim):
        d[0, a] = pts[0, a]
        d[m + 1, a] = pts[m - 1, a]
    return True


@njit(cache=True)
def first_coincident(pts):
    """Index ``i`` of the first pair of consecutive points closer than ``as_points`` accepts
    (every coordinate difference ``<= 4 eps max|pts|``), or -1; one pass, no temporaries."""
    n, dim = pts.shape
    scale = 0.0
    for i in range(n):
        for a in range(dim):
            v = abs(pts[i, a])
            if v > scale:
                scale = v
    thr = 4.0 * 2.220446049250313e-16 * max(scale, 2.2250738585072014e-308)
    for i in range(n - 1):
        same = True
        for a in range(dim):
            if abs(pts[i + 1, a] - pts[i, a]) > thr:
                same = False
                break
        if same:
            return i
    return -1
