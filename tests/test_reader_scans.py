"""The compiled scans of the point-list readers (:mod:`curvefair._kernels.corners`:
``noise_terms_2d``, ``point_checks``, ``corner_turns_range``, ``coord_extent``) against the
numpy expressions they replaced, bit for bit, on noisy, smooth, zigzag, closed, degenerate
and bad data; and the readers' messages."""

from __future__ import annotations

import numpy as np
import pytest

from curvefair._kernels.corners import (
    noise_terms_2d,
    noise_terms_reference,
    point_checks,
    point_checks_reference,
)
from curvefair.errors import FileFormatError
from curvefair.io._common import check_points, noise_scale


def _lists(rng):
    t = np.linspace(0, 7, 400)
    yield np.c_[t, np.sin(t)]                                         # smooth
    yield np.c_[t, np.sin(t) + 1e-3 * rng.normal(size=t.size)]        # noisy
    yield np.c_[t, (-1.0) ** np.arange(t.size)]                       # zigzag
    s = np.linspace(0, 2 * np.pi, 300, endpoint=False)
    yield np.c_[np.cos(s), np.sin(s)] + 1e-4 * rng.normal(size=(300, 2))  # a noisy loop
    p = np.c_[t, np.sin(t)]
    p[50] = p[52]                                                     # a zero chord
    yield p
    yield np.c_[t, np.zeros_like(t)]                                  # collinear: sign 0
    yield rng.normal(size=(12, 2)) * 1e8


def test_noise_terms_are_the_numpy_figures():
    rng = np.random.default_rng(3)
    for p in _lists(rng):
        for closed in (False, True):
            ratio = np.empty(len(p))
            nr, flips = noise_terms_2d(np.ascontiguousarray(p), closed, ratio)
            ref, ref_flips = noise_terms_reference(p, closed)
            assert ratio[:nr].tobytes() == ref.tobytes()
            assert flips == ref_flips


def test_noise_scale_flags_noise_only():
    """The figure through the compiled pass: noise of ``sigma`` in each coordinate measured
    at about 1.22 sigma (the spread of a point's offset from its neighbours' chord), none on
    smooth samples or a deliberate zigzag."""
    rng = np.random.default_rng(4)
    t = np.linspace(0, 7, 20000)
    sigma = 1e-4
    est = noise_scale(np.c_[t, np.sin(t)] + sigma * rng.normal(size=(t.size, 2)), False)
    assert 1.1 * sigma < est < 1.35 * sigma
    assert noise_scale(np.c_[t, np.sin(t)], False) == 0.0
    assert noise_scale(np.c_[t, (-1.0) ** np.arange(t.size)], False) == 0.0


def test_point_checks_are_the_numpy_checks():
    rng = np.random.default_rng(5)
    eps4 = 4 * np.finfo(float).eps
    base = rng.normal(size=(300, 3)) * 10
    cases = [base, base[:, :2], base[:1], base[:2]]
    for i, bad in ((7, np.nan), (30, np.inf), (299, -np.inf)):
        q = base.copy()
        q[i, 1] = bad
        q[200, 0] = 2e30
        cases.append(q)
    q = base.copy()
    q[40, 2] = -3e30
    q[60, 0] = 4e30
    cases.append(q)
    for k in (0, 10, 298):
        q = base.copy()
        q[k + 1] = q[k] + 1e-16 * np.abs(q).max() * np.array([1.0, -1.0, 0.5])
        cases.append(q)
    cases.append(np.full((5, 2), 3.0))
    cases.append(np.c_[np.linspace(0, 1e-21, 6), np.zeros(6)])
    for q in cases:
        q = np.ascontiguousarray(q)
        assert point_checks(q, 1e30, eps4) == point_checks_reference(q, 1e30, eps4)


@pytest.mark.parametrize("row, value, words", [(7, np.nan, "non-finite"),
                                               (8, 5e30, "magnitudes up to"),
                                               (9, None, "duplicate consecutive")])
def test_check_points_names_the_row_and_line(row, value, words):
    p = np.c_[np.arange(20.0), np.arange(20.0) ** 2]
    if value is None:
        p[row + 1] = p[row]
    else:
        p[row, 1] = value
    lines = np.arange(20) + 3  # numpy line numbers, as the points reader passes them
    with pytest.raises(FileFormatError, match=words) as exc:
        check_points(p, "f.csv", lines)
    want = row + 3 + (1 if value is None else 0)
    assert exc.value.line == want and type(exc.value.line) is int
    assert f"f.csv:{want}: " in str(exc.value)


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("par_min", [2, 100_000])
def test_fused_corner_turning_is_the_composition_of_chord_turns(closed, dim, par_min,
                                                                monkeypatch):
    """``corner_turning``'s compiled passes (``_kernels.corners.corner_turns_range``: one walk
    per direction for the three chord lengths and the minimum, by point ranges; then
    ``keep_local_maxima``) give the bits of its numpy composition from ``_chord_turns`` at
    each length (``corner_turning_reference``), on noisy lists with corners, repeated points,
    lists too short for the longer chords and lists whose noise hides a corner or not; the
    chord walk itself is checked against a plain Python walk in test_geom_smooth.py. Also
    the compiled extent against ``np.ptp``. ``par_min`` 2: the point ranges on two threads
    from 2 points on."""
    import curvefair.io._common as common
    from curvefair._kernels.corners import coord_extent
    from curvefair.io._common import corner_turning, corner_turning_reference, noise_scale

    monkeypatch.setattr(common, "THREADS", 2)
    monkeypatch.setattr(common, "_CORNER_PAR_MIN", par_min)

    rng = np.random.default_rng(31 + dim + 10 * closed)
    noisy = 0
    for n in (10, 11, 14, 25, 60, 400, 3000):
        for rel in (0.0, 0.1, 0.3, 1.0):  # noise per point spacing
            sigma = rel * 2.0 * np.pi / n
            t = np.linspace(0.0, 2.0 * np.pi, n, endpoint=not closed)
            arc = np.c_[np.cos(t), np.sin(t)] if dim == 2 else np.c_[np.cos(t), np.sin(t), 0.3 * t]
            legs = np.zeros((n, dim))  # two straight legs (a short list is noisy on them)
            legs[:, 0] = t
            legs[n // 2:, 1] = t[n // 2:] - t[n // 2]
            for p in (arc, legs):
                p = p.copy()
                p[n // 3:] += 0.4 * (t[n // 3:, None] - t[n // 3])  # a corner
                p = p + sigma * rng.standard_normal(p.shape)
                if n >= 25:
                    p[7] = p[6]  # a repeated point (a zero chord)
                noisy += noise_scale(p, closed) > 0
                # a closed list also with its corner moved to the seam (the neighbours of the
                # first and last points wrap around)
                for q in [p] + ([np.roll(p, -(n // 3) + r, axis=0) for r in (-1, 0, 1, 2)]
                                if closed else []):
                    a, b = corner_turning(q, closed), corner_turning_reference(q, closed)
                    assert a.dtype == b.dtype and a.shape == b.shape
                    assert a.tobytes() == b.tobytes(), (n, sigma)
                assert coord_extent(np.ascontiguousarray(p)) == np.ptp(p, axis=0).max()
    assert noisy >= 15  # the compiled path ran (noisy lists), not only turning_angles
    q = rng.standard_normal((20, dim))
    q[5, dim - 1] = np.nan
    assert np.isnan(coord_extent(q)) and np.isnan(np.ptp(q, axis=0).max())
