"""Small helpers shared by test modules (imported as ``_helpers``; pytest puts tests/ first)."""

from __future__ import annotations

import numpy as np


def record_points(recs) -> np.ndarray:
    """The whole point list of a file's records, put back in file order from each record's
    ``source["indices"]`` (corners split a list into several records); NaN where none wrote."""
    n = int(recs[0].source["n_points"])
    out = np.full((n, 2), np.nan)
    for r in recs:
        out[np.asarray(r.source["indices"])] = r.points
    return out


def assert_copied_with_note(run, src, out, report, tol, n_drawn: int) -> None:
    """``curvefair fair SRC -o OUT --tol TOL --report REPORT`` on a drawing of straight-line
    shapes only (``run``: the test module's CLI runner): exit 0, OUT the input's bytes, the
    note naming ``--polylines``, and the report's counts."""
    import json
    from pathlib import Path

    res = run("fair", src, "-o", out, "--tol", tol, "--report", report)
    assert res.exit_code == 0, res.output
    shapes = f"{n_drawn} straight-line shape{'s' if n_drawn > 1 else ''}"
    assert f"{shapes} left as drawn: --polylines fairs them" in res.output
    assert Path(out).read_bytes() == Path(src).read_bytes()
    rep = json.loads(Path(report).read_text())
    assert rep["n_curves"] == 0 and rep["n_drawn_shapes"] == n_drawn and rep["output_written"]
