"""Which ground-truth counts no natural-end cubic can reach: the cap of issue 13's count.

A point file stores points; the curve a reader rebuilds from it is the chord-length natural
cubic through them, and the result of ``fair()`` for point data is a natural cubic on the
input's parameters too. Natural ends mean ``r'' = 0`` at both ends of an open curve, hence
curvature 0 there (``kappa = |r' x r''| / |r'|^3``).

Claim: an open, non-straight curve with ``kappa = 0`` at both ends has at least one interior
curvature extremum. (Planar: the signed curvature is 0 at both ends and not identically 0,
so it has an interior maximum or minimum; 3-D: the same for ``|kappa| >= 0``.) The counted
extremum is not a rounding-level one: ``kappa`` climbs from 0 to its largest value
``kappa_max`` and back, so ``dkappa/ds`` averages at least ``kappa_max / L`` in absolute value
on each side (``L`` the arc length), far above the counting band of ``curvefair.analyze``
(``1e-9`` of the largest ``|dkappa/ds|``).

So every ground-truth case whose true curve is open and has no curvature extremum (true count
0: the circle arcs, clothoids and helices of ``corpus.ground_truth_cases``) is out of reach of
every natural-end curve, whatever points are written. This script lists those cases (checking
the hypotheses on the true curve: open, true count 0, ``|kappa| > 0`` at both ends) and, as a
sanity check of the claim on the benchmark's own data, counts the extrema of the natural
rebuild through the noise-free samples, the noisy samples and ``--trials`` random point sets
inside the tolerance balls of the noisy ones: the smallest count is at least 1 on every such
case.

Usage::

    python benchmarks/quality/natural_end_cap.py [--trials 20]
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from quality import corpus as C  # noqa: E402

import curvefair as cf  # noqa: E402


def natural_extrema(pts: np.ndarray) -> int:
    """Curvature extrema of the chord-length natural cubic through ``pts`` (open curve)."""
    return int(cf.analyze(cf.interpolate_cubic(pts, "chord", "natural")).extrema)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=20,
                    help="random point sets inside the tolerance balls per case")
    args = ap.parse_args()
    cases = C.ground_truth_cases(instances=4)  # the 84 cases of make bench-quality
    rng = np.random.default_rng(13)
    out: dict[str, list[int]] = {}
    for c in cases:
        tc = c.truth
        assert tc is not None
        k = tc.curvature()
        if c.closed or c.true_extrema != 0 or not (abs(k[0]) > 0 and abs(k[-1]) > 0):
            continue
        counts = [natural_extrema(c.clean), natural_extrema(c.points)]
        for _ in range(args.trials):
            d = rng.normal(size=c.points.shape)
            d *= (c.tol * rng.uniform(0, 1, (len(d), 1)) ** (1 / d.shape[1])
                  / np.linalg.norm(d, axis=1, keepdims=True))
            counts.append(natural_extrema(c.points + d))
        out.setdefault(c.family, []).append(min(counts))
        assert min(counts) >= 1, (c.name, counts)
    total = len(cases)
    out_n = sum(len(v) for v in out.values())
    print(f"{total} ground-truth cases; open with true extrema count 0 and nonzero end "
          f"curvature: {out_n}")
    for fam, mins in sorted(out.items()):
        print(f"  {fam:>9}: {len(mins)} cases, smallest natural-rebuild extrema count over "
              f"{args.trials + 2} point sets each: {min(mins)} (median of the smallest "
              f"{float(np.median(mins)):g})")
    print(f"reachable by a natural-end curve at most: {total - out_n}/{total} "
          f"(issue 13 asks 55)")


if __name__ == "__main__":
    main()
