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

from bendpam.physics.braid import (
    CLOSED_FORM,
    DEFAULT_ORDER,
    circle_ibar,
    gauss_nodes,
    kernel_args,
    radius_state,
    radius_terms,
)
from bendpam.physics.material import MooneyRivlin

__all__ = ["basis", "bladder_energy", "coefficients", "terms"]


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
#: Names of the section means of :func:`section_means` (besides ``ib`` and ``dib``).
MEANS = ("d1_10", "d2_10", "d1_01", "d2_01")


def section_means(u, alpha0, order: int = DEFAULT_ORDER, ib=None, dib=None) -> dict:
    """The section integrals of the energy model that depend on ``u = k'R`` and ``alpha0`` only.

    ``ib, dib``: the circle mean ``Ibar(u)`` of eq 5 and its derivative; ``d1_10, d2_10`` (and
    ``_01``): the circle means of ``dW/dlambda1 (1 - cos Phi)`` and ``dW/dlambda2`` for a unit C10
    (C01) at the stretches ``lambda1 = 1 + u (1 - cos Phi)``, ``lambda2 = xi(u)`` (eq 17-19).
    Everything else in the moment is per-actuator arithmetic (:func:`assemble`), so actuators that
    share a braid angle share these (the sweeps tabulate them once per angle).
    """
    c, s = np.cos(alpha0), np.sin(alpha0)
    u = np.asarray(u, dtype=float)
    if ib is None or dib is None:
        ib, dib = circle_ibar(u, c, order)
    xi = np.where(u == 0.0, 1.0, 1.0 / (s * ib))
    # With lambda2 = xi uniform, the Mooney-Rivlin derivatives (MooneyRivlin.dW_dl1, dW_dl2) reduce to
    # four circle means of powers of lambda1 = 1 + u (1 - cos Phi): two are polynomials in u
    # (mean(1 - cos) = 1, mean((1 - cos)^2) = 3/2), two are elementary: from
    # mean 1/(a - b cos) = (a^2 - b^2)^(-1/2) with a = 1 + u, b = u and its derivatives in a,
    # mean(lambda1^-2) = (1 + u) / (1 + 2u)^(3/2) and mean((1 - cos) lambda1^-3) = (2 + u) / (2 (1 + 2u)^(5/2)).
    if order == CLOSED_FORM:
        r = 1.0 / (1.0 + 2.0 * u)
        sr = np.sqrt(r)
        m_im2 = (1.0 + u) * r * sr
        m_oim3 = 0.5 * (2.0 + u) * r * r * sr
    else:
        phi, wbar = gauss_nodes(order)
        omc = 1.0 - np.cos(phi)
        inv = 1.0 / (1.0 + u[..., None] * omc)
        inv2 = inv * inv
        m_im2 = inv2 @ wbar  # mean(lambda1^-2)
        m_oim3 = (omc * inv2 * inv) @ wbar  # mean((1 - cos) lambda1^-3)
    m_lo = 1.0 + 1.5 * u  # mean(lambda1 (1 - cos))
    m_l2 = 1.0 + u * (2.0 + 1.5 * u)  # mean(lambda1^2)
    x2 = xi * xi
    return {
        "ib": ib, "dib": dib,
        "d1_10": 2.0 * (m_lo - m_oim3 / x2),
        "d2_10": 2.0 * (xi - m_im2 / (x2 * xi)),
        "d1_01": 2.0 * (x2 * m_lo - m_oim3),
        "d2_01": 2.0 * (xi * m_l2 - 1.0 / (x2 * xi)),
    }


def assemble(params, k, u, R, dR, means, *, eq19_factor: bool = True):
    """``(A, b10, b01)`` (per MPa) from the kinematics and :func:`section_means` (eq 13, 19).

    ``A = pi[(2R + 3k'R^2) dR/dk' + R^3]`` (eq 13) and ``M_bl = C10 b10 + C01 b01`` with
    ``b = A_bl (1 + k'R) [(R + k' dR/dk') mean(dW/dl1 (1 - cos Phi)) + (dR/dk' / R0) mean(dW/dl2)]``.
    """
    fac = params.bladder_area * ((1.0 + u) if eq19_factor else 1.0)
    g1 = R + k * dR  # d lambda1 / dk' over (1 - cos Phi)
    g2 = dR / params.R0_start  # d lambda2 / dk'
    b10 = fac * (g1 * means["d1_10"] + g2 * means["d2_10"])
    b01 = fac * (g1 * means["d1_01"] + g2 * means["d2_01"])
    return _air_coefficient(k, R, dR), b10, b01


def basis(params, curvature, *, order: int = DEFAULT_ORDER, eq19_factor: bool = True):
    """Linear decomposition ``M = P_active A - E_f I_f k' - C10 b10 - C01 b01`` (C in MPa).

    Returns ``(A, b10, b01)``; they depend only on the kinematics (alpha0, R0_start, t0_start), so
    identification can solve for C10, C01, E_f and P_start by linear least squares.

    Examples
    --------
    >>> import numpy as np, bendpam
    >>> A, b10, b01 = basis(bendpam.physics.presets.be_pam().params, np.array([0.0, 0.01]))
    >>> A.round(2).tolist(), b10.round(1).tolist(), b01.round(1).tolist()
    ([2350.98, 1932.5], [0.0, 1088.7], [0.0, 1038.9])
    """
    k, = kernel_args(params, ("curvature", curvature, "1/mm"))
    u, R, dR, ib, dib = radius_state(k, params.alpha0, params.R0_start, order)
    means = section_means(u, params.alpha0, order, ib, dib)
    return assemble(params, k, u, R, dR, means, eq19_factor=eq19_factor)


def coefficients(params, curvature, *, order: int = DEFAULT_ORDER, eq19_factor: bool = True):
    """``(A, B)`` with ``M = P_active A - B`` (N*mm/MPa and N*mm), shape of ``curvature``.

    No range checks: callers validate the curvature against the lock-up limits.

    Examples
    --------
    The blocked moment at 200 kPa is ``P_active A(0)`` with ``P_active = 0.2 - 0.068`` MPa:

    >>> import numpy as np, bendpam
    >>> A, B = coefficients(bendpam.physics.presets.be_pam().params, np.array([0.0, 0.01]))
    >>> A.round(2).tolist(), B.round(2).tolist(), round(0.132 * float(A[0]), 2)
    ([2350.98, 1932.5], [0.0, 191.91], 310.33)
    """
    k, = kernel_args(params, ("curvature", curvature, "1/mm"))
    A, b10, b01 = basis(params, k, order=order, eq19_factor=eq19_factor)
    return A, params.C10 * b10 + params.C01 * b01 + params.frame_stiffness * k


def terms(params, p_active, curvature, *, order: int = DEFAULT_ORDER, eq19_factor: bool = True):
    """The parts of eq 21 in N*mm: ``M_load``, ``M_air`` (eq 13), ``M_bl`` (eq 19), ``M_f`` (eq 16).

    ``p_active`` is ``max(P - P_start, 0)`` in MPa and broadcasts against ``curvature``.

    Examples
    --------
    >>> import numpy as np, bendpam
    >>> t = terms(bendpam.physics.presets.be_pam().params, 0.132, np.array([0.0, 0.01]))   # 200 kPa
    >>> {name: v.round(2).tolist() for name, v in t.items()}
    {'M_load': [310.33, 63.18], 'M_air': [310.33, 255.09], 'M_bl': [0.0, 188.37], 'M_f': [0.0, 3.54]}
    """
    k, p_active = kernel_args(params, ("curvature", curvature, "1/mm"), ("p_active", p_active, "MPa"))
    A, b10, b01 = basis(params, k, order=order, eq19_factor=eq19_factor)
    m_air = np.asarray(p_active, dtype=float) * A
    m_bl = params.C10 * b10 + params.C01 * b01
    m_f = params.frame_stiffness * k
    m_bl, m_f = np.broadcast_arrays(m_bl, m_f)
    m_air, m_bl, m_f = np.broadcast_arrays(m_air, m_bl, m_f)
    return {"M_load": m_air - m_bl - m_f, "M_air": m_air, "M_bl": m_bl, "M_f": m_f}


def bladder_energy(params, curvature, *, order: int = DEFAULT_ORDER):
    """Stored bladder energy per unit reference length ``U_bl(k')`` (N*mm/mm = N), eq 18.

    ``dU_bl/dk'`` is the bladder moment of eq 19 without its ``(1 + k'R)`` factor; the tests check
    :func:`terms` against a finite difference of this function.

    Examples
    --------
    >>> import numpy as np, bendpam
    >>> bladder_energy(bendpam.physics.presets.be_pam().params, np.array([0.0, 0.01])).round(4).tolist()
    [0.0, 0.9774]
    """
    k, = kernel_args(params, ("curvature", curvature, "1/mm"))
    _u, R, _dR, _omc, wbar, lam1 = _state(params, k, order)
    eta = (R / params.R0_start)[..., None]
    return params.bladder_area * (MooneyRivlin(params.C10, params.C01).energy(lam1, eta) @ wbar)


