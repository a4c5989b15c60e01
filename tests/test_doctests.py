"""The examples in curvefair's docstrings run and print what they show.

Every ``>>>`` example of every module of the package is collected (``doctest.DocTestFinder``)
and run as one test each, with ``ELLIPSIS`` as under ``pytest --doctest-modules``. The expected
output in a docstring was written from the documented behaviour; a failure means the docstring
or the code is wrong.
"""

from __future__ import annotations

import doctest
import importlib
import pkgutil

import pytest

import curvefair

SKIP_MODULES = {"curvefair.__main__"}  # runs the CLI; has no examples


def _doctests() -> list[doctest.DocTest]:
    finder = doctest.DocTestFinder(exclude_empty=True)
    found = []
    names = ["curvefair"] + [m.name for m in pkgutil.walk_packages(curvefair.__path__,
                                                                  prefix="curvefair.")]
    for name in sorted(set(names) - SKIP_MODULES):
        # the finder looks only at objects defined in the module (not re-exports)
        found += [t for t in finder.find(importlib.import_module(name), name) if t.examples]
    return sorted(found, key=lambda t: t.name)


DOCTESTS = _doctests()


def test_doctests_were_found() -> None:
    # the package documents its public functions with examples; finding none means the
    # collection (not the docstrings) broke
    assert len(DOCTESTS) >= 30, [t.name for t in DOCTESTS]


@pytest.mark.parametrize("test", DOCTESTS, ids=[t.name for t in DOCTESTS])
def test_docstring_examples(test: doctest.DocTest) -> None:
    out: list[str] = []
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS, verbose=False)
    try:
        runner.run(test, out=out.append, clear_globs=True)
    finally:  # an example that draws on pyplot's current figure must not leave it to others
        import sys

        if "matplotlib.pyplot" in sys.modules:
            sys.modules["matplotlib.pyplot"].close("all")
    result = runner.summarize(verbose=False)
    assert result.failed == 0, "".join(out)
