"""Fairing methods and the automatic loop :func:`fair`.

``fair.py`` holds the registry; each module in :data:`METHOD_MODULES` registers its methods
when imported. To add a method module, append its name to the list.
"""

from __future__ import annotations

import importlib

from ._guard import is_chord_interpolant, rebuilt_curve
from ._tolerance import point_report
from .fair import (
    METHODS,
    DriverOutput,
    FairingHistory,
    FairingResult,
    MethodSpec,
    available_methods,
    fair,
    method_options,
    register_method,
)
from .problem import FairingProblem, Outcome, make_problem
from .stop import STOP_REASONS, StopReason

__all__ = [
    "fair",
    "FairingResult",
    "FairingHistory",
    "DriverOutput",
    "Outcome",
    "FairingProblem",
    "make_problem",
    "MethodSpec",
    "METHODS",
    "register_method",
    "available_methods",
    "method_options",
    "StopReason",
    "STOP_REASONS",
    "point_report",
    "is_chord_interpolant",
    "rebuilt_curve",
]

METHOD_MODULES = [
    "local_hermite",
    "eck_hadenfeld",
    "knot_removal",
    "global_fair",
    "cheng_yu",
    "points_l1",
]

for _name in METHOD_MODULES:  # every listed module must import: a missing one is an error
    importlib.import_module(f"{__name__}.{_name}")
