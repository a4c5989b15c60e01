"""examples/demo.py (what `make demo` runs) works and writes valid JSON reports."""

import json
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
