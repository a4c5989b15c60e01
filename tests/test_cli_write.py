"""The write side of the ``curvefair`` command: output paths, signals, errors, the tolerance
in the file read back, DXF R12 drawings, values refused.

Everything runs the real command in subprocesses (``python -m curvefair``, or a small
``python -c`` script that patches one OS call to simulate a full disk or a slow write). Files
are checked with independent tools: bytes before and after, ``os.path.islink``, ezdxf's own
entity counts, svgpathtools' parse of the written SVG, scipy's cubic spline through the
written airfoil points; distances between curves by dense sampling with an explicit upper
bound (see :func:`hausdorff_upper`).
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from test_cli import EX1, assert_user_error, cli, cli_many

import curvefair as cf
from curvefair.cli import main

REAL = Path(__file__).parent / "data" / "real"
DATA = Path(__file__).parent / "data"
SRC = str(Path(__file__).resolve().parents[1] / "src")


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env.pop("COLUMNS", None)
    env["PYTHONWARNINGS"] = "ignore"
    env["PYTHONPATH"] = SRC + os.pathsep + env.get("PYTHONPATH", "")
    return env


@pytest.fixture
def ex1(tmp_path: Path) -> Path:
    p = tmp_path / "ex1.csv"
    p.write_text(EX1)
    return p


def hausdorff_upper(X: np.ndarray, Y: np.ndarray) -> float:
    """An upper bound of the Hausdorff distance between two polylines' underlying curves
    sampled densely as ``X`` and ``Y`` (consecutive samples in order along each curve).

    For a point x of curve A between samples x_i, x_{i+1}: dist(x, B) <= dist(x_i, B) +
    |x - x_i|, and dist(x_i, B) <= distance to the nearest sample of B. The bound is
    ``max_i d(x_i, Y) + (largest sample gap of X) / 2``, both ways (up to the gap, chords
    stand for arcs: the samples are far denser than the curvature radius).
    """
    from scipy.spatial import cKDTree

    def one(P: np.ndarray, Q: np.ndarray) -> float:
        gap = float(np.max(np.linalg.norm(np.diff(P, axis=0), axis=1)))
        return float(cKDTree(Q).query(P)[0].max()) + 0.5 * gap

    return max(one(X, Y), one(Y, X))


# ---------------------------------------------------------------------------------------------
# output paths
# ---------------------------------------------------------------------------------------------
def test_outputs_that_are_an_input_or_another_output_are_refused(tmp_path: Path, ex1: Path,
                                                                 monkeypatch):
    """(In-process with click's runner: these are usage errors found before any work; the
    subprocess behaviour of usage errors is covered in test_cli.py.)"""
    svg = tmp_path / "in.svg"
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg"><path d="M 0,0 C 1,2 2,-1 3,1 '
                   'C 4,3 5,0 6,1"/></svg>\n')
    (tmp_path / "sub").mkdir()
    os.symlink(ex1, tmp_path / "link.csv")
    os.link(ex1, tmp_path / "hard.csv")
    os.symlink(svg, tmp_path / "svglink.svg")
    before = {p: p.read_bytes() for p in (ex1, svg)}
    cases = [
        (["fair", "ex1.csv", "-o", "./ex1.csv", "--tol", "0.5"], "is the input file"),
        (["fair", "ex1.csv", "-o", "sub/../ex1.csv", "--tol", "0.5"], "is the input file"),
        (["fair", "ex1.csv", "-o", str(ex1), "--tol", "0.5"], "is the input file"),
        (["fair", "ex1.csv", "-o", "link.csv", "--tol", "0.5"], "is the input file"),
        (["fair", "ex1.csv", "-o", "hard.csv", "--tol", "0.5"], "is the input file"),
        (["fair", "ex1.csv", "-o", "o.csv", "--report", "ex1.csv"], "--report"),
        (["fair", "ex1.csv", "-o", "o.csv", "--report", "./sub/../link.csv"], "--report"),
        (["fair", "ex1.csv", "--in-place", "--report", "ex1.csv"], "--report"),
        (["fair", "ex1.csv", "-o", "o.csv", "--report", "./o.csv"], "same file as -o"),
        (["fair", "in.svg", "-o", "o.svg", "--plot", "svglink.svg"], "--plot"),
        (["fair", "in.svg", "-o", "o.svg", "--plot", "o.svg"], "same file as -o"),
        (["fair", "ex1.csv", "-o", "o.csv", "--report", "r.json", "--plot", "./r.json"], "same"),
        (["plot", "in.svg", "-o", "in.svg"], "is the input file"),
        (["plot", "ex1.csv", "--compare", "in.svg", "-o", "svglink.svg"], "--compare"),
    ]
    monkeypatch.chdir(tmp_path)
    for args, needle in cases:
        r = CliRunner().invoke(main, args)
        assert r.exit_code == 2, (args, r.output)
        assert needle in r.stderr and "Traceback" not in r.output, (args, r.stderr)
    for p, b in before.items():
        assert p.read_bytes() == b
    assert os.path.islink(tmp_path / "link.csv") and os.path.islink(tmp_path / "svglink.svg")
    assert not any((tmp_path / n).exists() for n in ("o.csv", "o.svg", "r.json"))


def test_in_place_on_a_symlink_and_o_naming_a_symlink_write_through(tmp_path: Path, ex1: Path):
    real_dir = tmp_path / "real"
    real_dir.mkdir()
    target = real_dir / "target.csv"
    target.write_text(EX1)
    os.symlink(target, tmp_path / "via.csv")
    out_target = real_dir / "out_target.csv"
    out_target.write_text("old\n")
    os.symlink(out_target, tmp_path / "out_link.csv")
    res = cli_many([["fair", "via.csv", "--in-place", "--tol", "0.5", "-q"],
                    ["fair", "ex1.csv", "-o", "out_link.csv", "--tol", "0.5", "-q"]], tmp_path)
    for r in res:
        assert r.returncode == 0, r.stderr
    for link, tgt in ((tmp_path / "via.csv", target), (tmp_path / "out_link.csv", out_target)):
        assert os.path.islink(link) and Path(os.readlink(link)) == tgt
        text = tgt.read_text()
        assert text != EX1 and text != "old\n" and text.startswith("# Wang & Cao")
    # no stray temporary files next to the links or the targets
    assert sorted(p.name for p in real_dir.iterdir()) == ["out_target.csv", "target.csv"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ex1.csv", "out_link.csv", "real",
                                                          "via.csv"]


_SLOW_WRITE = """
import os, sys, time
real_fsync = os.fsync
def slow_fsync(fd):
    real_fsync(fd)
    print("WRITING", flush=True)
    time.sleep(60)
os.fsync = slow_fsync
from curvefair.cli import main
main(sys.argv[1:])
"""


@pytest.mark.parametrize("signame", ["SIGTERM", "SIGHUP"])
def test_temp_files_removed_when_killed_mid_write(tmp_path: Path, ex1: Path, signame: str):
    if not hasattr(signal, signame):
        pytest.skip(f"no {signame} here")
    sig = getattr(signal, signame)
    before = ex1.read_bytes()
    # the child starts with the signal's default action: under nohup (SIGHUP ignored, as the
    # test run may be) the command rightly keeps ignoring it and would not be killed
    p = subprocess.Popen([sys.executable, "-c", _SLOW_WRITE, "fair", "ex1.csv", "-o", "out.csv",
                          "--tol", "0.5", "-q"], cwd=tmp_path, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, env=_env(),
                         preexec_fn=lambda: signal.signal(sig, signal.SIG_DFL))
    try:
        line = p.stdout.readline()  # type: ignore[union-attr]
        assert line.strip() == "WRITING", (line, p.stderr.read())  # type: ignore[union-attr]
        temps = [n for n in os.listdir(tmp_path) if n.startswith(".out.csv.")]
        assert temps, "the write should be under way"
        p.send_signal(sig)
        p.wait(timeout=30)
    finally:
        if p.poll() is None:
            p.kill()
    assert p.returncode == -sig
    assert sorted(os.listdir(tmp_path)) == ["ex1.csv"]
    assert ex1.read_bytes() == before


_DISK_FULL = """
import errno, os, sys
def full(fd):
    raise OSError(errno.ENOSPC, "No space left on device")
os.fsync = full
from curvefair.cli import main
main(sys.argv[1:])
"""

_NO_PERMISSION = """
import errno, sys, tempfile
def denied(prefix=None, suffix=None, dir=None, **kw):
    raise PermissionError(errno.EACCES, "Permission denied", f"{dir}/{prefix}x1y2z3{suffix}")
tempfile.mkstemp = denied
from curvefair.cli import main
main(sys.argv[1:])
"""


def test_write_errors_name_the_users_path_never_the_temp_file(tmp_path: Path, ex1: Path):
    (tmp_path / "folder.csv").mkdir()
    procs = {
        "full": [sys.executable, "-c", _DISK_FULL, "fair", "ex1.csv", "-o", "out.csv", "--tol",
                 "0.5"],
        "perm": [sys.executable, "-c", _NO_PERMISSION, "fair", "ex1.csv", "-o", "out.csv",
                 "--tol", "0.5"],
    }
    runs = {k: subprocess.run(v, cwd=tmp_path, capture_output=True, text=True, env=_env(),
                              timeout=120) for k, v in procs.items()}
    assert_user_error(runs["full"], 1, "out.csv", "No space left on device")
    assert_user_error(runs["perm"], 1, "out.csv", "Permission denied")
    for r in runs.values():
        assert ".out.csv." not in r.stderr and "x1y2z3" not in r.stderr
    folder, empty, unknown = cli_many([["fair", "ex1.csv", "-o", "folder.csv", "--tol", "0.5"],
                                       ["fair", "ex1.csv", "-o", "", "--tol", "0.5"],
                                       ["fair", "ex1.csv", "--report", "folder.csv", "-o",
                                        "x.csv"]], tmp_path)
    assert_user_error(folder, 2, "'folder.csv' is a folder")
    assert_user_error(empty, 2, "empty")
    assert_user_error(unknown, 2, "--report", "folder")
    assert sorted(os.listdir(tmp_path)) == ["ex1.csv", "folder.csv"]


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() == 0,
                    reason="root writes into read-only folders")
def test_read_only_folder_names_the_output(tmp_path: Path, ex1: Path):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        res = cli(["fair", "ex1.csv", "-o", "ro/out.csv", "--tol", "0.5"], tmp_path)
    finally:
        ro.chmod(0o755)
    assert_user_error(res, 1, "ro/out.csv", "Permission denied")
    assert ".out.csv." not in res.stderr and list(ro.iterdir()) == []


def test_no_message_names_an_option_the_cli_lacks(tmp_path: Path, ex1: Path):
    (tmp_path / "data.foo").write_text(EX1)
    res = cli_many([["fair", "data.foo", "-o", "x.csv", "--tol", "0.5"],
                    ["analyze", "data.foo"], ["plot", "data.foo", "-o", "p.png"]], tmp_path)
    for r in res:
        assert r.returncode == 1 and "Traceback" not in r.stderr, r.stderr
        assert "format=" not in r.stderr and "'.foo'" in r.stderr, r.stderr


# ---------------------------------------------------------------------------------------------
# the tolerance in the file read back
# ---------------------------------------------------------------------------------------------
def _airfoil_points(path: Path) -> np.ndarray:
    rows = [ln.split() for ln in path.read_text().splitlines()[1:] if ln.strip()]
    return np.array(rows, dtype=float)


def _scipy_curve_samples(pts: np.ndarray, n: int) -> np.ndarray:
    """The natural cubic spline on chord-length parameters through ``pts`` (what a reader of
    the point file interpolates), sampled at ``n`` parameters, with scipy."""
    from scipy.interpolate import CubicSpline

    t = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))]
    return CubicSpline(t, pts, bc_type="natural")(np.linspace(0.0, t[-1], n))


def _hausdorff_checked(p0: np.ndarray, p1: np.ndarray, tol: float, n: int) -> float:
    """The Hausdorff distance between the chord-length natural cubics through ``p0`` and
    ``p1`` (scipy), certified by sampling where the sampled upper bound is below ``tol`` and
    maximised locally (nested bounded ``minimize_scalar``) in the sample intervals where it is
    not."""
    from scipy.interpolate import CubicSpline
    from scipy.optimize import minimize_scalar
    from scipy.spatial import cKDTree

    def spline(p: np.ndarray) -> tuple[CubicSpline, np.ndarray]:
        t = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))]
        return CubicSpline(t, p, bc_type="natural"), np.linspace(0.0, t[-1], n)

    def one(a: np.ndarray, b: np.ndarray) -> float:
        (A, u), (B, v) = spline(a), spline(b)
        P, Q = A(u), B(v)
        d, j = cKDTree(Q).query(P)
        gap = float(np.max(np.linalg.norm(np.diff(P, axis=0), axis=1)))
        hot = np.flatnonzero(d + 0.5 * gap > tol)
        worst = float(d.max()) + 0.5 * gap if hot.size == 0 else float(
            np.delete(d, hot).max(initial=0.0)) + 0.5 * gap
        for i in hot:
            lo, hi = u[max(i - 1, 0)], u[min(i + 1, n - 1)]
            s0, s1 = v[max(j[i] - 3, 0)], v[min(j[i] + 3, n - 1)]

            def to_b(uu: float, s0: float = s0, s1: float = s1) -> float:
                x = A(uu)
                return float(minimize_scalar(lambda s: np.linalg.norm(B(s) - x), bounds=(s0, s1),
                                             method="bounded", options={"xatol": 1e-15}).fun)

            r = minimize_scalar(lambda uu: -to_b(uu), bounds=(lo, hi), method="bounded",
                                options={"xatol": 1e-15})
            worst = max(worst, -float(r.fun), float(d[i]))
        return worst

    return max(one(p0, p1), one(p1, p0))


def test_airfoil_point_file_within_tol_after_reinterpolation(tmp_path: Path):
    src = tmp_path / "clarky.dat"
    src.write_bytes((DATA / "clarky.dat").read_bytes())
    tol = 1e-4
    res = cli(["fair", "clarky.dat", "-o", "out.dat", "--tol", str(tol), "--report", "r.json"],
              tmp_path)
    assert res.returncode == 0, res.stderr
    p0, p1 = _airfoil_points(src), _airfoil_points(tmp_path / "out.dat")
    assert p0.shape == p1.shape and np.abs(p1 - p0).max() > 0.2 * tol  # it did fair
    assert np.linalg.norm(p1 - p0, axis=1).max() <= tol
    # scipy's natural cubics through both point lists: the sampled bound (max sample distance
    # + half a sample gap: ~1e-6 at 1e6 samples of the 2.04-long outline; the nearest sample
    # of the other curve adds only gap^2 / (8 d), 5e-9 at d ~ 1e-4); where that exceeds tol,
    # the distance is maximised locally in those sample intervals (bounded scalar searches
    # on both splines). (4e6 samples took 29 s here, 1e6 about a quarter of that.)
    up = _hausdorff_checked(p0, p1, tol, 1_000_001)
    assert up <= tol
    rep = json.loads((tmp_path / "r.json").read_text())
    on_disk = rep["output_check"]["max_deviation"]
    assert on_disk <= tol and rep["curves"][0]["report"]["on_disk_deviation"] == on_disk
    # the stated figure is an upper bound of the re-read curve's distance (the per-span bound
    # of analysis.matched_hermite_bound, labelled so): never below the distance (up to the
    # sampled figure's slack), and sharp enough to be useful (within 5 % of it)
    assert rep["output_check"]["kinds"] == ["geometric upper bound"]
    assert up - 2e-6 <= on_disk <= 1.05 * up
    assert f"max deviation {on_disk:.6g}" in res.stdout


def _svg_samples(path: Path, per_unit: float) -> list[np.ndarray]:
    """Dense samples of every subpath of every <path> element, by svgpathtools."""
    import svgpathtools as spt

    paths, _ = spt.svg2paths(str(path))
    out = []
    for p in paths:
        for sub in p.continuous_subpaths():
            pts = []
            for seg in sub:
                z8 = seg.poly()(np.linspace(0.0, 1.0, 9))
                n = max(64, int(np.abs(np.diff(z8)).sum() * per_unit * 1.2))
                z = seg.poly()(np.linspace(0.0, 1.0, n))
                pts.append(np.c_[z.real, z.imag])
            out.append(np.vstack(pts))
    return out


def _svg_distance(a: Path, b: Path, per_unit: float) -> float:
    sa, sb = _svg_samples(a, per_unit), _svg_samples(b, per_unit)
    assert len(sa) == len(sb)
    return max(hausdorff_upper(x, y) for x, y in zip(sa, sb, strict=True))


def _wavy_svg(path: Path) -> str:
    """A wavy 2-decimal Bezier chain, written to ``path``; returns its ``d``."""
    rng = np.random.default_rng(11)
    x = np.linspace(0.0, 60.0, 31)
    y = np.round(3.0 * np.sin(x / 5.0) + rng.normal(scale=0.4, size=x.size), 2)
    d = "M %.2f,%.2f " % (x[0], y[0]) + " ".join(
        "C %.2f,%.2f %.2f,%.2f %.2f,%.2f" % (x[i] + 0.66, y[i] + 0.3, x[i + 1] - 0.66,
                                              y[i + 1] - 0.3, x[i + 1], y[i + 1])
        for i in range(x.size - 1))
    path.write_text(f'<svg xmlns="http://www.w3.org/2000/svg">\n<path id="w" d="{d}"/>\n'
                    '</svg>\n')
    return d


def test_svg_rounding_to_element_decimals_undone_when_it_breaks_tol(tmp_path: Path):
    # rounding the faired control points of the wavy chain to its 2 decimals moves them by up
    # to 0.005 * sqrt(2), more than the room tol leaves; 3 more decimals (5e-6) leave room
    tol, precision, note = 0.009, "file+", "written with 3 more decimals"
    d = _wavy_svg(tmp_path / "w.svg")
    res = cli(["fair", "w.svg", "-o", "o.svg", "--tol", str(tol), "--report", "r.json"],
              tmp_path)
    assert res.returncode == 0, res.stderr
    assert note in res.stderr
    # samples 1/1000 apart: the bound exceeds the true distance by 5e-4 at most
    up = _svg_distance(tmp_path / "w.svg", tmp_path / "o.svg", per_unit=1000)
    assert up <= tol + 6e-4, up
    rep = json.loads((tmp_path / "r.json").read_text())["output_check"]
    assert rep["precision"] == precision and rep["max_deviation"] <= tol
    out_d = re.search(r' d="([^"]*)"', (tmp_path / "o.svg").read_text()).group(1)
    longest = max(len(f) for f in re.findall(r"\.(\d+)", out_d))
    assert longest == 5
    assert out_d != d  # the fairing shows in the file


def test_svg_rounding_beyond_three_more_decimals_writes_exact_numbers(tmp_path: Path,
                                                                       monkeypatch):
    """When the element's decimals plus three still put a curve read back beyond tol, the
    numbers are written exactly. (Forced here by making the "three more" zero: the chain
    faired at tol 0.009 then fails twice at its own 2 decimals.)"""
    from curvefair.io import svg

    _wavy_svg(tmp_path / "w.svg")
    (rec,) = cf.read_curves(tmp_path / "w.svg")
    tol = 0.009
    res = cf.fair(rec.curve, tol=tol)
    monkeypatch.setattr(svg, "MORE_DECIMALS", 0)
    with pytest.warns(UserWarning, match="written with exact numbers"):
        chk = cf.write_curves(tmp_path / "o.svg", rec.with_curve(res.curve),
                              template=tmp_path / "w.svg", tol=tol)
    assert chk.precision == "exact" and chk.max_deviation <= tol
    assert any("written with 3 more decimals" in n for n in chk.notes)
    assert any("written with exact numbers" in n for n in chk.notes)


def test_report_after_figures_are_those_of_the_rounded_file(tmp_path: Path):
    """The numbers written are the faired ones rounded to the file's precision: the report's
    after-figures are those of the curve read back (a rounding ripple is an extremum like any
    other), the faired curve's under fair_after."""
    _wavy_svg(tmp_path / "w.svg")
    res = cli(["fair", "w.svg", "-o", "o.svg", "--tol", "0.009", "--report", "r.json"],
              tmp_path)
    assert res.returncode == 0, res.stderr
    rep = json.loads((tmp_path / "r.json").read_text())["curves"][0]["report"]
    assert "rounded to the file's precision" in rep["after_figures"]
    (back,) = cf.read_curves(tmp_path / "o.svg")
    a = cf.analyze(back.curve)
    assert rep["extrema_after"] == a.extrema and rep["inflections_after"] == a.inflections
    assert rep["energy_after"] == pytest.approx(a.energy2, rel=1e-12)
    assert set(rep["fair_after"]) >= {"extrema", "energy"}


def test_svg_moves_undone_by_the_elements_decimals_are_kept(tmp_path: Path):
    """Faired at tol 0.004, every move of the 2-decimal chain is smaller than half its last
    decimal: rounded to 2 decimals the file would hold the input unchanged (and did, with a
    read-back deviation of 0). The write-back takes three more decimals instead."""
    d = _wavy_svg(tmp_path / "w.svg")
    tol = 0.004
    res = cli(["fair", "w.svg", "-o", "o.svg", "--tol", str(tol), "--report", "r.json"],
              tmp_path)
    assert res.returncode == 0, res.stderr
    assert "were undone; written with 3 more decimals" in res.stderr
    chk = json.loads((tmp_path / "r.json").read_text())["output_check"]
    assert chk["precision"] == "file+" and 0.0 < chk["max_deviation"] <= tol
    out_d = re.search(r' d="([^"]*)"', (tmp_path / "o.svg").read_text()).group(1)
    assert out_d != d
    assert _svg_distance(tmp_path / "w.svg", tmp_path / "o.svg", per_unit=1000) <= tol + 6e-4


def test_svg_whole_number_element_gets_three_decimals(tmp_path: Path):
    """An element written in whole numbers: rounded to whole numbers, sub-unit fairing moves
    would be undone; its rewritten numbers get 3 decimals (not 17 digits of rounding noise)."""
    d = "M 20,40 C 30,10 50,10 60,40 S 90,70 100,40 S 130,10 140,40"
    (tmp_path / "s.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg">\n'
                                    f'<path id="s" d="{d}"/>\n</svg>\n')
    res = cli(["fair", "s.svg", "-o", "o.svg", "--tol", "0.5"], tmp_path)
    assert res.returncode == 0, res.stderr
    out_d = re.search(r' d="([^"]*)"', (tmp_path / "o.svg").read_text()).group(1)
    nums = re.findall(r"-?\d+(?:\.\d+)?", out_d)
    assert any("." in v for v in nums)  # moved off the whole numbers
    assert all(len(v.split(".")[1]) <= 3 for v in nums if "." in v)
    assert _svg_distance(tmp_path / "s.svg", tmp_path / "o.svg", per_unit=100) <= 0.5 + 6e-3


def test_real_glyph_svg_within_tol(tmp_path: Path):
    """Font Awesome 3.svg at --tol 1: rounded to its 1 decimal after fairing it reads back
    1.03 from the input; curvefair writes exact numbers instead."""
    (tmp_path / "3.svg").write_bytes((REAL / "fontawesome" / "3.svg").read_bytes())
    res = cli(["fair", "3.svg", "-o", "o.svg", "--tol", "1", "--report", "r.json"], tmp_path)
    assert res.returncode == 0, res.stderr
    # samples 1/100 apart: the bound exceeds the true distance by 5e-3 at most
    up = _svg_distance(tmp_path / "3.svg", tmp_path / "o.svg", per_unit=100)
    assert up <= 1.0 + 6e-3, up
    rep = json.loads((tmp_path / "r.json").read_text())["output_check"]
    assert rep["max_deviation"] <= 1.0


def test_decimals_that_break_tol_or_readability_write_nothing(tmp_path: Path, ex1: Path):
    (tmp_path / "clarky.dat").write_bytes((DATA / "clarky.dat").read_bytes())
    res = cli_many([["fair", "ex1.csv", "-o", "a.csv", "--tol", "0.05", "--decimals", "0"],
                    ["fair", "clarky.dat", "-o", "b.dat", "--decimals", "0"],
                    ["fair", "ex1.csv", "-o", "c.csv", "--tol", "0.5", "--decimals", "4"]],
                   tmp_path)
    assert_user_error(res[0], 1, "a.csv", "not written", "--decimals 0")
    # without a tolerance the rounded file must still read back: points round onto each other
    assert_user_error(res[1], 1, "b.dat", "not written", "--decimals 0")
    assert res[2].returncode == 0, res[2].stderr
    assert sorted(os.listdir(tmp_path)) == ["c.csv", "clarky.dat", "ex1.csv"]


# ---------------------------------------------------------------------------------------------
# DXF R12 (no $ACADVER): SPLINEs survive
# ---------------------------------------------------------------------------------------------
def test_dxf_without_acadver_keeps_its_splines(tmp_path: Path):
    ezdxf = pytest.importorskip("ezdxf")
    src = tmp_path / "splines.dxf"
    src.write_bytes((REAL / "dxf-parser" / "splines.dxf").read_bytes())
    assert b"$ACADVER" not in src.read_bytes()
    res = subprocess.run([sys.executable, "-m", "curvefair", "fair", "splines.dxf", "-o",
                          "out.dxf", "--tol", "1"], cwd=tmp_path, capture_output=True,
                         text=True, env=_env(), timeout=300)
    assert res.returncode == 0, res.stderr
    assert "R2000" in res.stderr and "SPLINE" in res.stderr
    doc_in, doc_out = ezdxf.readfile(src), ezdxf.readfile(tmp_path / "out.dxf")
    assert doc_out.dxfversion >= "AC1015"

    def kinds(doc):
        return Counter(e.dxftype() for blk in doc.blocks for e in blk)

    assert kinds(doc_in) == kinds(doc_out) and kinds(doc_out)["SPLINE"] == 2
    for a, b in zip(doc_in.modelspace(), doc_out.modelspace(), strict=True):
        assert a.dxf.handle == b.dxf.handle and a.dxf.layer == b.dxf.layer
        ca, cb = np.array(a.control_points), np.array(b.control_points)
        assert ca.shape == cb.shape and np.linalg.norm(ca - cb, axis=1).max() <= 1.0


# ---------------------------------------------------------------------------------------------
# values the command used to accept silently
# ---------------------------------------------------------------------------------------------
def test_bad_values_are_refused_with_one_line(tmp_path: Path, ex1: Path):
    pytest.importorskip("matplotlib")
    bs = tmp_path / "bs.json"
    from curvefair import interpolate_bspline, write_curves

    t = np.linspace(0, 6, 12)
    write_curves(bs, [interpolate_bspline(np.c_[t, np.sin(t)])])
    cases = [
        (["fair", "ex1.csv", "-o", "o.csv", "--protect", "1000"], 2, "--protect", "1000"),
        (["fair", "bs.json", "-o", "o.json", "-m", "cheng-yu", "-O", "pair=3"], 2, "pair",
         "true or false"),
        (["fair", "bs.json", "-o", "o.json", "-m", "cheng-yu", "-O", "relative=maybe"], 2,
         "relative", "true or false"),
        (["fair", "bs.json", "-o", "o.json", "-O", "l=2.5"], 2, "'l'", "integer"),
        (["plot", "ex1.csv", "-o", "p.png", "--comb-density", "100000000"], 2,
         "--comb-density"),
        (["plot", "ex1.csv", "-o", "p.png", "--comb-scale", "1e308"], 2, "--comb-scale"),
    ]
    for res, (_a, code, *needles) in zip(cli_many([c[0] for c in cases], tmp_path), cases,
                                         strict=True):
        assert_user_error(res, code, *needles)
        assert len([ln for ln in res.stderr.splitlines() if ln.strip()]) <= 4, res.stderr
    assert not any((tmp_path / n).exists() for n in ("o.csv", "o.json", "p.png"))
    ok = cli(["fair", "bs.json", "-o", "o.json", "-m", "cheng-yu", "-O", "pair=false", "-q"],
             tmp_path)
    assert ok.returncode == 0, ok.stderr
