"""numba is imported by one module only, ``curvefair._jit`` (issue 15).

Every compiled kernel takes :func:`curvefair._jit.njit` (and the ``prefetch`` intrinsic) from
there, so numba's API (and that of its backend, llvmlite) is met in a single file."""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "curvefair"
BACKENDS = {"numba", "llvmlite"}


def _backend_imports(path: Path) -> list[str]:
    """The numba/llvmlite modules a file imports (``import``, ``from ... import``, at any
    depth of the file: inside functions too)."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found += [a.name for a in node.names if a.name.split(".")[0] in BACKENDS]
        elif isinstance(node, ast.ImportFrom) and not node.level and node.module \
                and node.module.split(".")[0] in BACKENDS:
            found.append(node.module)
    return found


def test_the_checker_sees_numba_imports(tmp_path):
    f = tmp_path / "x.py"
    f.write_text("import numpy\nfrom numba.core import cgutils\n"
                 "def g():\n    import llvmlite.ir as ir\n    from .numba import x\n")
    assert sorted(_backend_imports(f)) == ["llvmlite.ir", "numba.core"]


def test_only_jit_imports_numba():
    importers = {p.relative_to(SRC).as_posix() for p in sorted(SRC.rglob("*.py"))
                 if _backend_imports(p)}
    assert importers == {"_jit.py"}


def _jit_users(path: Path) -> bool:
    """Whether a file takes ``njit`` (or ``prefetch``) from ``curvefair._jit``, relative or
    absolute import alike."""
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[-1] == "_jit" \
                and (node.level or (node.module or "").startswith("curvefair.")) \
                and any(a.name in ("njit", "prefetch") for a in node.names):
            return True
    return False


def test_the_checker_sees_jit_users(tmp_path):
    f = tmp_path / "x.py"
    f.write_text("from .._typing import FloatArray\n")
    assert not _jit_users(f)
    for src in ("from .._jit import njit\n", "from curvefair._jit import prefetch\n",
                "def g():\n    from ..._jit import njit as nj\n"):
        f.write_text(src)
        assert _jit_users(f), src


def test_kernels_live_in_the_kernels_package():
    # issue 15: every compiled kernel is in curvefair._kernels, beside the others (and beside
    # its slow reference); the public packages keep the Python drivers only
    users = {p.relative_to(SRC).as_posix() for p in sorted(SRC.rglob("*.py")) if _jit_users(p)}
    outside = sorted(u for u in users if not u.startswith("_kernels/"))
    assert not outside, "compiled kernels outside curvefair._kernels: " + ", ".join(outside)
    assert "_kernels/sampling.py" in users  # the checker finds the kernels it should
