"""The cheap paths of a fair() call give what the full computation gives.

- a Hermite tolerance re-run starts from a copy of the prepared state (``_retarget``): its
  kernel arguments equal those of a fresh ``prepare()`` at the new tolerance, array for array;
- ``FairingReport.to_dict()`` turns the per-point arrays into lists equal to them, and a
  non-finite float anywhere into None (``json.dumps(allow_nan=False)`` accepts it).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import curvefair as cf
from curvefair.fairing import local_hermite as lh
from curvefair.fairing.fair import FairingReport


def _noisy(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    s = np.cumsum(rng.uniform(0.5, 1.0, n))
    return np.c_[s, np.sin(s)] + 0.05 * rng.normal(size=(n, 2))


@pytest.mark.parametrize("method,builder", [("poliakoff", cf.interpolate_cubic),
                                            ("wang-cao", cf.interpolate_cubic),
                                            ("wang-quintic", cf.interpolate_quintic)])
@pytest.mark.parametrize("mode", ["spline", "hermite"])
def test_retarget_equals_fresh_prepare(method, builder, mode):
    c = builder(_noisy(25, 3))
    kw = dict(method=method, eps=0.0, max_steps=50, clamp=("g1", "g0"),
              protect=frozenset({4}), mode=mode)
    first = lh.prepare(c, tol=0.02, **kw)
    snap = lh._copy_state(first)
    lh._k.drive(*first["args"])  # modifies first's state in place, not snap's
    again = lh._retarget(snap, 0.0123)
    fresh = lh.prepare(c, tol=0.0123, **kw)
    assert len(again["args"]) == len(fresh["args"])
    for k, (a, b) in enumerate(zip(again["args"], fresh["args"], strict=True)):
        if isinstance(b, np.ndarray):
            assert a.dtype == b.dtype and np.array_equal(a, b), k
        else:
            assert a == b, k
    # the retargeted run is the fresh run
    ra = lh._k.drive(*again["args"])
    rb = lh._k.drive(*fresh["args"])
    assert ra[0] == rb[0] and ra[1] == rb[1]
    assert np.array_equal(again["P"], fresh["P"]) and np.array_equal(again["D"], fresh["D"])


def test_report_to_dict_lists_arrays_and_drops_non_finite():
    res = cf.fair(cf.interpolate_cubic(_noisy(30, 5)), "poliakoff", tol=0.01)
    rep = res.report
    assert isinstance(rep, FairingReport) and isinstance(rep, dict)
    d = rep.to_dict()
    assert type(d) is dict
    assert d["moved"]["indices"] == [int(i) for i in rep["moved"]["indices"]]
    assert d["moved"]["displacement"] == [float(v) for v in rep["moved"]["displacement"]]
    # a report entry a user adds (the CLI adds on-disk figures) goes through to_dict too
    rep2 = FairingReport(rep)
    rep2["extra_values"] = np.array([1.0, np.nan, np.inf, 2.0])
    rep2["extra_int"] = np.int64(3)
    d2 = rep2.to_dict()
    assert d2["extra_values"] == [1.0, None, None, 2.0] and d2["extra_int"] == 3
    json.dumps(d2, allow_nan=False)


@pytest.mark.parametrize("degree,closed,dim", [(3, False, 2), (3, True, 2), (2, False, 3),
                                               (5, True, 3), (4, False, 2)])
def test_primed_power_forms_equal_separate_ones(degree, closed, dim):
    # fair() builds the result's power form and the difference curve's in one pass over the
    # spans; each must be bitwise what the curve's own power form and the certificate's
    # separate pass (_difference_form on new - original) give
    from curvefair.fairing import _tolerance as T

    rng = np.random.default_rng(degree * 10 + closed)
    P = _noisy(40, 7)
    if dim == 3:
        P = np.c_[P, 0.1 * rng.normal(size=40)]
    c = cf.interpolate_bspline(P, degree=degree, closed=closed)
    moved = np.array(c.control_points) + 1e-3 * rng.normal(size=c.control_points.shape)
    new = c.replace(control_points=moved)
    primed = T.prime_power_forms(c, new)
    assert primed is not None and primed[0] is new
    fresh = c.replace(control_points=moved)  # no cached form
    assert np.array_equal(new.piecewise.coeffs, fresh.piecewise.coeffs)
    assert np.array_equal(new.piecewise.breaks, fresh.piecewise.breaks)
    delta = {"control_points": np.asarray(fresh.control_points) - np.asarray(c.control_points)}
    sep = T._difference_form(c, delta)
    assert np.array_equal(primed[1].coeffs, sep.coeffs)
    assert np.array_equal(primed[1].breaks, sep.breaks)
    # and the certificate from it is the one computed from scratch
    assert T.difference_deviation(c, new, primed[1]) == T.difference_deviation(c, fresh)
    # other knots or a Hermite curve: nothing primed
    other = cf.interpolate_bspline(P * 1.01, degree=degree, closed=closed)
    assert T.prime_power_forms(c, other) is None
    h = cf.interpolate_cubic(P)
    assert T.prime_power_forms(h, h) is None
