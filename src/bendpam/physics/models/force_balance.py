r"""Force-balance model of the output moment, paper eq 22-49.

Axial moment balance of a unit body about the frame (eq 23, 28)::

    M_load = M_p - M_frame - M_bl - M_br

* ``M_p = pi R^3 P`` as in eq 49.  Eq 49 writes ``pi R^3 P`` for the pressure term instead of eq
  26's ``pi (R - t)^2 P R``; the difference is the hydrostatic part ``-P`` of the bladder's axial
  stress acting over the wall (``pi R (R-t)^2 + 2 pi R^2 t ~ pi R^3``).  We follow eq 49 and
  therefore leave ``-P`` out of the bladder term (docs/paper-reading.md item 9).
* ``M_frame = E_f I_f k'`` (eq 27).
* ``M_bl = \int sigma_bl,1^el h dA`` with ``h = R (1 - cos Phi)``, ``dA = t_bar R dPhi`` and the
  elastic part of eq 43::

      sigma_bl,1^el(Phi) = 2C10 (lambda1^2 - 1/(lbar^2 eta^2)) - 2C01 (1/lambda1^2 - lbar^2 eta^2)

  where ``lbar = 1 + k'R`` (eq 39), ``eta = R/R0`` and ``t_bar = t0 / (lbar eta)`` (eq 40,
  docs/paper-reading.md item 12).  Its Phi-independent part integrates to
  ``-2 pi R^2 t_bar (2C10/(lbar^2 eta^2) - 2C01 lbar^2 eta^2)``, so in ``M_load`` it enters with a
  *plus* sign.  Eq 49 prints a minus: a misprint (docs/paper-reading.md item 10).  With the sign derived here the
  C10 and C01 terms cancel at ``k' = 0`` and both models give the same blocked moment.
* ``M_br = \int sigma_br,1 h dA_br``.  The braid hoop stress is ``sigma_br,2 = P_e R / t_br``
  (eq 31), the fibre angle gives ``sigma_br,1 / sigma_br,2 = cot^2 alpha`` with
  ``cot^2 alpha = c^2 lambda1^2 / (1 - c^2 lambda1^2)`` (eq 46-47; alpha is measured from the axis,
  docs/paper-reading.md item 11) and the interfacial pressure is eq 45::

      P_e R = P (R - t_bar) - sigma_bl,2 t_bar = P R - sigma_bl,2^el t_bar

  so ``M_br = (P R - sigma_bl,2^el t_bar) R^2 c^2 J`` with
  ``J = \int_0^{2pi} lambda1^2 (1 - cos Phi) / (1 - c^2 lambda1^2) dPhi``; ``t_br`` cancels.

With the corrections of section 3.3, ``P`` is the active pressure ``max(P - P_start, 0)`` and
``R0, t0`` are ``R0_start, t0_start``.  As in the energy model, ``M = P_active A(k') - B(k')`` with::

    A = R^3 (pi - c^2 J),   B = E_f I_f k' + M_bl - sigma_bl,2^el t_bar R^2 c^2 J
"""

from __future__ import annotations

import numpy as np

from bendpam.physics.braid import (
    CLOSED_FORM,
    DEFAULT_ORDER,
    case_column,
    circle_ibar,
    gauss_nodes,
    kernel_args,
    radius_state,
    radius_terms,
)

__all__ = ["axial_forces", "basis", "coefficients", "stress_state", "terms"]


def _bladder_elastic(C1, C2, lbar, eta):
    """Elastic (pressure-free) parts of eq 43-44: ``(const1, sig2e)`` in MPa.

    ``const1`` is the Phi-independent part of ``sigma_bl,1^el`` and ``sig2e`` is ``sigma_bl,2^el``;
    ``lbar = 1 + k'R`` (eq 39) and ``eta = R/R0`` (eq 5).
    """
    le2 = (lbar * eta) ** 2
    const1 = -2.0 * C1 / le2 + 2.0 * C2 * le2
    sig2e = 2.0 * C1 * (eta * eta - 1.0 / le2) - 2.0 * C2 * (1.0 / (eta * eta) - le2)
    return const1, sig2e


def _state(params, k, order):
    R0 = params.R0_start
    u, R, _dR = radius_terms(k, params.alpha0, R0, order)
    phi, wbar = gauss_nodes(order)
    omc = 1.0 - np.cos(phi)
    lam1 = 1.0 + u[..., None] * omc
    c = np.cos(params.alpha0)
    lbar = 1.0 + u
    eta = R / R0
    tbar = params.t0_start / (lbar * eta)
    cl2 = (case_column(c) * lam1) ** 2
    J = 2.0 * np.pi * ((lam1 * lam1 * omc / (1.0 - cl2)) @ wbar)
    C1, C2 = params.C10, params.C01
    const1, sig2e = _bladder_elastic(C1, C2, lbar, eta)
    varpart = 2.0 * np.pi * (((2.0 * case_column(C1) * lam1 * lam1 - 2.0 * case_column(C2) / (lam1 * lam1)) * omc)
                             @ wbar)
    m_bl = tbar * R * R * (varpart + 2.0 * np.pi * const1)
    return dict(u=u, R=R, lam1=lam1, c=c, lbar=lbar, eta=eta, tbar=tbar, J=J, sig2e=sig2e, const1=const1, m_bl=m_bl,
                omc=omc, wbar=wbar)


#: Names of the section means of :func:`section_means` (besides ``ib`` and ``dib``).
MEANS = ("J", "L2", "Lm2")


def _rsqrt_m1(y):
    """``(1 + y)^(-1/2) - 1`` without cancellation for small ``y``."""
    return np.expm1(-0.5 * np.log1p(y))


def _j_closed_form(u, c):
    """``J = 2 pi mean(lambda1^2 (1 - cos) / (1 - c^2 lambda1^2))`` in closed form.

    ``lambda1^2 / (1 - c^2 lambda1^2) = (-1 + 1/(1 - c^2 lambda1^2)) / c^2``, ``(1 - cos) = (lambda1 - 1)/u``
    and partial fractions in ``1 -+ c lambda1`` leave means of ``1/(alpha + beta cos Phi)``, which are
    ``(alpha^2 - beta^2)^(-1/2)``: ``mean((1 - cos)/(1 - c^2 lambda1^2)) = (g(-x/(1 - c)) - g(x/(1 + c))) / x``
    with ``x = 2 c u`` and ``g(y) = (1 + y)^(-1/2) - 1``, whose limit at ``u = 0`` is ``1/s^2``.
    """
    x = 2.0 * c * u
    x = np.where(x == 0.0, 1e-300, x)  # the formula's limit at u = 0 (1/s^2) without a 0/0
    t = (_rsqrt_m1(-x / (1.0 - c)) - _rsqrt_m1(x / (1.0 + c))) / x
    return 2.0 * np.pi * (t - 1.0) / (c * c)


def _axial_means(u, c):
    """Circle means of ``cot^2 alpha(Phi) = c^2 lambda1^2 / (1 - c^2 lambda1^2)`` and ``lambda1^-2``, closed form.

    With ``lambda1 = (1 + u) - u cos Phi``: ``1 / (1 - c^2 lambda1^2)`` is
    ``(1/(1 - c lambda1) + 1/(1 + c lambda1)) / 2`` and
    ``mean 1/(alpha + beta cos Phi) = (alpha^2 - beta^2)^(-1/2)``, so
    ``mean cot^2 = ((1 - c)(1 - c - 2cu))^(-1/2) / 2 + ((1 + c)(1 + c + 2cu))^(-1/2) / 2 - 1`` (``cot^2 alpha0``
    at ``u = 0``; finite below the lock-up ``u = (1/c - 1)/2``) and
    ``mean lambda1^-2 = (1 + u) / (1 + 2u)^(3/2)`` (its derivative in ``alpha``).
    """
    cu2 = 2.0 * c * u
    cot2 = 0.5 / np.sqrt((1.0 - c) * (1.0 - c - cu2)) + 0.5 / np.sqrt((1.0 + c) * (1.0 + c + cu2)) - 1.0
    q = 1.0 + 2.0 * u
    return cot2, (1.0 + u) / (q * np.sqrt(q))


def section_means(u, alpha0, order: int = DEFAULT_ORDER, ib=None, dib=None) -> dict:
    """The section integrals of the force-balance model that depend on ``u = k'R`` and ``alpha0`` only.

    ``ib, dib`` (eq 5), ``J = int_0^2pi lambda1^2 (1 - cos Phi) / (1 - c^2 lambda1^2) dPhi`` (eq 46-48),
    ``L2`` and ``Lm2``: the circle means of ``lambda1^2 (1 - cos Phi)`` and ``(1 - cos Phi) / lambda1^2``
    (eq 43).  The rest is per-actuator arithmetic (:func:`assemble`).
    """
    c = np.cos(alpha0)
    u = np.asarray(u, dtype=float)
    if ib is None or dib is None:
        ib, dib = circle_ibar(u, c, order)
    if order == CLOSED_FORM:
        J = _j_closed_form(u, c)
        Lm2 = (1.0 + 2.0 * u) ** -1.5  # mean((1 - cos) / lambda1^2), elementary
    else:
        phi, wbar = gauss_nodes(order)
        omc = 1.0 - np.cos(phi)
        lam1 = 1.0 + u[..., None] * omc
        l2o = lam1 * lam1 * omc
        J = 2.0 * np.pi * ((l2o / (1.0 - case_column(c * c) * (lam1 * lam1))) @ wbar)
        Lm2 = ((omc / lam1) / lam1) @ wbar
    # mean(lambda1^2 (1 - cos)) is a polynomial in u: mean((1 - cos)^n) = 1, 3/2, 5/2 for n = 1, 2, 3
    return {"ib": ib, "dib": dib, "J": J, "L2": 1.0 + u * (3.0 + 2.5 * u), "Lm2": Lm2}


def assemble(params, k, u, R, dR, means):
    """``(A, b10, b01)`` (per MPa) from the kinematics and :func:`section_means` (eq 43-49).

    ``B = M_bl - sigma_bl,2^el t_bar R^2 c^2 J`` is linear in C10 and C01; ``b10`` and ``b01`` are
    its coefficients, and ``A = R^3 (pi - c^2 J)``.
    """
    c2 = np.cos(params.alpha0) ** 2
    eta = R / params.R0_start
    lbar = 1.0 + u
    tb = params.t0_start / (lbar * eta)
    le2 = (lbar * eta) ** 2
    e2 = eta * eta
    J = means["J"]
    w = tb * R * R
    br = w * c2 * J  # sigma_bl,2^el enters as - sigma2e * t_bar R^2 c^2 J
    b10 = w * 2.0 * np.pi * (2.0 * means["L2"] - 2.0 / le2) - 2.0 * (e2 - 1.0 / le2) * br
    b01 = w * 2.0 * np.pi * (-2.0 * means["Lm2"] + 2.0 * le2) + 2.0 * (1.0 / e2 - le2) * br
    return R**3 * (np.pi - c2 * J), b10, b01


def basis(params, curvature, *, order: int = DEFAULT_ORDER):
    """Linear decomposition ``M = P_active A - E_f I_f k' - C10 b10 - C01 b01`` (C in MPa).

    Returns ``(A, b10, b01)``, see :func:`assemble`.

    Examples
    --------
    >>> import numpy as np, bendpam
    >>> A, b10, b01 = basis(bendpam.physics.presets.be_pam("force_balance").params, np.array([0.0, 0.01]))
    >>> A.round(2).tolist(), bool(abs(b10[0]) + abs(b01[0]) < 1e-9)    # no bladder terms when straight
    ([2350.98, 1919.94], True)
    """
    k, = kernel_args(params, ("curvature", curvature, "1/mm"))
    u, R, dR, ib, dib = radius_state(k, params.alpha0, params.R0_start, order)
    return assemble(params, k, u, R, dR, section_means(u, params.alpha0, order, ib, dib))


def coefficients(params, curvature, *, order: int = DEFAULT_ORDER):
    """``(A, B)`` with ``M = P_active A - B`` (N*mm/MPa and N*mm), shape of ``curvature``.

    >>> import numpy as np, bendpam
    >>> A, B = coefficients(bendpam.physics.presets.be_pam("force_balance").params, np.array([0.0, 0.01]))
    >>> A.round(2).tolist(), B.round(2).tolist()
    ([2350.98, 1919.94], [0.0, 194.51])
    """
    k, = kernel_args(params, ("curvature", curvature, "1/mm"))
    A, b10, b01 = basis(params, k, order=order)
    return A, params.C10 * b10 + params.C01 * b01 + params.frame_stiffness * k


def terms(params, p_active, curvature, *, order: int = DEFAULT_ORDER):
    """The parts of eq 49 in N*mm: ``M_load``, ``M_p``, ``M_frame``, ``M_bl``, ``M_br``.

    >>> import numpy as np, bendpam
    >>> t = terms(bendpam.physics.presets.be_pam("force_balance").params, 0.132, np.array([0.0, 0.01]))
    >>> {name: v.round(2).tolist() for name, v in t.items()}
    {'M_load': [310.33, 58.92], 'M_p': [427.26, 408.42], 'M_frame': [0.0, 3.54],
     'M_bl': [0.0, 207.22], 'M_br': [116.93, 138.74]}
    """
    k, p = kernel_args(params, ("curvature", curvature, "1/mm"), ("p_active", p_active, "MPa"))
    st = _state(params, k, order)
    R, c, J = st["R"], st["c"], st["J"]
    m_p = p * np.pi * R**3
    m_frame = params.frame_stiffness * k
    m_bl = st["m_bl"]
    m_br = (p * R - st["sig2e"] * st["tbar"]) * R * R * c * c * J
    m_p, m_frame, m_bl, m_br = np.broadcast_arrays(m_p, m_frame, m_bl, m_br)
    return {"M_load": m_p - m_frame - m_bl - m_br, "M_p": m_p, "M_frame": m_frame, "M_bl": m_bl, "M_br": m_br}


def stress_state(params, p_active, curvature, phi, *, order: int = DEFAULT_ORDER):
    """Internal stresses of the force-balance model at angles ``phi`` (rad) around the section.

    ``p_active`` and ``curvature`` are scalars or arrays broadcasting to a shape S; ``phi`` is
    1-D (n,).  Returns a dict of arrays (MPa unless noted):

    * ``sigma_bl1`` (S, n): bladder axial stress, eq 43 (including ``-P``).
    * ``sigma_bl2`` (S): bladder hoop stress, eq 44.
    * ``sigma_bl3`` (S): bladder radial stress, ``-P`` (eq 37).
    * ``P_e`` (S): interfacial pressure between bladder and braid, eq 45.
    * ``N_br1`` (S, n): braid axial line tension ``sigma_br,1 t_br`` (N/mm), eq 48 times ``t_br``.
    * ``N_br2`` (S): braid hoop line tension ``P_e R`` (N/mm), eq 31 times ``t_br``.
    * ``sigma_br1`` (S, n), ``sigma_br2`` (S): nominal braid stresses with the actuator's
      ``braid_thickness_mm`` (eq 48, 31).
    * ``braid_angle`` (S, n): local braid angle alpha(Phi), rad.
    * ``t_bar`` (S): mean bladder thickness (mm), eq 40; ``R`` (S): radius (mm).

    Examples
    --------
    The BC-PAM at 120 kPa (active 88 kPa) and k' = -0.006 1/mm, at the frame, a quarter turn and
    the far side:

    >>> import numpy as np, bendpam
    >>> st = stress_state(bendpam.physics.presets.bc_pam().params, 0.088, -0.006, np.radians([0.0, 90.0, 180.0]))
    >>> st["sigma_bl1"].round(4).tolist(), round(float(st["P_e"]), 4)      # MPa
    ([-0.0649, -0.0959, -0.0508], 0.0375)
    """
    k, p = kernel_args(params, ("curvature", curvature, "1/mm"), ("p_active", p_active, "MPa"))
    k, p = np.broadcast_arrays(k, p)
    st = _state(params, k, order)
    phi, = kernel_args(params, ("phi", phi, "rad"))
    lam1 = 1.0 + st["u"][..., None] * (1.0 - np.cos(phi))
    C1, C2 = params.C10, params.C01
    c = st["c"]
    sig1 = 2.0 * C1 * lam1**2 - 2.0 * C2 / lam1**2 + st["const1"][..., None] - p[..., None]
    sig2 = st["sig2e"] - p
    R, tbar = st["R"], st["tbar"]
    Pe = (p * R - st["sig2e"] * tbar) / R
    cl2 = (c * lam1) ** 2
    cot2 = cl2 / (1.0 - cl2)
    n2 = Pe * R
    n1 = cot2 * n2[..., None]
    tb = params.braid_thickness
    return {
        "sigma_bl1": sig1,
        "sigma_bl2": sig2,
        "sigma_bl3": -p,
        "P_e": Pe,
        "N_br1": n1,
        "N_br2": n2,
        "sigma_br1": n1 / tb,
        "sigma_br2": n2 / tb,
        "braid_angle": np.arccos(np.clip(c * lam1, -1.0, 1.0)),
        "t_bar": tbar,
        "R": R,
    }


def axial_forces(params, p_active, u, R, *, order: int = DEFAULT_ORDER):
    r"""Axial force balance of a cross-section (N): what the frame carries, eq 22 and 24-26 with eq 43-48.

    The section's axial stress resultants, with the stresses of this model (:func:`stress_state`)
    and eq 49's treatment of the pressure (docs/paper-reading.md item 9):

    * ``F_p = pi R^2 P``: the pressure on the lumen plus the hydrostatic ``-P`` of the bladder's
      axial stress over the wall (``pi (R - t)^2 P + 2 pi R t P ~ pi R^2 P``), the force whose
      moment about the frame is eq 49's ``pi R^3 P``;
    * ``F_br = \int N_br,1 R dPhi = (P R - sigma_bl,2^el t_bar) R \int_0^{2pi} cot^2 alpha dPhi``,
      the braid's axial resultant (eq 31, 45-47);
    * ``F_bl = t_bar R \int_0^{2pi} sigma_bl,1^el dPhi``, the bladder's elastic axial resultant (eq 43);
    * ``N_frame = F_p - F_br - F_bl``: with no external axial load the section's resultants sum to
      zero, so the frame carries the rest (tension positive).  At ``k' = 0`` this is
      ``pi R0^2 P (1 - 2 cot^2 alpha0)``, the McKibben force with the opposite sign (the frame holds
      the actuator at its length), and ``N_frame R0`` is the blocked moment (docs/paper-reading.md item 14).

    ``u = k'R`` and ``R`` are the kinematic state of eq 5 (mm) and ``p_active`` the active pressure
    (MPa); the parameter fields broadcast against ``u`` (a block of cases needs a trailing axis,
    :meth:`~bendpam.ModelParams.col`).  Returns a dict of arrays: ``F_p``, ``F_br``, ``F_bl``,
    ``N_frame`` (N), ``P_e`` (MPa, eq 45), ``t_bar`` (mm, eq 40) and ``eta`` (``R/R0``).  With the
    default ``order = 0`` the two circle means are in closed form (:func:`_axial_means`), otherwise
    Gauss-Legendre with ``order`` nodes.

    Examples
    --------
    Straight at 200 kPa: ``N_frame R0`` is the blocked moment (310.33 N*mm):

    >>> import numpy as np, bendpam
    >>> p = bendpam.physics.presets.be_pam("force_balance").params
    >>> f = axial_forces(p, 0.132, np.array(0.0), np.array(p.R0_start))
    >>> round(float(f["N_frame"]), 3), round(float(f["N_frame"] * p.R0_start), 2)
    (30.726, 310.33)
    """
    u, p, R = kernel_args(params, ("u", u, "1"), ("p_active", p_active, "MPa"), ("R", R, "mm"))
    lbar = 1.0 + u
    eta = R / params.R0_start
    tbar = params.t0_start / (lbar * eta)
    const1, sig2e = _bladder_elastic(params.C10, params.C01, lbar, eta)
    if order == CLOSED_FORM:
        mean_cot2, mean_lm2 = _axial_means(u, np.cos(params.alpha0))
    else:
        phi, wbar = gauss_nodes(order)
        lam1 = 1.0 + u[..., None] * (1.0 - np.cos(phi))
        cl2 = (case_column(np.cos(params.alpha0)) * lam1) ** 2
        mean_cot2 = (cl2 / (1.0 - cl2)) @ wbar  # circle mean of cot^2 alpha(Phi), eq 46-47
        mean_lm2 = (1.0 / (lam1 * lam1)) @ wbar
    mean_l2 = 1.0 + u * (2.0 + 1.5 * u)  # circle mean of lambda1^2: mean((1 - cos)^n) = 1, 3/2
    n2 = p * R - sig2e * tbar  # braid hoop line tension P_e R (eq 31, 45)
    f_p = p * np.pi * R * R
    f_br = 2.0 * np.pi * n2 * R * mean_cot2
    f_bl = 2.0 * np.pi * tbar * R * (2.0 * params.C10 * mean_l2 - 2.0 * params.C01 * mean_lm2 + const1)
    return {"F_p": f_p, "F_br": f_br, "F_bl": f_bl, "N_frame": f_p - f_br - f_bl, "P_e": n2 / R, "t_bar": tbar,
            "eta": eta}
