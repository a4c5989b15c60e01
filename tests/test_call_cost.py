"""The cheap paths of a fair() call give what the full computation gives.

- a Hermite tolerance re-run rebuilds the loop's start from the pristine data (``_restart``):
  its kernel arguments equal those of a fresh ``prepare()`` at the new tolerance, byte for
  byte;
- ``FairingReport.to_dict()`` turns the per-point arrays into lists equal to them, and a
  non-finite float anywhere into None (``json.dumps(allow_nan=False)`` accepts it).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import curvefair as cf
from curvefair.fairing import local_hermite as lh
from curvefair.fairing.fair import FairingReport


def _noisy(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    s = np.cumsum(rng.uniform(0.5, 1.0, n))
    return np.c_[s, np.sin(s)] + 0.05 * rng.normal(size=(n, 2))


@pytest.mark.parametrize("method,builder", [("poliakoff", cf.interpolate_cubic),
                                            ("wang-cao", cf.interpolate_cubic),
                                            ("wang-quintic", cf.interpolate_quintic)])
@pytest.mark.parametrize("mode", ["spline", "hermite"])
def test_restart_equals_fresh_prepare(method, builder, mode):
    c = builder(_noisy(25, 3))
    kw = dict(method=method, eps=0.0, max_steps=50, clamp=("g1", "g0"),
              protect=frozenset({4}), mode=mode)
    first = lh.prepare(c, tol=0.02, **kw)
    run = lh._k.drive(*first["args"])  # modifies first's state in place
    assert run[0] > 0  # it moved points: the restart has something to undo
    old_P = first["P"]
    again = lh._restart(first, 0.0123)
    fresh = lh.prepare(c, tol=0.0123, **kw)
    assert again["P"] is not old_P and not np.array_equal(old_P, fresh["P"])
    assert len(again["args"]) == len(fresh["args"])
    for k, (a, b) in enumerate(zip(again["args"], fresh["args"], strict=True)):
        if isinstance(b, np.ndarray):
            assert a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes(), k
        else:
            assert a == b, k
    # the retargeted run is the fresh run
    ra = lh._k.drive(*again["args"])
    rb = lh._k.drive(*fresh["args"])
    assert ra[0] == rb[0] and ra[1] == rb[1]
    assert np.array_equal(again["P"], fresh["P"]) and np.array_equal(again["D"], fresh["D"])


def test_report_to_dict_lists_arrays_and_drops_non_finite():
    res = cf.fair(cf.interpolate_cubic(_noisy(30, 5)), "poliakoff", tol=0.01)
    rep = res.report
    assert isinstance(rep, FairingReport) and isinstance(rep, dict)
    d = rep.to_dict()
    assert type(d) is dict
    assert d["moved"]["indices"] == [int(i) for i in rep["moved"]["indices"]]
    assert d["moved"]["displacement"] == [float(v) for v in rep["moved"]["displacement"]]
    # a report entry a user adds (the CLI adds on-disk figures) goes through to_dict too
    rep2 = FairingReport(rep)
    rep2["extra_values"] = np.array([1.0, np.nan, np.inf, 2.0])
    rep2["extra_int"] = np.int64(3)
    d2 = rep2.to_dict()
    assert d2["extra_values"] == [1.0, None, None, 2.0] and d2["extra_int"] == 3
    json.dumps(d2, allow_nan=False)


@pytest.mark.parametrize("degree,closed,dim", [(3, False, 2), (3, True, 2), (2, False, 3),
                                               (5, True, 3), (4, False, 2)])
def test_primed_power_forms_equal_separate_ones(degree, closed, dim):
    # fair() builds the result's power form and the difference curve's in one pass over the
    # spans; each must be bitwise what the curve's own power form and the certificate's
    # separate pass (_difference_form on new - original) give
    from curvefair.fairing import _tolerance as T

    rng = np.random.default_rng(degree * 10 + closed)
    P = _noisy(40, 7)
    if dim == 3:
        P = np.c_[P, 0.1 * rng.normal(size=40)]
    c = cf.interpolate_bspline(P, degree=degree, closed=closed)
    moved = np.array(c.control_points) + 1e-3 * rng.normal(size=c.control_points.shape)
    new = c.replace(control_points=moved)
    primed = T.prime_power_forms(c, new)
    assert primed is not None and primed[0] is new
    fresh = c.replace(control_points=moved)  # no cached form
    assert np.array_equal(new.piecewise.coeffs, fresh.piecewise.coeffs)
    assert np.array_equal(new.piecewise.breaks, fresh.piecewise.breaks)
    delta = {"control_points": np.asarray(fresh.control_points) - np.asarray(c.control_points)}
    sep = T._difference_form(c, delta)
    # the pair pass's difference form (what prime_power_forms measures and then frees) is
    # bitwise the separate pass's
    from curvefair.curves import bspline as B

    s = np.ascontiguousarray(c.spans, dtype=np.int64)
    own = np.empty((s.size, degree + 1, dim))
    diff = np.empty_like(own)
    B.power_form(np.ascontiguousarray(c.knots), degree, s, np.ascontiguousarray(moved), closed,
                 own, np.ascontiguousarray(c.control_points), diff)
    assert np.array_equal(own, fresh.piecewise.coeffs)
    assert np.array_equal(diff, sep.coeffs)
    # and the certificate figures it gives are the ones computed from scratch
    figs = T.difference_deviation(c, fresh)
    assert primed[1] == figs and all(np.isfinite(figs))
    # other knots or a Hermite curve: nothing primed
    other = cf.interpolate_bspline(P * 1.01, degree=degree, closed=closed)
    assert T.prime_power_forms(c, other) is None
    h = cf.interpolate_cubic(P)
    assert T.prime_power_forms(h, h) is None


def test_difference_forms_are_borrowed_not_copied():
    """fair()'s tolerance checks build difference curves that no user sees: their power forms
    keep the freshly computed coefficients (no frozen copy), marked read-only; the zero curve
    they are measured against shares their breaks. The curve's own cached form stays frozen."""
    from curvefair.curves.piecewise import _frozen
    from curvefair.fairing import _tolerance as T

    rng = np.random.default_rng(4)
    for c in (cf.interpolate_bspline(_noisy(60, 3)), cf.interpolate_cubic(_noisy(60, 3))):
        f = T.curve_fields(c)
        delta = {k: 1e-3 * rng.normal(size=v.shape) for k, v in f.items()}
        pp = T._difference_form(c, delta)
        assert not pp.coeffs.flags.writeable and not _frozen(pp.coeffs)
        assert pp.coeffs.base is None or not isinstance(pp.coeffs.base, bytes)
        with pytest.raises(ValueError):
            pp.coeffs[0, 0, 0] = 1.0
        # the same figures as a frozen form of the same coefficients
        frozen = T.PiecewisePolynomial(np.array(pp.breaks), np.array(pp.coeffs))
        assert T._against_zero(pp, c.closed).to_dict() == \
            T._against_zero(frozen, c.closed).to_dict()
    b = cf.interpolate_bspline(_noisy(60, 3))
    moved = np.asarray(b.control_points) + 1e-3
    new, figs = T.prime_power_forms(b, b.replace(control_points=moved))
    assert _frozen(new.piecewise.coeffs) and _frozen(new.piecewise.breaks)
    assert figs == T.difference_deviation(b, b.replace(control_points=moved))


def test_readonly_of_strided_views_is_one_frozen_copy():
    """``readonly`` of a strided or Fortran-ordered view: the same values in C order, in memory
    nobody can make writeable (an immutable ``bytes`` base), the source untouched."""
    from curvefair.curves.piecewise import readonly

    rng = np.random.default_rng(3)
    a = rng.normal(size=(50, 4, 3))
    for view in (a[:, 0, :], a[1:, 2, 1], np.asfortranarray(a[:, :, 0]), a[::3, ::-1, :]):
        r = readonly(view)
        np.testing.assert_array_equal(r, np.array(view))
        assert r.flags.c_contiguous and not r.flags.writeable
        base = r
        while isinstance(base, np.ndarray):
            base = base.base
        assert isinstance(base, bytes)
        with pytest.raises(ValueError):
            r.setflags(write=True)
    assert readonly(r) is r  # already frozen: no copy


@pytest.mark.parametrize("dim", [2, 3])
def test_extent_reductions_equal_the_axis0_formulas(dim):
    """``analysis._sampling._unit`` and ``fairing.joins._size`` reduce column by column; the
    figures equal the axis-0 formulas they replaced (min/max are exact)."""
    from curvefair.analysis._sampling import _unit
    from curvefair.fairing.joins import _size

    rng = np.random.default_rng(dim)
    for scale in (1e-30, 1.0, 3e5, 1e30):
        cw = scale * rng.normal(size=(257, 4, dim))
        start = cw[:, 0, :]
        diag = float(np.sqrt(np.sum((start.max(axis=0) - start.min(axis=0)) ** 2)))
        assert _unit(cw) == float(2.0 ** int(np.clip(np.round(np.log2(diag)), -1000, 1000)))
        pts = np.ascontiguousarray(cw[:, 1, :]) + 7.0 * scale
        ref = max(float(np.ptp(pts, axis=0).max()), float(np.abs(pts).max()), 1e-300)
        assert _size(pts) == ref


def test_point_data_read_back_bound_meets_a_dense_hausdorff_distance(tmp_path):
    """The write check of point data uses the O(n) per-span bound
    (:func:`curvefair.analysis.matched_hermite_bound`): the figure it reports for faired DXF
    polylines is at least their Hausdorff distance measured independently (scipy's natural
    CubicSpline through the points read back with ezdxf, sampled 20,001 times per curve,
    nearest neighbours with cKDTree) and the file holds within tol."""
    ezdxf = pytest.importorskip("ezdxf")
    from scipy.interpolate import CubicSpline
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(5)
    doc = ezdxf.new("R2010")
    for k in range(3):
        t = np.linspace(0.0, 20.0, 40)
        P = np.c_[t, np.sin(t / 3 + k) * 4] + 0.02 * rng.normal(size=(40, 2))
        doc.modelspace().add_lwpolyline([tuple(p) for p in P])
    src, dst = tmp_path / "in.dxf", tmp_path / "out.dxf"
    doc.saveas(src)
    tol = 0.01
    recs = cf.read_curves(src, polylines=True)
    faired = [r.with_curve(cf.fair(r.curve, "poliakoff", tol=tol).curve) for r in recs]
    check = cf.write_curves(dst, faired, template=src, tol=tol)

    def dense(P: np.ndarray) -> np.ndarray:
        u = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))]
        return CubicSpline(u, P, bc_type="natural")(np.linspace(0.0, u[-1], 20001))

    back = [np.array([(v[0], v[1]) for v in e.get_points("xy")])
            for e in ezdxf.readfile(dst).modelspace().query("LWPOLYLINE")]
    assert len(back) == len(recs) == len(check.deviations)
    for r, q, d, kind in zip(recs, back, check.deviations, check.kinds, strict=True):
        a, b = dense(np.asarray(r.curve.points)), dense(q)
        h = max(cKDTree(b).query(a)[0].max(), cKDTree(a).query(b)[0].max())
        spacing = np.linalg.norm(np.diff(a, axis=0), axis=1).max()
        assert kind == "geometric upper bound"
        assert h - spacing <= d <= tol


def _report_without_time(r):
    d = r.report.to_dict()
    d.pop("time_s")
    return d


@pytest.mark.parametrize("method,opts", [("eck-hadenfeld", {"tol": 0.02}),
                                         ("global", {"tol": 0.02}),
                                         ("knot-removal", {"tol": 0.02}),
                                         ("cheng-yu", {"tol": 0.02})])
def test_fair_leaves_the_input_caches_as_they_were(method, opts):
    """fair() drops what it built on the caller's curve (its power form after the analysis and
    join plan, the Gram bands after the method: 72 and 56 bytes per span of a planar cubic at
    the call's peak), keeps what the caller had built, and gives bitwise the same result
    either way."""
    P = _noisy(300, 11)
    base = cf.interpolate_bspline(P)
    ctrl, knots = np.array(base.control_points), np.array(base.knots)
    bare = cf.BSplineCurve(ctrl, knots, 3)
    assert "piecewise" not in bare.__dict__ and not bare._gram_cache
    r_bare = cf.fair(bare, method, **opts)
    assert "piecewise" not in bare.__dict__ and not bare._gram_cache
    assert not r_bare.curve._gram_cache

    warm = cf.BSplineCurve(ctrl, knots, 3)
    form = warm.piecewise
    band = warm.gram_band(2)
    r_warm = cf.fair(warm, method, **opts)
    assert warm.__dict__["piecewise"] is form and warm._gram_cache[2] is band
    assert np.array_equal(r_bare.curve.control_points, r_warm.curve.control_points)
    assert np.array_equal(r_bare.curve.knots, r_warm.curve.knots)
    assert _report_without_time(r_bare) == _report_without_time(r_warm)
    assert r_bare.report["steps"] > 0 and r_bare.report["n_moved"] > 0


def test_certificate_against_the_zero_curve_reads_the_form_in_place():
    """The certificate measures the difference form against one broadcast 0.0 without copying
    the form (x - 0.0 is x bit for bit): the same figures as against an explicit zero curve."""
    from curvefair.analysis import deviation
    from curvefair.fairing import _tolerance as T

    rng = np.random.default_rng(8)
    for c in (cf.interpolate_bspline(_noisy(80, 5)),
              cf.interpolate_bspline(_noisy(80, 6), closed=True),
              cf.interpolate_cubic(_noisy(80, 7))):
        delta = {k: 1e-3 * rng.normal(size=v.shape) for k, v in T.curve_fields(c).items()}
        pp = T._difference_form(c, delta)
        explicit = T.PiecewisePolynomial(np.array(pp.breaks), np.zeros(pp.coeffs.shape))
        ref = deviation(T._PowerForm(pp, c.closed), T._PowerForm(explicit, c.closed))
        got = T._against_zero(pp, c.closed)
        assert got.to_dict() == ref.to_dict()
        assert got.max_distance > 0.0
        # and the figure is the difference curve's largest norm (dense sampling below it)
        u = np.linspace(*c.domain, 20001)
        dense = np.linalg.norm(pp.evaluate(u), axis=1).max()
        assert dense <= got.upper_bound and got.max_distance <= dense * (1 + 1e-3)


def test_import_leaves_scipy_interpolate_unloaded():
    """``import curvefair`` (every CLI run pays it) does not load ``scipy.interpolate``
    (0.3 s of a 2 s import): the modules that use it import it where used. Checked in a fresh
    interpreter; then one function that needs it still works there."""
    import subprocess
    import sys

    code = ("import sys, numpy as np, curvefair as cf\n"
            "print('scipy.interpolate' in sys.modules)\n"
            "c = cf.BSplineCurve(np.arange(8.).reshape(4, 2), [0.] * 4 + [1.] * 4, 3)\n"
            "b = cf.BSplineCurve.from_scipy(c.to_scipy())\n"
            "print(type(b).__name__, 'scipy.interpolate' in sys.modules)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=600, check=True).stdout.split()
    assert out == ["False", "BSplineCurve", "True"]
