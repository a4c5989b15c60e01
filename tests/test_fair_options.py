"""fair(**options) is checked against the method driver's keyword parameters; method_options."""

import inspect

import numpy as np
import pytest

from curvefair import InputError, fair, interpolate_bspline, interpolate_cubic
from curvefair.fairing import METHODS
from curvefair.fairing.fair import DriverOutput, MethodSpec, method_options, register_method


def _bspline():
    x = np.linspace(0, 10, 12)
    y = np.sin(x / 2)
    y[5] += 0.4
    return interpolate_bspline(np.c_[x, y])


@pytest.mark.parametrize("method, listed", [
    ("eck-hadenfeld", "eps_relative, history_max, l, schedule"),
    ("knot-removal", "eps_relative, on_tol, variant"),
    ("global", "l"),
    ("cheng-yu", "pair, relative"),
])
def test_unknown_option_is_an_input_error_naming_it(method, listed):
    with pytest.raises(InputError) as exc:
        fair(_bspline(), method, bogus=1)
    assert str(exc.value) == (f"method {method!r} has no option 'bogus'; "
                              f"its options are: {listed}")


def test_several_unknown_options_are_all_named():
    with pytest.raises(InputError, match=r"no options 'a', 'zz'; its options are: l$"):
        fair(_bspline(), "global", zz=1, a=2, l=2)


def test_hermite_driver_takes_kwargs_and_checks_them_itself():
    # the Hermite driver declares **options: fair() passes them on and the driver refuses them
    c = interpolate_cubic(np.c_[np.arange(8.0), np.sin(np.arange(8.0))])
    with pytest.raises(InputError, match="bogus"):
        fair(c, "poliakoff", bogus=1)
    assert fair(c, "poliakoff", tol_on="points", tol=0.1).report["method"] == "poliakoff"


def test_known_options_still_work():
    b = _bspline()
    assert fair(b, "eck-hadenfeld", schedule="sweep").report["schedule"] == "sweep"
    assert fair(b, "eck-hadenfeld").report["schedule"] == "sweep"
    r = fair(b, "knot-removal", variant="least-squares", tol=0.1)
    assert r.report["method"] == "knot-removal"
    assert r.report["variant"] == "least-squares"


def test_method_options_contents():
    eh = method_options("eck-hadenfeld")
    assert eh == {"l": 2, "eps_relative": True, "history_max": 1_000_000,
                  "schedule": "sweep"}
    assert method_options("knot-removal")["variant"] == "one-point"
    assert method_options("global") == {"l": 2}
    assert method_options("poliakoff") == {"tol_on": "curve", "measure": None}  # method: partial
    for name in METHODS:
        opts = method_options(name)
        assert not {"tol", "eps", "max_steps", "clamp", "protect", "mode", "curve"} & set(opts)
    eh["schedule"] = "ranking"  # a copy: the registry is not changed
    assert method_options("eck-hadenfeld")["schedule"] == "sweep"
    with pytest.raises(InputError, match="unknown method 'nope'"):
        method_options("nope")


def test_method_options_exported():
    import importlib

    fair_mod = importlib.import_module("curvefair.fairing.fair")  # the attribute is fair()
    assert "method_options" in fair_mod.__all__


def test_registered_driver_without_options_and_with_kwargs():
    def no_opts(curve, *, tol, eps, max_steps, clamp, protect):
        return DriverOutput(curve=curve, steps=0, stop_reason="converged")

    def any_opts(curve, *, tol, eps, max_steps, clamp, protect, required, **kw):
        return DriverOutput(curve=curve, steps=0, stop_reason="converged",
                            extra={"got": sorted(kw), "required": required})

    saved = dict(METHODS)
    try:
        register_method(MethodSpec("t-none", (type(_bspline()),), no_opts, "s", "src"))
        register_method(MethodSpec("t-any", (type(_bspline()),), any_opts, "s", "src"))
        with pytest.raises(InputError, match="^method 't-none' has no option 'x'; "
                                             "it takes no options$"):
            fair(_bspline(), "t-none", x=1)
        assert method_options("t-none") == {}
        assert fair(_bspline(), "t-none").report["steps"] == 0
        assert method_options("t-any") == {"required": inspect.Parameter.empty}
        r = fair(_bspline(), "t-any", required=1, whatever=2)
        assert r.report["got"] == ["whatever"] and r.report["required"] == 1
    finally:
        METHODS.clear()
        METHODS.update(saved)
