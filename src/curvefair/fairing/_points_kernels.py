"""Compiled kernels of :mod:`curvefair.fairing.points_l1`: the block-banded Newton matrix.

Unknowns interleaved: B-spline coefficient ``j`` (of the natural cubic, after the two end
conditions are eliminated), coordinate ``a`` is unknown ``j dim + a``. The Newton matrix is

    M = K + sum_i A_i^T B_i A_i,

``K`` the interleaved energy matrix, banded with ``dim x dim`` blocks of block half-bandwidth
4 (given by its lower band ``L0``), the
collocation ``A`` tridiagonal (``A[i, i - 1 + s] = Aw[i, s]``) and one symmetric
``dim x dim`` block ``B_i`` per data point. Lower band storage ``L[r, k] = M[r + k, r]`` with
``kd = 5 dim - 1``, as :func:`curvefair.fairing._global_kernels.band_cholesky` takes it.
"""

from __future__ import annotations

from .._jit import njit


@njit(cache=True)
def assemble_newton(L0, Aw, B, dim, L):  # type: ignore[no-untyped-def]
    """``L = L0 + band(sum_i A_i^T B_i A_i)``: ``L0`` the lower band of the (interleaved)
    energy matrix, ``L`` of the same shape ``(N dim, 5 dim)``."""
    N = Aw.shape[0]
    kd = L.shape[1] - 1
    L[:, :] = L0
    for i in range(N):
        for s2 in range(3):
            j2 = i - 1 + s2
            if j2 < 0 or j2 >= N:
                continue
            w2 = Aw[i, s2]
            if w2 == 0.0:
                continue
            for s1 in range(s2, 3):
                j1 = i - 1 + s1
                if j1 < 0 or j1 >= N:
                    continue
                w = Aw[i, s1] * w2
                if w == 0.0:
                    continue
                for b in range(dim):
                    r = j2 * dim + b
                    for a in range(dim):
                        rr = j1 * dim + a
                        k = rr - r
                        if k >= 0 and k <= kd:
                            L[r, k] += w * B[i, a, b]
    return 0
