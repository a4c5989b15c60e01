"""One contract between fair() and the methods (issue 15): the options parsed once into a
FairingProblem, every built-in method a solver returning one Outcome, one meaning of eps."""

from __future__ import annotations

import math

import numpy as np
import pytest

from curvefair import BSplineCurve, fair, interpolate_cubic, interpolate_quintic
from curvefair.analysis.discrete import second_discrete_curvature
from curvefair.errors import InputError
from curvefair.fairing import METHODS
from curvefair.fairing.problem import FairingProblem, Outcome, fixed_mask, make_problem


def _pts(n=12, seed=3):
    rng = np.random.default_rng(seed)
    x = np.linspace(0.0, 3.0, n)
    return np.c_[x, np.sin(x) + 0.04 * rng.standard_normal(n)]


def _bs(p=3):
    pts = _pts()
    k = np.r_[[0.0] * p, np.linspace(0.0, 1.0, len(pts) - p + 1), [1.0] * p]
    return BSplineCurve(pts, k, p)


def test_make_problem_normalises():
    c = _bs()
    pr = make_problem(c, tol=None, clamp="G1", protect=[4])
    assert pr.tol == math.inf and pr.tol_or_none is None
    assert pr.clamp == ("g1", "g1") and pr.protect == frozenset({4})
    assert pr.eps is None and pr.max_steps is None
    # fixed points: 2 per g1 end of a B-spline, and the protected one (counted independently)
    want = np.zeros(c.n_ctrl, dtype=bool)
    want[[0, 1, 4, c.n_ctrl - 2, c.n_ctrl - 1]] = True
    np.testing.assert_array_equal(pr.fixed, want)
    h = interpolate_cubic(_pts())
    np.testing.assert_array_equal(fixed_mask(h, ("g2", "g2"), [5]),
                                  np.isin(np.arange(12), [0, 5, 11]))
    for bad in (0, 0.0, -1.0, math.inf, math.nan):
        with pytest.raises(InputError, match="tol"):
            make_problem(c, tol=bad)
    with pytest.raises(InputError, match="eps"):
        make_problem(c, eps=-1.0)
    with pytest.raises(InputError, match="protect"):
        make_problem(c, protect=[99])


def test_method_functions_refuse_tol_zero_like_fair():
    from curvefair.fairing.cheng_yu import cheng_yu_driver
    from curvefair.fairing.eck_hadenfeld import eck_hadenfeld_fair
    from curvefair.fairing.global_fair import global_fair
    from curvefair.fairing.knot_removal import knot_removal_fair

    c = _bs()
    for fn in (eck_hadenfeld_fair, knot_removal_fair, global_fair, cheng_yu_driver):
        with pytest.raises(InputError, match="tol"):
            fn(c, tol=0.0)
    with pytest.raises(InputError, match="tol"):
        fair(c, "global", tol=0.0)


def test_every_builtin_method_is_a_solver_of_the_problem():
    c3, c5, b = interpolate_cubic(_pts()), interpolate_quintic(_pts()), _bs()
    for name, spec in METHODS.items():
        assert spec.solver is not None, name
        curve = c5 if name == "wang-quintic" else (b if name in (
            "eck-hadenfeld", "knot-removal", "global", "cheng-yu") else c3)
        if name == "kjellander":
            curve = interpolate_cubic(_pts(), param="uniform")
        out = spec.solver(make_problem(curve, tol=0.05, max_steps=5))
        assert isinstance(out, Outcome)
        assert out.history is not None
        want = ("knot" if name == "knot-removal" else
                "control point" if curve is b else "data point")
        assert out.history.counts == want, name
        # the keyword (driver) form is derived from the solver and gives the same result
        out2 = spec.driver(curve, tol=0.05, eps=None, max_steps=5, clamp=("g0", "g0"),
                           protect=frozenset())
        np.testing.assert_array_equal(np.asarray(out.curve(np.linspace(*curve.domain, 7))),
                                      np.asarray(out2.curve(np.linspace(*curve.domain, 7))))



def test_points_l1_without_a_tolerance_runs_poliakoff_on_the_same_problem():
    # no tube to work in: the solver hands the problem to poliakoff (and says so); the same
    # curve as poliakoff's own solver gives for that problem
    c = interpolate_cubic(_pts())
    out = METHODS["points-l1"].solver(make_problem(c, max_steps=7))
    ref = METHODS["poliakoff"].solver(make_problem(c, max_steps=7))
    assert "poliakoff" in out.extra["points_l1"]
    u = np.linspace(*c.domain, 11)
    np.testing.assert_array_equal(np.asarray(out.curve(u)), np.asarray(ref.curve(u)))
    assert out.steps == ref.steps

def test_fair_history_says_what_it_counts():
    r = fair(_bs(), "knot-removal", tol=0.05)
    assert r.history.counts == "knot" and r.history.to_dict()["counts"] == "knot"
    assert fair(_bs(), "eck-hadenfeld", tol=0.05).history.counts == "control point"
    assert fair(interpolate_cubic(_pts()), "poliakoff", tol=0.05).history.counts == "data point"


@pytest.mark.parametrize("method", ["poliakoff", "wang-cao", "wang-quintic", "eck-hadenfeld",
                                    "knot-removal", "global", "cheng-yu"])
def test_eps_is_relative_to_the_initial_measure(method):
    """report["eps_absolute"] = eps x the method's initial fairness measure, each measure
    recomputed here from its own definition or the report's before-figure."""
    eps = 0.05
    if method in ("poliakoff", "wang-cao"):
        c = interpolate_cubic(_pts())
    elif method == "wang-quintic":
        c = interpolate_quintic(_pts())
    else:
        c = _bs()
    r = fair(c, method, tol=0.05, eps=eps, guard=False).report
    assert r["eps"] == eps
    if method in ("poliakoff", "wang-cao", "wang-quintic"):
        ref = r["measure_max_before"]
        if r["stop_reason"] == "eps":
            assert r["measure_max_after"] < r["eps_absolute"]
    elif method in ("eck-hadenfeld", "global"):
        ref = r["energy_l_before"]  # E_2 from the Gram matrix; the analysis integrates it
        assert math.isclose(ref, r["energy_before"], rel_tol=1e-9)
    elif method == "knot-removal":
        from curvefair.fairing.knot_removal import knot_jumps

        ref = float(np.max(knot_jumps(c)[1]))
    else:
        ref = second_discrete_curvature(c).indicator
        assert math.isclose(ref, r["indicator_before"], rel_tol=0, abs_tol=0)
    assert r["eps_absolute"] == pytest.approx(eps * ref, rel=1e-12)


def test_problem_is_frozen():
    pr = make_problem(_bs())
    assert isinstance(pr, FairingProblem)
    with pytest.raises(AttributeError):
        pr.tol = 1.0  # type: ignore[misc]
