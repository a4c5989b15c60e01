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
