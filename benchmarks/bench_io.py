"""Speed of reading and writing back point files, against numpy's own text I/O.

Seeded smooth 2-D data (a noisy sine) written as a CSV with a header; for each size:
``read_curves`` (parse + layout + corner detection + the C2 spline through the points) and
``write_curves`` back into the same layout, against the peer measured in the same run:
``np.loadtxt`` + ``np.savetxt`` of the same file (no layout kept, no curve built). Also the
same for a DXF LWPOLYLINE when ezdxf is installed (peer: ezdxf's own readfile + saveas).

Usage::

    python benchmarks/bench_io.py --sizes 1000 10000 100000
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time

import numpy as np

from curvefair import read_curves, write_curves


def data(n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 20.0, n)
    return np.c_[t, np.sin(t) + 1e-3 * rng.normal(size=n)]


def best(f, repeat: int = 3) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return min(times)


def run_csv(n: int, d: str) -> tuple[float, float, float]:
    src = os.path.join(d, f"p{n}.csv")
    np.savetxt(src, data(n), fmt="%.8f", delimiter=",", header="x,y", comments="")
    recs: list = []
    tr = best(lambda: recs.__setitem__(slice(None), read_curves(src, corner_angle=None)))
    tw = best(lambda: write_curves(os.path.join(d, f"o{n}.csv"), recs))

    def peer() -> None:
        a = np.loadtxt(src, delimiter=",", skiprows=1)
        np.savetxt(os.path.join(d, f"q{n}.csv"), a, fmt="%.8f", delimiter=",", header="x,y",
                   comments="")

    return tr, tw, best(peer)


def run_dxf(n: int, d: str, ezdxf: object) -> tuple[float, float, float]:
    src = os.path.join(d, f"p{n}.dxf")
    doc = ezdxf.new("R2010")  # type: ignore[attr-defined]
    doc.modelspace().add_lwpolyline([tuple(p) for p in data(n)])
    doc.saveas(src)
    recs: list = []
    tr = best(lambda: recs.__setitem__(slice(None), read_curves(src, corner_angle=None,
                                                                polylines=True)))
    tw = best(lambda: write_curves(os.path.join(d, f"o{n}.dxf"), recs, template=src))

    def peer() -> None:
        ezdxf.readfile(src).saveas(os.path.join(d, f"q{n}.dxf"))  # type: ignore[attr-defined]

    return tr, tw, best(peer)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", type=int, nargs="+", default=[1000, 10000, 100000])
    args = ap.parse_args()
    d = tempfile.mkdtemp()
    print(f"{'format':8s} {'n':>8s} {'read_curves':>12s} {'write_curves':>13s} "
          f"{'peer r+w':>10s} {'ratio':>7s}")
    runs = [("csv", lambda n: run_csv(n, d))]
    try:
        import ezdxf

        runs.append(("dxf", lambda n: run_dxf(n, d, ezdxf)))
    except ImportError:
        pass
    for name, run in runs:
        for n in args.sizes:
            tr, tw, tp = run(n)
            print(f"{name:8s} {n:8d} {tr:12.4f} {tw:13.4f} {tp:10.4f} {(tr + tw) / tp:7.2f}")


if __name__ == "__main__":
    main()
