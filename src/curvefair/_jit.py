"""Where curvefair's compiled kernels are decorated: ``njit`` with a cache that cannot go stale.

numba's own on-disk cache keys a kernel on the source file that defines it. A kernel that
inlines or calls a function from another file (``residual_row`` from ``_kernels/bspline.py``
inside the Eck-Hadenfeld loop, say) is not invalidated when that callee changes, and a module
constant frozen into the machine code is not either: the old machine code keeps running. Here
every curvefair kernel is cached under a directory named by a hash of *all* of the package's
Python sources together with the numba, llvmlite and Python versions and the compile options
that change the machine code (``NUMBA_BOUNDSCHECK``, ``NUMBA_OPT``, ``NUMBA_DEBUGINFO``). Any
edit to any module, or another compile setting, selects a new, empty directory: a stale kernel
cannot be loaded. (numba keys each entry on the CPU name and features itself, so
``NUMBA_CPU_NAME=generic`` and the host CPU share a directory without mixing.)

Where the cache lives, first that is writable:

1. ``$CURVEFAIR_CACHE_DIR`` (an empty value, or ``0``/``off``/``none``, turns caching off);
2. ``__pycache__/curvefair-jit-<key>`` inside the installed package (a source checkout);
3. the user cache, ``$XDG_CACHE_HOME/curvefair`` or ``~/.cache/curvefair``;
4. ``<tempdir>/curvefair-<uid>``;
5. nowhere: kernels are compiled in every process (a read-only system install whose user has
   no writable home still imports and runs).

When a new directory is made, the ``curvefair-jit-*`` ones beside it made from other sources are
removed: at once inside the package, after 14 days unused in a shared cache (which may serve
several installs). The directory name is ``curvefair-jit-<sources>-<options>``; the folders of
the same sources under other compile options are kept.
The first compilation into a new cache directory prints one line to stderr saying so
(set ``CURVEFAIR_QUIET=1`` to silence it).

Processes sharing a cache directory compile each kernel once between them: a kernel's compile
holds a lock file in ``<cache>/locks`` (``fcntl.flock``; released by the system when its
process ends), and a process that finds the lock held waits for it and then loads the machine
code the other one saved, instead of compiling the same kernel beside it. Without that, the
workers of a process pool on a cold cache (``curvefair batch``, the test suite's processes)
each compiled every kernel they ran: the same minutes of CPU time once per process. A wait
longer than ``LOCK_WAIT`` seconds compiles anyway; on systems without ``fcntl`` (Windows)
every process compiles for itself, as before.

This is the one module of curvefair that imports numba (and llvmlite): kernels elsewhere use
:func:`njit` and :func:`prefetch` from here (``tests/test_numba_layering.py`` checks it), so a
change of numba's API is met in one file.

The locator plugs into numba's documented-by-example cache machinery
(``numba.core.caching.CacheImpl._locator_classes``), placed first so that it answers for
curvefair's own files only; every other numba user in the process is unaffected.
"""

from __future__ import annotations

import contextlib
import hashlib
import inspect
import os
import shutil
import sys
import tempfile
import time
from collections.abc import Callable
from typing import Any

import llvmlite
import numba
from llvmlite import ir as _ir
from numba import config as _nb_config
from numba import njit as _numba_njit
from numba import types as _types
from numba.core import caching as _caching
from numba.core import cgutils as _cgutils
from numba.core import sigutils as _sigutils
from numba.core.compiler_lock import global_compiler_lock as _compiler_lock
from numba.core.dispatcher import OmittedArg as _OmittedArg
from numba.extending import intrinsic as _intrinsic

try:
    import fcntl as _fcntl
except ImportError:  # pragma: no cover - Windows: every process compiles for itself
    _fcntl = None  # type: ignore[assignment]

__all__ = ["njit", "prefetch", "cache_dir", "cache_key"]

_PKG_DIR = os.path.dirname(os.path.abspath(__file__))
_PREFIX = "curvefair-jit-"
_OFF = {"", "0", "off", "none", "false", "no"}


def _source_hash() -> str:
    """sha256 over every ``.py`` file of the package (relative path and bytes, sorted) and the
    numba, llvmlite and Python versions: which sources the kernels are compiled from."""
    h = hashlib.sha256()
    files: list[str] = []
    for root, dirs, names in os.walk(_PKG_DIR):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        files.extend(os.path.join(root, n) for n in names if n.endswith(".py"))
    for path in sorted(files):
        h.update(os.path.relpath(path, _PKG_DIR).replace(os.sep, "/").encode())
        h.update(b"\0")
        with open(path, "rb") as f:
            h.update(f.read())
        h.update(b"\0")
    h.update(repr((numba.__version__, llvmlite.__version__, sys.version,
                   sys.platform)).encode())
    return h.hexdigest()[:20]


def _options_hash() -> str:
    """The compile options that change the machine code but not numba's own cache key."""
    opts = (int(_nb_config.BOUNDSCHECK or 0), int(_nb_config.OPT),
            int(_nb_config.DEBUGINFO_DEFAULT or 0))
    return hashlib.sha256(repr(opts).encode()).hexdigest()[:6]


def _writable_dir(path: str) -> bool:
    try:
        os.makedirs(path, exist_ok=True)
        tempfile.TemporaryFile(dir=path).close()
    except OSError:
        return False
    return True


def _prune_siblings(parent: str, keep: str, older_than: float) -> None:
    """Remove the ``curvefair-jit-*`` folders of ``parent`` made from other sources than
    ``keep`` and not used for ``older_than`` seconds (0: all of them). The folders of the same
    sources under other compile options (``NUMBA_BOUNDSCHECK=1`` beside the plain kernels) are
    kept: switching an option back and forth compiles nothing again."""
    try:
        names = os.listdir(parent)
    except OSError:
        return
    same_sources = keep.rsplit("-", 1)[0] + "-"
    now = time.time()
    for name in names:
        path = os.path.join(parent, name)
        if not name.startswith(_PREFIX) or name.startswith(same_sources):
            continue
        try:
            if now - os.stat(path).st_mtime < older_than:
                continue
        except OSError:
            continue
        shutil.rmtree(path, ignore_errors=True)


_SHARED_KEEP = 14 * 86400.0  # a shared cache folder keeps other versions' kernels for 14 days


def _choose_cache_dir(key: str) -> str | None:
    """The first usable folder of the list in the module docstring, made if need be; the
    package's own ``__pycache__`` serves one source tree, so its older folders go at once, while
    a shared one (user cache, temp, ``$CURVEFAIR_CACHE_DIR``) may serve several installs."""
    name = _PREFIX + key
    env = os.environ.get("CURVEFAIR_CACHE_DIR")
    if env is not None:
        if env.strip().lower() in _OFF:
            return None
        parents = [(env, _SHARED_KEEP)]
    else:
        xdg = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
        uid = os.getuid() if hasattr(os, "getuid") else "user"
        parents = [(os.path.join(_PKG_DIR, "__pycache__"), 0.0),
                   (os.path.join(xdg, "curvefair"), _SHARED_KEEP),
                   (os.path.join(tempfile.gettempdir(), f"curvefair-{uid}"), _SHARED_KEEP)]
    for parent, keep in parents:
        path = os.path.join(parent, name)
        existed = os.path.isdir(path)
        if _writable_dir(path):
            if existed:
                with contextlib.suppress(OSError):
                    os.utime(path)  # in use: not pruned by another install
            else:
                _prune_siblings(parent, name, keep)
            return path
    return None


_KEY = f"{_source_hash()}-{_options_hash()}"
_CACHE_DIR = _choose_cache_dir(_KEY)
_noticed = False


def cache_key() -> str:
    """The hash that names the kernel cache (changes with any source edit or compile option)."""
    return _KEY


def cache_dir() -> str | None:
    """The directory compiled kernels are cached in, or ``None`` when caching is off."""
    return _CACHE_DIR


def _notice_first_compile(path: str) -> None:
    """One stderr line, once per new cache directory (a marker file records that it was said)."""
    global _noticed
    if _noticed:
        return
    _noticed = True
    if os.environ.get("CURVEFAIR_QUIET", "").strip().lower() not in _OFF:
        return
    try:
        fd = os.open(os.path.join(path, ".notice"), os.O_CREAT | os.O_EXCL | os.O_WRONLY)
    except OSError:
        return  # said before (or the directory went away): stay quiet
    os.close(fd)
    sys.stderr.write("curvefair: compiling its numerical kernels for this machine "
                     f"(once, about a minute per method used; cached in {path})\n")


class _CurvefairCacheLocator(_caching._CacheLocator):
    """numba cache locator for curvefair's own source files: one directory per :func:`cache_key`,
    whose key is also the source stamp."""

    def __init__(self, py_func: Callable[..., Any], py_file: str) -> None:
        self._py_file = py_file
        self._lineno = py_func.__code__.co_firstlineno
        rel = os.path.relpath(os.path.dirname(os.path.abspath(py_file)), _PKG_DIR)
        sub = "pkg" if rel == "." else rel.replace(os.sep, "_")
        assert _CACHE_DIR is not None
        self._path = os.path.join(_CACHE_DIR, sub)

    def ensure_cache_path(self) -> None:  # called before every save
        super().ensure_cache_path()
        _notice_first_compile(_CACHE_DIR or self._path)

    def get_cache_path(self) -> str:
        return self._path

    def get_source_stamp(self) -> str:
        return _KEY

    def get_disambiguator(self) -> str:
        return str(self._lineno)

    @classmethod
    def from_function(cls, py_func: Callable[..., Any], py_file: str) -> Any:
        if _CACHE_DIR is None:
            return None
        path = os.path.abspath(py_file)
        if os.path.commonpath([path, _PKG_DIR]) != _PKG_DIR:
            return None  # not curvefair's: numba's own locators answer
        return cls(py_func, py_file)


# numba >= 0.61 calls the implementation class ``CacheImpl``, earlier ones ``_CacheImpl``
_IMPL = getattr(_caching, "CacheImpl", None) or _caching._CacheImpl
if _CurvefairCacheLocator not in _IMPL._locator_classes:
    _IMPL._locator_classes.insert(0, _CurvefairCacheLocator)


def njit(*args: Any, readonly: tuple[str, ...] = (), any_layout: tuple[str, ...] = (),
         **kwargs: Any) -> Any:
    """``numba.njit`` for curvefair kernels: ``cache=True`` goes to the keyed cache above, or is
    dropped when no cache directory is writable (the kernel is then compiled per process).

    ``readonly`` names array parameters that the kernel only reads, ``any_layout`` array
    parameters that some callers pass as strided views: a call from Python compiles the kernel
    for them typed as read-only arrays, or arrays of any layout, whatever the flags of the
    arrays passed. numba compiles one machine code per distinct argument type, and an array's
    writeable flag and contiguity are part of its type: a kernel fed a curve's frozen
    coefficients by one caller and fresh ones by another was compiled twice (36 kernels 2 to 5
    times). numba converts a writable (or contiguous) array to the
    read-only (any-layout) type of an existing machine code by itself, so after the first call
    every variant of the arguments runs the same code. Calls from other kernels are typed by
    the caller as usual.

    Every kernel releases the GIL (``nogil=True`` unless a kernel says otherwise): a kernel
    running on one thread then never holds up another thread's Python, e.g. the analysis that
    :func:`curvefair.fair` runs on the worker thread beside a method's compiled loop (whose
    calls otherwise hold the GIL for their whole run). It changes no machine code of the
    kernel's body, only its entry from Python."""
    kwargs.setdefault("nogil", True)
    if kwargs.get("cache") and _CACHE_DIR is None:
        kwargs["cache"] = False

    def decorate(fn: Callable[..., Any]) -> Any:
        disp = _numba_njit(**kwargs)(fn)
        if readonly or any_layout:
            names = list(inspect.signature(fn).parameters)
            unknown = [x for x in (*readonly, *any_layout) if x not in names]
            if unknown:
                raise TypeError(f"njit({fn.__qualname__}): no parameter named {unknown}")
            _canonical_types(disp, [names.index(x) for x in readonly],
                             [names.index(x) for x in any_layout])
        if kwargs.get("cache"):
            _one_compile_at_a_time(disp)
        return disp

    return decorate(args[0]) if args and callable(args[0]) else decorate


#: the longest a process waits for another one's compile of a kernel before compiling it too (s)
LOCK_WAIT = 900.0
#: lock files this process holds (a kernel whose compile types a call to itself asks for its own
#: lock again: a second ``flock`` on another descriptor would wait forever)
_held: set[str] = set()


@contextlib.contextmanager
def _kernel_lock(path: str) -> Any:
    """Hold the lock file ``path`` across processes (re-entrant within this one, whose compiles
    are serialised by numba's compiler lock); after ``LOCK_WAIT`` s, or if the file cannot be
    made, go on without it."""
    if path in _held:  # held by an outer compile of this process
        yield
        return
    try:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
    except OSError:
        yield
        return
    deadline = time.monotonic() + LOCK_WAIT
    locked = False
    try:
        while True:
            try:
                _fcntl.flock(fd, _fcntl.LOCK_EX | _fcntl.LOCK_NB)
                locked = True
                break
            except OSError:
                if time.monotonic() > deadline:
                    break
                time.sleep(0.05)
        _held.add(path)
        try:
            yield
        finally:
            _held.discard(path)
    finally:
        if locked:
            _fcntl.flock(fd, _fcntl.LOCK_UN)
        os.close(fd)


def _one_compile_at_a_time(disp: Any) -> None:
    """Make ``disp``'s compiles hold a lock file per kernel in the cache directory (see the
    module docstring), so that processes sharing the cache compile it once: numba's
    ``Dispatcher.compile`` looks in the disk cache before it compiles, so a process that waited
    loads what the other one saved. The compiler lock is taken first: the threads of one
    process then never hold a kernel's lock file while waiting for numba's lock, and the lock
    files are taken in the order of the kernels' calls (a caller's before its callees'), which
    has no cycle across processes."""
    if _fcntl is None or _CACHE_DIR is None:
        return
    plain = disp.compile
    fn = disp.py_func
    path = os.path.join(_CACHE_DIR, "locks", f"{fn.__module__}.{fn.__qualname__}.lock")

    def compile(sig: Any) -> Any:  # noqa: A001 (numba's method name)
        with _compiler_lock:
            args, _ = _sigutils.normalize_signature(sig)
            if tuple(args) in disp.overloads:  # compiled or loaded here already: no wait
                return plain(sig)
            with _kernel_lock(path):
                return plain(sig)

    disp.compile = compile


def _canonical_types(disp: Any, ro: list[int], anyl: list[int]) -> None:
    """Make ``disp`` compile a call's signature with the arrays at positions ``ro`` read-only
    and those at ``anyl`` of layout ``A`` (see :func:`njit`). numba's C dispatcher
    asks the instance's ``_compile_for_args`` for machine code when no compiled signature
    accepts the arguments, then calls what it returns with the arguments as they are; the
    arguments' own types are then registered as another key of that machine code, so the next
    such call is dispatched in C."""
    plain = disp._compile_for_args

    def _compile_for_args(*args: Any, **kws: Any) -> Any:
        if kws:
            return plain(*args, **kws)
        tys = [_types.Omitted(a.value) if isinstance(a, _OmittedArg) else disp.typeof_pyval(a)
               for a in args]
        canon = list(tys)
        for i in ro:
            t = canon[i] if i < len(canon) else None
            if isinstance(t, _types.Array) and t.mutable:
                canon[i] = t.copy(readonly=True)
        for i in anyl:
            t = canon[i] if i < len(canon) else None
            if isinstance(t, _types.Array) and t.layout != "A":
                canon[i] = t.copy(layout="A")
        if canon == tys:
            return plain(*args)
        disp._compilation_chain_init_hook()
        entry = disp.compile(tuple(canon))
        # While compiling is allowed, the C dispatcher takes only an exact match of the argument
        # types and would come back here on every call (typing every argument in Python: 0.1-2
        # ms a call). Register these exact types as another key of the same machine code: its
        # wrapper unboxes the arguments with the canonical types, which accept these arrays
        # (the same array structure; only the flags differ). ``disp.overloads`` (and so the
        # disk cache) keeps the canonical signature only.
        disp._insert([t._code for t in tys], entry, False)
        return entry

    disp._compile_for_args = _compile_for_args


@_intrinsic
def prefetch(typingctx, arr, idx):
    """Hint the CPU to load the cache line holding ``arr.flat[idx]`` (a C-contiguous array;
    ``idx`` need not be in range: a prefetch never faults). ``llvm.prefetch``; no effect on
    results.

    Used by the ranking-list loops to fetch, one step ahead, the data of the control point
    that will most probably be faired next (the runner-up of the tournament tree): on curves
    too large for the caches the step is otherwise bound by memory latency."""
    if not isinstance(arr, _types.Array):
        return None
    sig = _types.void(arr, _types.intp)

    def codegen(context, builder, signature, args):
        aryty = signature.args[0]
        ary = context.make_array(aryty)(context, builder, args[0])
        ptr = builder.gep(ary.data, [args[1]])
        i8p = _ir.IntType(8).as_pointer()
        i32 = _ir.IntType(32)
        fnty = _ir.FunctionType(_ir.VoidType(), [i8p, i32, i32, i32])
        fn = _cgutils.get_or_insert_function(builder.module, fnty, "llvm.prefetch.p0")
        # read, high temporal locality, data cache
        builder.call(fn, [builder.bitcast(ptr, i8p), _ir.Constant(i32, 0), _ir.Constant(i32, 3),
                          _ir.Constant(i32, 1)])
        return context.get_dummy_value()

    return sig, codegen
