"""Compiled kernel of the join planning (:mod:`curvefair.fairing.joins`): the straight knot
spans of a B-spline (:func:`straight_kernel`), whose control points :func:`curvefair.fair` holds
so that a line stays that line.
"""

from __future__ import annotations

import numpy as np

from .._jit import njit


@njit(cache=True)
def straight_kernel(P, spans, p, closed, rel, eps, mark):
    """Mark (``mark[i] = True``) the control points of every straight span; return how many
    spans are straight. Span ``s`` uses control points ``s - p .. s`` (mod ``n`` if closed);
    it is straight when its line ``d = W_p - W_0`` has ``L = |d| > eps`` and every
    ``r_a = W_a - W_0`` is within ``rel L + eps`` of that line: ``|r_a - (r_a . u) u| <=
    rel L + eps``, ``u = d / max(L, 1e-300)``. One pass, no temporaries; sums over the
    coordinates in order (no fastmath), so the decisions do not depend on the CPU's vector
    width."""
    n = P.shape[0]
    dim = P.shape[1]
    u = np.empty(dim)
    r = np.empty(dim)
    count = 0
    for m in range(spans.shape[0]):
        s = spans[m]
        i0 = s - p
        i1 = s
        if closed:
            i0 = i0 % n
            i1 = i1 % n
        L2 = 0.0
        for e in range(dim):
            de = P[i1, e] - P[i0, e]
            L2 += de * de
        L = np.sqrt(L2)
        den = max(L, 1e-300)
        for e in range(dim):
            u[e] = (P[i1, e] - P[i0, e]) / den
        lim = rel * L + eps
        ok = L > eps
        a = 0
        while ok and a <= p:
            i = s - p + a
            if closed:
                i = i % n
            dot = 0.0
            for e in range(dim):
                r[e] = P[i, e] - P[i0, e]
                dot += r[e] * u[e]
            o2 = 0.0
            for e in range(dim):
                o = r[e] - dot * u[e]
                o2 += o * o
            ok = np.sqrt(o2) <= lim
            a += 1
        if ok:
            count += 1
            for a in range(p + 1):
                i = s - p + a
                if closed:
                    i = i % n
                mark[i] = True
    return count
