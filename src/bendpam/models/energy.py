r"""Energy (virtual-work) model of the output moment, paper eq 9-21.

For a unit body of reference length ``dl0`` the work balance (eq 9-12) gives, per unit bending
angle ``theta = k' L0``::

    M_load = M_air - M_bl - M_f                                                   (eq 15, 21)

* ``M_air = P dV/dtheta = pi P [(2R + 3 k' R^2) dR/dk' + R^3]``  (eq 13, with the printed ``k``
  read as ``k'``, docs/paper-reading.md item 5).  It follows from ``V = pi R^2 L0 (1 + k'R)``.
* ``M_f = E_f I_f k'`` (eq 16).
* ``M_bl = (1 + k'R) dU_bl/dk'`` (eq 19) with ``U_bl`` the bladder's stored energy per unit
  reference length, ``U_bl = \int_A W(lambda1(Phi), lambda2) dA`` over the reference annulus.  The
  bladder's hoop stretch ``lambda2 = R/R0`` is uniform (eq 17), so material and spatial angles
  coincide and ``U_bl = A_bl * mean_Phi W``.  ``dU_bl/dk'`` is the *total* derivative: it includes
  the ``dR/dk'`` terms through both stretches (docs/paper-reading.md item 6).

  The factor ``(1 + k'R)`` is kept as printed (``eq19_factor=True``, the default); a strict reading
  of ``dU/dtheta = (1/L0) dU/dk'`` per unit reference length has no such factor, so it can be
  switched off (``eq19_factor=False``).  Dropping it moves the BE-PAM's free-bending angle at
  200 kPa by about 18 deg (tested).

With the corrections of section 3.3 (eq 50-52), ``P`` is the active pressure ``max(P - P_start, 0)``
and ``R0, t0`` are ``R0_start, t0_start``.  ``M`` is affine in the active pressure::

    M(P, k') = P_active * A(k') - B(k'),   A = pi[(2R + 3k'R^2) R' + R^3],   B = M_bl + M_f

which is what :func:`coefficients` returns; the kinematics are computed once per curvature.
"""

from __future__ import annotations


import numpy as np

from ..braid import DEFAULT_ORDER, gauss_nodes, radius_terms
from ..material import MooneyRivlin

__all__ = ["basis", "coefficients", "terms", "bladder_energy"]


def _state(params, k, order):
    R0 = params.R0_start
    u, R, dR = radius_terms(k, params.alpha0, R0, order)
    phi, wbar = gauss_nodes(order)
    omc = 1.0 - np.cos(phi)
    lam1 = 1.0 + u[..., None] * omc
    return u, R, dR, omc, wbar, lam1


def _air_coefficient(k, R, dR):
    return np.pi * ((2.0 * R + 3.0 * k * R * R) * dR + R**3)


_UNIT10 = MooneyRivlin(1.0, 0.0)
_UNIT01 = MooneyRivlin(0.0, 1.0)


def _bladder_basis(params, k, u, R, dR, omc, wbar, lam1, eq19_factor):
    """Bladder moment per unit C10 and per unit C01 (N*mm/MPa): M_bl = C10 b10 + C01 b01 (eq 19)."""
    eta = (R / params.R0_start)[..., None]
    dl1 = (R + k * dR)[..., None] * omc  # d lambda1 / dk'
    dl2 = (dR / params.R0_start)[..., None]  # d lambda2 / dk'
    fac = params.bladder_area * ((1.0 + u) if eq19_factor else 1.0)
    out = []
    for mat in (_UNIT10, _UNIT01):
        dW = mat.dW_dl1(lam1, eta) * dl1 + mat.dW_dl2(lam1, eta) * dl2
        out.append(fac * (dW @ wbar))
    return out


def basis(params, curvature, *, order: int = DEFAULT_ORDER, eq19_factor: bool = True):
    """Linear decomposition ``M = P_active A - E_f I_f k' - C10 b10 - C01 b01`` (C in MPa).

    Returns ``(A, b10, b01)``; they depend only on the kinematics (alpha0, R0_start, t0_start), so
    identification can solve for C10, C01, E_f and P_start by linear least squares.
    """
    k = np.asarray(curvature, dtype=float)
    u, R, dR, omc, wbar, lam1 = _state(params, k, order)
    b10, b01 = _bladder_basis(params, k, u, R, dR, omc, wbar, lam1, eq19_factor)
    return _air_coefficient(k, R, dR), b10, b01


def coefficients(params, curvature, *, order: int = DEFAULT_ORDER, eq19_factor: bool = True):
    """``(A, B)`` with ``M = P_active A - B`` (N*mm/MPa and N*mm), shape of ``curvature``.

    No range checks: callers validate the curvature against the lock-up limits.
    """
    k = np.asarray(curvature, dtype=float)
    A, b10, b01 = basis(params, k, order=order, eq19_factor=eq19_factor)
    return A, params.C10 * b10 + params.C01 * b01 + params.frame_stiffness * k


def terms(params, p_active, curvature, *, order: int = DEFAULT_ORDER, eq19_factor: bool = True):
    """The parts of eq 21 in N*mm: ``M_load``, ``M_air`` (eq 13), ``M_bl`` (eq 19), ``M_f`` (eq 16).

    ``p_active`` is ``max(P - P_start, 0)`` in MPa and broadcasts against ``curvature``.
    """
    k = np.asarray(curvature, dtype=float)
    u, R, dR, omc, wbar, lam1 = _state(params, k, order)
    m_air = np.asarray(p_active, dtype=float) * _air_coefficient(k, R, dR)
    b10, b01 = _bladder_basis(params, k, u, R, dR, omc, wbar, lam1, eq19_factor)
    m_bl = params.C10 * b10 + params.C01 * b01
    m_f = params.frame_stiffness * k
    m_bl, m_f = np.broadcast_arrays(m_bl, m_f)
    m_air, m_bl, m_f = np.broadcast_arrays(m_air, m_bl, m_f)
    return {"M_load": m_air - m_bl - m_f, "M_air": m_air, "M_bl": m_bl, "M_f": m_f}


def bladder_energy(params, curvature, *, order: int = DEFAULT_ORDER):
    """Stored bladder energy per unit reference length ``U_bl(k')`` (N*mm/mm = N), eq 18.

    ``dU_bl/dk'`` is the bladder moment of eq 19 without its ``(1 + k'R)`` factor; the tests check
    :func:`terms` against a finite difference of this function.
    """
    k = np.asarray(curvature, dtype=float)
    u, R, dR, omc, wbar, lam1 = _state(params, k, order)
    eta = (R / params.R0_start)[..., None]
    return params.bladder_area * (MooneyRivlin(params.C10, params.C01).energy(lam1, eta) @ wbar)


