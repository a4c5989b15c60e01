"""The documentation builds with Sphinx warnings as errors (what ``make docs`` runs).

The build reads the API reference from the numpydoc docstrings (a docstring that docutils or
numpydoc cannot parse, or a broken cross-reference, is a warning and fails the test), renders
the Markdown pages, and runs every gallery script ``examples/plot_*.py`` (an example that raises
fails the build). The checks after the build look for what each part must have produced in the
HTML: an entry for every name in ``curvefair.__all__``, the formats and benchmark pages, and one
embedded figure per gallery example.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

import curvefair

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"

pytest.importorskip("sphinx")
pytest.importorskip("numpydoc")
pytest.importorskip("myst_parser")
pytest.importorskip("sphinx_gallery")


@pytest.fixture(scope="module")
def html(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("docs") / "html"
    doctrees = out.parent / "doctrees"
    env = dict(os.environ, CURVEFAIR_QUIET="1", MPLBACKEND="Agg")
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), env.get("PYTHONPATH", "")])
    cmd = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-E", "-q", "-b", "html",
           "-d", str(doctrees),
           # run every example again even if sphinx-gallery has its output from an earlier build
           "-D", "sphinx_gallery_conf.run_stale_examples=True",
           str(DOCS), str(out)]
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=ROOT, timeout=1800)
    assert proc.returncode == 0, f"sphinx-build failed:\n{proc.stdout}\n{proc.stderr}"
    assert "WARNING" not in proc.stderr and "ERROR" not in proc.stderr, proc.stderr
    return out


def test_api_reference_covers_public_names(html: Path) -> None:
    page = (html / "api" / "curvefair.html").read_text(encoding="utf-8")
    missing = [name for name in curvefair.__all__
               if name not in ("steps", "__version__") and f'id="curvefair.{name}"' not in page]
    assert not missing, f"not in the API reference: {missing}"
    assert 'id="curvefair.steps.poliakoff"' in (html / "api" / "steps.html").read_text("utf-8")
    fairing = (html / "api" / "fairing.html").read_text(encoding="utf-8")
    for name in ("eck_hadenfeld.eck_hadenfeld_fair", "knot_removal.knot_removal_fair",
                 "global_fair.global_fair", "cheng_yu.cheng_yu_driver"):
        assert f'id="curvefair.fairing.{name}"' in fairing, name
    io_page = (html / "api" / "io.html").read_text(encoding="utf-8")
    assert 'id="curvefair.io.detect_format"' in io_page
    # the public homes of what the CLI and batch use across packages (issue 15)
    assert 'id="curvefair.io.write_checked"' in io_page
    assert 'id="curvefair.io.rescaled_report"' in io_page
    assert 'id="curvefair.fairing.point_report"' in fairing


def test_markdown_pages(html: Path) -> None:
    formats = (html / "formats.html").read_text(encoding="utf-8")
    assert "File formats" in formats and "CurveRecord" in formats
    bench = (html / "benchmarks.html").read_text(encoding="utf-8")
    assert "Fairing quality benchmark" in bench
    # the benchmark page's figures are copied into the build
    for src in sorted((DOCS / "img" / "bench").glob("*.png")):
        assert (html / "_images" / src.name).is_file(), src.name


def test_gallery_examples_ran(html: Path) -> None:
    scripts = sorted((ROOT / "examples").glob("plot_*.py"))
    assert scripts
    for script in scripts:
        page = html / "auto_examples" / f"{script.stem}.html"
        assert page.is_file(), page
        figures = list((html / "_images").glob(f"sphx_glr_{script.stem}_0*.png"))
        assert figures, f"{script.name} embedded no figure"
        assert f"sphx_glr_{script.stem}_001.png" in page.read_text(encoding="utf-8")
