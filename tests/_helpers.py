"""Small helpers shared by test modules (imported as ``_helpers``; pytest puts tests/ first)."""

from __future__ import annotations

import numpy as np


def record_points(recs) -> np.ndarray:
    """The whole point list of a file's records, put back in file order from each record's
    ``source["indices"]`` (corners split a list into several records); NaN where none wrote."""
    n = int(recs[0].source["n_points"])
    out = np.full((n, 2), np.nan)
    for r in recs:
        out[np.asarray(r.source["indices"])] = r.points
    return out
