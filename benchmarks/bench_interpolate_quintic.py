"""C4 quintic interpolation: ``interpolate_quintic`` vs. scipy's ``make_interp_spline(k=5)``.

Seeded data: noisy samples of a smooth 3-D curve (noise 0.05 x spacing), chord parameters,
natural ends. Timed, best of ``--repeat``:

* ``interpolate_quintic``: the whole public call (validation, parameters, banded Hermite solve,
  the ``QuinticHermite``);
* ``hermite solve``: only its derivative solve (``quintic_hermite_data``);
* peer: ``make_interp_spline(t, pts, k=5, bc_type=natural)`` plus evaluating ``r'`` and
  ``r''`` at the data parameters -- the same output, as the previous implementation got it.

Accuracy columns, on a straight line through the same number of random non-uniform points
(chord parameters, so the exact spline is the line itself): the largest ``kappa h`` at the
data points (``kappa = |r' x r''| / |r'|^3`` the curvature, ``h`` the smaller adjacent spacing,
so ``kappa h`` is the turning angle per segment that ``r''`` implies), for both.

Usage::

    python benchmarks/bench_interpolate_quintic.py --sizes 1000 10000 100000 1000000
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import numpy as np
from scipy.interpolate import make_interp_spline

from curvefair import interpolate_quintic, parameterize
from curvefair.curves.interpolate import quintic_hermite_data


def data(n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    s = np.linspace(0.0, 20.0, n)
    pts = np.c_[s, np.sin(s), 0.3 * np.cos(0.7 * s)]
    return pts + 0.05 * (20.0 / (n - 1)) * rng.normal(size=pts.shape)


def line(n: int, seed: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    u = np.cumsum(rng.uniform(0.2, 1.0, n))
    u *= 10.0 / u[-1]
    d = np.array([3.0, -1.0, 2.0]) / np.sqrt(14.0)
    return np.array([0.3, 0.2, -0.1]) + u[:, None] * d


def best(f: Callable[[], object], repeat: int) -> float:
    t = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        t = min(t, time.perf_counter() - t0)
    return t


def scipy_derivs(pts: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    z = np.zeros(pts.shape[1])
    nat = [(3, z), (4, z)]
    spl = make_interp_spline(t, pts, k=5, bc_type=(nat, nat), axis=0)
    return spl(t, 1), spl(t, 2)


def bend(t: np.ndarray, d1: np.ndarray, d2: np.ndarray) -> float:
    h = np.diff(t)
    hloc = np.minimum(np.r_[h[0], h], np.r_[h, h[-1]])
    sp = np.linalg.norm(d1, axis=1)
    kappa = np.linalg.norm(np.cross(d1, d2), axis=1) / sp**3
    return float((kappa * hloc).max())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--sizes", type=int, nargs="+", default=[1000, 10000, 100000, 1000000])
    ap.add_argument("--repeat", type=int, default=3, help="best of N")
    args = ap.parse_args()

    z = [(3, np.zeros(3)), (4, np.zeros(3))]
    print(f"seconds, best of {args.repeat}; ratio = curvefair / scipy; line: max kappa h")
    print(f"{'n':>9} {'interpolate_quintic':>20} {'hermite solve':>14} {'scipy k=5':>10} "
          f"{'ratio':>6} {'line (ours)':>12} {'line (scipy)':>13}")
    for n in args.sizes:
        pts = data(n)
        t = parameterize(pts)
        t_pub = best(lambda: interpolate_quintic(pts), args.repeat)  # noqa: B023
        t_core = best(lambda: quintic_hermite_data(pts, t, z, z, False), args.repeat)  # noqa: B023
        t_sp = best(lambda: scipy_derivs(pts, t), args.repeat)  # noqa: B023
        lp = line(n)
        tl = parameterize(lp)
        q = interpolate_quintic(lp)
        e_ours = bend(tl, q.d1, q.d2)
        e_sp = bend(tl, *scipy_derivs(lp, tl))
        print(f"{n:>9} {t_pub:20.4f} {t_core:14.4f} {t_sp:10.4f} {t_pub / t_sp:6.2f} "
              f"{e_ours:12.1e} {e_sp:13.1e}", flush=True)


if __name__ == "__main__":
    main()
