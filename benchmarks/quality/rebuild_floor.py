"""What the curve rebuilt from a point file can reach: the noise-free samples' own interpolant.

Issue 13 counts point data on the curve a reader rebuilds from the written file: the
chord-length natural (closed: periodic) cubic through the written points. This script asks
what that count is when the written points are the *noise-free* samples themselves -- the
points of the true curve, at the benchmark's own sampling (``corpus.ground_truth_cases``,
``corpus.point_file_cases``: ``case.clean``). No fairing method moves the points there; it is
the count of the rebuild alone, and a method whose written points stay on the data's curve
inherits it.

Per family, for each rebuild:

* ``chord natural``: what a reader of the file does (and the benchmark counts);
* ``chord not-a-knot``: the same points, ends not forced to zero curvature (open curves only;
  closed ones stay periodic);
* ``4x chord natural``: the true curve sampled four times as densely (the same sampling law,
  ``corpus.sample_true_curve``), rebuilt as a reader does -- what a file with more rows than
  the input could reach.

Columns: cases; on how many the true curvature-extrema count (``case.true_extrema``, resolvable
at the sample spacing) is reached; the median excess of extrema over it; on how many the true
inflection count is reached.

Usage::

    python benchmarks/quality/rebuild_floor.py            # ground truth (4 instances) + point files
    python benchmarks/quality/rebuild_floor.py --instances 1
"""

from __future__ import annotations

import argparse
import os
import sys
import zlib

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from quality import corpus as C  # noqa: E402

import curvefair as cf  # noqa: E402


def rebuilt_counts(pts: np.ndarray, closed: bool, bc: str) -> tuple[int, int]:
    """Curvature extrema and inflections (``curvefair.analyze``) of the chord-length cubic
    through ``pts`` with end condition ``bc`` (closed: periodic)."""
    if closed:
        c = cf.interpolate_cubic(np.vstack([pts, pts[:1]]), "chord", "periodic")
    else:
        c = cf.interpolate_cubic(pts, "chord", bc)
    a = cf.analyze(c)
    return int(a.extrema), int(a.inflections)


def denser(case: C.Case, factor: int) -> np.ndarray:
    """The case's true curve sampled ``factor`` times as densely, same sampling law, seeded
    from the case's name."""
    rng = np.random.default_rng(zlib.crc32(case.name.encode()))
    assert case.truth is not None
    return C.sample_true_curve(case.truth, factor * case.clean.shape[0], rng)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--instances", type=int, default=4,
                    help="ground-truth instances per family (make bench-quality: 4)")
    args = ap.parse_args()
    corpora = {
        # one noise level: the clean samples are the same at every level
        "ground truth": C.ground_truth_cases(instances=args.instances, levels=(1e-3,)),
        "point files": C.point_file_cases(levels=(1e-3,)),
    }
    variants = ("chord natural", "chord not-a-knot", "4x chord natural")
    print("curvature extrema and inflections of the chord-length cubic through the "
          "noise-free samples (no fairing)")
    for corpus, cases in corpora.items():
        print(f"\n{corpus} ({len(cases)} curves, one per true curve and sampling)")
        head = f"{'family':>13} {'n':>3}"
        for v in variants:
            head += f" | {v + ': ext reached':>30} {'median excess':>13} {'infl':>5}"
        print(head)
        fams = sorted({c.family for c in cases})
        for fam in fams + ["all"]:
            sub = [c for c in cases if fam in (c.family, "all")]
            line = f"{fam:>13} {len(sub):>3}"
            for v in variants:
                reach, excess, infl, n_infl = 0, [], 0, 0
                for c in sub:
                    if v == "4x chord natural":
                        e, i = rebuilt_counts(denser(c, 4), c.closed, "natural")
                    else:
                        e, i = rebuilt_counts(c.clean, c.closed, v.split()[1])
                    if c.true_extrema is not None:
                        reach += e == c.true_extrema
                        excess.append(e - c.true_extrema)
                    if c.true_inflections is not None:
                        n_infl += 1
                        infl += i == c.true_inflections
                med = float(np.median(excess)) if excess else float("nan")
                line += (f" | {f'{reach}/{len(excess)}':>30} {med:>13g} "
                         f"{f'{infl}/{n_infl}':>5}")
            print(line)


if __name__ == "__main__":
    main()
