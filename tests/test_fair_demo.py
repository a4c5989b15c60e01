"""examples/demo.py (what `make demo` runs) works, writes valid JSON reports, and prints the
table the README shows for it."""

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def test_demo_writes_reports(tmp_path):
    out = tmp_path / "sub" / "report.json"
    proc = subprocess.run([sys.executable, str(ROOT / "examples" / "demo.py"), "--out", str(out)],
                          capture_output=True, text=True, timeout=300, check=True)
    assert "poliakoff" in proc.stdout and "wang-quintic" in proc.stdout
    _readme_table_is(proc.stdout)
    def no_nan(c):
        raise ValueError(f"non-finite number {c} in the report")

    data = json.loads(out.read_text(), parse_constant=no_nan)
    assert set(data["runs"]) >= {"kjellander", "poliakoff", "wang-cao", "wang-quintic"}
    pts = np.array(data["points"])
    np.testing.assert_array_equal(pts[3], [4.3, 1.6])
    for run in data["runs"].values():
        r = run["report"]
        assert r["energy_after"] < r["energy_before"]
    assert not list(out.parent.glob("*.tmp"))  # atomic write left no temp file


def _rows(text: str) -> list[str]:
    """The rows of the demo's table (after its header and dashes, up to the first blank or
    footnote line)."""
    lines = text.splitlines()
    k = next(i for i, line in enumerate(lines) if line.startswith("run "))
    rows = []
    for line in lines[k + 2:]:
        if not line.strip() or line.startswith("*"):
            break
        rows.append(line)
    return rows


def _readme_table_is(stdout: str) -> None:
    """Every row the README shows equals the demo's: the same words, every number within half a
    unit of the README's last printed digit (not a rounding-level comparison)."""
    readme = (ROOT / "README.md").read_text()
    block = readme.split("its output today:\n\n```\n", 1)[1].split("```", 1)[0]
    want, got = _rows(block), _rows(stdout)
    assert len(want) == len(got)
    num = re.compile(r"-?\d+(?:\.\d+)?(?:e-?\d+)?")
    for w, g in zip(want, got, strict=True):
        assert num.sub("#", w).split() == num.sub("#", g).split(), (w, g)
        for a, b in zip(num.findall(w), num.findall(g), strict=True):
            digits = len(a.split(".")[1]) if "." in a else 0
            assert abs(float(a) - float(b)) <= 0.51 * 10.0 ** -digits, (w, g)
