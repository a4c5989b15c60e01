"""The compiled Sapidis-Farin loop against the old Python loop.

REFERENCE: ``reference_knot_removal_fair`` below is the Python ``while`` loop that
``knot_removal_fair`` was up to session 2 (copied verbatim apart from the signature defaults and
names, with its ``_KnotData`` as ``_RefKnotData``; it still uses the module's unchanged step
``_removal_moves`` and ``sapidis_measure``): numpy ``einsum`` for the measure at the touched
knots, ``c @ d`` for the one-point move,
LAPACK ``lstsq`` (SVD) for the least-squares removal system, ``np.unique`` for the touched knots.
It is kept here as the slow reference; the compiled loop re-implements every one of these steps
in scalar code, so the comparison is between two independent computations of the same loop.

What is compared, on many random cases (degrees 2..5, 2-D/3-D, open/closed, non-uniform knots,
with/without tol, clamp/protect, both variants, both on_tol values, eps settings, max_steps):
the step sequence (knot indices), the blocked knots, the stop reason, steps, exactly; the
control points, the history and the tracked sum to 1e-12 relative (the reference's ``einsum``
and BLAS ``c @ d`` may sum in another order than the compiled loop, depending on the CPU's SIMD
width; least squares differs by the rounding of QR vs SVD).

Rounding-level ties: the loop's documented tie rule (``ROUNDING_FLOOR``: a jump below the floor
is zero, a step must lower the sum by more than the floor) is applied by the reference too, and
no case puts a tolerance exactly on a move (the tolerance of the long runs is taken between two
moves, not on one), so no comparison here hinges on the last bit of a sum.
"""

from __future__ import annotations

import numpy as np
import pytest

from curvefair import BSplineCurve, interpolate_bspline
from curvefair._kernels.ranking import tt_build, tt_top, tt_update
from curvefair._validate import as_nonnegative, as_step_count
from curvefair.curves.bspline import basis_derivatives
from curvefair.errors import InputError
from curvefair.fairing.eck_hadenfeld import movable_mask
from curvefair.fairing.knot_removal import (
    ROUNDING_FLOOR,
    VARIANTS,
    KRResult,
    _KnotData,
    _removal_moves,
    knot_jumps,
    knot_removal_fair,
    sapidis_measure,
)
from curvefair.fairing.problem import check_bspline


# ------------------------------------------------------------------------------------------
# REFERENCE: the old Python loop (slow; do not optimise)
# ------------------------------------------------------------------------------------------
def _ref_jump_coefficients(curve, js):
    p = curve.degree
    t = np.asarray(curve.knots)
    js = np.asarray(js, dtype=np.int64)
    right = basis_derivatives(t, p, js, np.zeros(js.size), p, local=True)[:, p, :]
    left = basis_derivatives(t, p, js - 1, t[js] - t[js - 1], p, local=True)[:, p, :]
    c = np.zeros((js.size, p + 2))
    c[:, 1:] += right  # N_{j-p} .. N_j
    c[:, :-1] -= left  # N_{j-1-p} .. N_{j-1}
    return c


class _RefKnotData:
    """The session-2 ``_KnotData`` (per-knot basis data, numpy ``einsum`` measure)."""

    def __init__(self, curve):
        p = curve.degree
        t = np.asarray(curve.knots)
        self.p = p
        self.js = _ref_interior_knots(curve)
        js = self.js
        self.c = _ref_jump_coefficients(curve, js)  # (k, p+2)
        self.right = basis_derivatives(t, p, js, np.zeros(js.size), 2, local=True)[:, 1:3, :]
        self.left2 = basis_derivatives(t, p, js - 1, t[js] - t[js - 1], 2,
                                       local=True)[:, 2, :]
        self.ctrl = curve.control_index(js[:, None] + np.arange(-p - 1, 1)[None, :])

    def jumps(self, d, k=slice(None)):
        p = self.p
        Q = d[self.ctrl[k]]  # (m, p+2, dim)
        J = np.einsum("ma,mad->md", self.c[k], Q)
        r1 = np.einsum("ma,mad->md", self.right[k][:, 0, :], Q[:, 1:, :])
        r2 = np.einsum("ma,mad->md", self.right[k][:, 1, :], Q[:, 1:, :])
        l2 = np.einsum("ma,mad->md", self.left2[k], Q[:, :-1, :])
        return sapidis_measure(r1, r2, l2, J, p)


def _ref_interior_knots(curve):
    t = curve.knots
    p = curve.degree
    n = curve.n_ctrl
    j = np.arange(p, p + n) if curve.closed else np.arange(p + 1, n)
    if j.size == 0:
        return j
    simple = (t[j - 1] < t[j]) & (t[j] < t[j + 1])
    return j[simple]


def reference_knot_removal_fair(curve, *, variant="one-point", tol=None, eps=None,
                                eps_relative=True, max_steps=None, clamp=(None, None),
                                protect=(), on_tol="skip"):
    curve = check_bspline(curve)
    if not isinstance(variant, str) or variant not in VARIANTS:
        raise InputError(f"unknown variant {variant!r}")
    if on_tol not in ("skip", "stop"):
        raise InputError(f"on_tol must be 'skip' or 'stop', got {on_tol!r}")
    tolv = as_nonnegative(tol, "tol", none_means=np.inf)
    mask = movable_mask(curve, clamp, protect)
    kd = _RefKnotData(curve)
    js = kd.js
    nk = js.size
    d = np.array(curve.control_points)
    orig = d.copy()
    max_steps = as_step_count(max_steps, default=10 * nk)
    if nk == 0:
        return KRResult(curve, 0, "no_knots", 0.0, 0.0, np.zeros((0, 3)))
    z = kd.jumps(d)
    sum0 = float(z.sum())
    epsv = (1e-6 if eps_relative else 0.0) if eps is None else as_nonnegative(eps, "eps")
    eps_abs = epsv * float(z.max()) if eps_relative else epsv
    floor = ROUNDING_FLOOR * float(z.max())  # the documented tie rule (session 5)
    p = curve.degree
    n = curve.n_ctrl
    pos = np.full(len(curve.knots), -1, dtype=np.int64)
    pos[js] = np.arange(nk)

    def touched_knots(idx):
        jj = (idx[:, None] + np.arange(p + 2)[None, :]).ravel()
        if curve.closed:
            jj = p + (jj - p) % n  # the period's copy of each knot
        jj = jj[(jj >= 0) & (jj < pos.size)]
        kk = pos[jj]
        return np.unique(kk[kk >= 0])
    rank = z.copy()
    tv, ti = tt_build(rank)
    blocked = []
    hist = []
    total = sum0
    steps = 0
    reason = "max_steps"
    while steps < max_steps:
        k, zk = tt_top(tv, ti)
        k, zk = int(k), float(zk)
        if zk < 0:  # every knot blocked
            reason = "tolerance"
            break
        if zk <= eps_abs or zk <= floor:
            reason = "eps"
            break
        j = int(js[k])
        idx, new = _removal_moves(curve, d, j, variant, kd.c[k])
        ok = bool(np.all(mask[idx]))
        if ok and tolv < np.inf:
            ok = bool(np.all(np.sqrt(np.sum((new - orig[idx]) ** 2, axis=1)) <= tolv))
        if not ok:
            if on_tol == "stop":
                reason = "tolerance"
                break
            rank[k] = -1.0
            tt_update(tv, ti, k, -1.0)
            blocked.append(j)
            continue
        old = d[idx].copy()
        d[idx] = new
        tk = touched_knots(np.asarray(idx, dtype=np.int64))
        znew = kd.jumps(d, tk)
        new_total = total - float(z[tk].sum()) + float(znew.sum())
        if new_total >= total - floor:
            d[idx] = old
            reason = "no_decrease"
            break
        total = new_total
        z[tk] = znew
        for kk, zz in zip(tk.tolist(), znew.tolist(), strict=True):
            if rank[kk] >= 0:
                rank[kk] = zz
                tt_update(tv, ti, kk, zz)
        steps += 1
        hist.append((j, zk, float(np.sqrt(np.sum((new - old) ** 2, axis=1)).max())))
    out = curve.replace(control_points=d)
    h = np.array(hist, dtype=float).reshape(-1, 3)
    # session 3: an eps stop with a blocked knot still above the threshold is a tolerance stop
    zend = kd.jumps(d)
    if reason == "eps" and any(zend[int(pos[j])] > eps_abs for j in blocked):
        reason = "tolerance"
    return KRResult(out, steps, reason, sum0, float(zend.sum()), h, blocked, total)


# ------------------------------------------------------------------------------------------
# random cases
# ------------------------------------------------------------------------------------------
def random_curve(rng, n, p, dim, closed, kind):
    """Non-uniform knots; ``kind`` "noisy" (a noisy interpolant, the loop's use case) or
    "random" (random control points)."""
    if kind == "noisy":
        s = np.sort(rng.uniform(0, 2 * np.pi, n))
        if closed:
            pts = np.c_[np.cos(s), np.sin(s)]
        else:
            pts = np.c_[s, np.sin(s)]
        if dim == 3:
            pts = np.c_[pts, 0.3 * np.sin(2 * s)]
        pts = pts + 0.01 * rng.normal(size=pts.shape)
        return interpolate_bspline(pts, degree=p, closed=closed)
    if closed:
        t = np.r_[0.0, np.cumsum(rng.uniform(0.3, 1.7, n))]
        return BSplineCurve(rng.normal(size=(n, dim)), t, p, closed=True)
    inner = np.cumsum(rng.uniform(0.3, 1.7, n - p - 1))
    t = np.r_[[0.0] * (p + 1), inner, [inner[-1] + rng.uniform(0.3, 1.7)] * (p + 1)]
    return BSplineCurve(rng.normal(size=(n, dim)), t, p)


def assert_same(a: KRResult, b: KRResult, rtol=1e-12):
    assert a.stop_reason == b.stop_reason
    assert a.steps == b.steps
    np.testing.assert_array_equal(a.history[:, 0], b.history[:, 0])  # the knot sequence
    assert a.blocked == b.blocked
    scale = max(np.abs(b.curve.control_points).max(), 1e-300)
    np.testing.assert_allclose(a.curve.control_points, b.curve.control_points, rtol=0,
                               atol=rtol * scale)
    np.testing.assert_allclose(a.history[:, 1:], b.history[:, 1:], rtol=rtol,
                               atol=rtol * max(a.sum_before, 1e-300))
    for x, y in ((a.sum_before, b.sum_before), (a.sum_after, b.sum_after),
                 (a.sum_tracked, b.sum_tracked)):
        assert abs(x - y) <= rtol * max(abs(y), a.sum_before) + 1e-300


def case_args(rng, p, closed, n):
    kw = {}
    r = rng.integers(0, 4)
    if r == 1:
        kw["tol"] = float(rng.choice([1e-6, 1e-3, 0.01, 0.05]))
    elif r >= 2:
        kw["tol"] = float(rng.choice([0.02, 0.2, 1.0]))
    if not closed and rng.integers(0, 2):
        kw["clamp"] = str(rng.choice(["g0", "g1", "g2"]))
    if rng.integers(0, 3) == 0:
        kw["protect"] = [int(i) for i in rng.choice(n, size=2, replace=False)]
    kw["on_tol"] = str(rng.choice(["skip", "stop"]))
    r = rng.integers(0, 4)
    if r == 1:
        kw["eps"] = float(rng.choice([1e-3, 0.05, 0.3]))
    elif r == 2:
        kw["eps"] = float(rng.choice([0.0, 1e-6]))
        kw["eps_relative"] = False
    if rng.integers(0, 3) == 0:
        kw["max_steps"] = int(rng.integers(0, 40))
    return kw


CASES = [(p, dim, closed, variant)
         for p in (2, 3, 4, 5) for dim in (2, 3) for closed in (False, True)
         for variant in ("one-point", "least-squares")]


@pytest.mark.parametrize(("p", "dim", "closed", "variant"), CASES)
def test_compiled_loop_matches_python_reference(p, dim, closed, variant):
    seed = 1000 * p + 100 * dim + 10 * closed + (variant == "least-squares")
    rng = np.random.default_rng(seed)
    reasons = set()
    for trial in range(6):
        n = int(rng.integers(p + 3, 40))
        kind = "noisy" if trial % 2 == 0 else "random"
        c = random_curve(rng, n, p, dim, closed, kind)
        kw = case_args(rng, p, closed, c.n_ctrl)
        got = knot_removal_fair(c, variant=variant, **kw)
        ref = reference_knot_removal_fair(c, variant=variant, **kw)
        assert_same(got, ref)
        reasons.add(ref.stop_reason)
    assert reasons  # (the stop reasons covered over all cases are checked below)


def test_cases_cover_every_stop_reason_and_blocking():
    # the random cases above must exercise every branch of the loop: run a sample and check
    rng = np.random.default_rng(77)
    reasons, n_blocked = set(), 0
    for trial in range(60):
        p = int(rng.integers(2, 6))
        dim = int(rng.integers(2, 4))
        closed = bool(rng.integers(0, 2))
        variant = VARIANTS[trial % 2]
        c = random_curve(rng, int(rng.integers(p + 3, 30)), p, dim, closed,
                         ("noisy", "random")[trial % 3 == 0])
        kw = case_args(rng, p, closed, c.n_ctrl)
        got = knot_removal_fair(c, variant=variant, **kw)
        ref = reference_knot_removal_fair(c, variant=variant, **kw)
        assert_same(got, ref)
        reasons.add(ref.stop_reason)
        n_blocked += len(ref.blocked)
    assert reasons >= {"eps", "no_decrease", "tolerance", "max_steps"}
    assert n_blocked > 0


def noisy_circle(rng, n, p, dim, closed, rel=0.01):
    """Noise ``rel`` times the point spacing: the loop then runs for about n / 5 steps."""
    th = np.linspace(0, 2 * np.pi, n, endpoint=not closed)
    pts = np.c_[np.cos(th), np.sin(th)]
    if dim == 3:
        pts = np.c_[pts, 0.2 * np.sin(3 * th)]
    pts = pts + rel * (2 * np.pi / n) * rng.normal(size=pts.shape)
    return interpolate_bspline(pts, degree=p, closed=closed)


def tol_between_moves(moves):
    """A tolerance near the median move but halfway between two moves that differ by more than
    1e-9 relative, so that no move's ``|new - orig| <= tol`` is decided by rounding."""
    m = np.unique(np.asarray(moves, dtype=float))
    i = m.size // 2
    while i + 1 < m.size and m[i + 1] - m[i] <= 1e-9 * m[i + 1]:
        i += 1
    assert i + 1 < m.size
    return float(0.5 * (m[i] + m[i + 1]))


@pytest.mark.parametrize("variant", VARIANTS)
@pytest.mark.parametrize(("p", "dim", "closed"), [(3, 2, False), (3, 3, True), (2, 2, True),
                                                   (5, 3, False), (4, 2, False)])
def test_long_run_matches_reference(variant, p, dim, closed):
    # hundreds of steps, with and without blocked knots
    rng = np.random.default_rng(5 + p + dim + closed)
    c = noisy_circle(rng, 400, p, dim, closed)
    free = {"eps": 0.0, "eps_relative": False}
    ref = reference_knot_removal_fair(c, variant=variant, **free)
    assert ref.steps > 20
    assert_same(knot_removal_fair(c, variant=variant, **free), ref)
    tol = tol_between_moves(ref.history[:, 2])  # about half the free moves break it
    for kw in ({"tol": tol, "clamp": None if closed else "g2", "eps": 0.0, "protect": [7, 100]},
               {"tol": tol, "on_tol": "stop"}, {"tol": tol, "max_steps": 15}):
        ref = reference_knot_removal_fair(c, variant=variant, **kw)
        assert_same(knot_removal_fair(c, variant=variant, **kw), ref)
        if "clamp" in kw:
            assert ref.steps > 5 and len(ref.blocked) > 5


@pytest.mark.parametrize("variant", VARIANTS)
@pytest.mark.parametrize("p", [6, 7])
def test_higher_degrees_match_reference(variant, p):
    rng = np.random.default_rng(p)
    for closed in (False, True):
        for dim in (2, 3):
            c = noisy_circle(rng, 120, p, dim, closed, rel=0.1)
            for kw in ({"eps": 0.0, "eps_relative": False}, {"tol": 1e-3}):
                assert_same(knot_removal_fair(c, variant=variant, **kw),
                            reference_knot_removal_fair(c, variant=variant, **kw))


def test_no_knots_and_zero_steps():
    c = BSplineCurve(np.random.default_rng(0).normal(size=(4, 2)), [0, 0, 0, 0, 1, 1, 1, 1], 3)
    for kw in ({}, {"max_steps": 0}):
        assert_same(knot_removal_fair(c, **kw), reference_knot_removal_fair(c, **kw))
    c = noisy_circle(np.random.default_rng(1), 30, 3, 2, False)
    got, ref = knot_removal_fair(c, max_steps=0), reference_knot_removal_fair(c, max_steps=0)
    assert got.stop_reason == "max_steps" and got.steps == 0
    assert_same(got, ref)


def test_local_measure_equals_vectorised_one():
    # the loop's scalar measure at every knot, and _KnotData.jumps (bitwise), against the
    # session-2 numpy measure (einsum + sapidis_measure), all degrees/dims
    from curvefair._kernels.knot_removal import knot_measure

    rng = np.random.default_rng(9)
    for p in (2, 3, 4, 5):
        for dim in (2, 3):
            for closed in (False, True):
                c = random_curve(rng, 15, p, dim, closed, "random")
                kd = _KnotData(c)
                old = _RefKnotData(c)  # the per-knot data is bitwise the session-2 one
                for name in ("js", "c", "ctrl"):
                    np.testing.assert_array_equal(getattr(kd, name), getattr(old, name))
                # r'' is kept only where the measure reads it (a quadratic's both sides, a 3-D
                # curve's right one): a planar curve of degree >= 3 keeps r' alone
                two = p == 2 or dim == 3
                assert kd.right.shape == (kd.js.size, 2 if two else 1, p + 1)
                np.testing.assert_array_equal(kd.right, old.right[:, :kd.right.shape[1]])
                if p == 2:
                    np.testing.assert_array_equal(kd.left2, old.left2)
                else:
                    assert kd.left2.shape == (0, p + 1)
                d = np.array(c.control_points)
                ref = old.jumps(d)
                # the vectorised measure: bitwise equal on the development machine, but the
                # einsum reference's summation order may depend on the CPU's SIMD width
                np.testing.assert_allclose(kd.jumps(d), ref, rtol=1e-14, atol=0)
                sub = np.array([0, 3, 2, 2, kd.js.size - 1])
                np.testing.assert_allclose(kd.jumps(d, sub), old.jumps(d, sub), rtol=1e-14,
                                           atol=0)
                got = np.array([knot_measure(d, k, p, kd.ctrl, kd.c, kd.right, kd.left2)
                                for k in range(kd.js.size)])
                np.testing.assert_allclose(got, ref, rtol=4e-16 * 8, atol=0)
                np.testing.assert_array_equal(kd.js, knot_jumps(c)[0])
    # 3-D with straight pieces (r'' = 0 at some knots: the |r' x J| branch) and a planar piece
    for p in (3, 4):
        d = rng.normal(size=(16, 3))
        d[3:3 + p + 2] = np.linspace(0, 1, p + 2)[:, None] * np.array([1.0, 2.0, -1.0])
        d[10:16, 2] = 0.5
        c = BSplineCurve(d, np.r_[[0.0] * p, np.arange(17.0 - p), [16.0 - p] * p], p)
        kd = _KnotData(c)
        r2 = np.einsum("ma,mad->md", kd.right[:, 1, :], d[kd.ctrl[:, 1:]])
        assert np.any(np.abs(r2).max(axis=1) < 1e-12)  # the straight piece is there
        ref = _RefKnotData(c).jumps(d)
        np.testing.assert_array_equal(kd.jumps(d), ref)
        got = np.array([knot_measure(d, k, p, kd.ctrl, kd.c, kd.right, kd.left2)
                        for k in range(kd.js.size)])
        np.testing.assert_allclose(got, ref, rtol=4e-16 * 8, atol=0)


@pytest.mark.parametrize("p", [2, 3, 4, 5])
def test_small_closed_and_multiple_knots_match_reference(p):
    # closed curves with n = p+1 .. p+3 control points (a knot's p+2 basis functions wrap onto
    # the same control point) and open curves with double/triple interior knots (not removable,
    # their neighbours are). eps=0 only for one-point: after a step on a tiny closed curve the
    # jumps left are rounding noise (1e-14), and which noise the least-squares variant leaves
    # (QR here, SVD in the reference) decides further "steps" on noise.
    rng = np.random.default_rng(40 + p)
    for dim in (2, 3):
        curves = [BSplineCurve(rng.normal(size=(n, dim)),
                               np.r_[0.0, np.cumsum(rng.uniform(0.3, 1.7, n))], p, closed=True)
                  for n in range(p + 1, p + 4)]
        inner = np.cumsum(rng.uniform(0.3, 1.7, 25 - p - 1))
        inner[5] = inner[4]
        inner[12] = inner[11]
        if p >= 3:
            inner[13] = inner[12]
        t = np.r_[[0.0] * (p + 1), inner, [inner[-1] + 1] * (p + 1)]
        curves.append(BSplineCurve(rng.normal(size=(25, dim)), t, p))
        for c in curves:
            for variant in VARIANTS:
                for kw in ({}, {"tol": 0.3, "clamp": "g1"}, {"eps": 0.0, "eps_relative": False}):
                    if "eps" in kw and variant == "least-squares":
                        continue
                    assert_same(knot_removal_fair(c, variant=variant, **kw),
                                reference_knot_removal_fair(c, variant=variant, **kw))


def test_pairwise_sum_is_numpys():
    # the tracked sum adds the touched knots' z as numpy's sum does (pairwise), bitwise
    from curvefair._kernels.pairwise import pw_sum_long as _pw_sum_long

    rng = np.random.default_rng(2)
    for m in [*range(0, 140), 255, 256, 1000, 4097]:
        v = rng.normal(size=m) * 10.0 ** rng.uniform(-8, 8, m)
        assert _pw_sum_long(v, m) == v.sum()
