"""The C2 cubic spline through points: its slopes (first derivatives) at the data points.

With ``h_i = t_{i+1} - t_i`` and ``d_i = (y_{i+1} - y_i) / h_i``, continuity of the second
derivative at an interior point ``i`` reads (de Boor, *A Practical Guide to Splines*, ch. IV)

    h_i m_{i-1} + 2 (h_{i-1} + h_i) m_i + h_{i-1} m_{i+1} = 3 (h_i d_{i-1} + h_{i-1} d_i),

and an end condition adds one row per end: a given slope ``m_0 = v`` (order 1) or a given second
derivative ``y''(t_0) = v`` (order 2: ``2 m_0 + m_1 = 3 d_0 - v h_0 / 2``; at the right end
``m_{n-2} + 2 m_{n-1} = 3 d_{n-2} + v h_{n-2} / 2``); ``v = 0`` of order 2 is the natural end.
A closed (periodic) spline wraps the interior rows around. The matrix is strictly diagonally
dominant (by a factor 2 in the interior rows), so elimination without pivoting (Thomas) is
stable; the periodic system is solved by the Sherman-Morrison correction of its two corner
entries. The same system is what scipy's ``CubicSpline`` solves (with a banded LU, LAPACK
``gbsv``); the slopes agree with it to rounding (tests), computed in one pass per coordinate with
no temporaries of the data's size (at 1e7 points scipy's took 11 s where the data took 1 s to
build, docs/benchmarks.md).
"""

from __future__ import annotations

from .._jit import njit


@njit(cache=True, readonly=('t', 'y', 'lo_val', 'hi_val'))
def cubic_slopes_kernel(t, y, lo_order, lo_val, hi_order, hi_val, cp, pv, out):  # pragma: no cover
    """Slopes ``out`` (n, dim) of the C2 cubic through ``y`` (n, dim) at increasing ``t``
    (n >= 2) with the end conditions (``*_order`` 1 or 2, ``*_val`` (dim,)). ``cp``, ``pv``
    (n,) are work space: the elimination (row ``i`` becomes ``m_i + cp[i] m_{i+1}``, pivot
    ``pv[i]``) is made once, then applied to every coordinate."""
    n = t.shape[0]
    dim = y.shape[1]
    cp[0] = 0.0 if lo_order == 1 else 0.5
    pv[0] = 1.0 if lo_order == 1 else 2.0
    for i in range(1, n - 1):
        hl = t[i] - t[i - 1]
        hr = t[i + 1] - t[i]
        pv[i] = 2.0 * (hl + hr) - hr * cp[i - 1]
        cp[i] = hl / pv[i]
    pv[n - 1] = 1.0 if hi_order == 1 else 2.0 - cp[n - 2]
    h0 = t[1] - t[0]
    hl = t[n - 1] - t[n - 2]
    for a in range(dim):
        if lo_order == 1:
            out[0, a] = lo_val[a]
        else:
            out[0, a] = (3.0 * ((y[1, a] - y[0, a]) / h0) - 0.5 * lo_val[a] * h0) / pv[0]
        for i in range(1, n - 1):
            hli = t[i] - t[i - 1]
            hri = t[i + 1] - t[i]
            dl = (y[i, a] - y[i - 1, a]) / hli
            dr = (y[i + 1, a] - y[i, a]) / hri
            out[i, a] = (3.0 * (hri * dl + hli * dr) - hri * out[i - 1, a]) / pv[i]
        if hi_order == 1:
            out[n - 1, a] = hi_val[a]
        else:
            dl = (y[n - 1, a] - y[n - 2, a]) / hl
            out[n - 1, a] = (3.0 * dl + 0.5 * hi_val[a] * hl - out[n - 2, a]) / pv[n - 1]
        for i in range(n - 2, -1, -1):
            out[i, a] = out[i, a] - cp[i] * out[i + 1, a]


@njit(cache=True, readonly=('t', 'y'))
def periodic_slopes_kernel(t, y, cp, pv, z, out):  # pragma: no cover - compiled
    """Slopes ``out`` (n, dim) of the periodic C2 cubic through ``y`` (n, dim; ``y[-1]`` repeats
    ``y[0]``) at increasing ``t`` (n >= 4: at least 3 distinct points); ``out[-1] = out[0]``.
    ``cp``, ``pv``, ``z`` (n,) are work space: the elimination of the tridiagonal part (made
    once) and the Sherman-Morrison vector."""
    n = t.shape[0]
    N = n - 1  # unknowns m_0 .. m_{N-1}
    dim = y.shape[1]
    # row i (cyclic): h_i m_{i-1} + 2 (h_{i-1} + h_i) m_i + h_{i-1} m_{i+1}; corners
    # A[0, N-1] = h_0 (beta) and A[N-1, 0] = h_{N-2} (alpha)
    beta = t[1] - t[0]
    alpha = t[N - 1] - t[N - 2]
    hlast = t[N] - t[N - 1]  # h_{N-1} = h_{-1}
    gamma = -2.0 * (hlast + beta)
    # the tridiagonal part with b_0 - gamma and b_{N-1} - alpha beta / gamma, factored once
    # (row 0: diagonal b_0 - gamma, upper h_{-1}); z solves it for u = (gamma, 0, .., 0, alpha)
    pv[0] = 2.0 * (hlast + beta) - gamma
    cp[0] = hlast / pv[0]
    z[0] = gamma / pv[0]
    for i in range(1, N):
        hl = t[i] - t[i - 1]
        hr = t[i + 1] - t[i]
        diag = 2.0 * (hl + hr)
        if i == N - 1:
            diag = diag - alpha * beta / gamma
        pv[i] = diag - hr * cp[i - 1]
        cp[i] = hl / pv[i]
        z[i] = ((alpha if i == N - 1 else 0.0) - hr * z[i - 1]) / pv[i]
    for i in range(N - 2, -1, -1):
        z[i] = z[i] - cp[i] * z[i + 1]
    zf = 1.0 + z[0] + beta * z[N - 1] / gamma
    for a in range(dim):
        dlast = (y[N, a] - y[N - 1, a]) / hlast
        d0 = (y[1, a] - y[0, a]) / beta
        out[0, a] = 3.0 * (beta * dlast + hlast * d0) / pv[0]
        for i in range(1, N):
            hl = t[i] - t[i - 1]
            hr = t[i + 1] - t[i]
            dl = (y[i, a] - y[i - 1, a]) / hl
            dr = (y[i + 1, a] - y[i, a]) / hr
            out[i, a] = (3.0 * (hr * dl + hl * dr) - hr * out[i - 1, a]) / pv[i]
        for i in range(N - 2, -1, -1):
            out[i, a] = out[i, a] - cp[i] * out[i + 1, a]
        f = (out[0, a] + beta * out[N - 1, a] / gamma) / zf
        for i in range(N):
            out[i, a] = out[i, a] - f * z[i]
        out[N, a] = out[0, a]
