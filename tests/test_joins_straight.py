"""The compiled straight-span test of the joins plan against the numpy formula it replaced, and
``PiecewisePolynomial.evaluate`` on a few segments against Horner's rule on all of them."""

from __future__ import annotations

import numpy as np
import pytest

from curvefair import BSplineCurve, PiecewisePolynomial
from curvefair.curves.piecewise import derivative_coefficients
from curvefair.fairing import joins as J


def _reference(curve: BSplineCurve, P: np.ndarray, eps: float) -> tuple[set[int], int]:
    """The numpy formula of the joins plan before the compiled kernel (kept here as the
    reference): every span's ``p + 1`` control points, their distance from the chord's line."""
    p = curve.degree
    s = np.asarray(curve.spans)
    idx = curve.control_index(s[:, None] - p + np.arange(p + 1)[None, :])
    W = P[idx]
    d = W[:, -1] - W[:, 0]
    L = np.sqrt(np.sum(d * d, axis=1))
    u = d / np.maximum(L, 1e-300)[:, None]
    r = W - W[:, :1]
    off = r - np.sum(r * u[:, None, :], axis=2)[:, :, None] * u[:, None, :]
    lim = J._STRAIGHT_REL * L + eps
    ok = (np.sqrt(np.sum(off * off, axis=2)).max(axis=1) <= lim) & (L > eps)
    return {int(i) for i in np.unique(idx[ok])}, int(ok.sum())


def _open_knots(n: int, p: int, rng: np.random.Generator, multiple: bool) -> np.ndarray:
    inner = np.sort(rng.uniform(0.0, 1.0, n - p - 1))
    if multiple and inner.size >= 4:
        inner[1:min(p, 3)] = inner[0]  # a multiple knot (fewer spans than n - p)
        inner = np.sort(inner)
    return np.r_[np.zeros(p + 1), inner, np.ones(p + 1)]


def _with_lines(n: int, dim: int, rng: np.random.Generator, frac: float,
                noise: float) -> np.ndarray:
    """Random control points where runs are put on lines, then perturbed by ``noise`` times the
    straightness limit (some stay within it, some not)."""
    P = rng.normal(size=(n, dim)) * 10.0
    i = 0
    while i < n:
        if rng.uniform() < frac:
            k = int(rng.integers(2, 9))
            a, b = rng.normal(size=dim) * 10.0, rng.normal(size=dim)
            for j in range(i, min(n, i + k)):
                P[j] = a + (j - i) * b + noise * 1e-9 * rng.normal(size=dim)
            i += k
        else:
            i += 1
    return P


def _check(curve: BSplineCurve) -> tuple[set[int], int]:
    P = np.asarray(curve.control_points)
    eps = J._ROUND * J._size(P)
    got = J._straight_spans(curve, P, eps)
    want = _reference(curve, P, eps)
    assert got == want
    return got


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("p", [2, 3, 5])
@pytest.mark.parametrize("closed", [False, True])
def test_straight_spans_match_reference(dim: int, p: int, closed: bool) -> None:
    rng = np.random.default_rng(100 * p + 10 * dim + closed)
    counts = []
    for trial in range(12):
        n = int(rng.integers(p + 2, 60))
        P = _with_lines(n, dim, rng, frac=0.4, noise=float(rng.choice([0.0, 0.3, 3.0, 30.0])))
        if closed:
            c = BSplineCurve(P, np.sort(rng.uniform(0, 5, n + 1)), p, closed=True)
        else:
            c = BSplineCurve(P, _open_knots(n, p, rng, multiple=trial % 2 == 1), p)
        counts.append(_check(c)[1])
    assert max(counts) > 0 and min(counts) < len(np.asarray(c.spans))  # both kinds occurred


def test_no_straight_span() -> None:
    rng = np.random.default_rng(1)
    P = rng.normal(size=(40, 2))
    c = BSplineCurve(P, _open_knots(40, 3, rng, False), 3)
    assert _check(c) == (set(), 0)


@pytest.mark.parametrize("closed", [False, True])
def test_all_straight(closed: bool) -> None:
    t = np.linspace(0.0, 7.0, 30)
    P = np.c_[3.0 + t, -1.0 + 0.5 * t, 2.0 * t]
    if closed:  # the seam spans run back along the same line: collinear too
        c = BSplineCurve(P, np.arange(31.0), 3, closed=True)
        held, k = _check(c)
        assert held == set(range(30)) and k == 30
    else:
        c = BSplineCurve(P, _open_knots(30, 3, np.random.default_rng(2), False), 3)
        held, k = _check(c)
        assert held == set(range(30)) and k == 27


def test_straight_span_across_closed_seam() -> None:
    # points 28, 29, 0, 1 on one line: the spans wrapping the seam are found
    rng = np.random.default_rng(3)
    P = rng.normal(size=(30, 2)) * 5.0
    for j, i in enumerate([28, 29, 0, 1]):
        P[i] = (1.0 + j, 2.0 - 0.5 * j)
    c = BSplineCurve(P, np.arange(31.0), 3, closed=True)
    held, k = _check(c)
    assert {28, 29, 0, 1} <= held and k >= 1


@pytest.mark.parametrize("straight", [False, True])
def test_single_span(straight: bool) -> None:
    P = np.array([[0.0, 0.0], [1.0, 1.0 if not straight else 0.0], [2.0, 0.0], [3.0, 0.0]])
    c = BSplineCurve(P, [0, 0, 0, 0, 1, 1, 1, 1], 3)
    assert _check(c) == (({0, 1, 2, 3}, 1) if straight else (set(), 0))


def test_degenerate_chord_is_not_straight() -> None:
    # first and last control points of the span coincide: L = 0 <= eps, not a line
    P = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [0.0, 0.0]])
    c = BSplineCurve(P, [0, 0, 0, 0, 1, 1, 1, 1], 3)
    assert _check(c) == (set(), 0)


@pytest.mark.parametrize("nu", [0, 1, 2, 3, 4])
def test_evaluate_few_segments_matches_all(nu: int) -> None:
    rng = np.random.default_rng(nu)
    m = 50
    pp = PiecewisePolynomial(np.cumsum(np.r_[0.0, rng.uniform(0.5, 2.0, m)]),
                             rng.normal(size=(m, 4, 2)))
    seg = rng.integers(0, m, 7)
    u = pp.breaks[seg] + rng.uniform(0, 1, 7) * pp.widths[seg]
    # Horner's rule on the derivative coefficients of every segment (the path for many
    # parameters), segment by segment
    c = derivative_coefficients(np.asarray(pp.coeffs), nu)
    want = np.empty((7, 2))
    for q in range(7):
        s = u[q] - pp.breaks[seg[q]]
        acc = c[seg[q], -1].copy()
        for j in range(c.shape[1] - 2, -1, -1):
            acc = acc * s + c[seg[q], j]
        want[q] = acc
    assert np.array_equal(pp.evaluate(u, nu, segment=seg), want)
    assert np.array_equal(pp.at(seg, u - pp.breaks[seg], nu), want)
    many = np.repeat(seg, 10)  # more parameters than segments: the other path, same values
    assert np.array_equal(pp.evaluate(np.repeat(u, 10), nu, segment=many), np.repeat(want, 10, 0))
