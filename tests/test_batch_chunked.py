"""One point list faired in overlapping chunks (curvefair.batch.fair_chunked, ``curvefair fair
--chunk``; issue 17): every point within tol, the curve read back within tol, the joins G2, the
same bytes in one process, a process pool and from the command line, bounded reading, clear
refusals.

Checked independently of the chunk code: the written file is re-read with numpy and the
curves rebuilt with scipy ``CubicSpline`` (chord-length parameters, natural ends: what a points
file means); the Hausdorff distance is sampled with a k-d tree and refined with
``scipy.optimize.minimize_scalar``; the curve at a join is compared with a fair of the
neighbouring chunk's window run here with :func:`curvefair.fair` by the documented rule.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from scipy.interpolate import CubicSpline
from scipy.optimize import minimize_scalar
from scipy.spatial import cKDTree

from curvefair import fair, interpolate_cubic
from curvefair._chunked import G2_TOL, PointStream, windows
from curvefair.batch import fair_chunked
from curvefair.cli import main
from curvefair.errors import CurvefairError

TOL = 0.01
N, CHUNK, OVERLAP, HOLD = 6000, 2000, 64, 16


def _noisy(n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    s = np.linspace(0.0, 8.0 * np.pi * n / 1000.0, n)
    return np.c_[s, 3.0 * np.sin(s)] + 0.003 * rng.standard_normal((n, 2))


def _spline(P: np.ndarray) -> tuple[CubicSpline, np.ndarray]:
    t = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))]
    return CubicSpline(t, P, bc_type="natural"), t


def _directed(a: tuple[CubicSpline, np.ndarray], b: tuple[CubicSpline, np.ndarray],
              per: int = 12, refine: int = 60) -> float:
    """max over curve a of the distance to curve b: dense samples, then the largest ones
    refined (nearest point on b by bounded minimisation, the maximum over a likewise)."""
    sa, ta = a
    sb, tb = b
    f = np.linspace(0.0, 1.0, per, endpoint=False)
    ua = np.append((ta[:-1, None] + f * np.diff(ta)[:, None]).ravel(), ta[-1])
    ub = np.append((tb[:-1, None] + f * np.diff(tb)[:, None]).ravel(), tb[-1])
    tree = cKDTree(sb(ub))
    d, j = tree.query(sa(ua))

    def near(u: float, j0: int) -> float:
        x = sa(u)
        lo, hi = ub[max(j0 - 2, 0)], ub[min(j0 + 2, len(ub) - 1)]
        r = minimize_scalar(lambda v: float(np.linalg.norm(sb(v) - x)), bounds=(lo, hi),
                            method="bounded", options={"xatol": 1e-13})
        return min(float(r.fun), float(np.linalg.norm(sb(ub[j0]) - x)))

    best = 0.0
    for i in np.argsort(d)[-refine:]:
        lo, hi = ua[max(i - 1, 0)], ua[min(i + 1, len(ua) - 1)]
        r = minimize_scalar(lambda u, _j=j[i]: -near(u, int(tree.query(sa(u))[1])),
                            bounds=(lo, hi), method="bounded", options={"xatol": 1e-12})
        best = max(best, -float(r.fun), near(ua[i], int(j[i])))
    return best


def _kappa(s: CubicSpline, t: float) -> tuple[np.ndarray, float]:
    d1, d2 = s(t, 1), s(t, 2)
    sp = float(np.linalg.norm(d1))
    return d1 / sp, float(d1[0] * d2[1] - d1[1] * d2[0]) / sp**3


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, object]:
    root = tmp_path_factory.mktemp("chunked")
    P = _noisy(N)
    src = root / "big.csv"
    np.savetxt(src, P, delimiter=",", header="x,y", comments="")
    one = fair_chunked(src, root / "one.csv", tol=TOL, chunk=CHUNK, jobs=1)
    return {"root": root, "P": P, "src": src, "one": one}


def test_every_point_and_the_curve_read_back_are_within_tol(runs):
    root, P, one = runs["root"], runs["P"], runs["one"]
    assert one["n_chunks"] == 3 and one["n_points"] == N
    lines = (root / "one.csv").read_text().splitlines()
    assert lines[0] == "x,y"
    Q = np.loadtxt(root / "one.csv", delimiter=",", skiprows=1)
    assert Q.shape == P.shape
    moved = np.linalg.norm(Q - P, axis=1)
    assert moved.max() <= TOL  # exactly, per point
    assert np.count_nonzero(moved) > N // 2  # it did fair
    a, b = _spline(P), _spline(Q)
    h = max(_directed(a, b), _directed(b, a))
    assert h <= TOL
    # the report's figure (per core, on windows) bounds the whole curve's: each core's
    # O(n) upper bound where it meets tol (as a single point file is checked) ...
    assert h <= one["max_deviation"] * (1 + 1e-9) <= TOL
    assert {c["on_disk_deviation_kind"] for c in one["chunks"]} == {"matched bound"}
    # and it is fairer: fewer curvature sign changes on a dense sample
    u = np.linspace(0.0, a[1][-1], 200001)
    v = np.linspace(0.0, b[1][-1], 200001)
    infl = [int(np.count_nonzero(np.diff(np.sign(_kappa_all(s, w))) != 0))
            for s, w in ((a[0], u), (b[0], v))]
    assert infl[1] < infl[0] / 4


def test_each_core_bound_holds_and_the_refined_distance_is_the_whole_curves(runs):
    """Per core, the O(n) bound is at least the refined geometric distance, which (forced
    by a tol of 0, as for a core whose bound does not meet tol) gives the whole curve's
    Hausdorff distance, measured here independently with scipy splines."""
    import curvefair._chunked as ck

    root, P, src = runs["root"], runs["P"], str(runs["src"])
    out = str(root / "one.csv")
    Q = np.loadtxt(out, delimiter=",", skiprows=1)
    a, b = _spline(P), _spline(Q)
    h = max(_directed(a, b), _directed(b, a))
    ga = ck.windows(ck.PointStream(src).blocks(2048), CHUNK, OVERLAP, src, None)
    gb = ck.windows(ck.PointStream(out).blocks(2048), CHUNK, OVERLAP, out, None)
    bounds, refined = [], []
    for (ca, pa), (_cb, pb) in zip(ga, gb, strict=True):
        bounds.append(ck.measure_chunk(ca, pa, pb, TOL))
        refined.append(ck.measure_chunk(ca, pa, pb, 0.0))
    assert len(bounds) == 3
    assert {m["kind"] for m in bounds} == {"matched bound"}
    assert {m["kind"] for m in refined} == {"geometric"}
    for m, r in zip(bounds, refined, strict=True):
        assert r["deviation"] <= m["deviation"] * (1 + 1e-9) <= TOL
    assert abs(h - max(r["deviation"] for r in refined)) <= 1e-6 * TOL


def _kappa_all(s: CubicSpline, u: np.ndarray) -> np.ndarray:
    d1, d2 = s(u, 1), s(u, 2)
    return d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]


def test_joins_are_g2_and_each_core_is_its_own_fair(runs):
    root, P, one = runs["root"], runs["P"], runs["one"]
    Q = np.loadtxt(root / "one.csv", delimiter=",", skiprows=1)
    s_all, t_all = _spline(Q)
    # chunk 0 by the documented rule: window rows 0 .. CHUNK + OVERLAP, rows CHUNK - HOLD ..
    # CHUNK + HOLD held, kept on rows 0 .. CHUNK - 1
    j = CHUNK
    res = fair(interpolate_cubic(P[:j + OVERLAP + 1], "chord", "natural"), tol=TOL,
               protect=range(j - HOLD, j + HOLD + 1))
    mine = np.asarray(res.curve.points)
    assert np.array_equal(Q[:j], mine[:j])
    assert np.array_equal(Q[j - HOLD:j + HOLD + 1], P[j - HOLD:j + HOLD + 1])  # held
    s0, t0 = _spline(mine)
    tan_w, k_w = _kappa(s0, t0[j])
    tan_all, k_all = _kappa(s_all, t_all[j])
    angle = float(np.arctan2(abs(tan_w[0] * tan_all[1] - tan_w[1] * tan_all[0]),
                             float(tan_w @ tan_all)))
    assert angle <= G2_TOL
    assert abs(k_w - k_all) <= G2_TOL * max(abs(k_w), abs(k_all))
    assert one["joins_within_g2_tol"] and len(one["joins"]) == 2
    assert one["joins_g2_max"] <= G2_TOL
    # every chunk carries its own certificate, and the one read back
    for c in one["chunks"]:
        assert c["max_deviation"] <= TOL and c["on_disk_deviation"] <= TOL


def test_a_process_pool_npy_and_the_cli_write_the_same_points(runs):
    root, src = runs["root"], runs["src"]
    ref = (root / "one.csv").read_bytes()
    fair_chunked(src, root / "pool.csv", tol=TOL, chunk=CHUNK, jobs=2)
    assert (root / "pool.csv").read_bytes() == ref
    np.save(root / "big.npy", runs["P"])
    r = CliRunner().invoke(main, ["fair", str(root / "big.npy"), "-o", str(root / "cli.npy"),
                                  "--tol", str(TOL), "--chunk", str(CHUNK), "-j", "1"],
                           catch_exceptions=False)
    assert r.exit_code == 0, r.output
    assert "3 chunks" in r.output
    Q = np.loadtxt(root / "one.csv", delimiter=",", skiprows=1)
    assert np.array_equal(np.load(root / "cli.npy"), Q)
    rep = json.loads((root / ".curvefair" / "cli.npy.json").read_text())
    assert rep["n_chunks"] == 3 and rep["max_deviation"] <= TOL


def test_windows_read_lazily_and_cover_every_row_once():
    P = _noisy(1000)
    read: list[int] = []

    def blocks():
        for a in range(0, len(P), 50):
            read.append(a + 50)
            yield P[a:a + 50]

    seen = []
    for ch, w in windows(blocks(), 100, 10, "x.csv"):
        # never more read than the next window needs (bounded memory)
        assert read[-1] <= ch.stop + 100 // 2 + 10 + 1 + 50
        assert np.array_equal(w, P[ch.w0:ch.w1])
        assert ch.w0 == max(0, ch.start - 10)
        seen.extend(range(ch.start, ch.stop))
    assert seen == list(range(1000))


def test_progress_reports_fair_phases_and_chunks(tmp_path: Path):
    calls: list[tuple[int, int]] = []
    P = _noisy(300)
    fair(interpolate_cubic(P), tol=TOL, progress=lambda d, t: calls.append((d, t)))
    assert calls == [(1, 4), (2, 4), (3, 4), (4, 4)]
    with pytest.raises(CurvefairError, match="progress"):
        fair(interpolate_cubic(P), tol=TOL, progress=3)
    src = tmp_path / "p.csv"
    np.savetxt(src, P, delimiter=" ")
    got: list[tuple[int, int]] = []
    rep = fair_chunked(src, tmp_path / "o.txt", tol=TOL, chunk=100, overlap=10, hold=4,
                       jobs=1, progress=lambda d, t: got.append((d, t)))
    assert [d for d, _ in got] == list(range(1, 2 * rep["n_chunks"] + 1))
    assert got[-1] == (2 * rep["n_chunks"], 2 * rep["n_chunks"])
    assert all(d <= t for d, t in got)
    # fair_file passes the phases on, and the write
    from curvefair.batch import fair_file

    ev: list[str] = []
    fair_file(str(src), str(tmp_path / "f.txt"), {"tol": TOL},
              progress=lambda e, v: ev.append(e))
    assert ev[0] == "curves" and ev.count("phase") == 4 and ev[-2:] == ["write", "write"]
    from curvefair._batch_cli import _progress

    with _progress(True, 1) as event:  # the rich bars take every event
        for e, v in (("curves", 1), ("phase", (1, 4)), ("phase", (4, 4)), ("curve", 1),
                     ("write", 0), ("write", 1), ("chunk", (3, 8)), ("file", 1)):
            event("f.csv", e, v)


@pytest.mark.parametrize("rows, match", [
    ("".join(f"{np.cos(a):.6f},{np.sin(a):.6f}\n" for a in np.r_[np.arange(12) / 6 * np.pi,
                                                                 0.0]), "closed loop"),
    ("0,0\n1,0\n1,0\n3,1\n", "same point"),
    ("0,0\n1,0\n1,1\n0,1.1\n", "corner"),
    ("0,0\n1,0\nx,y\n", "bad.csv:3: not a row of numbers"),
    ("0,0,0,0\n", "4 columns"),
    # point numbers or x coordinates? (the reader without chunks refuses it too)
    ("".join(f"{i},{np.cos(i / 9):.6f},{np.sin(i / 9):.6f}\n" for i in range(1, 40)),
     "consecutive integers 1 .. 39"),
    # a header keeping a point-number column: the chunked reader fairs every column
    ("id,x,y\n" + "".join(f"{i},{np.cos(i / 9):.6f},{np.sin(i / 9):.6f}\n"
                           for i in range(1, 40)), "bad.csv:2: the header names columns 1, 2"),
    ("0,5;1,25\n1,5;2,5\n", "bad.csv:1: numbers with decimal commas"),
])
def test_unsuitable_files_are_refused_naming_the_row(tmp_path: Path, rows: str, match: str):
    src = tmp_path / "bad.csv"
    src.write_text(rows)
    with pytest.raises(CurvefairError, match=match):
        fair_chunked(src, tmp_path / "o.csv", tol=0.1, chunk=20, overlap=4, hold=2, jobs=1)
    assert not (tmp_path / "o.csv").exists()
    assert [p.name for p in tmp_path.iterdir()] == ["bad.csv"]  # no temporary file left


def test_bad_arguments_and_cli_usage(tmp_path: Path):
    src = tmp_path / "p.csv"
    np.savetxt(src, _noisy(200), delimiter=",")
    for kw, match in (({"chunk": 5}, "chunk"), ({"overlap": 60, "chunk": 100}, "chunk"),
                      ({"hold": 70}, "hold"), ({"clamp": "none"}, "clamp")):
        with pytest.raises(CurvefairError, match=match):
            fair_chunked(src, tmp_path / "o.csv", tol=0.1, **kw)
    with pytest.raises(CurvefairError, match="is the input"):
        fair_chunked(src, src, tol=0.1, chunk=100, overlap=10, hold=4)
    with pytest.raises(CurvefairError, match="point file"):
        fair_chunked(src, tmp_path / "o.dxf", tol=0.1, chunk=100, overlap=10, hold=4)
    run = CliRunner().invoke
    r = run(main, ["fair", str(src), "-o", str(tmp_path / "o.csv"), "--chunk", "100"])
    assert r.exit_code == 2 and "--tol" in r.output
    r = run(main, ["fair", str(src), "-o", str(tmp_path / "o.csv"), "--chunk", "100",
                   "--tol", "0.1", "--hold-shared"])
    assert r.exit_code == 2 and "--hold-shared" in r.output
    r = run(main, ["fair", str(src), "-o", str(tmp_path / "o.csv"), "--chunk", "20",
                   "--tol", "0.1"])
    assert r.exit_code == 1 and "chunk" in r.output and "Traceback" not in r.output
    assert not (tmp_path / "o.csv").exists()


def test_point_stream_reads_header_comments_and_separators(tmp_path: Path):
    p = tmp_path / "a.xyz"
    p.write_text("name of it\n# a comment\n1 2 3\n\n4 5 6  # trailing\n7\t8\t9\n")
    s = PointStream(p)
    (blk,) = list(s.blocks(10))
    assert blk.tolist() == [[1, 2, 3], [4, 5, 6], [7, 8, 9]]
    assert s.header == "name of it" and s.sep == " " and s.n_rows == 3
    assert s.preamble == ["name of it", "# a comment"] and s.n_comments_dropped == 1


def test_chunked_text_output_keeps_the_comments_before_and_between_rows(tmp_path: Path):
    P = _noisy(900)
    src = tmp_path / "p.csv"
    head = "# station 12, port side\n# units: m\n\nx,y\n"
    rows = [f"{x!r},{y!r}\n" for x, y in P.tolist()]
    src.write_text(head + "".join(rows[:450]) + "# mid-file note\n" + "".join(rows[450:]))
    rep = fair_chunked(src, tmp_path / "o.csv", tol=TOL, chunk=400, overlap=20, hold=5,
                       jobs=1)
    text = (tmp_path / "o.csv").read_text()
    assert text.startswith(head)  # comments, blank line and header, as they were
    lines = text.splitlines()
    assert lines[4 + 450] == "# mid-file note" and rep["n_comments_dropped"] == 0
    assert not any("comment" in n for n in rep["notes"])
    Q = np.loadtxt(tmp_path / "o.csv", delimiter=",", comments="#", skiprows=4)
    assert Q.shape == P.shape and np.linalg.norm(Q - P, axis=1).max() <= TOL


def test_a_core_read_back_over_tol_gets_its_moves_scaled(tmp_path: Path, monkeypatch):
    """The rewrite path: the measure of chunk 1 is made to say 2 tol once; that core is
    written again with its moves scaled (p0 + s (p - p0), unmoved rows exact), the others
    byte-identical, and everything is measured again."""
    import curvefair._chunked as ck

    P = _noisy(1200)
    src = tmp_path / "p.csv"
    np.savetxt(src, P, delimiter=",")
    plain = fair_chunked(src, tmp_path / "a.csv", tol=TOL, chunk=400, overlap=20, hold=5,
                         jobs=1)
    real = ck.measure_chunk
    calls = {"n": 0}

    def inflated(ch, orig, new, tol=None):
        m = real(ch, orig, new, tol)
        if ch.index == 1 and calls["n"] == 0:
            calls["n"] += 1
            m = dict(m, deviation=2.0 * TOL)
        return m

    monkeypatch.setattr(ck, "measure_chunk", inflated)
    rep = fair_chunked(src, tmp_path / "b.csv", tol=TOL, chunk=400, overlap=20, hold=5,
                       jobs=1)
    assert plain["n_chunks"] == rep["n_chunks"] == 3
    s = rep["chunks"][1]["move_scale"]
    assert s == pytest.approx(0.995 / 2.0) and rep["notes"]
    A = np.loadtxt(tmp_path / "a.csv", delimiter=",")
    B = np.loadtxt(tmp_path / "b.csv", delimiter=",")
    assert np.array_equal(A[:400], B[:400]) and np.array_equal(A[800:], B[800:])
    same = np.all(A[400:800] == P[400:800], axis=1)
    np.testing.assert_array_equal(B[400:800][same], P[400:800][same])
    np.testing.assert_allclose(B[400:800], P[400:800] + s * (A[400:800] - P[400:800]),
                               rtol=0, atol=1e-12)
    assert np.linalg.norm(B - P, axis=1).max() <= TOL


def test_a_units_row_after_the_header_is_kept(tmp_path: Path):
    """Lines before the data without a number in them (a units row) are written back as they
    are; they were refused ("not a row of numbers")."""
    t = np.linspace(0.0, 6.0, 80)
    rows = "".join(f"{np.cos(a):.5f},{np.sin(a) + 0.002 * np.sin(29 * a):.5f}\n" for a in t)
    src = tmp_path / "in.csv"
    src.write_text("x,y\nmm,mm\n" + rows)
    fair_chunked(src, tmp_path / "o.csv", tol=0.01, chunk=40, overlap=8, hold=2, jobs=1)
    out = (tmp_path / "o.csv").read_text().splitlines()
    assert out[:2] == ["x,y", "mm,mm"] and len(out) == 82
    got = np.array([[float(v) for v in ln.split(",")] for ln in out[2:]])
    want = np.array([[float(v) for v in ln.split(",")] for ln in rows.splitlines()])
    assert np.linalg.norm(got - want, axis=1).max() <= 0.01
