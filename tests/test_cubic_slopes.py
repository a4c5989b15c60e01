"""The compiled slopes of the C2 cubic spline (curvefair._kernels.cubic_spline) against exact
rational arithmetic and against scipy's CubicSpline, for every end condition."""

from fractions import Fraction as Fr

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

import curvefair as cf
from curvefair.curves.interpolate import cubic_slopes


def _exact(t, y, ends):
    """Slopes by exact Gaussian elimination of the C2 system (ends: 'periodic' or
    ((order, v), (order, v)) with scalar v)."""
    n = len(t)
    T = [Fr(float(x)) for x in t]
    Y = [Fr(float(v)) for v in y]
    h = [T[i + 1] - T[i] for i in range(n - 1)]
    d = [(Y[i + 1] - Y[i]) / h[i] for i in range(n - 1)]
    periodic = ends == "periodic"
    N = n - 1 if periodic else n
    A = [[Fr(0)] * N for _ in range(N)]
    r = [Fr(0)] * N
    for i in range(0 if periodic else 1, N if periodic else n - 1):
        hl, hr = h[i - 1], h[i]
        A[i][(i - 1) % N] += hr
        A[i][i] += 2 * (hl + hr)
        A[i][(i + 1) % N] += hl
        r[i] = 3 * (hr * d[i - 1] + hl * d[i])
    if not periodic:
        (lo, lv), (hi, hv) = ends
        lv, hv = Fr(float(lv)), Fr(float(hv))
        if lo == 1:
            A[0][0], r[0] = Fr(1), lv
        else:
            A[0][0], A[0][1], r[0] = Fr(2), Fr(1), 3 * d[0] - lv * h[0] / 2
        if hi == 1:
            A[n - 1][n - 1], r[n - 1] = Fr(1), hv
        else:
            A[n - 1][n - 2], A[n - 1][n - 1] = Fr(1), Fr(2)
            r[n - 1] = 3 * d[n - 2] + hv * h[n - 2] / 2
    for c in range(N):
        p = next(k for k in range(c, N) if A[k][c] != 0)
        A[c], A[p], r[c], r[p] = A[p], A[c], r[p], r[c]
        for k in range(N):
            if k != c and A[k][c] != 0:
                f = A[k][c] / A[c][c]
                A[k] = [a - f * b for a, b in zip(A[k], A[c], strict=True)]
                r[k] -= f * r[c]
    x = [float(r[i] / A[i][i]) for i in range(N)]
    return np.array(x + [x[0]] if periodic else x)


ENDS = [((2, 0.0), (2, 0.0)), ((1, 3.0), (2, -7.0)), ((2, 5.0), (1, -0.5)), ((1, 1.0), (1, 2.0))]


@pytest.mark.parametrize("n", [2, 3, 4, 9, 30])
def test_slopes_match_exact_elimination(n):
    rng = np.random.default_rng(n)
    for _ in range(3):
        t = np.cumsum(10.0 ** rng.uniform(-3, 3, n))  # spacing over six decades
        y = 100.0 * rng.normal(size=n)
        cases = list(ENDS) + (["periodic"] if n >= 4 else [])
        for ends in cases:
            yy = y.copy()
            if ends == "periodic":
                yy[-1] = yy[0]
                bc = "periodic"
            else:
                bc = tuple((o, np.array([v, -v])) for o, v in ends)
            got = cubic_slopes(t, np.c_[yy, -yy], bc)
            ex = _exact(t, yy, ends)
            scale = np.max(np.abs(ex))
            assert np.max(np.abs(got[:, 0] - ex)) <= 1e-13 * scale, ends
            assert np.max(np.abs(got[:, 1] + ex)) <= 1e-13 * scale, ends


@pytest.mark.parametrize("dim", [2, 3])
def test_slopes_match_scipy_and_make_a_c2_curve(dim):
    rng = np.random.default_rng(11)
    n = 3000
    s = np.cumsum(rng.uniform(0.01, 1.0, n))
    P = np.c_[s, np.sin(s / 20.0), np.cos(s / 7.0)][:, :dim] + 1e-3 * rng.normal(size=(n, dim))
    for bc in ("natural", "periodic", "clamped", ((1, np.ones(dim)), (2, np.ones(dim)))):
        kw = {"end_tangents": np.ones((2, dim))} if bc == "clamped" else {}
        c = cf.interpolate_cubic(P, "chord", bc, **kw)
        t = np.asarray(c.params)
        Q = np.asarray(c.points)
        scipy_bc = {"natural": "natural", "periodic": "periodic",
                    "clamped": ((1, np.ones(dim)), (1, np.ones(dim)))}.get(bc, bc) \
            if isinstance(bc, str) else bc
        ref = CubicSpline(t, Q, bc_type=scipy_bc, axis=0)(t, 1)
        np.testing.assert_allclose(c.tangents, ref, rtol=0, atol=1e-10 * np.abs(ref).max())
        # C2: the second derivative is continuous at every interior point (and the seam)
        pp = c.piecewise
        seg = np.arange(1, t.size - 1)
        left = pp.evaluate(t[1:-1], 2, segment=seg - 1)
        right = pp.evaluate(t[1:-1], 2, segment=seg)
        size = np.abs(right).max()
        assert np.max(np.abs(left - right)) <= 1e-7 * size


def test_not_a_knot_still_goes_through_scipy():
    rng = np.random.default_rng(2)
    P = np.c_[np.arange(8.0), rng.normal(size=8)]
    c = cf.interpolate_cubic(P, "uniform", "not-a-knot")
    ref = CubicSpline(np.arange(8.0), P, bc_type="not-a-knot", axis=0)(np.arange(8.0), 1)
    np.testing.assert_allclose(c.tangents, ref, rtol=0, atol=1e-12)
