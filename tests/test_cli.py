"""Tests of the ``curvefair`` command.

End-to-end behaviour runs the real command in subprocesses (``python -m curvefair`` and the
console script), several at once where they are independent, on files the tests write. Argument
parsing details use click's in-process runner. Reference values are independent of the code
under test: point displacements measured from the files, third-derivative jumps by finite
differences of curve positions, file bytes compared before and after.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import curvefair
from curvefair import interpolate_bspline, interpolate_cubic, read_curves, write_curves
from curvefair.cli import main

EX1 = "# Wang & Cao 2006, Example 1\nx,y\n1,1\n2,1\n3,1\n4.3,1.6\n5,1\n6,1\n7,1\n"


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env.pop("COLUMNS", None)
    env["PYTHONWARNINGS"] = "ignore"
    return env


def cli_many(arglists: list[list[str]], cwd: Path, timeout: float = 120.0
             ) -> list[subprocess.CompletedProcess]:
    """Run ``python -m curvefair ARGS`` for each argument list, concurrently."""
    procs = [subprocess.Popen([sys.executable, "-m", "curvefair", *args], cwd=cwd,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                              env=_env()) for args in arglists]
    out = []
    for args, p in zip(arglists, procs, strict=True):
        so, se = p.communicate(timeout=timeout)
        out.append(subprocess.CompletedProcess(args, p.returncode, so, se))
    return out


def cli(args: list[str], cwd: Path) -> subprocess.CompletedProcess:
    return cli_many([args], cwd)[0]


def assert_user_error(res: subprocess.CompletedProcess, code: int, *needles: str) -> None:
    assert res.returncode == code, (res.args, res.stdout, res.stderr)
    assert "Traceback" not in res.stderr and "Traceback" not in res.stdout
    for n in needles:
        assert n in res.stderr, (n, res.stderr)


def fd_third_derivative_jumps(c) -> np.ndarray:
    """|r'''(t_k+) - r'''(t_k-)| at interior breakpoints, by third differences of positions.

    r''' is constant on each cubic segment; the forward third difference is exact up to
    rounding.
    """
    br = c.piecewise.breaks
    h = np.diff(br) / 4
    d3 = np.array([(c(b + 3 * hh) - 3 * c(b + 2 * hh) + 3 * c(b + hh) - c(b)) / hh**3
                   for b, hh in zip(br[:-1], h, strict=True)])
    return np.linalg.norm(np.diff(d3, axis=0), axis=1)


@pytest.fixture
def ex1(tmp_path: Path) -> Path:
    p = tmp_path / "ex1.csv"
    p.write_text(EX1)
    return p


# ---------------------------------------------------------------------------------------------
def test_fair_csv_end_to_end(tmp_path: Path, ex1: Path):
    before = ex1.read_bytes()
    tol = 0.3
    res = cli(["fair", "ex1.csv", "-o", "out.csv", "--tol", str(tol), "--no-corners",
               "--decimals", "12", "--report", "rep.json", "--plot", "fig.png"], tmp_path)
    assert res.returncode == 0, res.stderr
    assert ex1.read_bytes() == before  # input untouched, byte for byte
    for col in ("energy", "inflections", "extrema", "max deviation", "steps", "time"):
        assert col in res.stdout
    assert "points-l1" in res.stdout  # the default method for open point lists
    p0 = np.loadtxt(ex1, delimiter=",", skiprows=2)
    (rec,) = read_curves(tmp_path / "out.csv")
    p1 = np.asarray(rec.points)
    assert p1.shape == p0.shape
    moved = np.linalg.norm(p1 - p0, axis=1)
    assert moved.max() <= tol * (1 + 1e-9) + 1e-12  # the tolerance holds
    assert moved[0] == 0.0 and moved[-1] == 0.0  # g0 clamp: ends stay
    assert moved[3] > 0.1  # P4 (0-based 3), the bad point, moved
    assert (tmp_path / "out.csv").read_text().startswith("# Wang & Cao 2006")  # layout kept
    rep = json.loads((tmp_path / "rep.json").read_text())
    assert rep["n_curves"] == 1 and rep["n_failed"] == 0
    r = rep["curves"][0]["report"]
    assert r["energy_after"] < r["energy_before"]
    assert r["max_point_displacement"] == pytest.approx(moved.max(), abs=1e-9)
    assert (tmp_path / "fig.png").read_bytes()[:4] == b"\x89PNG"
    leftovers = sorted(f.name for f in tmp_path.iterdir())
    assert leftovers == ["ex1.csv", "fig.png", "out.csv", "rep.json"]  # no temp files left


MALFORMED = {
    # name: (content, expected text in the message besides the file name)
    "truncated.csv": ("x,y\n1,1\n2,1\n3,", "truncated.csv:4"),
    "garbage.csv": (b"\x00\x01\xff\xfegarbage\n", "garbage.csv:1"),
    "empty.csv": ("", "empty"),
    "nocurve.csv": ("x,y\n", "no data"),
    "nan.csv": ("x,y\n1,1\n2,nan\n3,1\n4,2\n", "nan.csv:3"),
    # (an exact repeat is dropped with a warning; one closer than rounding error is refused)
    "dup.csv": ("x,y\n1,1\n2,1\n2.0000000000000004,1\n3,1\n", "dup.csv:4"),
}


def test_malformed_inputs_exit_1_with_file_and_line(tmp_path: Path):
    for name, (content, _) in MALFORMED.items():
        f = tmp_path / name
        if isinstance(content, bytes):
            f.write_bytes(content)
        else:
            f.write_text(content)
    runs = cli_many([["fair", name, "-o", "out_" + name] for name in MALFORMED]
                    + [["analyze", "nan.csv"], ["plot", "dup.csv", "-o", "f.png"]], tmp_path)
    for (name, (_, needle)), res in zip(MALFORMED.items(), runs, strict=False):
        assert_user_error(res, 1, name, needle)
        assert not (tmp_path / ("out_" + name)).exists()
    assert_user_error(runs[-2], 1, "nan.csv:3")
    assert_user_error(runs[-1], 1, "dup.csv:4")
    assert not (tmp_path / "f.png").exists()


def test_out_equal_in_refused_and_in_place(tmp_path: Path, ex1: Path):
    before = ex1.read_bytes()
    (tmp_path / "sub").mkdir()
    runs = cli_many([["fair", "ex1.csv", "-o", "ex1.csv", "--no-corners"],
                     ["fair", "ex1.csv", "-o", "sub/../ex1.csv", "--no-corners"],
                     ["fair", "ex1.csv", "--no-corners"]], tmp_path)
    for res in runs:
        assert_user_error(res, 2)
        assert "--in-place" in res.stderr
    assert ex1.read_bytes() == before
    res = cli(["fair", "ex1.csv", "--in-place", "--tol", "0.2", "--no-corners", "-q"], tmp_path)
    assert res.returncode == 0, res.stderr
    assert res.stdout == ""  # --quiet
    assert ex1.read_bytes() != before
    (rec,) = read_curves(ex1)
    p0 = np.loadtxt(EX1.splitlines()[2:], delimiter=",")
    assert np.max(np.linalg.norm(np.asarray(rec.points) - p0, axis=1)) <= 0.2 + 0.05  # 1 decimal
    assert sorted(f.name for f in tmp_path.iterdir()) == ["ex1.csv", "sub"]


def test_analyze_json_ranks_bad_points_by_fd_third_derivative_jumps(tmp_path: Path, ex1: Path):
    res = cli(["analyze", "ex1.csv", "--json", "--no-corners"], tmp_path)
    assert res.returncode == 0, res.stderr
    doc = json.loads(res.stdout)
    (item,) = doc["curves"]
    bad = item["bad_points"]
    c = interpolate_cubic(np.loadtxt(ex1, delimiter=",", skiprows=2))  # chord, natural: as read
    jumps = fd_third_derivative_jumps(c)
    order = np.argsort(-jumps) + 1  # breakpoint k = data point k
    assert [b["index"] for b in bad] == order.tolist()
    np.testing.assert_allclose([b["measure"] for b in bad], jumps[order - 1], rtol=1e-6)
    assert bad[0]["index"] == 3 and bad[0]["index_of"] == "data point"
    assert item["analysis"]["inflections"] == 4  # sign changes of the curvature (Fig. 1b)


def test_plot_command_compare_and_bad_extension(tmp_path: Path, ex1: Path):
    q = np.loadtxt(ex1, delimiter=",", skiprows=2)
    q[3] = (4.2, 1.05)
    np.savetxt(tmp_path / "other.csv", q, delimiter=",", header="x,y", comments="")
    runs = cli_many([["plot", "ex1.csv", "--compare", "other.csv", "-o", "cmp.svg",
                      "--comb-density", "4", "--no-corners", "--tol", "0.6"],
                     ["plot", "ex1.csv", "-o", "fig.jpg"]], tmp_path)
    assert runs[0].returncode == 0, runs[0].stderr
    svg = (tmp_path / "cmp.svg").read_text()
    assert svg.startswith("<?xml") and "<svg" in svg
    assert_user_error(runs[1], 2, ".png")
    assert not (tmp_path / "fig.jpg").exists()


def test_partial_failure_processes_the_other_curves(tmp_path: Path):
    x = np.linspace(0, 4, 9)
    y = np.sin(x)
    y[4] += 0.3
    herm = interpolate_cubic(np.c_[x, y])
    bsp = interpolate_bspline(np.c_[x, np.cos(x) + 3])
    write_curves(tmp_path / "two.json", [herm, bsp])
    before = (tmp_path / "two.json").read_bytes()
    res = cli(["fair", "two.json", "-o", "out.json", "--method", "poliakoff", "--tol", "0.2"],
              tmp_path)
    assert_user_error(res, 1, "curve 1", "BSplineCurve")
    assert (tmp_path / "two.json").read_bytes() == before
    a, b = read_curves(tmp_path / "out.json")
    moved = np.linalg.norm(np.asarray(a.curve.points) - herm.points, axis=1)
    assert 0 < moved.max() <= 0.2 * (1 + 1e-9)
    np.testing.assert_array_equal(b.curve.control_points, bsp.control_points)  # unchanged


def test_dxf_spline_fairing(tmp_path: Path):
    ezdxf = pytest.importorskip("ezdxf")
    x = np.linspace(0, 10, 12)
    y = np.sin(x / 2)
    y[5] += 0.4
    b = interpolate_bspline(np.c_[x, y])
    doc = ezdxf.new()
    doc.modelspace().add_open_spline([(px, py, 0.0) for px, py in b.control_points], degree=3,
                                     knots=list(b.knots))
    doc.saveas(tmp_path / "part.dxf")
    before = (tmp_path / "part.dxf").read_bytes()
    # tol 0.2: at 0.05 the fairing adds two inflections and the never-worse guard keeps the input
    res = cli(["fair", "part.dxf", "-o", "out.dxf", "--tol", "0.2"], tmp_path)
    assert res.returncode == 0, res.stderr
    assert "global" in res.stdout  # the default B-spline method (l=3)
    assert (tmp_path / "part.dxf").read_bytes() == before
    (rec,) = read_curves(tmp_path / "out.dxf")
    moved = np.linalg.norm(np.asarray(rec.curve.control_points) - b.control_points, axis=1)
    assert 0 < moved.max() <= 0.2 * (1 + 1e-9)


def test_console_script_and_version(tmp_path: Path):
    script = Path(sys.executable).with_name("curvefair")
    if not script.exists():
        pytest.skip("console script not installed in this environment")
    res = subprocess.run([str(script), "--version"], capture_output=True, text=True,
                         cwd=tmp_path, env=_env(), timeout=120)
    assert res.returncode == 0
    assert res.stdout.strip() == f"curvefair {curvefair.__version__}"


# --- in-process: argument parsing and help ---------------------------------------------------
def test_help_lists_examples_and_default_methods():
    from curvefair.fairing import METHODS

    r = CliRunner().invoke(main, ["--help"])
    assert r.exit_code == 0
    assert "Examples" in r.output and "curvefair fair" in r.output
    r = CliRunner().invoke(main, ["fair", "--help"])
    assert r.exit_code == 0
    text = " ".join(r.output.split()).replace("- ", "-")
    method_help = text[text.index("--method M"):text.index("--tol T")]
    for spec in METHODS.values():
        if spec.default:
            for t in spec.curve_types:
                # each curve type is named once, with every default it can get
                assert method_help.count(f"{t.__name__}:") == 1, t.__name__
                entry = method_help.split(f"{t.__name__}:")[1].split(";")[0]
                assert spec.name in entry, (t.__name__, spec.name, entry)


def test_methods_listing_matches_registry():
    from curvefair.fairing import METHODS

    r = CliRunner().invoke(main, ["methods", "--json"])
    assert r.exit_code == 0
    rows = json.loads(r.output)
    assert [x["name"] for x in rows] == list(METHODS)
    assert all(x["source"] and x["summary"] for x in rows)
    r = CliRunner().invoke(main, ["methods"])
    assert r.exit_code == 0
    for name in METHODS:
        assert name in r.output


@pytest.mark.parametrize("args", [
    ["fair", "ex1.csv", "-o", "o.csv", "--protect", "1,x"],
    ["fair", "ex1.csv", "-o", "o.csv", "--protect", "-1"],
    ["fair", "ex1.csv", "-o", "o.csv", "--tol", "0"],
    ["fair", "ex1.csv", "-o", "o.csv", "--clamp", "g3"],
    ["fair", "ex1.csv", "-o", "o.csv", "--method", "nope"],
    ["fair", "missing.csv", "-o", "o.csv"],
    ["fair", "ex1.csv", "-o", "nofolder/o.csv"],
    ["plot", "ex1.csv", "-o", "f.gif"],
    ["fair", "ex1.csv", "--bogus"],
    ["fair", "ex1.csv", "-o", "o.csv", "-O", "noequals"],
    ["fair", "ex1.csv", "-o", "o.csv", "--option", "=3"],
    ["fair", "ex1.csv", "-o", "o.csv", "-O", "tol=0.1"],
])
def test_usage_errors_exit_2(tmp_path: Path, ex1: Path, args, monkeypatch):
    monkeypatch.chdir(tmp_path)
    r = CliRunner().invoke(main, args)
    assert r.exit_code == 2, r.output
    assert not (tmp_path / "o.csv").exists()


def test_protect_indices_follow_file_order(tmp_path: Path, ex1: Path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    r = CliRunner().invoke(main, ["fair", "ex1.csv", "-o", "o.csv", "--protect", "3",
                                  "--no-corners", "--decimals", "12", "-q"])
    assert r.exit_code == 0, r.output
    (rec,) = read_curves(tmp_path / "o.csv", corner_angle=None)
    p0 = np.loadtxt(ex1, delimiter=",", skiprows=2)
    np.testing.assert_array_equal(np.asarray(rec.points)[3], p0[3])  # protected P4 stays
    assert np.max(np.abs(np.asarray(rec.points) - p0)) > 1e-3  # others moved


# --- method options: -O KEY=VALUE -------------------------------------------------------------
def _bspline_file(tmp_path: Path) -> Path:
    x = np.linspace(0, 10, 12)
    y = np.sin(x / 2)
    y[5] += 0.4
    write_curves(tmp_path / "b.json", [interpolate_bspline(np.c_[x, y])])
    return tmp_path / "b.json"


def test_method_options_reach_fair_and_unknown_ones_fail(tmp_path: Path):
    before = _bspline_file(tmp_path).read_bytes()
    runs = cli_many([["fair", "b.json", "-o", "sweep.json", "-m", "eck-hadenfeld",
                      "-O", "schedule=sweep", "--option", "l=3", "--report", "r.json"],
                     ["fair", "b.json", "-o", "bogus.json", "-m", "eck-hadenfeld",
                      "-O", "bogus=1"],
                     ["fair", "b.json", "-o", "bad.json", "-O", "l=7"]], tmp_path)
    assert runs[0].returncode == 0, runs[0].stderr
    rep = json.loads((tmp_path / "r.json").read_text())
    r = rep["curves"][0]["report"]
    assert r["method"] == "eck-hadenfeld"
    assert r["schedule"] == "sweep" and r["l"] == 3  # "3" parsed as an int
    assert rep["options"]["method_options"] == {"schedule": "sweep", "l": 3}
    assert_user_error(runs[1], 1, "bogus", "eck-hadenfeld", "schedule")
    assert_user_error(runs[2], 1, "order 7", "l must")  # a bad value for the default's option
    assert not (tmp_path / "bogus.json").exists()  # the only curve failed: nothing written
    assert not (tmp_path / "bad.json").exists()
    assert (tmp_path / "b.json").read_bytes() == before


def test_option_noequals_is_a_usage_error_naming_option(tmp_path: Path, ex1: Path,
                                                        monkeypatch):
    monkeypatch.chdir(tmp_path)
    r = CliRunner().invoke(main, ["fair", "ex1.csv", "-o", "o.csv", "-O", "noequals"])
    assert r.exit_code == 2, r.output
    assert "--option" in r.output and "noequals" in r.output
    assert not (tmp_path / "o.csv").exists()


def test_fair_arguments_given_as_method_options_name_a_real_flag(tmp_path: Path, ex1: Path,
                                                                monkeypatch):
    """``-O tol=...`` points to ``--tol``; a fair() argument the command has no flag for and
    does not pass on (``joins``, ``guard``) says the default is kept (``-O g1_angle=1`` named
    ``--g1-angle``, which does not exist)."""
    import click

    from curvefair.cli import _FAIR_FLAGS, _FAIR_VIA_OPTION, _fair_arguments, fair_cmd

    flags = {o for p in fair_cmd.params if isinstance(p, click.Option) for o in p.opts}
    for flag in _FAIR_FLAGS.values():
        assert flag == "the IN argument" or set(flag.split("/")) <= flags, flag
    assert set(_FAIR_FLAGS) | set(_FAIR_VIA_OPTION) <= _fair_arguments()
    monkeypatch.chdir(tmp_path)
    for key, want in (("tol", "use --tol"), ("joins", "keeps fair()'s default"),
                      ("guard", "keeps fair()'s default")):
        r = CliRunner().invoke(main, ["fair", "ex1.csv", "-o", "o.csv", "-O", f"{key}=1"])
        assert r.exit_code == 2 and want in r.output, r.output
        assert "--joins" not in r.output and "--guard" not in r.output
    assert not (tmp_path / "o.csv").exists()


def test_corner_turn_reaches_fair_through_option(tmp_path: Path, monkeypatch):
    """``-O corner_turn=inf`` reaches fair() (the corners of a B-spline may turn: nothing
    held for them); by default a corner that turned is held (tests/test_joins_corners.py)."""
    import json

    from test_joins_corners import _chain, _wiggly_chain

    from curvefair import CurveRecord, write_curves

    monkeypatch.chdir(tmp_path)
    write_curves("c.json", [CurveRecord(_chain(_wiggly_chain(35.0)), "chain")])
    held = []
    for extra in ([], ["-O", "corner_turn=inf"]):
        r = CliRunner().invoke(main, ["fair", "c.json", "-o", "o.json", "--tol", "0.2", "-q",
                                      "-m", "global", "--report", "r.json", *extra])
        assert r.exit_code == 0, r.output
        joins = json.loads(Path("r.json").read_text())["curves"][0]["report"]["joins"]
        held.append(joins.get("corner_points_held", 0))
    assert held[0] >= 3 and held[1] == 0


def test_option_values_are_typed():
    from curvefair.cli import _parse_method_options

    got = _parse_method_options(["a=3", "b=0.25", "c=1e-3", "d=true", "e=False", "f=sweep",
                                 "g=", "h=x=y", "a=-4"])
    assert got == {"a": -4, "b": 0.25, "c": 1e-3, "d": True, "e": False, "f": "sweep",
                   "g": "", "h": "x=y"}
    assert type(got["a"]) is int and type(got["d"]) is bool


def test_methods_lists_options_with_defaults():
    from curvefair.fairing.fair import method_options

    r = CliRunner().invoke(main, ["methods"])
    assert r.exit_code == 0
    assert "schedule" in r.output and "schedule=sweep" in r.output
    assert "variant=one-point" in r.output
    r = CliRunner().invoke(main, ["methods", "--json"])
    rows = {x["name"]: x for x in json.loads(r.output)}
    assert rows["eck-hadenfeld"]["options"]["schedule"] == "sweep"
    for name, row in rows.items():
        assert list(row["options"]) == list(method_options(name))


def test_fair_help_documents_option():
    r = CliRunner().invoke(main, ["fair", "--help"])
    assert r.exit_code == 0
    assert "-O, --option KEY=VALUE" in r.output
    r = CliRunner().invoke(main, ["--help"])
    assert "-O schedule=sweep" in r.output
