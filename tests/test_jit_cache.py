"""The compiled-kernel cache (``curvefair._jit``) cannot go stale and never stops an import.

Each case copies the package into a temporary folder, adds two small modules (a kernel in one file
that calls a jitted callee and reads a constant from another), and runs them in fresh
interpreters with their own cache folder: numba's own cache would keep running the old machine
code after the callee changed (it keys a kernel on its own file only).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import curvefair

PKG = Path(curvefair.__file__).resolve().parent

CALLER = '''
from ._jit import njit
from ._probe_callee import SCALE, callee


@njit(cache=True)
def kernel(x):
    s = 0.0
    for i in range(4):
        s += callee(x + i)
    return s * SCALE
'''

CALLEE = '''
from ._jit import njit

SCALE = {scale}


@njit(cache=True, inline="always")
def callee(x):
    return {factor} * x
'''

RUN = '''
import sys, json
from curvefair import _jit
from curvefair._probe_caller import kernel
v = kernel(1.0)
print(json.dumps({"value": v, "hits": sum(kernel.stats.cache_hits.values()),
                  "misses": sum(kernel.stats.cache_misses.values()), "dir": _jit.cache_dir()}))
'''


def _copy_package(tmp: Path, whole: bool = False) -> Path:
    """The package copied into ``tmp/site``, with the probe modules added. Unless ``whole``,
    its ``__init__`` is replaced by an empty module: the probes import ``curvefair._jit`` (and
    numba) only, not the whole package (1.7 s per interpreter, about 20 of them here); the
    cache key still hashes every source file of the copy."""
    root = tmp / "site"
    shutil.copytree(PKG, root / "curvefair", ignore=shutil.ignore_patterns("__pycache__"))
    if not whole:
        (root / "curvefair" / "__init__.py").write_text('"""curvefair, its __init__ emptied."""\n')
    (root / "curvefair" / "_probe_caller.py").write_text(CALLER)
    (root / "curvefair" / "_probe_callee.py").write_text(CALLEE.format(scale=1.0, factor=2.0))
    return root


def _run(root: Path, env_extra: dict[str, str], code: str = RUN) -> tuple[dict, str]:
    import json

    env = {k: v for k, v in os.environ.items() if not k.startswith(("CURVEFAIR_", "NUMBA_"))}
    env.update({"PYTHONPATH": str(root), "PYTHONDONTWRITEBYTECODE": "1"}, **env_extra)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                          cwd=root, timeout=600)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1]), proc.stderr


def test_callee_edit_in_another_file_invalidates_the_cache(tmp_path):
    root = _copy_package(tmp_path)
    env: dict[str, str] = {}  # the default place: the package's own __pycache__
    first, err = _run(root, env)
    assert first["dir"].startswith(str(root / "curvefair" / "__pycache__" / "curvefair-jit-"))
    assert first["value"] == 2.0 * (1 + 2 + 3 + 4)  # 2 * sum(x + i), i = 0..3
    assert first["misses"] == 1 and first["hits"] == 0
    assert "compiling" in err  # the one-line notice, into a new cache folder
    second, err = _run(root, env)
    assert second == {**first, "hits": 1, "misses": 0}  # loaded from the cache ...
    assert "compiling" not in err  # ... and said only once
    # edit the callee's file only (its caller's file is unchanged): the old machine code must
    # not be loaded
    (root / "curvefair" / "_probe_callee.py").write_text(CALLEE.format(scale=1.0, factor=3.0))
    third, _ = _run(root, env)
    assert third["value"] == 3.0 * 10
    assert third["dir"] != first["dir"]  # another source hash, another folder
    # a constant frozen into the kernel, defined in the other file, likewise
    (root / "curvefair" / "_probe_callee.py").write_text(CALLEE.format(scale=0.5, factor=3.0))
    fourth, _ = _run(root, env)
    assert fourth["value"] == 0.5 * 3.0 * 10
    # the folders of the superseded sources are pruned when a new one is made
    cache = root / "curvefair" / "__pycache__"
    assert sorted(p.name for p in cache.iterdir()) == [Path(fourth["dir"]).name]


def test_shared_cache_folder_keeps_other_versions(tmp_path):
    # $CURVEFAIR_CACHE_DIR (like ~/.cache) may serve several installs: editing one does not
    # throw away the other's kernels, and each finds its own again
    root = _copy_package(tmp_path)
    env = {"CURVEFAIR_CACHE_DIR": str(tmp_path / "cache")}
    a, _ = _run(root, env)
    (root / "curvefair" / "_probe_callee.py").write_text(CALLEE.format(scale=1.0, factor=3.0))
    b, _ = _run(root, env)
    assert b["value"] == 30.0 and b["dir"] != a["dir"]
    (root / "curvefair" / "_probe_callee.py").write_text(CALLEE.format(scale=1.0, factor=2.0))
    again, _ = _run(root, env)
    assert again == {**a, "hits": 1, "misses": 0}


@pytest.mark.skipif(sys.platform == "win32", reason="no fcntl: each process compiles")
def test_a_process_waits_for_anothers_compile_and_loads_its_machine_code(tmp_path):
    # processes sharing a cache compile each kernel once: while the kernel's lock file is held
    # (here by this test, as a compiling process would hold it), a process that needs the
    # kernel waits; a process that saved it meanwhile (the lock replaced by a null context in
    # it) is what the waiting one then loads from the cache instead of compiling
    import fcntl
    import json
    import time

    root = _copy_package(tmp_path)
    env = {k: v for k, v in os.environ.items() if not k.startswith(("CURVEFAIR_", "NUMBA_"))}
    env.update({"PYTHONPATH": str(root), "PYTHONDONTWRITEBYTECODE": "1",
                "CURVEFAIR_CACHE_DIR": str(tmp_path / "cache")})
    where, _ = _run(root, {"CURVEFAIR_CACHE_DIR": env["CURVEFAIR_CACHE_DIR"]},
                    "import json; from curvefair import _jit; "
                    "print(json.dumps({'dir': _jit.cache_dir()}))")
    lock = Path(where["dir"]) / "locks" / "curvefair._probe_caller.kernel.lock"
    lock.parent.mkdir(parents=True, exist_ok=True)
    with open(lock, "w") as held:
        fcntl.flock(held, fcntl.LOCK_EX)
        waiting = subprocess.Popen([sys.executable, "-c", RUN], stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE, text=True, env=env, cwd=root)
        unlocked = ("import contextlib; from curvefair import _jit; "
                    "_jit._kernel_lock = lambda path: contextlib.nullcontext()\n" + RUN)
        saver, _ = _run(root, {"CURVEFAIR_CACHE_DIR": env["CURVEFAIR_CACHE_DIR"]}, unlocked)
        assert saver["misses"] == 1 and saver["value"] == 20.0  # compiled and saved
        time.sleep(0.5)
        assert waiting.poll() is None  # still waiting for the lock
    out, err = waiting.communicate(timeout=600)
    assert waiting.returncode == 0, err
    got = json.loads(out.strip().splitlines()[-1])
    assert got == {**saver, "hits": 1, "misses": 0}  # loaded what the other process saved


def test_bounds_checking_gets_its_own_cache(tmp_path):
    # NUMBA_BOUNDSCHECK changes the machine code but not numba's own cache key
    root = _copy_package(tmp_path)
    env = {"CURVEFAIR_CACHE_DIR": str(tmp_path / "cache")}
    plain, _ = _run(root, env)
    checked, _ = _run(root, {**env, "NUMBA_BOUNDSCHECK": "1"})
    assert checked["dir"] != plain["dir"] and checked["misses"] == 1


def test_bounds_checked_and_plain_kernels_live_side_by_side_in_the_package(tmp_path):
    # CI runs the suite, then the compiled tests with NUMBA_BOUNDSCHECK=1, whose native
    # comparison run needs the plain kernels again: making the checked folder in the package's
    # __pycache__ must not prune the plain one (the same sources), only other sources' folders
    root = _copy_package(tmp_path)
    cache = root / "curvefair" / "__pycache__"
    plain, _ = _run(root, {})
    checked, _ = _run(root, {"NUMBA_BOUNDSCHECK": "1"})
    assert checked["dir"] != plain["dir"] and checked["misses"] == 1
    again, _ = _run(root, {})
    assert again == {**plain, "hits": 1, "misses": 0}  # not compiled again
    assert sorted(p.name for p in cache.iterdir()) == sorted(
        [Path(plain["dir"]).name, Path(checked["dir"]).name])
    (root / "curvefair" / "_probe_callee.py").write_text(CALLEE.format(scale=1.0, factor=3.0))
    edited, _ = _run(root, {})
    assert edited["value"] == 30.0
    assert [p.name for p in cache.iterdir()] == [Path(edited["dir"]).name]  # both pruned


def test_imports_and_runs_with_no_writable_cache(tmp_path):
    # a system install: the package's __pycache__, the user cache and the temp folder all
    # unusable (a regular file stands where a folder would have to be made: even root cannot
    # write there), and the explicit switch off
    root = _copy_package(tmp_path, whole=True)
    blocker = tmp_path / "not-a-dir"
    blocker.write_text("")
    (root / "curvefair" / "__pycache__").write_text("")
    # with no cache at all, a kernel of the package itself (compiled in the process) as well
    full = RUN.replace("v = kernel(1.0)", "v = kernel(1.0)\nimport numpy as np\n"
                       "import curvefair\n"
                       "from curvefair._kernels.ranking import tt_build, tt_top\n"
                       "assert tt_top(*tt_build(np.array([3.0, 7.0, 1.0]))) == (1, 7.0)")
    for env, code in (({"XDG_CACHE_HOME": str(blocker), "HOME": str(blocker / "home"),
                        "TMPDIR": str(tmp_path)}, RUN),  # only the temp folder is left
                      ({"CURVEFAIR_CACHE_DIR": "off"}, RUN),
                      ({"CURVEFAIR_CACHE_DIR": str(blocker / "cache")}, full)):  # unusable
        out, err = _run(root, env, code)
        assert out["value"] == 20.0
        assert "cannot cache" not in err
        if "TMPDIR" in env:
            assert out["dir"].startswith(str(tmp_path / f"curvefair-{os.getuid()}"))
        else:
            assert out["dir"] is None and out["hits"] == 0


@pytest.mark.parametrize("name", ["CURVEFAIR_QUIET"])
def test_notice_can_be_silenced(tmp_path, name):
    root = _copy_package(tmp_path)
    _, err = _run(root, {"CURVEFAIR_CACHE_DIR": str(tmp_path / "cache"), name: "1"})
    assert "compiling" not in err


# ------------------------------------------------------------------------------------------
# njit(readonly=..., any_layout=...): one machine code whatever the arrays' flags
# ------------------------------------------------------------------------------------------
def _kernels():
    """Two copies of one kernel, with and without the canonical argument types (no cache:
    each test compiles its own)."""
    import numpy as np  # noqa: F401  (the kernels' globals)

    from curvefair._jit import njit

    def total(x, w, out):
        s = 0.0
        for i in range(x.shape[0]):
            for j in range(x.shape[1]):
                s += x[i, j] * w[i]
        out[0] = s
        return s

    plain = njit(cache=False)(total)
    canon = njit(cache=False, readonly=("x", "w"), any_layout=("x",))(total)
    return plain, canon


def test_readonly_and_any_layout_compile_one_signature_for_every_variant():
    """A kernel fed writable, read-only and strided arrays: compiled three times without the
    option, once with it, and the same value every time (computed in numpy here)."""
    import numpy as np

    plain, canon = _kernels()
    rng = np.random.default_rng(3)
    x = rng.standard_normal((6, 4))
    w = rng.standard_normal(6)
    frozen = x.copy()
    frozen.flags.writeable = False
    strided = np.asfortranarray(x)[:, ::2]
    variants = [(x, w), (frozen, w), (strided, w), (x, w.copy())]
    for k in (plain, canon):
        for a, b in variants:
            out = np.zeros(1)
            v = k(a, b, out)
            assert v == out[0]
            np.testing.assert_allclose(v, float(np.sum(a * b[:, None])), rtol=1e-13)
    assert len(plain.signatures) == 3
    assert len(canon.signatures) == 1
    (sig,) = canon.signatures
    assert not sig[0].mutable and sig[0].layout == "A" and not sig[1].mutable
    assert sig[2].mutable  # the output keeps its type


def test_canonical_kernel_calls_are_dispatched_in_c_after_the_first():
    """After the first call with a given variant of the arguments, later calls with that variant
    reach the machine code without numba's Python-level compile hook (which types every
    argument in Python: it made every call of such a kernel cost 0.1-2 ms), and still compute
    the right value for each variant."""
    import numpy as np

    _, canon = _kernels()
    rng = np.random.default_rng(4)
    x = rng.standard_normal((5, 3))
    w = rng.standard_normal(5)
    strided = np.asfortranarray(x)[:, ::2]
    hook = canon._compile_for_args
    calls = []

    def counting(*a, **k):
        calls.append(1)
        return hook(*a, **k)

    canon._compile_for_args = counting
    for rep in range(3):
        for a in (x, strided):
            out = np.zeros(1)
            v = canon(a, w, out)
            np.testing.assert_allclose(v, float(np.sum(a * w[:, None])), rtol=1e-13)
        assert len(calls) == 2, rep  # once per variant, on its first call only
    assert len(canon.signatures) == 1


def test_canonical_kernel_first_called_from_many_threads_at_once():
    """Threads that make a kernel's first call together (curvefair's ranges run kernels in
    threads) all get its value, and later calls still resolve (each thread may register the
    arguments' types as a key of the machine code: the same key twice is harmless)."""
    import threading

    import numpy as np

    _, canon = _kernels()
    rng = np.random.default_rng(5)
    x = rng.standard_normal((7, 2))
    w = rng.standard_normal(7)
    want = float(np.sum(x * w[:, None]))
    barrier = threading.Barrier(8)
    got: list[float] = []
    errors: list[BaseException] = []

    def call() -> None:
        try:
            barrier.wait()
            got.append(canon(x, w, np.zeros(1)))
        except BaseException as exc:  # reported below
            errors.append(exc)

    threads = [threading.Thread(target=call) for _ in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    np.testing.assert_allclose(got, [want] * 8, rtol=1e-13)
    np.testing.assert_allclose(canon(x, w, np.zeros(1)), want, rtol=1e-13)


def test_readonly_names_must_be_parameters_and_stay_unwritten():
    import numpy as np
    from numba.core.errors import TypingError

    from curvefair._jit import njit

    def write(x):
        x[0] = 1.0
        return x[0]

    with pytest.raises(TypeError, match="no parameter named"):
        njit(cache=False, readonly=("y",))(write)
    k = njit(cache=False, readonly=("x",))(write)
    with pytest.raises(TypingError):
        k(np.zeros(3))


def test_every_kernel_releases_the_gil():
    """Every compiled kernel of the package releases the GIL (``curvefair._jit.njit``'s
    default): fair() runs its input's analysis on the worker thread beside the method's
    compiled loop, which would otherwise hold the GIL for its whole run and stall the
    analysis' Python between its passes. Counted over every module that defines kernels."""
    import importlib
    import pkgutil

    from numba.core.registry import CPUDispatcher

    found, holding = 0, []
    for info in pkgutil.walk_packages(curvefair.__path__, "curvefair."):
        if info.name.rsplit(".", 1)[-1] in ("__main__",):
            continue
        try:
            mod = importlib.import_module(info.name)
        except ImportError:  # an optional dependency's module
            continue
        for name, obj in vars(mod).items():
            if isinstance(obj, CPUDispatcher) and obj.py_func.__module__ == info.name:
                found += 1
                if not obj.targetoptions.get("nogil"):
                    holding.append(f"{info.name}.{name}")
    assert found > 100
    assert holding == []
