"""Exact derivative energies of piecewise-polynomial curves."""

from __future__ import annotations

import numpy as np

from ..curves.piecewise import derivative_coefficients
from ..errors import InputError
from ._core import check_curve

__all__ = ["energy", "segment_energies"]


def _check_order(order: object, degree: int) -> int:
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)):
        raise InputError(f"order must be an integer in [1, {degree}], got {order!r}")
    o = int(order)
    if o < 1 or o > degree:
        raise InputError(f"order must be an integer in [1, {degree}] (the curve's degree), "
                         f"got {o}")
    return o


def segment_energies(curve: object, order: int = 2) -> np.ndarray:
    """Exact per-segment energies ``int_{t_i}^{t_{i+1}} |r^(order)(t)|^2 dt``, shape ``(m,)``.

    See :func:`energy`, which is their sum.
    """
    c = check_curve(curve)
    pp = c.piecewise
    o = _check_order(order, pp.degree)
    d = derivative_coefficients(np.asarray(pp.coeffs), o)  # (m, q, dim)
    q = d.shape[1]
    h = pp.widths
    # scaled coefficients: r^(o)(t_i + h u) = sum_j (d_j h^j) u^j, u in [0, 1]
    ds = d * (h[:, None] ** np.arange(q)[None, :])[:, :, None]
    acc = np.zeros(ds.shape[0])
    for j in range(q):
        for k in range(j, q):
            # int_0^1 u^(j+k) du = 1/(j+k+1); off-diagonal pairs twice
            g = np.sum(ds[:, j, :] * ds[:, k, :], axis=1)
            acc += g * ((1.0 if j == k else 2.0) / (j + k + 1.0))
    out = h * acc
    if not np.isfinite(out).all():
        i = int(np.flatnonzero(~np.isfinite(out))[0])
        raise InputError(f"the order-{o} energy of segment {i} (parameter width {float(h[i])!r}) "
                         f"overflows float64: the derivative ~ coordinates / width^{o} is too "
                         f"large to square; rescale the parameters (knots) or the coordinates")
    return out


def energy(curve: object, order: int = 2) -> float:
    """Exact energy ``int |r^(order)(t)|^2 dt`` over the whole parameter domain.

    Parameters
    ----------
    curve : PiecewiseCurve
        Any curvefair curve (open or closed, 2-D or 3-D).
    order : int
        Derivative order, ``1 <= order <= curve.degree``. ``order=2`` is the strain energy of
        the papers, ``order=3`` the jerk energy.

    Returns
    -------
    float

    Notes
    -----
    On segment ``i`` with width ``h_i`` the derivative is ``r^(order)(t_i + h_i u) =
    sum_j e_j u^j`` with ``e_j = d_j h_i^j`` (``d_j`` its local power coefficients), so

    ``int_{t_i}^{t_{i+1}} |r^(order)|^2 dt = h_i sum_{j,k} (e_j . e_k) / (j + k + 1)``,

    exact up to rounding (no quadrature). This is ``W / C`` of Wang & Cao 2006 (strain energy,
    the ``W`` above eq. (13)) for ``order=2`` and the quintic energy of Wang 2005 for
    ``order=3``. The papers' constant ``C`` is not included.

    Examples
    --------
    >>> import numpy as np
    >>> from curvefair import interpolate_cubic, energy
    >>> c = interpolate_cubic([[0, 0], [1, 1], [2, 0]], param="uniform")
    >>> round(energy(c), 6)       # r'' = (0, -3 t) on [0, 1], mirrored: 2 * int 9 t^2 = 6
    6.0
    """
    return float(np.sum(segment_energies(curve, order)))
