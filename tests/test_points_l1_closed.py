"""points-l1 on closed point lists: the periodic cubic through moved points, checked against
independent computations (scipy's periodic CubicSpline for the operators and the curves,
scipy.optimize for the convex problem and its KKT conditions, dense sampling)."""

from __future__ import annotations

import numpy as np
from scipy.interpolate import BSpline, CubicSpline
from scipy.optimize import minimize

from curvefair import analyze, fair, interpolate_cubic
from curvefair.fairing.points_l1 import (
    _energy_matrix,
    _normal_projections,
    _solve,
    _tube_qp_cyclic,
    _zigzag,
    periodic_operators,
    points_l1,
)


def _chord_closed(p: np.ndarray) -> np.ndarray:
    c = np.vstack([p, p[:1]])
    return np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(c, axis=0), axis=1))]


def _noisy_loop(n: int, sigma: float, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0.0, 2 * np.pi, n))
    return np.c_[2.0 * np.cos(t), np.sin(t)] + rng.normal(0.0, sigma, (n, 2))


def test_zigzag_turns_a_cyclic_band_into_a_band() -> None:
    for N in (4, 5, 10, 11):
        pos = _zigzag(N)
        assert sorted(pos) == list(range(N))
        j = np.arange(N)
        for d in (1, 2, 3):
            assert np.max(np.abs(pos[(j + d) % N] - pos[j])) <= 2 * d


def test_periodic_operators_match_scipy_periodic_spline() -> None:
    p = _noisy_loop(13, 1e-2, seed=3)
    u = _chord_closed(p)
    ops = periodic_operators(u)
    x = _solve(ops.A, p, True)
    assert np.allclose(ops.A @ x, p, atol=1e-13)
    cs = CubicSpline(u, np.vstack([p, p[:1]]), bc_type="periodic")
    uu = np.linspace(u[0], u[-1], 3001)
    assert np.allclose(BSpline(ops.t, ops.E @ x, 3)(uu), cs(uu), atol=1e-12)
    g = ops.G @ x
    left = 6.0 * cs.c[0]  # S''' on span k
    assert np.allclose(g, left, rtol=1e-9, atol=1e-9 * np.abs(left).max())
    # jumps at every point, the seam (point 0: span 0 minus span N - 1) included
    assert np.allclose(ops.Jm @ x, left - np.roll(left, 1, axis=0), rtol=1e-8,
                       atol=1e-8 * np.abs(left).max())


def test_cyclic_tube_qp_matches_scipy_minimize_and_kkt() -> None:
    p = _noisy_loop(9, 3e-2, seed=1)
    N, dim = p.shape
    u = _chord_closed(p)
    ops = periodic_operators(u)
    w = np.linspace(0.5, 2.0, N)
    K = _energy_matrix(ops, w, 1e-3, _normal_projections(p, True), 0.1)
    tol = 0.05
    # constraint rows: the points and one sample inside every span (rows wrap at the seam)
    us = 0.5 * (u[:-1] + u[1:])
    Bs = (BSpline.design_matrix(us, ops.t, 3) @ ops.E).tocsr()
    import scipy.sparse as sp

    C = sp.vstack([ops.A, Bs]).tocsr()
    x0 = _solve(ops.A, p, True)
    Y = np.vstack([p, Bs @ x0])
    rad = np.full(C.shape[0], tol)
    x, lam, steps, reason = _tube_qp_cyclic(K, C, x0, Y, rad, gap=1e-12)
    assert reason == "converged"
    Kd, Cd = K.toarray(), C.toarray()

    def f(z: np.ndarray) -> float:
        return float(z @ Kd @ z)

    def cons(z: np.ndarray) -> np.ndarray:
        return np.sum((Cd @ z.reshape(N, dim) - Y) ** 2, axis=1)

    E0 = f(x0.reshape(-1))
    Ci = np.kron(Cd, np.eye(dim))

    def cons_jac(z: np.ndarray) -> np.ndarray:
        v = (Ci @ z - Y.reshape(-1)).reshape(-1, dim)
        return -2.0 * (v[:, :, None] * Ci.reshape(-1, dim, N * dim)).sum(axis=1) / (tol * tol)

    ref = minimize(lambda z: f(z) / E0, x0.reshape(-1), jac=lambda z: 2 * Kd @ z / E0,
                   method="SLSQP",
                   constraints=[{"type": "ineq", "fun": lambda z: 1.0 - cons(z) / (tol * tol),
                                 "jac": cons_jac}],
                   options={"ftol": 1e-12, "maxiter": 2000})
    assert ref.success, ref.message
    fx, fr = f(x.reshape(-1)), f(ref.x)
    assert np.all(cons(x.reshape(-1)) <= tol * tol)
    assert np.all(cons(ref.x) <= tol * tol * (1 + 1e-6))
    assert fx <= fr * (1 + 1e-5) + 1e-12
    assert fx < 0.5 * f(x0.reshape(-1))  # the tube is wide enough to matter
    # KKT: 2 K x + sum_i mu_i C_i^T (C_i x - Y_i) = 0, mu_i >= 0, mu_i = 0 off the ball
    v = Cd @ x - Y
    mu = lam * E0 / (tol * tol)
    grad = 2 * (Kd @ x.reshape(-1)).reshape(N, dim) + Cd.T @ (mu[:, None] * v)
    assert np.abs(grad).max() <= 1e-5 * np.abs(2 * Kd @ x0.reshape(-1)).max()
    assert np.all(mu >= 0)
    off = np.linalg.norm(v, axis=1) < 0.99 * tol
    assert np.all(mu[off] <= 1e-6 * max(mu.max(), 1e-300))


def test_closed_points_l1_tolerance_and_fairness() -> None:
    """The result is the periodic cubic through q at the input's parameters (scipy), within
    tol of the input's at equal parameter (dense sampling), its points within tol, and
    fairer both as returned and as rebuilt from its points (chord lengths of q)."""
    p = _noisy_loop(50, 2e-3, seed=7)
    tol = 8e-3
    res = points_l1(p, tol, closed=True)
    q = np.asarray(res.points)
    assert q.shape == p.shape
    assert np.max(np.linalg.norm(q - p, axis=1)) <= tol
    u = _chord_closed(p)
    uu = np.unique(np.r_[np.linspace(0.0, u[-1], 40001), u])
    cq = CubicSpline(u, np.vstack([q, q[:1]]), bc_type="periodic")
    assert np.allclose(res.curve(uu), cq(uu), rtol=0.0, atol=1e-12)
    cp = CubicSpline(u, np.vstack([p, p[:1]]), bc_type="periodic")
    assert np.linalg.norm(cq(uu) - cp(uu), axis=1).max() <= tol
    assert res.report["param_deviation"] <= tol
    before = analyze(interpolate_cubic(np.vstack([p, p[:1]]), "chord", "periodic")).extrema
    assert analyze(res.curve).extrema < before / 2
    rebuilt = interpolate_cubic(np.vstack([q, q[:1]]), "chord", "periodic")
    assert analyze(rebuilt).extrema <= 0.6 * before


def test_fair_closed_point_list() -> None:
    """fair(closed chord-length periodic cubic, "points-l1"): seam kept closed, points within
    tol, protected points unmoved, fewer extrema."""
    p = _noisy_loop(40, 2e-3, seed=4)
    c = interpolate_cubic(np.vstack([p, p[:1]]), "chord", "periodic")
    tol = 8e-3
    res = fair(c, "points-l1", tol=tol, protect=[5])
    out = np.asarray(res.curve.points)
    assert res.curve.closed and np.array_equal(out[0], out[-1])
    assert np.max(np.linalg.norm(out[:-1] - p, axis=1)) <= tol
    assert np.array_equal(out[5], p[5])
    assert res.report["max_deviation"] <= tol
    assert res.report["extrema_after"] < 0.6 * res.report["extrema_before"]


def test_select_keeps_the_formulation_with_the_fewest_rebuilt_extrema() -> None:
    """``select=3``: of the call's own formulation and two other jump costs, the one whose
    written points rebuild (chord-length natural cubic) into the fewest curvature extrema is
    kept, so never more than with ``select=1``; the tolerance holds either way."""
    rng = np.random.default_rng(11)
    t = np.sort(rng.uniform(0.0, 2.5, 50))
    t[0], t[-1] = 0.0, 2.5
    p = np.c_[np.cos(t), 0.6 * np.sin(t)] + rng.normal(0.0, 1e-3, (50, 2))
    c = interpolate_cubic(p)
    tol = 4e-3
    counts = []
    for select in (1, 3):
        res = fair(c, "points-l1", tol=tol, select=select)
        q = np.asarray(res.curve.points)
        assert np.max(np.linalg.norm(q - p, axis=1)) <= tol
        assert res.report["max_deviation"] <= tol
        counts.append(analyze(interpolate_cubic(q)).extrema)
    assert counts[1] <= counts[0]


def test_small_polygons_do_not_collapse_real_svg(tmp_path) -> None:
    """OCCT's documentation drawing has closed 8-vertex dots 1.7-3.7 units across; at tol 2 and
    5 points-l1 shrank them to a point (4e-12 across, or an internal error), and the written
    file read back without them, so the command refused to write. The tube radius is now at
    most SHRINK_CAP of a curve's extent: the command writes, svgpathtools reads back every
    path with its segments, every vertex within tol, and the dots keep 3/4 of their size
    (each extent loses at most two radii)."""
    import os
    import subprocess
    import sys

    import svgpathtools

    from curvefair.fairing.points_l1 import SHRINK_CAP

    src = os.path.join(os.path.dirname(__file__), "data", "real", "occt",
                       "modeling_data_continuity_curves.svg")
    paths0, attrs0 = svgpathtools.svg2paths(src)
    ids = {a.get("id"): k for k, a in enumerate(attrs0)}
    dots = [ids[i] for i in ("path19", "path203", "path359", "path621")]
    for tol in (2.0, 5.0):
        out = tmp_path / f"out_{tol:g}.svg"
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
        run = subprocess.run([sys.executable, "-m", "curvefair", "fair", src, "--tol", str(tol),
                              "-o", str(out), "--quiet"], capture_output=True, text=True,
                             env=env)
        assert run.returncode == 0, run.stderr
        paths1, attrs1 = svgpathtools.svg2paths(str(out))
        assert [a.get("id") for a in attrs1] == [a.get("id") for a in attrs0]
        assert [len(p) for p in paths1] == [len(p) for p in paths0]
        # in the drawing's units (svgpathtools applies the groups' transforms): every
        # vertex within tol
        drawn0 = svgpathtools.Document(src).paths()
        drawn1 = svgpathtools.Document(str(out)).paths()
        assert len(drawn1) == len(drawn0)
        for p0, p1 in zip(drawn0, drawn1, strict=True):
            assert len(p1) == len(p0)
            if len(p0):
                v0 = np.array([s.start for s in p0] + [p0[-1].end])
                v1 = np.array([s.start for s in p1] + [p1[-1].end])
                assert np.all(np.abs(v1 - v0) <= tol * (1 + 1e-9))
        for k in dots:
            v0 = np.array([s.start for s in paths0[k]])
            v1 = np.array([s.start for s in paths1[k]])
            big = max(np.ptp(v0.real), np.ptp(v0.imag))
            for part in (np.real, np.imag):  # each extent loses at most 2 radii
                assert np.ptp(part(v1)) >= np.ptp(part(v0)) - 2 * SHRINK_CAP * big - 1e-9
            assert max(np.ptp(v1.real), np.ptp(v1.imag)) >= (1 - 2 * SHRINK_CAP) * big - 1e-9
            steps = np.abs(np.diff(np.r_[v1, v1[:1]]))
            assert steps.min() > 0.05 * np.abs(np.diff(np.r_[v0, v0[:1]])).min()


def test_curve_smaller_than_tol_keeps_its_size() -> None:
    """A closed 8-point polygon 1.8 across faired at tol 5: no internal error (its points used
    to coincide), the radius used is reported, and the size is kept within SHRINK_CAP."""
    from curvefair.fairing.points_l1 import SHRINK_CAP

    a = 2 * np.pi * np.arange(8) / 8
    P = np.c_[235.0 + 0.9 * np.cos(a), 519.0 + 0.9 * np.sin(a)]
    c = interpolate_cubic(P, "chord", "periodic")
    res = fair(c, "points-l1", tol=5.0)
    q = np.asarray(res.curve.points)
    assert np.all(np.linalg.norm(q - np.asarray(c.points), axis=1) <= 5.0)
    ext0, ext1 = np.ptp(P, axis=0).max(), np.ptp(q, axis=0)
    assert np.all(ext1 >= np.ptp(P, axis=0) - 2 * SHRINK_CAP * ext0 - 1e-12)
    assert ext1.max() >= 0.5 * ext0  # was 1e-12 across (or an internal error)
    assert res.report["points_l1"]["tube_radius"] == SHRINK_CAP * ext0
