"""Shared test configuration: markers and the set of compiled-loop tests.

``compiled``: tests that drive curvefair's numba kernels against slow references or exact
properties. CI runs them a second time under another instruction set (``NUMBA_CPU_NAME=generic``
and numpy's wide SIMD paths disabled) and once with ``NUMBA_BOUNDSCHECK=1`` (see ``.ci/run``);
``pytest -m compiled`` selects them.

``slow``: tests that take more than ~20 s on the 2-core CI machine with a warm kernel cache
(still run by ``make test``; ``pytest -m "not slow"`` leaves them out while working).

Hypothesis: under ``CI=true`` the ``ci`` profile (derandomised, no example database) is loaded, so
CI draws the same examples on every run; locally the random default profile keeps exploring.
"""

from __future__ import annotations

import os

import pytest

try:
    from hypothesis import settings as _hyp_settings
except ImportError:  # pragma: no cover - hypothesis is in the test extra
    _hyp_settings = None

if _hyp_settings is not None:
    # CI runs the property tests derandomised: the same examples on every run and machine, so a
    # landing cannot fail on a case Hypothesis happened to draw that day (a case found while
    # developing, with the random default profile, is added to the test as an @example).
    _hyp_settings.register_profile("ci", derandomize=True, database=None,
                                   print_blob=True)
    if os.environ.get("CI", "").lower() in ("1", "true", "yes"):
        _hyp_settings.load_profile("ci")

#: test files whose tests exercise the compiled loops (marked ``compiled``). Not
#: ``test_jit_cache.py``: its kernels run in subprocesses whose environment drops every
#: ``NUMBA_*`` setting, so the second run repeated the first one's tests exactly (56 s of CI)
COMPILED_FILES = frozenset({
    "test_knot_removal_compiled.py",
    "test_knot_removal.py",
    "test_eh_sweep.py",
    "test_eck_hadenfeld.py",
    "test_global_fair.py",
    "test_points_l1.py",
    "test_points_l1_closed.py",
    "test_ranking.py",
    "test_fair_loop.py",
    "test_bspline_small_curves.py",
    "test_cheng_yu_driver.py",
    "test_steps_local.py",
    "test_hermite_measures.py",
    "test_analysis_deviation.py",
    "test_bspline_fairing_properties.py",
    "test_reproducible.py",
    "test_recorded_cases.py",
    "test_distance.py",
    "test_analysis_analyze.py",
    "test_text_kernel.py",
    "test_io_text_layout.py",
    "test_reader_scans.py",
    "test_hermite_delta_deviation.py",
    "test_pairwise_sums.py",
})

#: tests of those files that are not marked ``compiled``: behaviour of the whole pipeline
#: (never-worse guards on rebuilt curves, the command line, environment variables) on long
#: inputs, whose kernels the kernel tests of the same files already drive under CI's second
#: instruction set. Left out of that run because they cost 65 s of its CPU time there
#: (measured with ``--durations``) and check nothing that depends on the instruction set.
PIPELINE_TESTS = frozenset({
    ("test_points_l1.py", "test_point_data_whose_every_tube_rebuilds_worse_keep_the_input"),
    ("test_points_l1.py", "test_point_data_back_off_judges_the_curve_rebuilt_from_the_written_"
                          "points"),
    ("test_points_l1.py", "test_fair_guard_judges_the_curve_rebuilt_from_the_points_of_any_"
                          "method"),
    ("test_points_l1.py", "test_long_lists_shrink_the_tube_only_near_a_rebuilt_curve_excess"),
    ("test_points_l1.py", "test_cli_writes_a_point_file_whose_rebuilt_curve_is_not_worse"),
    ("test_points_l1.py", "test_fair_guard_catches_a_poliakoff_result_that_rebuilds_worse"),
    ("test_points_l1_closed.py", "test_small_polygons_do_not_collapse_real_svg"),
    ("test_global_fair.py", "test_curvefair_threads_environment_variable"),
})

#: test files whose tests each take more than ~20 s (marked ``slow``); measured with
#: ``pytest --durations=30``
SLOW_FILES = frozenset({
    "test_docs.py",  # one Sphinx build with the gallery (~25 s)
})


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "compiled: exercises the numba kernels (run again by CI "
                                       "under another instruction set and with bounds checks)")
    config.addinivalue_line("markers", "slow: takes more than ~20 s")


#: test files whose tests run curvefair in fresh interpreters (CLI subprocesses, process pools,
#: the recorded cases of test_reproducible.py): collected last, so that on a cold kernel cache
#: those interpreters load the kernels the in-process tests compiled and saved before them
#: instead of each compiling its own (test_reproducible's fresh interpreter compiles every
#: method's kernels: 180 s in one second-run measurement, under 8 s when collected last).
#: pytest-xdist's worksteal keeps this order within each worker's queue.
LATE_FILES = frozenset({
    "test_reproducible.py",
    "test_batch.py",
    "test_batch_chunked.py",
    "test_batch_progress_tty.py",
    "test_cli.py",
    "test_cli_write.py",
    "test_files_hunt4.py",
})


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        name = getattr(item, "originalname", item.name)
        if item.path.name in COMPILED_FILES and (item.path.name, name) not in PIPELINE_TESTS:
            item.add_marker(pytest.mark.compiled)
        if item.path.name in SLOW_FILES:
            item.add_marker(pytest.mark.slow)
    items.sort(key=lambda it: it.path.name in LATE_FILES)  # stable: the order within is kept


#: the kernel families whose compiles take minutes on a cold cache (the Hermite loop ``drive``
#: 80-160 s alone, the B-spline deviation kernels 60-130 s), each started by a tiny call
_PREWARM: list[tuple[str, str]] = [  # (method, interpolation)
    ("poliakoff", "interpolate_cubic"),
    ("eck-hadenfeld", "interpolate_bspline"),
    ("knot-removal", "interpolate_bspline"),
    ("global", "interpolate_bspline"),
]
#: a whole-suite run (CI's ``make test``: 2,600 tests, its second pass: 1,000) from this many
#: tests on; a run of a few files compiles only what its tests need
_PREWARM_MIN_TESTS = 500


def pytest_collection_finish(session: pytest.Session) -> None:
    """On a cold kernel cache, the worker processes of a whole-suite run (pytest-xdist) begin
    by compiling different kernel families, ``gw0`` the first, ``gw1`` the second, and so on
    round the families. Left to the tests, every worker's first tests need the same big
    kernels at once: each waited for the other's compile (``curvefair._jit`` compiles a
    kernel once between the processes sharing a cache) or, before that lock, compiled it
    again (265 of the 940 s of compile time of CI's second pass). On a warm cache each call
    loads its kernels in well under a second."""
    worker = os.environ.get("PYTEST_XDIST_WORKER", "")
    count = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1") or 1)
    if not worker.startswith("gw") or count < 2 or len(session.items) < _PREWARM_MIN_TESTS:
        return
    import numpy as np

    import curvefair as cf

    x = np.linspace(0.0, 6.0, 40)
    P = np.c_[x, np.sin(x)]  # noqa: N806
    for method, make in _PREWARM[int(worker[2:]) % count::count]:
        cf.fair(getattr(cf, make)(P), method, tol=0.05)
