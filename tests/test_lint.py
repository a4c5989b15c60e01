"""ruff finds nothing in the package and the tests, and mypy no type error in the package, with
the settings in pyproject.toml (``[tool.ruff]``, ``[tool.mypy]``; both are in the test extra).

Without the tool installed the test is skipped, except under ``CI=true``, where it fails.
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _require(module: str) -> None:
    if importlib.util.find_spec(module) is None:
        why = f"{module} is not installed (pip install -e '.[test]' installs it)"
        if os.environ.get("CI") == "true":
            pytest.fail(f"CI needs the lint test: {why}")
        pytest.skip(why)


def test_ruff_clean() -> None:
    _require("ruff")
    proc = subprocess.run([sys.executable, "-m", "ruff", "check", "--no-cache",
                           "--output-format", "concise", "src", "tests"],
                          capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_mypy_clean() -> None:
    # the files and the per-module settings come from [tool.mypy] in pyproject.toml
    _require("mypy")
    proc = subprocess.run([sys.executable, "-m", "mypy", "--no-color-output"],
                          capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr
