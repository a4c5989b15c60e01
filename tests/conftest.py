"""Shared test configuration: markers and the set of compiled-loop tests.

``compiled``: tests that drive curvefair's numba kernels against slow references or exact
properties. CI runs them a second time under another instruction set (``NUMBA_CPU_NAME=generic``
and numpy's wide SIMD paths disabled) and once with ``NUMBA_BOUNDSCHECK=1`` (see ``.ci/run``);
``pytest -m compiled`` selects them.
"""

from __future__ import annotations

import pytest

#: test files whose tests exercise the compiled loops (marked ``compiled``)
COMPILED_FILES = frozenset({
    "test_knot_removal_compiled.py",
    "test_knot_removal.py",
    "test_eh_sweep.py",
    "test_eck_hadenfeld.py",
    "test_global_fair.py",
    "test_ranking.py",
    "test_fair_loop.py",
    "test_bspline_small_curves.py",
    "test_cheng_yu_driver.py",
    "test_steps_local.py",
    "test_hermite_measures.py",
    "test_analysis_deviation.py",
    "test_bspline_fairing_properties.py",
    "test_jit_cache.py",
    "test_reproducible.py",
})


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "compiled: exercises the numba kernels (run again by CI "
                                       "under another instruction set and with bounds checks)")
    config.addinivalue_line("markers", "slow: takes more than ~20 s")


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        if item.path.name in COMPILED_FILES:
            item.add_marker(pytest.mark.compiled)
