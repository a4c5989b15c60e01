"""curvefair.analysis.rank_bad_points: one ranking, shown alike by `analyze` and the plots."""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from click.testing import CliRunner  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from curvefair import BSplineCurve, bad_points, interpolate_cubic, write_curves  # noqa: E402
from curvefair import plot as cfplot  # noqa: E402
from curvefair.analysis import rank_bad_points  # noqa: E402
from curvefair.cli import main  # noqa: E402


def _bumped_open_bspline() -> BSplineCurve:
    x = np.linspace(0.0, 6.0, 14)
    P = np.c_[x, np.sin(x)]
    P[5, 1] += 0.25
    P[9, 1] -= 0.15
    knots = np.r_[[0.0] * 3, np.linspace(0.0, 1.0, 12), [1.0] * 3]
    return BSplineCurve(P, knots, 3)


def _bumped_closed_bspline() -> BSplineCurve:
    a = np.linspace(0.0, 2 * np.pi, 13)[:-1]
    P = np.c_[np.cos(a), np.sin(a)]
    P[4] *= 1.2
    return BSplineCurve(P, np.arange(13.0), 3, closed=True)


def _hermite():
    x = np.linspace(0.0, 4.0, 9)
    y = np.sin(x)
    y[4] += 0.3
    y[6] -= 0.1
    return interpolate_cubic(np.c_[x, y])


def _analyze_json(curve, tmp_path: Path) -> list[dict]:
    f = tmp_path / "c.json"
    write_curves(f, [curve])
    r = CliRunner().invoke(main, ["analyze", str(f), "--json", "--no-corners"],
                           catch_exceptions=False)
    assert r.exit_code == 0, r.output
    (item,) = json.loads(r.output)["curves"]
    return item["bad_points"]


def _plotted(curve, n_bad: int) -> np.ndarray:
    fig = Figure()
    ax = fig.add_subplot()
    cfplot.plot_curve(curve, ax, n_bad=n_bad)
    (line,) = [ln for ln in ax.get_lines() if ln.get_gid() == "curvefair-bad-points"]
    return np.asarray(line.get_xydata())


@pytest.mark.parametrize("make", [_bumped_open_bspline, _bumped_closed_bspline, _hermite])
def test_analyze_and_plot_report_the_same_bad_points(make, tmp_path: Path):
    c = make()
    listed = _analyze_json(c, tmp_path)
    assert len(listed) >= 2
    n = min(3, len(listed))
    # the plot marks the curve at each listed bad point's parameter, in the listed order
    want = np.array([c(b["param"]) for b in listed[:n]]).reshape(n, -1)
    np.testing.assert_allclose(_plotted(c, n), want, atol=1e-12)
    assert [b.to_dict() for b in rank_bad_points(c)] == listed


def test_jump_ranking_matches_finite_difference_third_derivative_jumps():
    c = _hermite()
    # independent: r''' is constant on a cubic segment; the forward third difference is exact
    br = c.piecewise.breaks
    h = np.diff(br) / 4
    d3 = np.array([(c(b + 3 * hh) - 3 * c(b + 2 * hh) + 3 * c(b + hh) - c(b)) / hh**3
                   for b, hh in zip(br[:-1], h, strict=True)])
    jumps = np.linalg.norm(np.diff(d3, axis=0), axis=1)  # at breakpoints 1 .. m-1
    order = np.argsort(-jumps) + 1
    assert np.min(np.abs(np.diff(np.sort(jumps)))) > 1e-3 * jumps.max()  # no near-ties
    ranked = rank_bad_points(c)
    assert [b.index for b in ranked] == order.tolist()
    assert all(b.index_of == "data point" and b.derivative == 3 for b in ranked)
    np.testing.assert_allclose([b.measure for b in ranked], jumps[order - 1], rtol=1e-6)
    np.testing.assert_allclose([b.param for b in ranked], br[order], rtol=0, atol=0)


def test_cheng_yu_ranking_on_a_c0_curve_is_that_of_its_pieces_built_by_hand():
    # two cubic B-splines sharing the end control point, joined by a triple knot (a C0 corner)
    a, b = _bumped_open_bspline(), _bumped_closed_bspline()
    Pa = np.asarray(a.control_points)
    Pb = np.asarray(b.control_points)[:8] + (Pa[-1] - np.asarray(b.control_points)[0])
    ka = np.asarray(a.knots)
    kb = np.r_[[0.0] * 4, np.linspace(0.0, 1.0, 6)[1:-1], [1.0] * 4]
    whole = BSplineCurve(np.r_[Pa, Pb[1:]], np.r_[ka[:-1], 1.0 + kb[4:]], 3)
    first = BSplineCurve(Pa, ka, 3)
    second = BSplineCurve(Pb, 1.0 + kb, 3)
    expect = ([(bp.value, bp.index, 0) for bp in bad_points(first)]
              + [(bp.value, bp.index + Pa.shape[0] - 1, 1) for bp in bad_points(second)])
    expect.sort(key=lambda e: -e[0])
    ranked = rank_bad_points(whole)
    assert [(b.measure, b.index, b.piece) for b in ranked] == expect
    assert all(b.index_of == "control point" and b.derivative is None for b in ranked)


def test_cheng_yu_bump_is_ranked_worst_at_its_joint():
    c = _bumped_closed_bspline()
    (worst, *_) = rank_bad_points(c)
    assert worst.index == 4 and worst.kinds[0] == 2
    # one period 0 .. 12 given: the full knot vector is -3 .. 15, so N_4 lives on
    # [t_4, t_8] = [1, 5] and peaks at its middle knot t_6 = 3 (uniform knots: symmetric basis)
    assert np.asarray(c.knots)[4:9].tolist() == [1.0, 2.0, 3.0, 4.0, 5.0]
    assert worst.param == 3.0
