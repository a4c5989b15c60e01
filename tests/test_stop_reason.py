"""Every method's stop_reason is one of curvefair.fairing.StopReason (a typing.Literal)."""

from __future__ import annotations

import typing

import numpy as np
import pytest

from curvefair import BSplineCurve, fair, interpolate_cubic, interpolate_quintic
from curvefair.errors import CurvefairError
from curvefair.fairing import STOP_REASONS, StopReason, available_methods


def _curves() -> dict[str, object]:
    rng = np.random.default_rng(11)
    x = np.linspace(0.0, 3.0, 12)
    opn = np.c_[x, np.sin(x) + 0.03 * rng.standard_normal(12)]
    a = np.linspace(0.0, 2 * np.pi, 15)[:-1]
    ring = np.c_[np.cos(a), np.sin(a)] * (1 + 0.05 * rng.standard_normal(14))[:, None]
    line = np.c_[x, 2.0 * x]
    k3 = np.r_[[0.0] * 3, np.linspace(0.0, 1.0, 10), [1.0] * 3]
    k5 = np.r_[[0.0] * 5, np.linspace(0.0, 1.0, 8), [1.0] * 5]
    return {
        "bs3": BSplineCurve(opn, k3, 3),
        "bs3_closed": BSplineCurve(ring, np.arange(len(ring) + 1.0), 3, closed=True),
        "bs5": BSplineCurve(opn, k5, 5),
        "bs3_line": BSplineCurve(line, k3, 3),
        "bezier": BSplineCurve(opn[:4], [0.0] * 4 + [1.0] * 4, 3),
        "hermite3": interpolate_cubic(opn),
        "hermite3_uniform": interpolate_cubic(opn, param="uniform"),
        "hermite5": interpolate_quintic(opn),
        "hermite3_line": interpolate_cubic(line),
    }


_RUNS = [dict(), dict(tol=1e-2), dict(tol=1e-6), dict(max_steps=1), dict(eps=1e-1),
         "protect_all"]


def test_stop_reason_values():
    assert STOP_REASONS == typing.get_args(StopReason)
    assert len(set(STOP_REASONS)) == len(STOP_REASONS)
    assert "nothing_to_move" not in STOP_REASONS  # one name: "no_movable_point"


def test_every_method_stops_with_a_stop_reason():
    seen: dict[str, set[str]] = {}
    for name, c in _curves().items():
        for m in available_methods(c):
            for run in _RUNS:
                kw = (dict(protect=range(c.control_points.shape[0] if hasattr(c, "control_points")
                                         else c.points.shape[0]))
                      if run == "protect_all" else run)
                try:
                    r = fair(c, m, **kw)
                except CurvefairError:
                    continue  # a method refusing this curve or option (e.g. kjellander)
                reason = r.report["stop_reason"]
                assert reason in typing.get_args(StopReason), (name, m, kw, reason)
                seen.setdefault(m, set()).add(reason)
    # the runs cover every method and the common reasons (the test can fail)
    assert {"poliakoff", "wang-cao", "kjellander", "wang-quintic", "eck-hadenfeld",
            "knot-removal", "global", "cheng-yu"} <= set(seen)
    allr = set().union(*seen.values())
    assert {"converged", "max_steps", "eps", "tolerance", "no_movable_point"} <= allr, allr
    assert "no_knots" in seen["knot-removal"]  # the Bezier curve


@pytest.mark.parametrize("method", ["poliakoff", "eck-hadenfeld", "global"])
def test_protect_everything_is_no_movable_point(method):
    c = _curves()["hermite3" if method == "poliakoff" else "bs3"]
    n = c.points.shape[0] if method == "poliakoff" else c.control_points.shape[0]
    r = fair(c, method, protect=range(n))
    assert r.report["steps"] == 0 and r.report["stop_reason"] == "no_movable_point"
