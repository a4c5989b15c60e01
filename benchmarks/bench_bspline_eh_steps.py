"""Eck-Hadenfeld ranking-list steps per second (uniform cubic planar B-spline).

Seeded data: ``n`` control points ``(i, noise)`` on a uniform clamped knot vector, energy
``E_2``, tolerance 0.5 from the original points, ``eps = 0`` so that the loop runs the requested
number of steps (unless every move has become zero). Only the compiled loop is timed (the
``O(n)`` set-up -- Gram band, residual, patterns -- is reported separately), best of
``--repeat`` on fresh copies of the state.

Last column: the same step in the sweep schedule (``schedule="sweep"``: Gauss-Seidel order on a
queue, no priority structure; threshold 0, the same step cap) on the same state.

Peer, measured in the same run: the same loop written with the generic per-point tournament tree
of ``curvefair._kernels.ranking`` (``tt_build`` / ``tt_update`` per changed entry, one leaf per
control point, separate arrays for points, residuals and originals).

Usage::

    python benchmarks/bench_bspline_eh_steps.py --sizes 1000 10000 100000 1000000 --steps 3000000
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from numba import njit

from curvefair import BSplineCurve
from curvefair._kernels import eck_hadenfeld as ek
from curvefair._kernels.ranking import tt_build, tt_update
from curvefair.fairing import eck_hadenfeld as eh


def make_curve(n: int, seed: int = 0) -> BSplineCurve:
    rng = np.random.default_rng(seed)
    d = np.c_[np.arange(n, dtype=float), rng.normal(size=n)]
    t = np.r_[[0.0] * 3, np.arange(n - 2.0), [n - 3.0] * 3]
    return BSplineCurve(d, t, 3)


def prepare(c: BSplineCurve):
    n = c.n_ctrl
    W = c.gram_band(2)
    X = np.zeros((n, 6))
    X[:, :2] = c.control_points
    X[:, 2:4] = eh._residual(c, W)
    X[:, 4:6] = c.control_points
    mask = eh.movable_mask(c, ("g2", "g2"))
    z = np.where(mask, 0.0, -1.0)
    return X, z, eh.band_patterns(W), np.ascontiguousarray(W), mask


def aligned_copy(a: np.ndarray) -> np.ndarray:
    """The loop's state as :func:`eck_hadenfeld_fair` allocates it (64-byte aligned)."""
    out = eh._aligned_empty(a.shape)
    out[...] = a
    return out


def run_loop(X, z, bp, tol: float, steps: int) -> int:
    Wu, pat, upat, ulo, uhi = bp
    return int(ek.eh_loop(X, z, Wu, pat, upat, ulo, uhi, 2, 3, False, tol, 0.0, steps,
                          np.zeros((0, 3)), eh._tree_buffer(X.shape[0]))[0])


def run_sweep(X, z, bp, tol: float, steps: int) -> int:
    """The same steps in the sweep schedule (``schedule="sweep"``), threshold 0."""
    Wu, pat, upat, ulo, uhi = bp
    n = X.shape[0]
    return int(ek.eh_sweep(X, z, Wu, pat, upat, ulo, uhi, 2, 3, False, tol, 0.0, steps,
                           np.zeros((0, 3)), np.empty(n, dtype=np.int64),
                           np.empty(n, dtype=np.uint8))[0])


@njit(cache=True)
def _peer_candidate(i, d, g, orig, W, p, tol):  # type: ignore[no-untyped-def]
    gii = W[i, p]
    s0 = -g[i, 0] / gii
    s1 = -g[i, 1] / gii
    v0 = d[i, 0] + s0 - orig[i, 0]
    v1 = d[i, 1] + s1 - orig[i, 1]
    vv = v0 * v0 + v1 * v1
    if vv > tol * tol:
        f = tol / np.sqrt(vv)
        e0 = orig[i, 0] + v0 * f - d[i, 0]
        e1 = orig[i, 1] + v1 * f - d[i, 1]
        z = gii * (2.0 * (e0 * s0 + e1 * s1) - (e0 * e0 + e1 * e1))
        return max(z, 0.0), e0, e1
    return gii * (s0 * s0 + s1 * s1), s0, s1


@njit(cache=True)
def peer_loop(d, g, orig, W, p, movable, tol, max_steps):  # type: ignore[no-untyped-def]
    n = d.shape[0]
    vals = np.full(n, -np.inf)
    for i in range(n):
        if movable[i]:
            vals[i] = _peer_candidate(i, d, g, orig, W, p, tol)[0]
    tv, ti = tt_build(vals)
    steps = 0
    while steps < max_steps:
        r = ti[1]
        if tv[1] <= 0.0:
            break
        z, e0, e1 = _peer_candidate(r, d, g, orig, W, p, tol)
        d[r, 0] += e0
        d[r, 1] += e1
        for c in range(2 * p + 1):
            i = r + c - p
            if 0 <= i < n:
                g[i, 0] += W[r, c] * e0
                g[i, 1] += W[r, c] * e1
        for i in range(max(r - p, 0), min(r + p + 1, n)):
            if movable[i]:
                tt_update(tv, ti, i, _peer_candidate(i, d, g, orig, W, p, tol)[0])
        steps += 1
    return steps


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--sizes", type=int, nargs="+", default=[1000, 10000, 100000, 1000000])
    ap.add_argument("--steps", type=int, default=3_000_000)
    ap.add_argument("--tol", type=float, default=0.5, help="inf: unconstrained")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    # compile both loops outside the timing
    X, z, bp, W, mask = prepare(make_curve(64))
    run_loop(aligned_copy(X), aligned_copy(z), bp, args.tol, 10)
    run_sweep(aligned_copy(X), aligned_copy(z), bp, args.tol, 10)
    d = np.ascontiguousarray(X[:, :2])
    peer_loop(d.copy(), np.ascontiguousarray(X[:, 2:4]), d.copy(), W, 3, mask, args.tol, 10)
    print(f"{'n':>9} {'setup s':>8} {'steps':>9} {'curvefair M/s':>14} {'peer M/s':>9} "
          f"{'ratio':>6} {'sweep M/s':>10}")
    for n in args.sizes:
        c = make_curve(n, args.seed)
        t0 = time.perf_counter()
        X, z, bp, W, mask = prepare(c)
        setup = time.perf_counter() - t0
        best, made = np.inf, 0
        for _ in range(args.repeat):
            Xc, zc = aligned_copy(X), aligned_copy(z)
            t0 = time.perf_counter()
            made = run_loop(Xc, zc, bp, args.tol, args.steps)
            best = min(best, (time.perf_counter() - t0) / max(made, 1))
        pbest, pmade = np.inf, 0
        for _ in range(args.repeat):
            d = np.ascontiguousarray(X[:, :2])
            g = np.ascontiguousarray(X[:, 2:4])
            t0 = time.perf_counter()
            pmade = peer_loop(d.copy(), g, d.copy(), W, 3, mask, args.tol, args.steps)
            pbest = min(pbest, (time.perf_counter() - t0) / max(pmade, 1))
        sbest = np.inf
        for _ in range(args.repeat):
            Xc, zc = aligned_copy(X), aligned_copy(z)
            t0 = time.perf_counter()
            smade = run_sweep(Xc, zc, bp, args.tol, args.steps)
            sbest = min(sbest, (time.perf_counter() - t0) / max(smade, 1))
        print(f"{n:>9} {setup:>8.3f} {made:>9} {1e-6 / best:>14.2f} {1e-6 / pbest:>9.2f} "
              f"{pbest / best:>6.2f} {1e-6 / sbest:>10.2f}")


if __name__ == "__main__":
    main()
