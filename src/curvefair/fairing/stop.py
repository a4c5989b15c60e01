"""Why a fairing method stopped: the one vocabulary of ``stop_reason``.

Every method (through :class:`~curvefair.fairing.problem.Outcome` and the report of
:func:`~curvefair.fair`) and every method result type (``EHResult``, ``KRResult``,
``CYResult``, ``GlobalResult``, the points-l1 report) says why it stopped with one of
:data:`STOP_REASONS`:

``"converged"``
    The method's own criterion is met (no bad point left, the optimality conditions hold).
``"max_steps"``
    ``max_steps`` steps (iterations) were taken.
``"eps"``
    The worst measure fell below the threshold ``eps``.
``"tolerance"``
    Moves that would still be worth making are refused by the tolerance ``tol``.
``"no_movable_point"``
    Nothing may move: every point is fixed by ``clamp``/``protect`` or the curve is too
    short. (The Hermite methods said ``"nothing_to_move"`` before; one name now.)
``"no_improvement"``
    Cheng & Yu: bad points remain but none of their moves lowers the indicator.
``"no_decrease"``
    Knot removal: no removal lowers the jump sum.
``"numerical"``
    An iterative solver stopped on rounding before its convergence test (global, points-l1).
``"no_knots"``
    Knot removal: the curve has no interior knot.
``"unconstrained"``
    Global: the unconstrained minimiser is within the tolerance, taken in one step.
``"zero_energy"``
    The curve has zero fairing energy (a straight line): nothing to do.
"""

from __future__ import annotations

from typing import Literal, get_args

__all__ = ["StopReason", "STOP_REASONS"]

StopReason = Literal["converged", "max_steps", "eps", "tolerance", "no_movable_point",
                     "no_improvement", "no_decrease", "no_knots", "numerical", "unconstrained",
                     "zero_energy"]

#: Every value a :data:`StopReason` may take.
STOP_REASONS: tuple[str, ...] = get_args(StopReason)
