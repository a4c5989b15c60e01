"""points-l1's compiled replacements of numpy / scipy.sparse steps give bit for bit the same
numbers as the code they replace (kept as references), and the per-call reuse (shared set-up,
memoised analyses, rebuilt curves and deviations) leaves fair()'s result unchanged."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from curvefair import fair, interpolate_cubic
from curvefair._kernels import points as pk
from curvefair.fairing.fair import analysis_block
from curvefair.fairing.points_l1 import (
    _natural_operators_sparse,
    _polyline_distance,
    _polyline_distance_numpy,
    _zigzag,
    natural_operators,
    periodic_operators,
)


def _same_csr(a: sp.spmatrix, b: sp.spmatrix) -> bool:
    return (type(a) is type(b) and a.shape == b.shape
            and a.indptr.dtype == b.indptr.dtype and a.indices.dtype == b.indices.dtype
            and np.array_equal(a.indptr, b.indptr) and np.array_equal(a.indices, b.indices)
            and np.array_equal(a.data, b.data)
            and a.has_canonical_format == b.has_canonical_format)


@pytest.mark.parametrize("seed", range(6))
def test_natural_operators_bitwise_as_scipy_sparse(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for _ in range(40):
        N = int(rng.integers(3, 120))
        u = np.cumsum(rng.uniform(0.01, 1.0, N) * 10.0 ** rng.uniform(-3, 3)) + rng.normal()
        a, b = natural_operators(u), _natural_operators_sparse(u)
        assert np.array_equal(a.t, b.t)
        for name in ("A", "G", "Jm", "E"):
            assert _same_csr(getattr(a, name), getattr(b, name)), name


@pytest.mark.parametrize("dim", [2, 3])
def test_polyline_distance_kernel_bitwise(dim: int) -> None:
    rng = np.random.default_rng(dim)
    for it in range(300):
        n, m = int(rng.integers(3, 150)), int(rng.integers(1, 200))
        poly = np.cumsum(rng.normal(size=(n, dim)), axis=0) * 10.0 ** rng.uniform(-5, 5)
        x = poly[rng.integers(0, n, m)] + rng.normal(size=(m, dim)) * np.ptp(poly) * 0.01
        if m >= 3:
            x[:3] = poly[:3]  # on vertices
        ok = rng.random(n - 1) > 0.2 if it % 2 else None
        got = _polyline_distance(x, poly, ok)
        ref = _polyline_distance_numpy(x, poly, ok)
        assert np.array_equal(got, ref)


def test_sparse_products_bitwise_as_scipy() -> None:
    """csr_matvecs / csr_t_matvecs / csr_matmat against scipy.sparse on unsorted CSR."""
    rng = np.random.default_rng(5)
    for _ in range(50):
        m, n = int(rng.integers(2, 60)), int(rng.integers(2, 60))
        A = sp.random(m, n, density=0.3, random_state=rng, format="csr")
        B = sp.random(n, int(rng.integers(2, 40)), density=0.3, random_state=rng, format="csr")
        A = (A @ sp.random(n, n, density=0.3, random_state=rng, format="csr")).tocsr()  # unsorted
        X = rng.normal(size=(n, 3))
        Z = rng.normal(size=(m, 2))
        out = np.empty((m, 3))
        pk.csr_matvecs(A.indptr.astype(np.int64), A.indices.astype(np.int64), A.data, X, out)
        assert np.array_equal(out, A @ X)
        out_t = np.empty((n, 2))
        pk.csr_t_matvecs(A.indptr.astype(np.int64), A.indices.astype(np.int64), A.data, Z,
                         out_t)
        assert np.array_equal(out_t, A.T @ Z)
        C = A @ B
        p, j, x = pk.csr_matmat(m, B.shape[1], A.indptr, A.indices, A.data, B.indptr,
                                B.indices, B.data)
        assert np.array_equal(p, C.indptr) and np.array_equal(j, C.indices)
        assert np.array_equal(x, C.data)


@pytest.mark.parametrize("dim", [2, 3])
def test_cyclic_newton_band_bitwise_as_scipy(dim: int) -> None:
    """The closed curves' Newton band against the scipy.sparse assembly it replaces."""
    rng = np.random.default_rng(dim)
    for N in (5, 9, 24):
        u = np.r_[0.0, np.cumsum(rng.uniform(0.5, 1.5, N))]
        ops = periodic_operators(u)
        C = sp.vstack([ops.A, ops.A]).tocsr()
        m = C.shape[0]
        K = sp.kron(ops.Jm.T @ ops.Jm, sp.identity(dim), format="csr") * 0.7
        B = rng.normal(size=(m, dim, dim))
        B = B @ np.transpose(B, (0, 2, 1))
        n = N * dim
        base = np.arange(m)[:, None, None] * dim
        r = np.broadcast_to(base + np.arange(dim)[None, :, None], B.shape).reshape(-1)
        c = np.broadcast_to(base + np.arange(dim)[None, None, :], B.shape).reshape(-1)
        Bd = sp.csr_matrix((B.reshape(-1), (r, c)), shape=(m * dim, m * dim))
        CI = sp.kron(C, sp.identity(dim), format="csr")
        pos = (_zigzag(N)[:, None] * dim + np.arange(dim)[None, :]).reshape(-1)
        Pm = sp.csr_matrix((np.ones(n), (pos, np.arange(n))), shape=(n, n))
        Mp = (Pm @ (K + CI.T @ Bd @ CI) @ Pm.T).tocoo()
        low = Mp.row >= Mp.col
        kd = int(np.max(Mp.row[low] - Mp.col[low]))
        ab = np.zeros((kd + 1, n))
        np.add.at(ab, (Mp.row[low] - Mp.col[low], Mp.col[low]), Mp.data[low])
        band, kd2 = pk.cyclic_newton_band(
            C.indptr.astype(np.int64), C.indices.astype(np.int64), C.data, B,
            K.indptr.astype(np.int64), K.indices.astype(np.int64), K.data, _zigzag(N), dim)
        assert kd2 == kd
        assert np.array_equal(band[:kd2 + 1], ab)


def _noisy(n: int, seed: int, closed: bool = False):
    rng = np.random.default_rng(seed)
    if closed:
        th = np.linspace(0, 2 * np.pi, n, endpoint=False)
        P = np.c_[3 * np.cos(th), 2 * np.sin(th)] + 0.02 * rng.normal(size=(n, 2))
        return interpolate_cubic(np.vstack([P, P[:1]]), bc="periodic")
    t = np.linspace(0, 20, n)
    return interpolate_cubic(np.c_[t, np.sin(t / 3) * 4] + 0.02 * rng.normal(size=(n, 2)))


@pytest.mark.parametrize("closed", [False, True])
def test_memoised_figures_do_not_change_a_second_call(closed: bool) -> None:
    """fair() twice on the same curve object (its analysis memoised by the first) and on an
    equal fresh curve: the same result, bit for bit."""
    c = _noisy(14, 3, closed)
    r1 = fair(c, tol=0.05)
    r2 = fair(c, tol=0.05)
    r3 = fair(_noisy(14, 3, closed), tol=0.05)
    for r in (r2, r3):
        assert np.array_equal(r.curve.points, r1.curve.points)
        assert np.array_equal(r.curve.tangents, r1.curve.tangents)
        d1, d = r1.report.to_dict(), r.report.to_dict()
        d1.pop("time_s")
        d.pop("time_s")
        assert d == d1


def test_analysis_block_memo_returns_fresh_dicts() -> None:
    c = _noisy(10, 1)
    a = analysis_block(c)
    a["extrema"] = -1
    b = analysis_block(c)
    assert b["extrema"] >= 0 and b is not a
