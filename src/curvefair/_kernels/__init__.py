"""curvefair's compiled kernels (private): the numba-jitted loops of its curves and methods.

One module per family, each kernel written once; the Python drivers that prepare arrays, call
the kernels and read their results live in the public packages (:mod:`curvefair.fairing`,
:mod:`curvefair.curves`, :mod:`curvefair.steps`, :mod:`curvefair.analysis`,
:mod:`curvefair.io`):

* :mod:`.bspline` -- B-spline basis functions, power form and Gram band, and the energy and
  residual in difference form that the B-spline methods share;
* :mod:`.hermite` -- the local Hermite steps (Kjellander, Poliakoff, Wang-Cao, Wang quintic)
  and their automatic loop;
* :mod:`.eck_hadenfeld`, :mod:`.knot_removal`, :mod:`.cheng_yu` -- the steps and automatic
  loops of the B-spline methods of those names;
* :mod:`.global_fair` -- the block-banded Newton systems of the global fairing;
* :mod:`.joins` -- the straight-span test of the join planning;
* :mod:`.points` -- the interior point of the point-fairing tube QP;
* :mod:`.ranking` -- the indexed max tournament tree of the ranking-list drivers;
* :mod:`.sampling` -- the sampling pass of :func:`curvefair.analyze` (curvature and
  ``dkappa/ds`` on a grid, quadratures, sign certificates, sign changes);
* :mod:`.deviation` -- the parametric search of :func:`curvefair.deviation` and the per-span
  bound :func:`curvefair.analysis.matched_hermite_bound`;
* :mod:`.corners` -- the corner search of the point-list readers at the data's noise scale.

Every kernel is decorated with :func:`curvefair._jit.njit`, and no module outside this package
defines one (``tests/test_numba_layering.py`` checks it). A slow reference that a kernel is
tested against (plain numpy or Python) lives beside it, named ``*_reference``
(:func:`.deviation.matched_hermite_bound_reference`, :func:`.corners.chord_turns_reference`).
The package is private, but its public names (no leading underscore) may be imported by every
other curvefair package (``tests/test_layering.py`` treats it as a shared internal, like
``curvefair._typing``). The package itself imports nothing, so that importing one kernel module
loads only what that module needs.
"""
