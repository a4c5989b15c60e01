"""Compiled kernels of the local Hermite fairing steps and of their automatic loop.

Everything here works on the DISTINCT data of a Hermite spline (a closed curve drops its repeated
last point) in a uniform layout:

* ``P``  -- points, ``(nd, dim)``;
* ``D``  -- derivative data, ``(nd, nb, dim)`` with ``nb = 1`` (cubic: ``r'``) or ``nb = 2``
  (quintic: ``r'``, ``r''``);
* ``h``  -- segment widths, ``(nseg,)``; segment ``j`` joins point ``j`` and ``(j + 1) % nd``
  (``nseg = nd - 1`` open, ``nd`` closed).

Paper notation (Wang & Cao 2006; Wang 2005) for a step at point ``k`` (0-based here, 1-based in the
papers): ``D0 = Delta_{k-1} = t_k - t_{k-1}`` (left segment), ``D1 = Delta_k = t_{k+1} - t_k``
(right segment), ``a_{k-1,j}`` and ``a_{k,j}`` the power coefficients of those two segments.

The spline-mode re-interpolation is written with the Gram matrix of the spline's own energy
(``int |r''|^2`` for the C2 cubic, ``int |r'''|^2`` for the C4 quintic) in the Hermite unknowns:
its stationarity conditions are exactly the C2 (C4) continuity conditions, the system is symmetric
positive definite and block tridiagonal, and the change caused by moving one point decays
geometrically away from it, so it is solved on a window that grows until the change at its edges is
below machine precision relative to the change itself.
"""

from __future__ import annotations

import numpy as np

from .._jit import njit, prefetch
from ..curves.hermite import cubic_hermite_coefficients, quintic_hermite_coefficients
from .ranking import tt_build, tt_top, tt_update, tt_update_range

# method codes (internal only; the public API uses names)
KJELLANDER = 0
POLIAKOFF = 1
WANG_CAO = 2
WANG_QUINTIC = 3

# stop codes
STOP_EPS = 0
STOP_MAX_STEPS = 1
STOP_ALL_BLOCKED = 2


# ----------------------------------------------------------------------------------------------
# Gram matrices of Hermite segments (exact, by Gauss-Legendre quadrature of polynomials)
# ----------------------------------------------------------------------------------------------
def hermite_gram(degree: int, q: int) -> tuple[np.ndarray, np.ndarray]:
    """Gram matrix ``K0`` of ``int_0^1 |d^q r / du^q|^2 du`` in the local Hermite data.

    Local data order ``z = [r0, d0_1..d0_nb, r1, d1_1..d1_nb]`` (``nb = (degree - 1) // 2``).
    For a segment of width ``h`` the matrix is ``K0[a, b] * h**(1 - 2 q + p[a] + p[b])`` where
    ``p`` (returned) is the derivative order of each datum.
    """
    nb = (degree - 1) // 2
    nz = 2 * (nb + 1)
    p = np.array([j for _ in range(2) for j in range(nb + 1)], dtype=np.int64)
    t = np.array([0.0, 1.0])
    basis = np.zeros((nz, degree + 1))
    for a in range(nz):
        data = np.zeros((2, nb + 1, 1))
        data[a // (nb + 1), a % (nb + 1), 0] = 1.0
        if degree == 3:
            c = cubic_hermite_coefficients(data[:, 0], data[:, 1], t)
        else:
            c = quintic_hermite_coefficients(data[:, 0], data[:, 1], data[:, 2], t)
        basis[a] = c[0, :, 0]
    # q-th derivative, then exact quadrature (Gauss-Legendre with 8 nodes: degree <= 15)
    x, w = np.polynomial.legendre.leggauss(8)
    u = 0.5 * (x + 1.0)
    w = 0.5 * w
    vals = np.zeros((nz, u.size))
    for a in range(nz):
        dc = np.polynomial.polynomial.polyder(basis[a], q)
        vals[a] = np.polynomial.polynomial.polyval(u, dc)
    K0 = (vals * w) @ vals.T
    return K0, p


# ----------------------------------------------------------------------------------------------
# segment coefficients
# ----------------------------------------------------------------------------------------------
@njit(cache=True, inline="always")
def _prev(i, nd):
    """``(i - 1) % nd`` for ``0 <= i < nd`` without an integer division (a division is tens of
    cycles, and the loops below take several per point)."""
    return i - 1 if i > 0 else nd - 1


@njit(cache=True, inline="always")
def _next(i, nd):
    """``(i + 1) % nd`` for ``0 <= i < nd``."""
    return i + 1 if i < nd - 1 else 0


@njit(cache=True, inline="always")
def _cubic_a23(P, D, h, j, c):
    """``(a_{j,2}, a_{j,3})`` of cubic segment ``j``, coordinate ``c`` (Wang & Cao, eq. (6))."""
    return _cubic_seg(P, D, h, j, _next(j, P.shape[0]), c)


@njit(cache=True, inline="always")
def _cubic_seg(P, D, h, i0, i1, c):
    """:func:`_cubic_a23` of the segment from point ``i0`` to point ``i1``."""
    H = h[i0]
    dp = P[i1, c] - P[i0, c]
    a2 = 3.0 * dp / (H * H) - (2.0 * D[i0, 0, c] + D[i1, 0, c]) / H
    a3 = -2.0 * dp / (H * H * H) + (D[i0, 0, c] + D[i1, 0, c]) / (H * H)
    return a2, a3


@njit(cache=True, inline="always")
def _quintic_a2345(P, D, h, j, c):
    """``a_{j,2..5}`` of quintic segment ``j``, coordinate ``c`` (Wang 2005, eq. (2))."""
    return _quintic_seg(P, D, h, j, _next(j, P.shape[0]), c)


@njit(cache=True, inline="always")
def _quintic_seg(P, D, h, i0, i1, c):
    """:func:`_quintic_a2345` of the segment from point ``i0`` to point ``i1``."""
    H = h[i0]
    m0 = D[i0, 0, c]
    s0 = D[i0, 1, c]
    b1 = P[i1, c] - P[i0, c] - m0 * H - 0.5 * s0 * H * H
    b2 = D[i1, 0, c] - m0 - s0 * H
    b3 = D[i1, 1, c] - s0
    H2 = H * H
    a2 = 0.5 * s0
    a3 = (10.0 * b1 - 4.0 * b2 * H + 0.5 * b3 * H2) / (H2 * H)
    a4 = (-15.0 * b1 + 7.0 * b2 * H - b3 * H2) / (H2 * H2)
    a5 = (6.0 * b1 - 3.0 * b2 * H + 0.5 * b3 * H2) / (H2 * H2 * H)
    return a2, a3, a4, a5


@njit(cache=True, inline="always")
def _poliakoff_den(D0, D1):
    """Denominator of Poliakoff's step (eq. (8) as corrected in ERRATA)."""
    return 2.0 / D1**3 + 2.0 / D0**3


@njit(cache=True, inline="always")
def _poliakoff_delta(al3, ar3, den):
    """Poliakoff's step in one coordinate, ``-(a_{k,3} - a_{k-1,3}) / den``, ``den`` from
    :func:`_poliakoff_den`."""
    return -(ar3 - al3) / den


@njit(cache=True, inline="always")
def _wang_cao_de(al2, al3, ar2, ar3, D0, D1):
    """Wang-Cao's ``(delta*, eta*)`` in one coordinate (eqs. (11)-(12)) from the ``a_2, a_3``
    of the segments left and right of the point."""
    J = al3 - ar3
    G = ar2 - al2 - 3.0 * al3 * D0
    f = D1 * D0 / (D1 + D0) ** 3
    d = f * D1 * D0 * (2.0 * D1 * D0 * J + (D1 - D0) * G)
    e = f * (3.0 * D1 * D0 * (D1 - D0) * J + 2.0 * (D1 * D1 - D1 * D0 + D0 * D0) * G)
    return d, e


# ----------------------------------------------------------------------------------------------
# the local steps
# ----------------------------------------------------------------------------------------------
@njit(cache=True)
def cubic_step(P, D, h, k, method, hstep, delta, eta):
    """Unconstrained step of a cubic method at point ``k``; fills ``delta`` (and ``eta``).

    * Kjellander (Wang & Cao 2006, eq. (4), spacing ``hstep``):
      ``r_new = (r_{k-1} + r_{k+1}) / 2 + hstep (r'_{k-1} - r'_{k+1}) / 4``.
    * Poliakoff (eq. (8) as corrected in ERRATA):
      ``delta = -(a_{k,3} - a_{k-1,3}) / (2 / D1^3 + 2 / D0^3)``.
    * Wang-Cao (eqs. (11)-(12)): ``delta*``, ``eta*``.
    ``eta`` is zero for the position-only methods.
    """
    nd = P.shape[0]
    km = _prev(k, nd)
    kp = _next(k, nd)
    D0 = h[km]
    D1 = h[k]
    for c in range(P.shape[1]):
        eta[c] = 0.0
        if method == KJELLANDER:
            delta[c] = (0.5 * (P[km, c] + P[kp, c]) + 0.25 * hstep * (D[km, 0, c] - D[kp, 0, c])
                        - P[k, c])
            continue
        al2, al3 = _cubic_a23(P, D, h, km, c)
        ar2, ar3 = _cubic_a23(P, D, h, k, c)
        if method == POLIAKOFF:
            delta[c] = _poliakoff_delta(al3, ar3, _poliakoff_den(D0, D1))
        else:
            delta[c], eta[c] = _wang_cao_de(al2, al3, ar2, ar3, D0, D1)


@njit(cache=True)
def wang_cao_eta_given_delta(P, D, h, k, delta, eta):
    """Energy-optimal ``eta`` for a GIVEN position change ``delta`` (Wang & Cao, Lemma 1, eq. (14)).

    ``dF/deta = 0``: ``eta = (G - (3/D1^2 - 3/D0^2) delta) / (2 (1/D1 + 1/D0))`` with
    ``G = a_{k,2} - a_{k-1,2} - 3 a_{k-1,3} D0``. With ``delta = delta*`` this is ``eta*``.
    """
    nd = P.shape[0]
    km = _prev(k, nd)
    D0 = h[km]
    D1 = h[k]
    for c in range(P.shape[1]):
        al2, al3 = _cubic_a23(P, D, h, km, c)
        ar2, ar3 = _cubic_a23(P, D, h, k, c)
        G = ar2 - al2 - 3.0 * al3 * D0
        eta[c] = (G - (3.0 / D1**2 - 3.0 / D0**2) * delta[c]) / (2.0 * (1.0 / D1 + 1.0 / D0))


@njit(cache=True, inline="always")
def _quintic_C(P, D, h, k, c):
    """Wang 2005, Lemma: ``(C1, C2, C3)`` of coordinate ``c`` at point ``k``."""
    nd = P.shape[0]
    km = _prev(k, nd)
    l2, l3, l4, l5 = _quintic_a2345(P, D, h, km, c)
    r2, r3, r4, r5 = _quintic_a2345(P, D, h, k, c)
    return _quintic_C_of(l2, l3, l4, l5, r2, r3, r4, r5, h[km], h[k])


@njit(cache=True, inline="always")
def _quintic_C_of(l2, l3, l4, l5, r2, r3, r4, r5, D0, D1):
    """:func:`_quintic_C` from the coefficients of the segments left (``l``) and right (``r``)
    of the point and their widths ``D0``, ``D1``."""
    C1 = (12.0 * (r3 - l3) + 24.0 * (r4 * D1 - l4 * D0)
          + 240.0 / 7.0 * (r5 * D1**2 - l5 * D0**2))
    C2 = (-4.0 * (r2 - l2) + 12.0 * l3 * D0 + 24.0 / 5.0 * r4 * D1**2
          + 96.0 / 5.0 * l4 * D0**2 + 64.0 / 7.0 * r5 * D1**3 + 176.0 / 7.0 * l5 * D0**3)
    C3 = (2.0 / 5.0 * (r4 * D1**3 + l4 * D0**3) + 6.0 / 7.0 * r5 * D1**4
          + 8.0 / 7.0 * l5 * D0**4)
    return C1, C2, C3


@njit(cache=True, inline="always")
def _quintic_H(D0, D1):
    """Wang 2005, Theorem: Hessian entries ``(H00, H01, H02, H11, H22)``; ``H12 = 0``."""
    H00 = 240.0 / 7.0 * (1.0 / D1**3 + 1.0 / D0**3)
    H01 = 120.0 / 7.0 * (1.0 / D1**2 - 1.0 / D0**2)
    H02 = 6.0 / 7.0 * (1.0 / D1 + 1.0 / D0)
    H11 = 384.0 / 35.0 * (1.0 / D1 + 1.0 / D0)
    H22 = 6.0 / 35.0 * (D0 + D1)
    return H00, H01, H02, H11, H22


@njit(cache=True)
def quintic_system(P, D, h, k, C):
    """Wang 2005, Lemma: gradient ``C[c] = (C1, C2, C3)`` per coordinate and the Hessian entries
    ``(H00, H01, H02, H11, H22)`` (``H12 = 0``), with ``W* - W = C.x + x^T H x / 2``."""
    nd = P.shape[0]
    for c in range(P.shape[1]):
        C[c, 0], C[c, 1], C[c, 2] = _quintic_C(P, D, h, k, c)
    return _quintic_H(h[_prev(k, nd)], h[k])


@njit(cache=True)
def quintic_step(P, D, h, k, delta, eta, xi, clamped_delta):
    """Wang 2005 step: solve ``H [delta, eta, xi] = -[C1, C2, C3]`` per coordinate.

    Because ``H12 = 0`` the system is solved by eliminating ``eta`` and ``xi``:
    ``delta = -(C1 - H01 C2 / H11 - H02 C3 / H22) / S``, ``S = H00 - H01^2/H11 - H02^2/H22``,
    ``eta = -(C2 + H01 delta) / H11``, ``xi = -(C3 + H02 delta) / H22``.
    If ``clamped_delta`` is True, ``delta`` is taken as given and only ``eta``, ``xi`` are
    computed (the optimal derivatives for that position). Returns the energy drops
    ``(drop_total, drop_position)`` of the unconstrained step (``int |r''|^2`` units).
    """
    nd = P.shape[0]
    H00, H01, H02, H11, H22 = _quintic_H(h[_prev(k, nd)], h[k])
    S = H00 - H01 * H01 / H11 - H02 * H02 / H22
    drop_pos = 0.0
    drop_der = 0.0
    for c in range(P.shape[1]):
        C1, C2, C3 = _quintic_C(P, D, h, k, c)
        c1 = C1 - H01 * C2 / H11 - H02 * C3 / H22
        d_opt = -c1 / S
        drop_pos += 0.5 * S * d_opt * d_opt
        drop_der += 0.5 * (C2 * C2 / H11 + C3 * C3 / H22)
        if not clamped_delta:
            delta[c] = d_opt
        eta[c] = -(C2 + H01 * delta[c]) / H11
        xi[c] = -(C3 + H02 * delta[c]) / H22
    return drop_pos + drop_der, drop_pos


@njit(cache=True)
def quintic_measure(P, D, h, k, spline):
    """Energy drop of the Wang step at ``k`` (whole step, or only its position part)."""
    nd = P.shape[0]
    H00, H01, H02, H11, H22 = _quintic_H(h[_prev(k, nd)], h[k])
    S = H00 - H01 * H01 / H11 - H02 * H02 / H22
    out = 0.0
    for c in range(P.shape[1]):
        C1, C2, C3 = _quintic_C(P, D, h, k, c)
        out = _quintic_drop_add(out, C1, C2, C3, H01, H02, H11, H22, S, spline)
    return out


@njit(cache=True, inline="always")
def _quintic_drop_add(out, C1, C2, C3, H01, H02, H11, H22, S, spline):
    """``out`` plus one coordinate's part of :func:`quintic_measure`."""
    c1 = C1 - H01 * C2 / H11 - H02 * C3 / H22
    out += 0.5 * c1 * c1 / S
    if not spline:
        out += 0.5 * (C2 * C2 / H11 + C3 * C3 / H22)
    return out


@njit(cache=True)
def cubic_jump(P, D, h, k):
    """``|r'''(t_k+) - r'''(t_k-)| = 6 |a_{k,3} - a_{k-1,3}|`` (Wang & Cao 2006, eq. (7))."""
    nd = P.shape[0]
    km = _prev(k, nd)
    s = 0.0
    for c in range(P.shape[1]):
        al2, al3 = _cubic_a23(P, D, h, km, c)
        ar2, ar3 = _cubic_a23(P, D, h, k, c)
        s += (ar3 - al3) ** 2
    return 6.0 * np.sqrt(s)


# bad-point measures (``fair(..., measure=...)``); 0 is each method's published measure
M_DEFAULT = 0  # cubic: third-derivative jump (seed 001); quintic: energy drop of the Wang step
M_ENERGY = 1   # exact drop of int |r''|^2 that the method's (unclamped) step achieves
M_SAPIDIS = 2  # jump of dkappa/ds (Sapidis & Farin 1990), cubic only
M_MOVE = 3     # length of the (unclamped) move the method's step wants


@njit(cache=True, inline="always")
def _cubic_step_coord(P, D, h, k, method, hstep, c):
    """``(delta_c, eta_c, delta_poliakoff_c)`` of :func:`cubic_step`, one coordinate, no
    allocation (the same formulas)."""
    nd = P.shape[0]
    km = _prev(k, nd)
    kp = _next(k, nd)
    D0 = h[km]
    D1 = h[k]
    al2, al3 = _cubic_a23(P, D, h, km, c)
    ar2, ar3 = _cubic_a23(P, D, h, k, c)
    dpol = _poliakoff_delta(al3, ar3, _poliakoff_den(D0, D1))
    if method == KJELLANDER:
        d = (0.5 * (P[km, c] + P[kp, c]) + 0.25 * hstep * (D[km, 0, c] - D[kp, 0, c])
             - P[k, c])
        return d, 0.0, dpol
    if method == POLIAKOFF:
        return dpol, 0.0, dpol
    d, e = _wang_cao_de(al2, al3, ar2, ar3, D0, D1)
    return d, e, dpol


@njit(cache=True)
def cubic_energy_drop(P, D, h, k, method, hstep):
    """Exact drop of ``int |r''|^2 dt`` over the two segments at ``k`` when the method's
    unclamped step (derivatives as the step leaves them) is applied.

    In the Hermite data of point ``k`` the energy is quadratic with the Hessian
    ``Hpp = 24 (1/D0^3 + 1/D1^3)``, ``Hpd = 12 (1/D1^2 - 1/D0^2)``, ``Hdd = 8 (1/D0 + 1/D1)``
    (twice the cubic Hermite stiffness matrices of the two segments). Poliakoff's step is the
    minimiser over ``r_k`` and Wang-Cao's over ``(r_k, r'_k)``, so their drop is
    ``x^T H x / 2``; Kjellander's is not, and its drop is ``-(g . delta + Hpp |delta|^2 / 2)``
    with the gradient ``g = -Hpp delta_Poliakoff`` (it can be negative).
    """
    nd = P.shape[0]
    D0 = h[_prev(k, nd)]
    D1 = h[k]
    Hpp = 24.0 * (1.0 / D0**3 + 1.0 / D1**3)
    Hpd = 12.0 * (1.0 / D1**2 - 1.0 / D0**2)
    Hdd = 8.0 * (1.0 / D0 + 1.0 / D1)
    out = 0.0
    for c in range(P.shape[1]):
        d, e, dpol = _cubic_step_coord(P, D, h, k, method, hstep, c)
        if method == KJELLANDER:
            out += Hpp * (dpol * d - 0.5 * d * d)
        else:
            out += 0.5 * (Hpp * d * d + 2.0 * Hpd * d * e + Hdd * e * e)
    return out


@njit(cache=True)
def cubic_move(P, D, h, k, method, hstep):
    """Length of the position change the method's unclamped step wants at ``k``."""
    s = 0.0
    for c in range(P.shape[1]):
        d, e, dpol = _cubic_step_coord(P, D, h, k, method, hstep, c)
        s += d * d
    return np.sqrt(s)


@njit(cache=True, inline="always")
def _dkds(r1, r2, r3, dim):
    """``dkappa/ds`` from the first three derivatives (plane: signed curvature; space: the
    derivative of ``|r1 x r2| / |r1|^3``, and ``|r1 x r3| / |r1|^4`` where ``r1 x r2 = 0``)."""
    v2 = 0.0
    dot12 = 0.0
    for c in range(dim):
        v2 += r1[c] * r1[c]
        dot12 += r1[c] * r2[c]
    if v2 == 0.0 or dim == 1:
        return 0.0
    v = np.sqrt(v2)
    if dim == 2:
        c12 = r1[0] * r2[1] - r1[1] * r2[0]
        c13 = r1[0] * r3[1] - r1[1] * r3[0]
        return (c13 / (v2 * v) - 3.0 * c12 * dot12 / (v2 * v2 * v)) / v
    ax = r1[1] * r2[2] - r1[2] * r2[1]
    ay = r1[2] * r2[0] - r1[0] * r2[2]
    az = r1[0] * r2[1] - r1[1] * r2[0]
    bx = r1[1] * r3[2] - r1[2] * r3[1]
    by = r1[2] * r3[0] - r1[0] * r3[2]
    bz = r1[0] * r3[1] - r1[1] * r3[0]
    na = np.sqrt(ax * ax + ay * ay + az * az)
    if na <= 1e-300:
        return np.sqrt(bx * bx + by * by + bz * bz) / (v2 * v2)
    kt = (ax * bx + ay * by + az * bz) / (na * v2 * v) - 3.0 * na * dot12 / (v2 * v2 * v)
    return kt / v


@njit(cache=True)
def cubic_sapidis(P, D, h, k):
    """``|kappa_s(t_k+) - kappa_s(t_k-)|``, the jump of ``dkappa/ds`` at point ``k``
    (Sapidis & Farin 1990; seed 004), each side from its own segment (first three
    coordinates of a curve in more than three dimensions)."""
    nd = P.shape[0]
    dim = P.shape[1]
    km = _prev(k, nd)
    D0 = h[km]
    m = 3 if dim > 3 else dim
    l1 = np.zeros(3)
    l2 = np.zeros(3)
    l3 = np.zeros(3)
    q1 = np.zeros(3)
    q2 = np.zeros(3)
    q3 = np.zeros(3)
    for c in range(m):
        al2, al3 = _cubic_a23(P, D, h, km, c)
        ar2, ar3 = _cubic_a23(P, D, h, k, c)
        l1[c] = D[k, 0, c]
        l2[c] = 2.0 * al2 + 6.0 * al3 * D0
        l3[c] = 6.0 * al3
        q1[c] = D[k, 0, c]
        q2[c] = 2.0 * ar2
        q3[c] = 6.0 * ar3
    return abs(_dkds(q1, q2, q3, m) - _dkds(l1, l2, l3, m))


@njit(cache=True)
def quintic_move(P, D, h, k):
    """Length of the position change of the unclamped Wang step at ``k``."""
    nd = P.shape[0]
    H00, H01, H02, H11, H22 = _quintic_H(h[_prev(k, nd)], h[k])
    S = H00 - H01 * H01 / H11 - H02 * H02 / H22
    s = 0.0
    for c in range(P.shape[1]):
        C1, C2, C3 = _quintic_C(P, D, h, k, c)
        d = _quintic_delta(C1, C2, C3, H01, H02, H11, H22, S)
        s += d * d
    return np.sqrt(s)


@njit(cache=True, inline="always")
def _quintic_delta(C1, C2, C3, H01, H02, H11, H22, S):
    """The position change of the Wang step in one coordinate (:func:`quintic_move`)."""
    return -(C1 - H01 * C2 / H11 - H02 * C3 / H22) / S


@njit(cache=True)
def measure_at(P, D, h, k, degree, spline, method=POLIAKOFF, hstep=0.0, mcode=M_DEFAULT):
    """Ranking measure of point ``k``. ``mcode`` ``M_DEFAULT`` (the papers'): cubic ->
    third-derivative jump; quintic -> energy drop of the Wang step (hermite mode: whole step;
    spline mode: the part due to the position). ``M_ENERGY``: the energy drop of the method's
    step (the quintic's is ``M_DEFAULT``); ``M_SAPIDIS``: jump of dkappa/ds (cubic);
    ``M_MOVE``: length of the move the step wants."""
    if mcode == M_MOVE:
        if degree == 3:
            return cubic_move(P, D, h, k, method, hstep)
        return quintic_move(P, D, h, k)
    if degree == 3:
        if mcode == M_ENERGY:
            return cubic_energy_drop(P, D, h, k, method, hstep)
        if mcode == M_SAPIDIS:
            return cubic_sapidis(P, D, h, k)
        return cubic_jump(P, D, h, k)
    return quintic_measure(P, D, h, k, spline)


# the measures that :func:`range_measures` computes from each segment's coefficients once
MF_GENERIC = 0  # measure_at per point
MF_JUMP = 1  # cubic, M_DEFAULT
MF_POLIAKOFF_MOVE = 2  # cubic, M_MOVE, Poliakoff
MF_WANG_CAO_MOVE = 3  # cubic, M_MOVE, Wang-Cao
MF_QUINTIC = 4  # quintic, M_DEFAULT (the energy drop)
MF_QUINTIC_MOVE = 5  # quintic, M_MOVE


@njit(cache=True)
def fast_measure_code(degree, method, mcode):
    """Which :data:`MF_GENERIC` .. :data:`MF_QUINTIC_MOVE` path :func:`range_measures`
    takes for these options."""
    if degree == 5:
        return MF_QUINTIC_MOVE if mcode == M_MOVE else MF_QUINTIC
    if degree != 3:
        return MF_GENERIC
    if mcode == M_DEFAULT:
        return MF_JUMP
    if mcode == M_MOVE and method == POLIAKOFF:
        return MF_POLIAKOFF_MOVE
    if mcode == M_MOVE and method == WANG_CAO:
        return MF_WANG_CAO_MOVE
    return MF_GENERIC


@njit(cache=True, inline="always")
def _wrap(v, nd):
    """``v % nd`` for ``-nd <= v < 2 nd``."""
    if v < 0:
        return v + nd
    if v >= nd:
        return v - nd
    return v


@njit(cache=True)
def range_measures(P, D, h, closed, degree, spline, method, hstep, mcode, mfast, a, b, seg,
                   out):
    """``out[v - a]`` = :func:`measure_at` of point ``v`` (``v % nd`` on a closed curve) for
    ``v`` in ``a .. b``, bit for bit (``-nd <= a``, ``b < 2 nd``; ``1 <= a``, ``b <= nd - 2``
    when open).

    The measures that read only the coefficients of the two segments at a point (``mfast``,
    :func:`fast_measure_code`: the cubic jump, Poliakoff's and Wang-Cao's move, both quintic
    measures) compute each segment's once into ``seg`` (``(b - a + 2, 4, dim)``, ``a_2 ..
    a_5``): a point's measure reads the segment on each side, so this halves the segment
    work of :func:`measure_at` per point, and the cubic moves no longer repeat it per
    coordinate. The same formulas (shared inlined functions) in the same order as
    :func:`cubic_jump`, :func:`cubic_move`, :func:`quintic_measure` and :func:`quintic_move`.
    """
    nd = P.shape[0]
    dim = P.shape[1]
    if b < a:
        return
    if mfast == MF_GENERIC:
        for v in range(a, b + 1):
            out[v - a] = measure_at(P, D, h, _wrap(v, nd) if closed else v, degree, spline,
                                    method, hstep, mcode)
        return
    for v in range(a - 1, b + 1):
        j = _wrap(v, nd) if closed else v
        j1 = _next(j, nd)
        for c in range(dim):
            if degree == 5:
                a2, a3, a4, a5 = _quintic_seg(P, D, h, j, j1, c)
                seg[v - a + 1, 2, c] = a4
                seg[v - a + 1, 3, c] = a5
            else:
                a2, a3 = _cubic_seg(P, D, h, j, j1, c)
            seg[v - a + 1, 0, c] = a2
            seg[v - a + 1, 1, c] = a3
    if degree == 5:
        _quintic_range(h, nd, dim, closed, spline, mfast == MF_QUINTIC_MOVE, a, b, seg, out)
        return
    for v in range(a, b + 1):
        i = _wrap(v, nd) if closed else v
        r = v - a + 1
        s = 0.0
        if mfast == MF_JUMP:
            for c in range(dim):
                s += (seg[r, 1, c] - seg[r - 1, 1, c]) ** 2
            out[v - a] = 6.0 * np.sqrt(s)
            continue
        D0 = h[_prev(i, nd)]
        D1 = h[i]
        if mfast == MF_POLIAKOFF_MOVE:
            den = _poliakoff_den(D0, D1)
            for c in range(dim):
                d = _poliakoff_delta(seg[r - 1, 1, c], seg[r, 1, c], den)
                s += d * d
        else:
            for c in range(dim):
                d, e = _wang_cao_de(seg[r - 1, 0, c], seg[r - 1, 1, c], seg[r, 0, c],
                                    seg[r, 1, c], D0, D1)
                s += d * d
        out[v - a] = np.sqrt(s)


@njit(cache=True, inline="always")
def _quintic_range(h, nd, dim, closed, spline, move, a, b, seg, out):
    """The quintic part of :func:`range_measures`: :func:`quintic_measure` (or, ``move``,
    :func:`quintic_move`) of the points ``a .. b`` from their segments' coefficients."""
    for v in range(a, b + 1):
        i = _wrap(v, nd) if closed else v
        r = v - a + 1
        D0 = h[_prev(i, nd)]
        D1 = h[i]
        H00, H01, H02, H11, H22 = _quintic_H(D0, D1)
        S = H00 - H01 * H01 / H11 - H02 * H02 / H22
        s = 0.0
        for c in range(dim):
            C1, C2, C3 = _quintic_C_of(seg[r - 1, 0, c], seg[r - 1, 1, c], seg[r - 1, 2, c],
                                       seg[r - 1, 3, c], seg[r, 0, c], seg[r, 1, c],
                                       seg[r, 2, c], seg[r, 3, c], D0, D1)
            if move:
                d = _quintic_delta(C1, C2, C3, H01, H02, H11, H22, S)
                s += d * d
            else:
                s = _quintic_drop_add(s, C1, C2, C3, H01, H02, H11, H22, S, spline)
        out[v - a] = np.sqrt(s) if move else s


# ----------------------------------------------------------------------------------------------
# window solve of the spline system (block tridiagonal, SPD, block size nb = 1 or 2)
# ----------------------------------------------------------------------------------------------
@njit(cache=True, inline="always")
def _powers(hj, q, pw):
    """``pw[e] = hj ** (1 - 2 q + e)`` for ``e = 0 .. 2 q - 2`` (exponents up to -1)."""
    ih = 1.0 / hj
    x = ih
    for e in range(2 * q - 2, -1, -1):
        pw[e] = x
        x *= ih


@njit(cache=True, inline="always")
def _kseg(K0, pe, pw, a, b):
    """Entry (a, b) of the Gram matrix of a segment whose powers ``pw`` are set."""
    return K0[a, b] * pw[pe[a] + pe[b]]


@njit(cache=True, inline="always")
def _inv_small(M, nb, out):
    if nb == 1:
        out[0, 0] = 1.0 / M[0, 0]
    else:
        det = M[0, 0] * M[1, 1] - M[0, 1] * M[1, 0]
        out[0, 0] = M[1, 1] / det
        out[1, 1] = M[0, 0] / det
        out[0, 1] = -M[0, 1] / det
        out[1, 0] = -M[1, 0] / det


@njit(cache=True, inline="always")
def _assemble_window(nd, closed, h, K0, pe, q, nb, fixed, idx, L, Bd, Cu, pw):
    """Diagonal blocks ``Bd[v]`` and super-diagonal blocks ``Cu[v]`` (v -> v+1) of the window
    whose actual point indices are ``idx[0..L-1]``; fixed unknowns become identity rows/cols."""
    r1 = nb + 1  # offset of the end point's data in the local vector
    for v in range(L):
        i = idx[v]
        for a in range(nb):
            for b in range(nb):
                Bd[v, a, b] = 0.0
                Cu[v, a, b] = 0.0
        if closed or i >= 1:  # segment i-1 ends at i
            _powers(h[_prev(i, nd)], q, pw)
            for a in range(nb):
                for b in range(nb):
                    Bd[v, a, b] += _kseg(K0, pe, pw, r1 + 1 + a, r1 + 1 + b)
        if closed or i <= nd - 2:  # segment i starts at i
            _powers(h[i], q, pw)
            for a in range(nb):
                for b in range(nb):
                    Bd[v, a, b] += _kseg(K0, pe, pw, 1 + a, 1 + b)
                    if v < L - 1:
                        Cu[v, a, b] = _kseg(K0, pe, pw, 1 + a, r1 + 1 + b)
    for v in range(L):
        i = idx[v]
        for a in range(nb):
            if fixed[i, a]:
                for b in range(nb):
                    Bd[v, a, b] = 0.0
                    Bd[v, b, a] = 0.0
                    Cu[v, a, b] = 0.0
                    if v > 0:
                        Cu[v - 1, b, a] = 0.0
                Bd[v, a, a] = 1.0


@njit(cache=True, inline="always")
def _block_thomas(L, nb, dim, Bd, Cu, R, X, Bp, Y, inv, W):
    """Solve the symmetric block tridiagonal system (sub-diagonal = Cu^T) for X (L, nb, dim);
    ``inv`` and ``W`` are 2x2 scratch arrays."""
    for v in range(L):
        for a in range(nb):
            for b in range(nb):
                Bp[v, a, b] = Bd[v, a, b]
            for c in range(dim):
                Y[v, a, c] = R[v, a, c]
        if v > 0:
            # W = A_v Bp_{v-1}^{-1}, A_v = Cu_{v-1}^T
            _inv_small(Bp[v - 1], nb, inv)
            for a in range(nb):
                for b in range(nb):
                    s = 0.0
                    for e in range(nb):
                        s += Cu[v - 1, e, a] * inv[e, b]
                    W[a, b] = s
            for a in range(nb):
                for b in range(nb):
                    s = 0.0
                    for e in range(nb):
                        s += W[a, e] * Cu[v - 1, e, b]
                    Bp[v, a, b] -= s
                for c in range(dim):
                    s = 0.0
                    for e in range(nb):
                        s += W[a, e] * Y[v - 1, e, c]
                    Y[v, a, c] -= s
    for v in range(L - 1, -1, -1):
        _inv_small(Bp[v], nb, inv)
        for c in range(dim):
            for a in range(nb):
                t = Y[v, a, c]
                if v < L - 1:
                    for e in range(nb):
                        t -= Cu[v, a, e] * X[v + 1, e, c]
                W[a, 0] = t
            for a in range(nb):
                s = 0.0
                for e in range(nb):
                    s += inv[a, e] * W[e, 0]
                X[v, a, c] = s


@njit(cache=True, inline="always")
def _rhs_for_move(nd, closed, h, K0, pe, q, nb, k, dr, idx, L, fixed, R, pw):
    """Right-hand side (minus the gradient change) caused by moving point ``k`` by ``dr``.

    Only the points ``k - 1, k, k + 1`` share a segment with ``k``; for point ``i`` the entry is
    ``-K[d_i, r_k] dr`` summed over the segments holding both.
    """
    dim = dr.shape[0]
    r1 = nb + 1
    for v in range(L):
        i = idx[v]
        for a in range(nb):
            coef = 0.0
            if not fixed[i, a]:
                if closed or i >= 1:  # segment j = i-1: i is its end point
                    j = _prev(i, nd)
                    if i == k or j == k:
                        _powers(h[j], q, pw)
                        if i == k:
                            coef += _kseg(K0, pe, pw, r1 + 1 + a, r1)
                        if j == k:
                            coef += _kseg(K0, pe, pw, r1 + 1 + a, 0)
                if closed or i <= nd - 2:  # segment i: i is its start point
                    if i == k or _next(i, nd) == k:
                        _powers(h[i], q, pw)
                        if i == k:
                            coef += _kseg(K0, pe, pw, 1 + a, 0)
                        if _next(i, nd) == k:
                            coef += _kseg(K0, pe, pw, 1 + a, r1)
            for c in range(dim):
                R[v, a, c] = -coef * dr[c]


@njit(cache=True, inline="always")
def _window_solve(nd, closed, h, K0, pe, q, nb, dim, fixed, idx, L, k, dr, Bd, Cu, R, X, Bp, Y,
                  pw, inv, W):
    """The change ``X`` of the window's derivative data when point ``k`` moves by ``dr``:
    assemble, right-hand side, block Thomas. Inlined (into the loop, and into the
    ``_window_solve_*`` kernels below), so that a caller passing constant ``nb`` and ``dim``
    gets their loops unrolled."""
    _assemble_window(nd, closed, h, K0, pe, q, nb, fixed, idx, L, Bd, Cu, pw)
    _rhs_for_move(nd, closed, h, K0, pe, q, nb, k, dr, idx, L, fixed, R, pw)
    _block_thomas(L, nb, dim, Bd, Cu, R, X, Bp, Y, inv, W)


# The loop calls the window solve of cubic curves through these kernels (the coordinate count
# constant in the first two) rather than inlining it: the same operations, but each inlined copy
# made the loop's compile 6-7 s longer (a cold Hermite call compiled 66 s, 33 s of it the loop
# with four copies inside; now 12 s with one, and 4 s for each kernel here). The quintic one
# (``nb == 2``, planar) stays inlined: through a kernel of its own, wang-quintic's whole call at
# 1e6 points was 2-4 % slower (fresh processes alternated), the cubic methods' within 1.5 %.
@njit(cache=True)
def _window_solve_1_2(nd, closed, h, K0, pe, q, fixed, idx, L, k, dr, Bd, Cu, R, X, Bp, Y, pw,
                      inv, W):
    _window_solve(nd, closed, h, K0, pe, q, 1, 2, fixed, idx, L, k, dr, Bd, Cu, R, X, Bp, Y,
                  pw, inv, W)


@njit(cache=True)
def _window_solve_1_3(nd, closed, h, K0, pe, q, fixed, idx, L, k, dr, Bd, Cu, R, X, Bp, Y, pw,
                      inv, W):
    _window_solve(nd, closed, h, K0, pe, q, 1, 3, fixed, idx, L, k, dr, Bd, Cu, R, X, Bp, Y,
                  pw, inv, W)


@njit(cache=True)
def _window_solve_any(nd, closed, h, K0, pe, q, nb, dim, fixed, idx, L, k, dr, Bd, Cu, R, X, Bp,
                      Y, pw, inv, W):
    _window_solve(nd, closed, h, K0, pe, q, nb, dim, fixed, idx, L, k, dr, Bd, Cu, R, X, Bp, Y,
                  pw, inv, W)


# ----------------------------------------------------------------------------------------------
# the automatic loop
# ----------------------------------------------------------------------------------------------
@njit(cache=True)
def _clamped_move(P, D, h, orig, k, method, degree, spline, hstep, tol, delta, eta, xi):
    """Step at ``k`` clamped onto the ball of radius ``tol`` around ``orig[k]``.

    Fills ``delta`` with the (clamped) position change and ``eta``/``xi`` with the derivative
    changes that are optimal for that position (hermite mode). Returns
    ``(norm of move, clamped?, norm of the unclamped move)``.
    """
    dim = P.shape[1]
    if degree == 3:
        cubic_step(P, D, h, k, method, hstep, delta, eta)
    else:
        quintic_step(P, D, h, k, delta, eta, xi, False)
    # work with the rounded new position (held in delta for now) so that the move applied is
    # exactly delta and the tolerance holds for the stored numbers, not only in exact arithmetic
    want = 0.0
    for c in range(dim):
        want += delta[c] ** 2
        delta[c] = P[k, c] + delta[c]
    want = np.sqrt(want)
    clamped = False
    if tol < np.inf:
        tol_eff = tol * (1.0 - 1e-12)
        for _ in range(8):
            off = 0.0
            for c in range(dim):
                off += (delta[c] - orig[k, c]) ** 2
            off = np.sqrt(off)
            if off <= tol_eff:
                break
            f = tol_eff / off * (1.0 - 1e-15)
            for c in range(dim):
                delta[c] = orig[k, c] + (delta[c] - orig[k, c]) * f
            clamped = True
    for c in range(dim):
        delta[c] = delta[c] - P[k, c]
    if clamped and not spline:
        if degree == 5:
            quintic_step(P, D, h, k, delta, eta, xi, True)
        elif method == WANG_CAO:
            wang_cao_eta_given_delta(P, D, h, k, delta, eta)
    mv = 0.0
    for c in range(dim):
        mv += delta[c] ** 2
    return np.sqrt(mv), clamped, want


# a clamped move smaller than this fraction of the move the step wants counts as blocked: the
# point sits on its tolerance sphere and could only creep along it
BLOCK_FRACTION = 1e-3


# relative change of a blocked point's measure that makes the loop try its step again
RECHECK = 1e-9


@njit(cache=True, inline="always")
def _is_blocked(mv, clamped, want, move_floor):
    return mv <= move_floor or (clamped and mv <= BLOCK_FRACTION * want)


@njit(cache=True)
def drive_setup(P, D, h, closed, degree, spline, eligible, method=POLIAKOFF, hstep=0.0,
                mcode=M_DEFAULT):
    """Initial state of the loop (``O(n)``): ``(measure, values, tv, ti, blocked,
    block_measure)`` -- measures, tree leaves, the tree, block flags and measures at blocking."""
    nd = P.shape[0]
    measure = all_measures(P, D, h, closed, degree, spline, method, hstep, mcode)
    values = np.full(nd, -np.inf)
    for i in range(nd):
        if eligible[i]:
            values[i] = measure[i]
    tv, ti = tt_build(values)
    return measure, values, tv, ti, np.zeros(nd, dtype=np.int8), np.zeros(nd)


_SPECULATE_BYTES = 1 << 22  # prefetch the runner-up's data when the state exceeds ~4 MB
_RUNNER_UP_TOP = 256  # the runner-up is sought among the siblings of the nodes below 256
_FAR = 16  # a step farther than this from the previous one is a far jump


@njit(cache=True, inline="always")
def _runner_up(tv, ti, k):
    """The entry that leads the tournament tree (:mod:`.ranking`) outside the winner ``k``'s
    subtree at the first level below node 256: the best of the siblings of the winner's path
    above that level, all in the tree's top (hot) levels. Unless the next step's winner
    shares that subtree with ``k`` or is changed by this step, it is the next step's point.
    -1 for a tree without such siblings."""
    n = np.int64(tv[0])
    ptop = (tv.shape[0] - n) // 2
    j = ptop + (k >> ti[0])
    while j >= _RUNNER_UP_TOP:
        j >>= 1
    bv = -np.inf
    bi = np.int64(-1)
    while j > 1:
        sj = j ^ 1
        if tv[sj] > bv:
            bv = tv[sj]
            bi = ti[sj]
        j >>= 1
    return bi


@njit(cache=True, inline="always")
def _prefetch_rows(arr, lo, hi, cols):
    """Prefetch rows ``lo .. hi`` of ``arr`` (``cols`` float64s per row, C order)."""
    for f in range(lo * cols, (hi + 1) * cols, 8):
        prefetch(arr, f)
    prefetch(arr, (hi + 1) * cols - 1)


@njit(cache=True, readonly=('orig',))
def drive(P, D, h, orig, closed, degree, method, spline, hstep, eligible, tol, eps,
          max_steps, move_floor, K0, pe, q, fixed, Hinv, w0, wmax, thr,
          measure, values, tv, ti, blocked, block_measure, mcode=M_DEFAULT):
    """Seed 001's steps 2-6 on the distinct data (``P``, ``D`` and the state from
    :func:`drive_setup` are modified in place; no ``O(n)`` work or allocation here).

    Returns ``(steps, stop_code, hist_index, hist_measure, hist_disp, blocked,
    n_truncated, n_skipped, max_window)``; ``blocked`` is 0 (free), 1 (blocked by the tolerance),
    2 (move ~0 without clamping).
    """
    nd = P.shape[0]
    dim = P.shape[1]
    nb = D.shape[1]
    cap = 1024 if max_steps > 1024 else max(max_steps, 1)
    h_idx = np.empty(cap, dtype=np.int64)
    h_meas = np.empty(cap)
    h_disp = np.empty(cap)
    delta = np.empty(dim)
    eta = np.empty(dim)
    xi = np.empty(dim)
    dense = Hinv.shape[0] > 0
    # window work arrays
    Lmax = 2 * wmax + 3
    if Lmax > nd:
        Lmax = nd
    if Lmax < 3:
        Lmax = 3
    idx = np.empty(Lmax, dtype=np.int64)
    # the measures a step recomputes (a window and its two neighbours, or every point when
    # the dense inverse updates them all) and their segments' coefficients
    mfast = fast_measure_code(degree, method, mcode)
    nm = nd + 3 if dense else Lmax + 3
    mbuf = np.empty(nm)
    seg = np.empty((nm + 1, 4, dim))
    Bd = np.empty((Lmax, nb, nb))
    Cu = np.empty((Lmax, nb, nb))
    R = np.empty((Lmax, nb, dim))
    X = np.empty((Lmax, nb, dim))
    Bp = np.empty((Lmax, nb, nb))
    Y = np.empty((Lmax, nb, dim))
    pw = np.empty(8)
    inv2 = np.empty((2, 2))
    W2 = np.empty((2, 2))
    w_cur = w0
    steps = 0
    n_trunc = 0
    n_skip = 0
    max_window = 0
    stop = STOP_MAX_STEPS
    # on data too large for the caches a step waits for memory: the next point is usually far
    # away (the largest measure anywhere). The runner-up's data are prefetched one step ahead
    # while far jumps are frequent (a running share above 1/4); prefetches never change results
    big = nd * (dim * (2 + nb) + 6) * 8 >= _SPECULATE_BYTES and not dense
    farrate = 0.0
    prev = np.int64(-(1 << 40))
    base = tv.shape[0] - nd  # the entries' own values in the tree's array
    while True:
        if steps >= max_steps:
            stop = STOP_MAX_STEPS
            break
        k, v = tt_top(tv, ti)
        if v == -np.inf or k < 0:
            stop = STOP_ALL_BLOCKED
            break
        if v < eps:
            stop = STOP_EPS
            break
        farrate = 0.9375 * farrate + (0.0625 if abs(k - prev) > _FAR else 0.0)
        prev = k
        if big and farrate > 0.25:
            r = _runner_up(tv, ti, k)
            if r >= 0:
                rlo = r - w_cur - 2
                rhi = r + w_cur + 2
                if rlo < 0:
                    rlo = 0
                if rhi > nd - 1:
                    rhi = nd - 1
                _prefetch_rows(P, rlo, rhi, dim)
                _prefetch_rows(D, rlo, rhi, nb * dim)
                _prefetch_rows(h, rlo, rhi, 1)
                _prefetch_rows(measure, rlo, rhi, 1)
                _prefetch_rows(values, rlo, rhi, 1)
                _prefetch_rows(tv, base + rlo, base + rhi, 1)
                prefetch(orig, r * dim)
                prefetch(eligible, rlo)
                prefetch(eligible, rhi)
                prefetch(blocked, rlo)
                prefetch(blocked, rhi)
                j = (base >> 1) + (rlo >> ti[0])  # the lower levels of its tree path
                for _ in range(4):
                    prefetch(tv, j)
                    prefetch(ti, j)
                    j >>= 1
        mv, clamped, want = _clamped_move(P, D, h, orig, k, method, degree, spline, hstep, tol,
                                          delta, eta, xi)
        if _is_blocked(mv, clamped, want, move_floor):
            blocked[k] = 1 if clamped else 2
            block_measure[k] = v
            tt_update(tv, ti, k, -np.inf)
            n_skip += 1
            continue
        # -- apply the move
        for c in range(dim):
            P[k, c] += delta[c]
        if not spline:
            if degree == 5:
                for c in range(dim):
                    D[k, 0, c] += eta[c]
                    D[k, 1, c] += xi[c]
            elif method == WANG_CAO:
                for c in range(dim):
                    D[k, 0, c] += eta[c]
        if steps == cap:
            cap2 = 2 * cap
            if cap2 > max_steps:
                cap2 = max_steps
            n1 = np.empty(cap2, dtype=np.int64)
            n2 = np.empty(cap2)
            n3 = np.empty(cap2)
            n1[:cap] = h_idx
            n2[:cap] = h_meas
            n3[:cap] = h_disp
            h_idx = n1
            h_meas = n2
            h_disp = n3
            cap = cap2
        h_idx[steps] = k
        h_meas[steps] = v
        h_disp[steps] = mv
        steps += 1
        # -- re-interpolate (spline mode) and find the affected range [a, b] (virtual indices)
        a = k - 1
        b = k + 1
        if spline:
            if dense:
                # closed and small: exact update with the precomputed inverse of the full system
                for jj in range(3):
                    idx[jj] = (k - 1 + jj) % nd
                _rhs_for_move(nd, closed, h, K0, pe, q, nb, k, delta, idx, 3, fixed, R, pw)
                for r in range(nd * nb):
                    for c in range(dim):
                        s = 0.0
                        for jj in range(3):
                            for e in range(nb):
                                s += Hinv[r, idx[jj] * nb + e] * R[jj, e, c]
                        D[r // nb, r % nb, c] += s
                a = 0
                b = nd - 1
            else:
                w = w_cur
                while True:
                    if closed:
                        if 2 * w + 1 > nd - 1:
                            w = (nd - 2) // 2
                        lo = k - w
                        L = 2 * w + 1
                        for vv in range(L):
                            idx[vv] = (lo + vv) % nd
                        left_open = True
                        right_open = True
                    else:
                        lo = k - w
                        if lo < 0:
                            lo = 0
                        hi = k + w
                        if hi > nd - 1:
                            hi = nd - 1
                        L = hi - lo + 1
                        for vv in range(L):
                            idx[vv] = lo + vv
                        left_open = lo > 0
                        right_open = hi < nd - 1
                    # the block and coordinate counts as constants where they are the common
                    # ones, so that the compiler unrolls their loops (the same operations); see
                    # _window_solve_1_2 for which is inlined
                    if nb == 1 and dim == 2:
                        _window_solve_1_2(nd, closed, h, K0, pe, q, fixed, idx, L, k, delta,
                                          Bd, Cu, R, X, Bp, Y, pw, inv2, W2)
                    elif nb == 1 and dim == 3:
                        _window_solve_1_3(nd, closed, h, K0, pe, q, fixed, idx, L, k, delta,
                                          Bd, Cu, R, X, Bp, Y, pw, inv2, W2)
                    elif nb == 2 and dim == 2:
                        _window_solve(nd, closed, h, K0, pe, q, 2, 2, fixed, idx, L, k, delta,
                                      Bd, Cu, R, X, Bp, Y, pw, inv2, W2)
                    else:
                        _window_solve_any(nd, closed, h, K0, pe, q, nb, dim, fixed, idx, L, k,
                                          delta, Bd, Cu, R, X, Bp, Y, pw, inv2, W2)
                    ok = True
                    for e in range(nb):
                        big = 0.0
                        for vv in range(L):
                            for c in range(dim):
                                t = abs(X[vv, e, c])
                                if t > big:
                                    big = t
                        for c in range(dim):
                            if left_open and abs(X[0, e, c]) > thr * big:
                                ok = False
                            if right_open and abs(X[L - 1, e, c]) > thr * big:
                                ok = False
                    can_grow = (closed and 2 * w + 1 < nd - 2 and w < wmax) or \
                        ((not closed) and (left_open or right_open) and w < wmax)
                    if ok or not can_grow:
                        if not ok:
                            n_trunc += 1
                        break
                    w = 2 * w
                    if w > wmax:
                        w = wmax
                    if w > w_cur:
                        w_cur = w
                if L > max_window:
                    max_window = L
                for vv in range(L):
                    i = idx[vv]
                    for e in range(nb):
                        for c in range(dim):
                            D[i, e, c] += X[vv, e, c]
                a = lo - 1
                b = lo + L
        # -- recompute measures / eligibility on [a, b] and update the tree
        if closed:
            if b - a + 1 >= nd:
                a = 0
                b = nd - 1
        else:
            if a < 1:
                a = 1
            if b > nd - 2:
                b = nd - 2
        range_measures(P, D, h, closed, degree, spline, method, hstep, mcode, mfast, a, b, seg,
                       mbuf)
        for vv in range(a, b + 1):
            i = vv % nd if closed else vv
            m_new = mbuf[vv - a]
            measure[i] = m_new
            if not eligible[i]:
                values[i] = -np.inf
                continue
            if blocked[i] != 0:
                # a blocked point stays blocked while its measure has not changed by more than a
                # relative RECHECK since it was blocked (far inside a spline window the change
                # is at rounding level); otherwise try its step again
                if abs(m_new - block_measure[i]) <= RECHECK * block_measure[i]:
                    values[i] = -np.inf
                    continue
                mv2, cl2, want2 = _clamped_move(P, D, h, orig, i, method, degree, spline, hstep,
                                                tol, delta, eta, xi)
                if _is_blocked(mv2, cl2, want2, move_floor):
                    blocked[i] = 1 if cl2 else 2
                    block_measure[i] = m_new
                    values[i] = -np.inf
                    continue
                blocked[i] = 0
            values[i] = m_new
        if closed and (a < 0 or b > nd - 1) and b - a + 1 < nd:
            a2 = a % nd
            b2 = b % nd
            tt_update_range(tv, ti, a2, nd - 1, values)
            tt_update_range(tv, ti, np.intp(0), b2, values)
        elif b >= a:
            tt_update_range(tv, ti, a, b, values)
    return (steps, stop, h_idx[:steps].copy(), h_meas[:steps].copy(), h_disp[:steps].copy(),
            blocked, n_trunc, n_skip, max_window)


# all_measures works in blocks of this many points (its segment buffer stays small)
_MEASURE_BLOCK = 4096


@njit(cache=True)
def all_measures(P, D, h, closed, degree, spline, method=POLIAKOFF, hstep=0.0,
                 mcode=M_DEFAULT):
    """Ranking measure of every point (0 at the ends of an open curve)."""
    nd = P.shape[0]
    out = np.zeros(nd)
    if closed:
        a, b = 0, nd - 1
    else:
        a, b = 1, nd - 2
    mfast = fast_measure_code(degree, method, mcode)
    # in blocks, so that the segments' buffer stays small
    seg = np.empty((_MEASURE_BLOCK + 1, 4, P.shape[1]))
    for lo in range(a, b + 1, _MEASURE_BLOCK):
        hi = min(lo + _MEASURE_BLOCK - 1, b)
        range_measures(P, D, h, closed, degree, spline, method, hstep, mcode, mfast, lo, hi,
                       seg, out[lo:hi + 1])
    return out

