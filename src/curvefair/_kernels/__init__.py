"""curvefair's compiled kernels (private): the numba-jitted loops of its curves and methods.

One module per family, each kernel written once; the Python drivers that prepare arrays, call
the kernels and read their results live in the public packages (:mod:`curvefair.fairing`,
:mod:`curvefair.curves`, :mod:`curvefair.steps`, :mod:`curvefair.analysis`,
:mod:`curvefair.io`):

* :mod:`.bspline` -- B-spline basis functions, power form and Gram band, and the energy and
  residual in difference form that the B-spline methods share;
* :mod:`.hermite_power` -- the power form of cubic and quintic Hermite data;
* :mod:`.cubic_spline` -- the slopes of the C2 cubic spline through points (natural, clamped,
  periodic ends);
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
* :mod:`.corners` -- the corner search of the point-list readers at the data's noise scale;
* :mod:`.text` -- the bulk rows of numeric text files: read (values, decimals per column) and
  rewritten (the decimals of each changed number decided and written) from their bytes.

Every kernel is decorated with :func:`curvefair._jit.njit`, and no module outside this package
defines one (``tests/test_numba_layering.py`` checks it). A slow reference that a kernel is
tested against (plain numpy or Python, never compiled) lives beside it, named ``*_reference``;
the other kernels are checked by independent computations in their tests:

* :mod:`.bspline` -- :func:`.bspline.basis_reference` (Cox-de Boor recursion, for
  ``ders_kernel``'s values); the rest against scipy's ``BSpline``, finite differences and
  Gram matrices by dense quadrature;
* :mod:`.cheng_yu` -- no reference: a step against an independent minimisation of ``E_2``
  (quadrature, scipy.optimize), the loop by dense sampling and a replay with the public step;
* :mod:`.corners` -- :func:`.corners.chord_turns_reference`;
* :mod:`.deviation` -- :func:`.deviation.matched_hermite_bound_reference`; the search against
  brute-force dense sampling;
* :mod:`.eck_hadenfeld` -- :func:`.eck_hadenfeld.eh_loop_reference` (ranking list) and
  :func:`.eck_hadenfeld.eh_sweep_reference` with :func:`.eck_hadenfeld.eh_drop_reference`
  (sweep), all from the dense Gram matrix recomputed from scratch;
* :mod:`.global_fair` -- no reference: KKT conditions, a dense direct solve, scipy's SLSQP;
* :mod:`.cubic_spline` -- no reference: exact rational elimination of the same system and
  scipy's ``CubicSpline`` (``tests/test_cubic_slopes.py``);
* :mod:`.hermite_power` -- :func:`.hermite_power.cubic_power_reference` and
  :func:`.hermite_power.quintic_power_reference` (numpy), exact rational arithmetic and scipy;
* :mod:`.hermite` -- no reference: scipy's Hermite and interpolating splines, quadrature,
  finite differences, a replay of the loop's history with the public steps;
* :mod:`.joins` -- the numpy formula it replaced, kept in ``tests/test_joins_straight.py``
  (it reads the driver's ``curvefair.fairing.joins`` constant and the curve's index helpers);
* :mod:`.knot_removal` -- the old Python loop ``reference_knot_removal_fair``, kept in
  ``tests/test_knot_removal_compiled.py`` (it is built on the public package's step, checks and
  helpers, which this package may not import);
* :mod:`.points` -- no reference: scipy's ``CubicSpline``, scipy.optimize, KKT conditions;
* :mod:`.ranking` -- :func:`.ranking.tt_top_reference` (argmax over the values);
* :mod:`.sampling` -- no reference: scipy evaluation and quadrature, brute-force dense
  sampling, closed forms on curves of known shape;
* :mod:`.text` -- :func:`.text.plain_rows_reference` (``str.split``, ``re`` and ``float``)
  for the reader; the writer against the row renderer of :mod:`curvefair.io._text` (the
  Python rule it compiles).

The package is private, but its public names (no leading underscore) may be imported by every
other curvefair package (``tests/test_layering.py`` treats it as a shared internal, like
``curvefair._typing``). The package itself imports nothing, so that importing one kernel module
loads only what that module needs.
"""
