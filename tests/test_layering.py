"""No private import across packages (issue 15).

A module may import an underscore name, or a name from an underscore module, only from its own
package (curves, analysis, fairing, io, ``_kernels``, and the top level each count as one).
The exception is the shared internals - ``curvefair._typing``, ``_validate``, ``_jit``,
``_distance`` and the other underscore modules directly under ``curvefair/``, and the compiled
kernels' package ``curvefair._kernels`` with its (non-underscore) modules: they exist to be
shared by every subpackage (array types, argument checks, the numba cache, the kernels), so
importing a public name from them is allowed; importing an underscore name from them is not.
Reading an underscore attribute of a module imported from another package (``from .._kernels
import points as _pk`` ... ``_pk._rows``) counts as importing it."""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "curvefair"


def _package(module: tuple[str, ...]) -> str:
    """``("fairing", "fair")`` -> ``"fairing"``; a top-level module -> ``""``."""
    return module[0] if len(module) > 1 else ""


def _modules() -> dict[tuple[str, ...], Path]:
    out = {}
    for p in sorted(SRC.rglob("*.py")):
        parts = p.relative_to(SRC).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[parts] = p
    return out


def _private_imports(mod: tuple[str, ...], path: Path) -> list[str]:
    """``"importer -> target.name"`` for every underscore name/module imported from another
    package, relative or absolute imports alike, and for every underscore attribute read
    through a module imported from another package (``from ..x import mod as m`` ...
    ``m._name``)."""
    is_pkg = path.name == "__init__.py"
    here = _package(mod if not is_pkg else mod + ("__init__",))
    found = []
    aliases: dict[str, tuple[str, ...]] = {}   # local name -> a module of another package
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        targets: list[tuple[tuple[str, ...], str | None, str | None]] = []
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = list(mod if is_pkg else mod[:-1])
                base = base[:len(base) - (node.level - 1)] if node.level > 1 else base
            elif node.module and node.module.split(".")[0] == "curvefair":
                base = []
            else:
                continue
            rest = [] if not node.module else node.module.split(".")
            if not node.level:
                rest = rest[1:]
            target = tuple(base + rest)
            targets += [(target, a.name, a.asname or a.name) for a in node.names]
        elif isinstance(node, ast.Import):
            for a in node.names:
                parts = a.name.split(".")
                if parts[0] == "curvefair":
                    targets.append((tuple(parts[1:]), None, a.asname))
        for target, name, local in targets:
            if name is not None and (SRC.joinpath(*target, name).is_dir()
                                     or SRC.joinpath(*target, name + ".py").is_file()):
                target, name = target + (name,), None   # "from . import _module"
            there = _package(target + (("__init__",) if SRC.joinpath(*target).is_dir() else ()))
            if there == here:
                continue
            if name is None and local is not None:
                aliases[local] = target
            shared = (len(target) == 1 and target[0].startswith("_") and SRC.joinpath(
                target[0] + ".py").is_file()   # a top-level shared internal module
                or target[:1] == ("_kernels",)    # the kernels' package and its modules
                and not any(p.startswith("_") for p in target[1:]))
            private = (any(p.startswith("_") for p in target) and not shared) \
                or ((name or "").startswith("_") and not (name or "").startswith("__"))
            if private:
                found.append(f"{'.'.join(mod) or '__init__'} -> {'.'.join(target)}"
                             + (f".{name}" if name else ""))
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) \
                and node.value.id in aliases and node.attr.startswith("_") \
                and not node.attr.startswith("__"):
            found.append(f"{'.'.join(mod) or '__init__'} -> "
                         f"{'.'.join(aliases[node.value.id])}.{node.attr}")
    return found


def test_the_checker_sees_a_private_import_across_packages(tmp_path):
    # the checker itself: a fabricated module importing across packages is flagged
    p = SRC / "fairing" / "fair.py"
    assert _private_imports(("fairing", "x"), p) is not None
    src = ("from ..curves.interpolate import _secret\nfrom ._own import ok\n"
           "from .._typing import A\nfrom .._validate import _hidden\n"
           "from ..analysis._sampling import sample_curve\nimport curvefair.io._verify\n"
           # the kernels' package is shared: its public names and modules may be imported,
           # its underscore names (and underscore modules) may not
           "from .._kernels import hermite\nfrom .._kernels.global_fair import band_cholesky\n"
           "import curvefair._kernels.points\nfrom .._kernels.hermite import _kseg\n"
           "from .._kernels._hidden import x\n"
           # an underscore attribute read through a module of another package
           "from ..curves import bspline as bs\nfrom . import fair as own\n"
           "def f():\n    return hermite.drive, hermite._kseg, bs._gauss, own._private\n")
    f = tmp_path / "x.py"
    f.write_text(src)
    got = _private_imports(("fairing", "x"), f)
    assert got == ["fairing.x -> curves.interpolate._secret", "fairing.x -> _validate._hidden",
                   "fairing.x -> analysis._sampling.sample_curve", "fairing.x -> io._verify",
                   "fairing.x -> _kernels.hermite._kseg", "fairing.x -> _kernels._hidden.x",
                   "fairing.x -> _kernels.hermite._kseg", "fairing.x -> curves.bspline._gauss"]


# The imports across packages that still reach private pieces. Issue 15 gave every one of them a
# public home in the owning package, so the list is empty; it may only shrink: a new private
# import fails the test, and so does an entry that no longer occurs (remove it from the list).
KNOWN: set[str] = set()


def test_no_new_private_import_across_packages():
    found = {v for mod, path in _modules().items() for v in _private_imports(mod, path)}
    new = sorted(found - KNOWN)
    assert not new, "private imports across packages:\n" + "\n".join(new)
    gone = sorted(KNOWN - found)
    assert not gone, "no longer imported (remove from KNOWN):\n" + "\n".join(gone)


def test_steps_exports_every_documented_step():
    # README's API table documents these as `steps.<name>`
    import curvefair.steps as steps
    for name in ("kjellander", "poliakoff", "wang_cao", "wang_quintic", "eck_hadenfeld",
                 "knot_removal", "cheng_yu"):
        assert name in steps.__all__ and callable(getattr(steps, name)), name


def test_every_method_module_imports_and_registers_a_method():
    # fairing/__init__ imports METHOD_MODULES without a try: a missing module is an error,
    # and each listed module registers at least one fair() method
    import ast
    import importlib
    import inspect

    import curvefair.fairing as fairing
    from curvefair.fairing.fair import METHODS

    tree = ast.parse(inspect.getsource(fairing))
    assert not any(isinstance(n, ast.Try) for n in ast.walk(tree))
    modules = {f"curvefair.fairing.{m}" for m in fairing.METHOD_MODULES}
    for m in modules:
        importlib.import_module(m)
    # one method of each listed module is registered
    for name in ("poliakoff", "eck-hadenfeld", "knot-removal", "global", "cheng-yu", "points-l1"):
        assert name in METHODS, name
