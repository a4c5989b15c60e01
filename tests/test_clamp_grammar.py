"""One clamp grammar (curvefair._validate.parse_clamp) for fair() and every method function."""

from __future__ import annotations

import numpy as np
import pytest

from curvefair import BSplineCurve, fair, interpolate_cubic
from curvefair._validate import parse_clamp
from curvefair.errors import InputError
from curvefair.fairing.cheng_yu import cheng_yu_driver
from curvefair.fairing.eck_hadenfeld import eck_hadenfeld_fair
from curvefair.fairing.global_fair import global_fair
from curvefair.fairing.knot_removal import knot_removal_fair


def _bspline() -> BSplineCurve:
    x = np.linspace(0.0, 3.0, 12)
    rng = np.random.default_rng(5)
    P = np.c_[x, np.sin(x) + 0.05 * rng.standard_normal(12)]
    return BSplineCurve(P, np.r_[[0.0] * 3, np.linspace(0.0, 1.0, 10), [1.0] * 3], 3)


def _fixed_ends(c: BSplineCurve, out: BSplineCurve) -> tuple[int, int]:
    """How many end control points did not move (left, right) -- read off the result."""
    same = np.all(np.asarray(out.control_points) == np.asarray(c.control_points), axis=1)
    left = int(np.argmin(same)) if not same.all() else same.size
    right = int(np.argmin(same[::-1])) if not same.all() else same.size
    return left, right


_FUNCS = {
    "eck_hadenfeld_fair": lambda c, cl: eck_hadenfeld_fair(c, tol=0.05, clamp=cl).curve,
    "knot_removal_fair": lambda c, cl: knot_removal_fair(c, tol=0.05, clamp=cl).curve,
    "global_fair": lambda c, cl: global_fair(c, tol=0.05, clamp=cl).curve,
    "cheng_yu_driver": lambda c, cl: cheng_yu_driver(c, tol=0.05, clamp=cl).curve,
    "fair eck-hadenfeld": lambda c, cl: fair(c, "eck-hadenfeld", tol=0.05, clamp=cl).curve,
    "fair global": lambda c, cl: fair(c, "global", tol=0.05, clamp=cl).curve,
    "fair knot-removal": lambda c, cl: fair(c, "knot-removal", tol=0.05, clamp=cl).curve,
    "fair cheng-yu": lambda c, cl: fair(c, "cheng-yu", tol=0.05, clamp=cl).curve,
}


def test_parse_clamp_grammar():
    assert parse_clamp("G1") == ("g1", "g1")
    assert parse_clamp(None) == ("none", "none")
    assert parse_clamp(("NONE", "g2")) == ("none", "g2")
    assert parse_clamp([None, "G0"]) == ("none", "g0")
    for bad in ("g3", "free", 1, ("g0",), ("g0", "g1", "g2"), ("g0", 2)):
        with pytest.raises(InputError, match="clamp"):
            parse_clamp(bad)


@pytest.mark.parametrize("entry", list(_FUNCS))
def test_every_entry_point_takes_the_same_spellings(entry):
    c = _bspline()
    run = _FUNCS[entry]
    # any case means the same: the results are identical
    for lower, other in (("g1", "G1"), ("g2", ("G2", "g2")), (("g0", "g2"), ["G0", "G2"])):
        a, b = run(c, lower), run(c, other)
        np.testing.assert_array_equal(np.asarray(a.control_points), np.asarray(b.control_points))
    # per-end pairs fix 1, 2, 3 end control points (g0, g1, g2) at least; Cheng-Yu never moves
    # the two end points of each side (see cheng_yu_driver)
    left, right = _fixed_ends(c, run(c, ("g0", "g2")))
    assert left >= 1 and right >= 3
    for bad in ("g3", "free", ("g0",)):
        with pytest.raises(InputError, match="clamp"):
            run(c, bad)


@pytest.mark.parametrize("entry", ["eck_hadenfeld_fair", "global_fair", "fair global"])
def test_none_frees_the_end_control_points(entry):
    c = _bspline()
    out = _FUNCS[entry](c, ("none", "NONE"))
    np.testing.assert_array_equal(_FUNCS[entry](c, (None, None)).control_points,
                                  out.control_points)
    moved = np.any(np.asarray(out.control_points) != np.asarray(c.control_points), axis=1)
    assert moved[0] or moved[-1]  # a free end point moves on this noisy curve


def test_hermite_methods_refuse_a_free_end_naming_clamp():
    h = interpolate_cubic(np.c_[np.linspace(0, 3, 9), np.sin(np.linspace(0, 3, 9))])
    for m in ("poliakoff", "wang-cao"):
        assert fair(h, m, tol=0.01, clamp="G1").report["steps"] >= 0
        with pytest.raises(InputError, match="clamp 'none'"):
            fair(h, m, tol=0.01, clamp="none")
