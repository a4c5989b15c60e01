"""numpy's pairwise summation streamed by leaves (curvefair._kernels.pairwise), and the summary
analysis that sums its jumps and energies block by block instead of keeping them per segment
(``sample_curve(..., sums_only=True)``): the same bits as ``np.sum`` / ``np.max`` of the
arrays, whatever the blocks and the threads' ranges."""

from __future__ import annotations

import numpy as np
import pytest

import curvefair as cf
from curvefair import _threads
from curvefair._kernels import pairwise as kp
from curvefair._kernels import sampling as _ksampling
from curvefair.analysis import _analyze as _analyze_mod
from curvefair.analysis import _sampling, fairness_figures

SIZES = [*range(0, 300), 511, 512, 513, 1023, 1024, 1025, 4097, 65_537, 100_003, 1_000_001]


def test_leaves_and_tree_sum_are_numpys_sum():
    # the leaves' sums (each by pw_sum over its own values) combined by tree_sum give
    # np.sum's bits, for contiguous arrays and strided columns, values over 16 decades
    rng = np.random.default_rng(0)
    for n in SIZES:
        v2 = rng.normal(size=(n, 2)) * 10.0 ** rng.uniform(-8, 8, (n, 2))
        for v in (v2[:, 0], np.ascontiguousarray(v2[:, 1])):
            lb = kp.leaf_bounds(n)
            assert lb[0] == 0 and lb[-1] == n
            assert np.all(np.diff(lb) >= 1) and np.all(np.diff(lb) <= kp.LEAF)
            ls = np.array([kp.pw_sum(np.ascontiguousarray(v[a:b]), b - a)
                           for a, b in zip(lb[:-1], lb[1:], strict=True)])
            assert kp.tree_sum(ls, n) == np.sum(v)
            assert kp.pw_sum_long(np.ascontiguousarray(v), n) == np.sum(v)


def test_tree_sum_is_not_a_plain_sum():
    # the check above can fail: a sequential sum of the same values differs from numpy's
    rng = np.random.default_rng(1)
    v = rng.normal(size=10_000) * 10.0 ** rng.uniform(-8, 8, 10_000)
    seq = 0.0
    for x in v:
        seq += x
    assert seq != np.sum(v)


def _figures(a: cf.Analysis) -> dict:
    return {"energy2": a.energy2, "energy3": a.energy3, "max_jump": a.max_jump or 0.0,
            "max_top_jump": a.max_top_jump, "sapidis_sum": a.sapidis_sum,
            "dkds_energy": a.dkds_energy, "inflections": a.inflections, "extrema": a.extrema}


@pytest.mark.parametrize("block,par_min", [(65_536, 50_000), (7, 4), (100, 4), (129, 300),
                                           (1000, 300)])
def test_streamed_summary_is_the_full_analysis(monkeypatch, block, par_min):
    # open planar cubic, quintic and B-spline curves whose segment forms are made range by
    # range: fairness_figures sums the jumps and energies by blocks (counted) and gives
    # analyze()'s figures bit for bit, on one thread and on two (tiny ranges and blocks:
    # leaves split between blocks and between ranges, ranges inside one leaf)
    calls = []
    real = _sampling._stream_sums
    monkeypatch.setattr(_sampling, "_stream_sums", lambda *a: calls.append(1) or real(*a))
    monkeypatch.setattr(_sampling, "STREAM_BLOCK", block)
    monkeypatch.setattr(_sampling, "PAR_MIN", par_min)
    rng = np.random.default_rng(block + par_min)
    sizes = (4, 5, 9, 130, 131, 257, 1000, 3000) if block < 1000 else (4, 9, 257, 3000, 70_001)
    cases = 0
    for threads in (1, 2):
        monkeypatch.setattr(_threads, "THREADS", threads)
        for n in sizes:
            x = np.linspace(0, 30, n)
            P = np.c_[x, np.sin(x)] + 1e-3 * rng.normal(size=(n, 2))
            curves = [cf.interpolate_cubic(P), cf.interpolate_bspline(P)]
            if n <= 3000:
                curves.append(cf.interpolate_quintic(P))
            for c in curves:
                ref = _figures(cf.analyze(c))
                got = fairness_figures(c)
                assert "piecewise" not in c.__dict__  # (both read the segment forms)
                for key, val in ref.items():
                    assert got[key] == val, (n, type(c).__name__, key)
                cases += 1
    assert len(calls) == cases


def test_streamed_summary_keeps_nan_and_closed_curves_are_not_streamed(monkeypatch):
    # a closed curve's seam row is made after the pass: its summary keeps the arrays
    calls = []
    real = _sampling._stream_sums
    monkeypatch.setattr(_sampling, "_stream_sums", lambda *a: calls.append(1) or real(*a))
    a = np.linspace(0, 2 * np.pi, 200, endpoint=False)
    c = cf.interpolate_cubic(np.c_[np.cos(a), 0.5 * np.sin(a)], "chord", "periodic")
    ref = _figures(cf.analyze(c))
    got = fairness_figures(c)
    assert not calls
    assert all(got[k] == v for k, v in ref.items())
    # the block fold's maxima: NaN sticks wherever it comes (np.max's rule)
    kb = np.array([[1.0, 2.0, 0.0], [np.nan, 1.0, 0.0], [3.0, np.nan, 0.0], [5.0, 7.0, 0.0]])
    eb = np.zeros((4, 2))
    lb = kp.leaf_bounds(4)
    ls = np.empty(1)
    for start in (0, 1):
        bufs = np.empty((3, 2, kp.LEAF))
        ints = np.zeros((3, 3), dtype=np.int64)
        mx = np.full(2, -np.inf)
        kp.fold_block(kb[start:], eb[start:], 4 - start, start, lb, kp.leaf_bounds(3), ls,
                      ls.copy(), ls.copy(), bufs, ints, np.zeros(3, dtype=np.int64), mx)
        assert np.isnan(mx).all()


def _wiggly(n: int, rng: np.random.Generator, scale: float) -> np.ndarray:
    # straight stretches (curvature at the rounding level: the zero bands decide) between
    # noisy ones (many sign changes, some across every block boundary)
    x = np.linspace(0, 30, n)
    y = np.where((x > 10) & (x < 20), 0.0, np.sin(x) + 1e-3 * rng.normal(size=n))
    return scale * np.c_[x, y] + np.array([3.0 * scale, -7.0 * scale])


@pytest.mark.parametrize("block,par_min", [(1, 4), (2, 4), (7, 300), (65_536, 50_000)])
def test_long_summary_rescans_the_signs_block_by_block(monkeypatch, block, par_min):
    # from RESCAN_MIN segments on (forced to 2 here) the summary keeps no samples: the sign
    # counts come from a second pass, scanned block by block (blocks of one segment: every
    # change between two segments is one between blocks) on one thread and on two. The
    # counts are analyze()'s (which scans the kept samples), for open planar curves whose
    # segment forms are made block by block, closed ones (the seam counted once) and twisted
    # 3-D ones (the whole power form), of size 1, 1e-15 and 1e25 (the samples' unit scales
    # the zero bands), and the other figures unchanged. The first pass counts each block's
    # signs between its gap segments with a band from the block's own largest value and
    # keeps the gap segments' samples; a block keeps those counts where its least nonzero
    # value is above the final band (its gap segments then scanned with their extra
    # samples), else it is sampled again (both happen here: "calm" curves, a line whose tiny
    # wiggles are nonzero in its own band but zero in the final one, which the tight circle
    # after it sets, when the circle is in another block)
    calls = []
    gap_pieces = []  # gap segments scanned with their extra samples at the end
    real = _sampling.rescan_sign_counts

    def rescan(*a):
        calls.append(1)
        gap_pieces.extend(pc for _, _, pieces in a[5].block_counts for q in pieces for pc in q
                          if pc[0] == "gap")
        return real(*a)

    monkeypatch.setattr(_analyze_mod, "rescan_sign_counts", rescan)
    passes = {True: 0, False: 0}  # sampling passes: first (full) and again (not full)
    real_pass = _ksampling.pass_kernel

    def spy(*a):
        passes[bool(a[-1])] += 1
        return real_pass(*a)

    monkeypatch.setattr(_ksampling, "pass_kernel", spy)
    lean_blocks = []  # the first pass's blocks (each counts dkappa/ds once)
    real_count = _ksampling.count_block
    monkeypatch.setattr(_ksampling, "count_block",
                        lambda *a: (lean_blocks.append(1) if a[-1] == 2 else None)
                        or real_count(*a))
    monkeypatch.setattr(_sampling, "STREAM_BLOCK", block)
    monkeypatch.setattr(_sampling, "PAR_MIN", par_min)
    monkeypatch.setattr(_sampling, "RESCAN_MIN", 2)
    rng = np.random.default_rng(block)
    cases = changes = 0
    for threads in (1, 2):
        monkeypatch.setattr(_threads, "THREADS", threads)
        for n in (4, 5, 60, 301, 2000):
            for scale in (1.0, 1e-15, 1e25):
                P = _wiggly(n, rng, scale)
                a = np.linspace(0.0, 2.0 * np.pi, n + 1)
                ring = scale * np.c_[np.cos(a), 0.5 * np.sin(a)]
                ring[:-1] += 1e-4 * scale * rng.normal(size=(n, 2))
                ring[-1] = ring[0]
                space = np.c_[P, scale * np.sin(np.linspace(0.0, 9.0, n))]
                t = np.linspace(0.0, 100.0, n)
                calm = scale * np.c_[t, 1e-12 * np.sin(3.0 * t)]  # |kappa| ~ 1e-11
                b = np.linspace(0.0, 1.5 * np.pi, 12)[1:]
                calm = np.r_[calm, calm[-1] + scale * 0.01 * np.c_[np.sin(b), 1.0 - np.cos(b)]]
                for c in (cf.interpolate_cubic(P), cf.interpolate_quintic(P),
                          cf.interpolate_bspline(P),
                          cf.interpolate_cubic(ring, "chord", "periodic"),
                          cf.interpolate_bspline(ring[:-1], closed=True),
                          cf.interpolate_cubic(space), cf.interpolate_quintic(space),
                          cf.interpolate_cubic(calm)):
                    ref = _figures(cf.analyze(c))
                    got = fairness_figures(c)
                    assert got == ref, (n, scale, type(c).__name__)
                    cases += 1
                    changes += ref["inflections"] + ref["extrema"]
    assert len(calls) == cases
    assert changes > 3000
    # blocks kept from the first pass and (short blocks: the calm line's own) sampled again
    assert passes[False] < 0.8 * len(lean_blocks), (passes, len(lean_blocks))
    assert passes[False] > 0 or block > 1000


@pytest.mark.parametrize("block", [7, 1000, 65_536])
def test_long_summary_scans_gap_segments_with_their_extra_samples(monkeypatch, block):
    # a long summary's first pass keeps the samples of the segments whose signs it could not
    # settle (the gaps that get extra samples afterwards) and counts the stretches between
    # them; the gap segments are scanned at the end with their extra samples: the counts are
    # analyze()'s, on quintics through 20,000 noisy samples of two sines (about one segment in
    # 3,000 has a gap), open, closed and twisted, on one thread and two
    monkeypatch.setattr(_sampling, "STREAM_BLOCK", block)
    monkeypatch.setattr(_sampling, "RESCAN_MIN", 2)
    gap_pieces = []
    real = _sampling.rescan_sign_counts

    def rescan(*a):
        gap_pieces.extend(pc for _, _, pieces in a[5].block_counts for q in pieces for pc in q
                          if pc[0] == "gap")
        return real(*a)

    monkeypatch.setattr(_analyze_mod, "rescan_sign_counts", rescan)
    rng = np.random.default_rng(0)
    t = np.arange(20_000, dtype=float)
    P = np.c_[t, 20.0 * np.sin(t / 7.0) + 50.0 * np.sin(t / 31.0)]
    P = P + 0.05 * rng.normal(size=P.shape)
    a = t / t.size * 2.0 * np.pi
    ring = 3e3 * np.c_[np.cos(a), np.sin(a)] + P[:, 1:] * [1.0, 0.5]
    space = np.c_[P, 10.0 * np.cos(t / 11.0)]
    curves = (cf.interpolate_quintic(P), cf.interpolate_quintic(np.r_[ring, ring[:1]],
                                                                 bc="periodic"),
              cf.interpolate_quintic(space))
    for threads in (1, 2):
        monkeypatch.setattr(_threads, "THREADS", threads)
        for c in curves:
            assert fairness_figures(c) == _figures(cf.analyze(c))
    assert len(gap_pieces) >= 10


@pytest.mark.parametrize("par_min", [2, 7, 50_000])
def test_summary_counts_in_ranges_are_the_scans(monkeypatch, par_min):
    # below RESCAN_MIN the summary counts the kept samples' sign changes in ranges on two
    # threads, joined at the ranges' ends (and a closed curve's seam): analyze()'s counts,
    # which one sequential scan makes, for open, closed, planar and twisted curves of
    # 4-3000 points (ranges of a few segments: changes between every two ranges)
    monkeypatch.setattr(_sampling, "PAR_MIN", par_min)
    calls = []
    real = _sampling.count_sign_changes
    monkeypatch.setattr(_analyze_mod, "count_sign_changes",
                        lambda *a: calls.append(1) or real(*a))
    rng = np.random.default_rng(par_min)
    changes = 0
    for threads in (1, 2):
        monkeypatch.setattr(_threads, "THREADS", threads)
        for n in (4, 9, 40, 3000):
            P = _wiggly(n, rng, 1.0)
            a = np.linspace(0.0, 2.0 * np.pi, n + 1)
            ring = np.c_[np.cos(a), 0.5 * np.sin(a)]
            ring[:-1] += 1e-3 * rng.normal(size=(n, 2))
            ring[-1] = ring[0]
            space = np.c_[P, np.sin(np.linspace(0.0, 9.0, n))]
            for c in (cf.interpolate_cubic(P), cf.interpolate_quintic(P),
                      cf.interpolate_bspline(P), cf.interpolate_cubic(ring, "chord", "periodic"),
                      cf.interpolate_bspline(ring[:-1], closed=True),
                      cf.interpolate_quintic(space)):
                ref = cf.analyze(c)
                got = fairness_figures(c)
                assert (got["inflections"], got["extrema"]) == (ref.inflections, ref.extrema)
                changes += ref.inflections + ref.extrema
    assert changes > 1000 and len(calls) > 40
