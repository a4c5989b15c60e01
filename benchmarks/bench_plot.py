"""Speed of :func:`curvefair.plot.figure` against drawing the same ink with bare matplotlib.

For each size ``n`` a seeded noisy planar curve (a sine over 10 periods plus Gaussian noise of
1/1000, chord-length parameters) is interpolated by :func:`curvefair.interpolate_cubic`. Timed,
interleaved, ``--repeat`` times, each to a PNG in memory (Agg, 80 dpi):

* ``interpolate_cubic`` + ``figure(curve)`` + ``savefig`` on a fresh curve (nothing cached;
  curve, comb, markers, curvature plot), and
* the peer: a bare matplotlib figure with the same two panels holding the same number of curve
  samples, hairs (one LineCollection) and curvature samples, with the data precomputed outside
  the timed region -- the cost of drawing alone.

The ratio figure / peer is what curvefair's sampling, analysis (:func:`curvefair.analyze` for
the markers) and layout add on top of drawing.

Usage::

    python benchmarks/bench_plot.py                 # sizes 1e3 1e4 1e5
    python benchmarks/bench_plot.py 2e4 --repeat 5
"""

from __future__ import annotations

import argparse
import io
import statistics
import time

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from curvefair import interpolate_cubic  # noqa: E402
from curvefair.plot import curvature_comb, figure  # noqa: E402


def make_curve(n: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 20 * np.pi, n)
    return interpolate_cubic(np.c_[t, np.sin(t) + 1e-3 * rng.standard_normal(n)])


def peer(samples: np.ndarray, hairs: np.ndarray, kappa: np.ndarray) -> None:
    fig = Figure(figsize=(9, 6), layout="constrained")
    a, b = fig.subplots(2, 1, height_ratios=(3, 2))
    a.plot(samples[:, 0], samples[:, 1])
    a.add_collection(LineCollection(hairs, linewidths=0.6))
    a.plot(hairs[:, 1, 0], hairs[:, 1, 1])
    a.set_aspect("equal", adjustable="datalim")
    a.autoscale_view()
    b.plot(np.arange(kappa.size), kappa)
    fig.savefig(io.BytesIO(), format="png", dpi=80)


def ours(curve) -> None:
    figure(curve).savefig(io.BytesIO(), format="png", dpi=80)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("sizes", nargs="*", type=float, default=[1e3, 1e4, 1e5])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    ours(make_curve(200))  # warm-up: numba caches, matplotlib fonts
    print(f"{'n':>8} {'figure best s':>14} {'peer best s':>12} {'ratio':>7} "
          f"{'figure median':>14} {'peer median':>12}")
    for nf in args.sizes:
        n = int(nf)
        c = make_curve(n)
        comb = curvature_comb(c)
        m = c.piecewise.n_segments
        samples = c(np.linspace(*c.domain, max(6000, 2 * m)))
        hairs = np.stack([comb.base, comb.tip], axis=1)
        kappa = np.repeat(comb.kappa, max(1, samples.shape[0] // max(comb.kappa.size, 1)))
        t_ours, t_peer = [], []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            ours(make_curve(n))  # fresh curve: nothing cached
            t1 = time.perf_counter()
            peer(samples, hairs, kappa)
            t2 = time.perf_counter()
            t_ours.append(t1 - t0)
            t_peer.append(t2 - t1)
        print(f"{n:>8} {min(t_ours):>14.3f} {min(t_peer):>12.3f} "
              f"{min(t_ours) / min(t_peer):>7.2f} {statistics.median(t_ours):>14.3f} "
              f"{statistics.median(t_peer):>12.3f}")


if __name__ == "__main__":
    main()
