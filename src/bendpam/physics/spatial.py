r"""Out-of-plane bending and torsion of a bending PAM: the section's energy with three curvatures.

The in-plane law of the actuator is :class:`~bendpam.physics.law.MomentLaw` (eq 9-21 or 22-49),
unchanged.  This module adds the two other deformations of the frame line (docs/out-of-plane.md):
a **lateral curvature** ``kappa2`` (1/mm: bending about the line from the frame to the tube axis,
the frame strip bent about its strong axis) and a **twist** ``tau`` (rad/mm: the section turning
about the frame line).  Both are derived by virtual work on the braid kinematics of
:mod:`bendpam.physics.braid` with those two extra components, per unit reference length:

* axial stretch of the braid and bladder at the section angle ``Phi`` (frame at ``Phi = 0``)::

      lambda1 = 1 + k' R (1 - cos Phi) + kappa2 R sin Phi

  and, with the twist, a material line parallel to the axis turns into a helix: its stretch is
  ``L1^2 = lambda1^2 + 2 tau^2 R^2 (1 - cos Phi)`` and the sleeve is sheared in the hoop
  direction by ``gamma = tau R (1 - cos Phi)`` (zero on the frame line, the twist axis).
* inextensible fibres: a fibre family at ``+alpha0`` keeps its length,
  ``c^2 L1^2 + 2 c s gamma lambda2 + s^2 lambda2^2 = 1`` (``c, s = cos, sin alpha0``).  A shear
  lengthens one family and shortens the other; fibres take no compression, so the shortened family
  goes slack and the stretched one sets the hoop stretch ``lambda2(Phi)``.  (With both families
  taut, a symmetric braid cannot twist at all: it is *locked* until the torque slackens one family,
  see below.)
* the radius closes the circumference: ``2 pi R0 = R \oint dPhi / lambda2(Phi)`` (eq 5 with the
  generalised stretches; without ``kappa2`` and ``tau`` it is eq 5 exactly).
* energy per unit reference length, ``N*mm/mm``::

      Pi = E_f I_f k'^2/2 + E_f I_s kappa2^2/2 + G_f J_f tau^2/2 + A_bl mean_Phi W(C) - P_a pi R^2 (1 + k'R)

  with the frame strip's strong-axis second moment ``I_s = w t^3... = t w^3 / 12`` and torsion
  constant ``J_f = w t^3 / 3 (1 - 0.63 t / w)``, the bladder's Mooney-Rivlin energy ``W`` of the
  membrane stretch tensor ``C = [[L1^2, gamma eta], [gamma eta, eta^2]]`` (hoop stretch
  ``eta = R / R0`` uniform, eq 17) and the enclosed volume (the section area times the stretch of
  the tube axis: a shear of the slices does not change the volume).

The stiffnesses are the derivatives of ``Pi`` at the in-plane state ``(k', 0, 0)``:

* ``EI_lat = d^2 Pi / d kappa2^2`` (N*mm^2): even in ``kappa2``.
* twisting with the ``+alpha0`` family taut: ``Pi = Pi_0 + T_lock |tau| + GJ tau^2/2 + ...``: the
  **lock torque** ``T_lock = dPi/dtau(0+)`` (N*mm: a symmetric braid under pressure carries a
  torque up to ``T_lock`` without twisting; beyond it one family slackens) and the torsional
  stiffness ``GJ = d^2 Pi / d tau^2 (0+)`` (N*mm^2/rad) of the twisting actuator.

The derivatives are the Taylor coefficients of ``Pi`` along a small circle in the complex plane
(Cauchy's integral, Lyness & Moler 1967): no finite-difference cancellation.  At zero active
pressure and zero curvature they are beam theory of the frame strip and the bladder tube (the
tube with the braid holding its circumference: plane-strain modulus ``4 mu``, ``mu = 2(C10 + C01)``).

The torsion-pressure coupling is the fibre-reinforced-actuator one: a single fibre family (or an
asymmetric pair) twists the tube under pressure, a symmetric pair does not (Connolly, Polygerinos,
Walsh & Bertoldi, Soft Robotics 2(1) 2015, doi:10.1089/soro.2015.0001; Krishnan, Bishop-Hill &
Pagano, J. Mechanisms Robotics 7(4) 2015); the pressure's generalised force is ``P dV/dq``
(Bruder, Sedal, Vasudevan & Remy, RA-L 2018, arXiv:1805.00124).  Here the symmetric braid's
taut family gives the pressure-proportional lock torque.

Units: kPa, 1/mm, rad/mm, N*mm^2, N*mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from bendpam.errors import InputError
from bendpam.physics.actuator import Actuator
from bendpam.physics.braid import radius_state
from bendpam.physics.law import MomentLaw
from bendpam.physics.models import resolve_model
from bendpam.validate import float_array, instance, number

__all__ = [
    "FRAME_POISSON",
    "SpatialStiffness",
    "SpatialTable",
    "frame_strong_axis_inertia_mm4",
    "frame_torsion_constant_mm4",
    "lateral_stiffness_nmm2",
    "section_energy_n",
    "spatial_stiffness",
    "torsion_lock_torque_nmm",
    "torsional_stiffness_nmm2_per_rad",
]

#: Poisson's ratio of the frame strip for its shear modulus ``G_f = E_f / (2 (1 + nu))`` (an assumption:
#: glass-fibre epoxy); give ``frame_shear_modulus_mpa`` to override.
FRAME_POISSON = 0.3
_NODES = 64  # trapezoidal nodes on the full circle (spectral for these periodic, analytic integrands)
_CONTOUR = 12  # points on the Cauchy circle
_RADIUS_NEWTON = 40


def frame_strong_axis_inertia_mm4(width_mm, thickness_mm):
    """Second moment of area of the frame strip about its strong axis, ``t w^3 / 12`` (mm^4).

    >>> frame_strong_axis_inertia_mm4(5.0, 0.5)
    5.208333333333333
    """
    return thickness_mm * width_mm ** 3 / 12.0


def frame_torsion_constant_mm4(width_mm, thickness_mm):
    """Saint-Venant torsion constant of the thin frame strip, ``w t^3 / 3 (1 - 0.63 t / w)`` (mm^4).

    >>> round(frame_torsion_constant_mm4(5.0, 0.5), 6)
    0.195208
    """
    return width_mm * thickness_mm ** 3 / 3.0 * (1.0 - 0.63 * thickness_mm / width_mm)


def _frame_constants(actuator: Actuator, frame_shear_modulus_mpa):
    a = actuator
    E = a.frame_modulus_mpa
    G = E / (2.0 * (1.0 + FRAME_POISSON)) if frame_shear_modulus_mpa is None else \
        number("frame_shear_modulus_mpa", frame_shear_modulus_mpa, 0.0, lo_open=True, unit="MPa")
    return (E * a.frame_inertia_mm4, E * frame_strong_axis_inertia_mm4(a.frame_width_mm, a.frame_thickness_mm),
            G * frame_torsion_constant_mm4(a.frame_width_mm, a.frame_thickness_mm))


def _circle():
    phi = 2.0 * np.pi * np.arange(_NODES) / _NODES
    return 1.0 - np.cos(phi), np.sin(phi)


def _closure(R, k, kap2, tau, c, s, omc, sn):
    """``R mean(1/lambda2) / R0`` parts: ``(lambda1, L1^2, gamma, lambda2)`` at radius ``R`` (nodes last)."""
    Rc = R[..., None]
    lam1 = 1.0 + k[..., None] * Rc * omc + kap2[..., None] * Rc * sn
    t2 = (tau[..., None] * Rc) ** 2
    L12 = lam1 * lam1 + 2.0 * t2 * omc
    gam = tau[..., None] * Rc * omc
    lam2 = (-c * gam + np.sqrt(c * c * gam * gam + 1.0 - c * c * L12)) / s
    return lam1, L12, gam, lam2


def _radius(R_start, R0, k, kap2, tau, c, s):
    """The braid radius (mm) closing the circumference, by Newton from ``R_start`` (complex allowed)."""
    omc, sn = _circle()
    R = np.asarray(R_start, dtype=complex) + 0.0 * (kap2 + tau)

    def g(Rv):
        lam2 = _closure(Rv, k, kap2, tau, c, s, omc, sn)[3]
        return Rv * np.mean(1.0 / lam2, axis=-1) - R0

    for _ in range(_RADIUS_NEWTON):
        h = 1e-7 * np.abs(R) + 1e-12
        gr = g(R)
        step = gr * h / (g(R + h) - gr)
        R = R - step
        if np.all(np.abs(step) <= 1e-15 * np.abs(R)):
            break
    return R


def _energy(params, frame, p_mpa, k, kap2, tau, R_start):
    """``Pi`` (N*mm/mm) at the curvatures (complex ``kap2``, ``tau`` allowed); everything broadcast."""
    EIf, EIs, GJf = frame
    c, s = math.cos(float(params.alpha0)), math.sin(float(params.alpha0))
    R0 = float(params.R0_start)
    R = _radius(R_start, R0, k, kap2, tau, c, s)
    omc, sn = _circle()
    _lam1, L12, gam, _lam2 = _closure(R, k, kap2, tau, c, s, omc, sn)
    eta = (R / R0)[..., None]
    det = eta * eta * (L12 - gam * gam)
    tr = L12 + eta * eta
    i1, i2 = tr + 1.0 / det, det + tr / det
    W = float(params.C10) * (i1 - 3.0) + float(params.C01) * (i2 - 3.0)
    U = float(params.bladder_area) * np.mean(W, axis=-1)
    V = np.pi * R * R * (1.0 + k * R)
    return 0.5 * (EIf * k * k + EIs * kap2 * kap2 + GJf * tau * tau) + U - p_mpa * V


def _taylor(params, frame, p_mpa, k, R_in, which: str):
    """First and second derivative of ``Pi`` in ``kappa2`` or ``tau`` at 0 (0+), by Cauchy's integral."""
    c = math.cos(float(params.alpha0))
    u = k * R_in
    margin = np.minimum(1.0 / c - (1.0 + 2.0 * np.maximum(u, 0.0)), 1.0 + 2.0 * np.minimum(u, 0.0))
    r = 0.05 * np.maximum(margin, 1e-6) / (R_in * (2.0 if which == "tau" else 1.0))
    w = np.exp(2j * np.pi * np.arange(_CONTOUR) / _CONTOUR)
    z = r[..., None] * w
    zero = np.zeros_like(z)
    kk, pp, RR = (np.broadcast_to(np.asarray(v)[..., None], z.shape) for v in (k, p_mpa, R_in))
    args = (z, zero) if which == "kap2" else (zero, z)
    f = _energy(params, frame, pp, kk, args[0], args[1], RR)
    f0 = _energy(params, frame, np.asarray(p_mpa), np.asarray(k), np.zeros(np.shape(k)), np.zeros(np.shape(k)), R_in)
    d = f - f0[..., None]
    a1 = np.real(np.mean(d * np.conj(w), axis=-1)) / r
    a2 = np.real(np.mean(d * np.conj(w) ** 2, axis=-1)) / (r * r)
    return a1, 2.0 * a2


@dataclass(frozen=True)
class SpatialStiffness:
    """The section's stiffnesses in the three directions at pressures and in-plane curvatures (arrays).

    Attributes
    ----------
    pressure_kpa, curvature_per_mm : the states (broadcast), kPa and 1/mm.
    moment_nmm : the in-plane moment ``M(P, k')`` of :class:`~bendpam.physics.law.MomentLaw`, N*mm.
    inplane_stiffness_nmm2 : ``-dM/dk'`` of the same law (positive on the stable branch), N*mm^2.
    lateral_stiffness_nmm2 : out-of-plane bending stiffness ``EI_lat``, N*mm^2.
    torsional_stiffness_nmm2_per_rad : ``GJ`` of the twisting actuator, N*mm^2/rad.
    torsion_lock_torque_nmm : the torque the pressurised braid carries without twisting, N*mm (0 without
        active pressure, and where the energy's slope would be negative: no lock).
    parts : the frame, bladder and air (pressure) parts of the lateral and torsional stiffness and of the
        lock torque (``{"lateral": {...}, "torsion": {...}, "lock": {...}}``, same units).

    Examples
    --------
    >>> import bendpam
    >>> st = spatial_stiffness(bendpam.physics.presets.be_pam(), 150.0)     # at the free curvature
    >>> round(float(st.lateral_stiffness_nmm2)), round(float(st.torsional_stiffness_nmm2_per_rad))
    (42752, 6473)
    >>> round(float(st.torsion_lock_torque_nmm), 1), round(float(st.inplane_stiffness_nmm2))   # N*mm, N*mm^2
    (182.3, 19055)
    """

    pressure_kpa: np.ndarray
    curvature_per_mm: np.ndarray
    moment_nmm: np.ndarray
    inplane_stiffness_nmm2: np.ndarray
    lateral_stiffness_nmm2: np.ndarray
    torsional_stiffness_nmm2_per_rad: np.ndarray
    torsion_lock_torque_nmm: np.ndarray
    parts: dict

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready values (lists for arrays), units in the key names."""
        def j(v):
            a = np.asarray(v, dtype=float)
            return float(a) if a.ndim == 0 else a.tolist()
        out = {k: j(getattr(self, k)) for k in (
            "pressure_kpa", "curvature_per_mm", "moment_nmm", "inplane_stiffness_nmm2", "lateral_stiffness_nmm2",
            "torsional_stiffness_nmm2_per_rad", "torsion_lock_torque_nmm")}
        return out


def _states(actuator, pressure_kpa, curvature_per_mm, model):
    instance("actuator", actuator, (Actuator,), "a bendpam.Actuator")
    law = MomentLaw.of(actuator, resolve_model(actuator, model))
    P = law.check_pressure(pressure_kpa)
    if curvature_per_mm is None:
        k = np.asarray(law.free_curvature(P).curvature_per_mm, dtype=float)
        if not np.all(np.isfinite(k)):
            raise InputError("some pressures have no free curvature (see MomentLaw.free_curvature); give "
                             "curvature_per_mm")
    else:
        k = law.check_curvature(curvature_per_mm)
    P, k = np.broadcast_arrays(P, k)
    return law, np.array(P, dtype=float), np.array(k, dtype=float)


def spatial_stiffness(actuator: Actuator, pressure_kpa, curvature_per_mm=None, *, model: str | None = None,
                      frame_shear_modulus_mpa: float | None = None) -> SpatialStiffness:
    """Lateral and torsional stiffness and the lock torque at ``pressure_kpa`` (kPa) and ``curvature_per_mm``.

    ``curvature_per_mm`` (1/mm) is the in-plane frame curvature ``k'`` of each state; default: the free
    curvature at each pressure.  Pressures and curvatures broadcast.  ``model`` picks the in-plane law
    (the actuator's own by default); ``frame_shear_modulus_mpa`` defaults to ``E_f / (2 (1 + 0.3))``.
    See the module notes and docs/out-of-plane.md for the derivation.

    >>> import bendpam
    >>> s = spatial_stiffness(bendpam.physics.presets.bc_pam(), [0.0, 100.0])    # kPa, at the free curvatures
    >>> s.lateral_stiffness_nmm2.round(-1).tolist(), s.torsion_lock_torque_nmm.round(1).tolist()
    ([45120.0, 44350.0], [0.0, 171.7])
    """
    law, P, k = _states(actuator, pressure_kpa, curvature_per_mm, model)
    params = actuator.params
    frame = _frame_constants(actuator, frame_shear_modulus_mpa)
    pa = np.maximum(P - law.P_start_kpa, 0.0) * 1e-3  # MPa (P was checked once)
    _u, R_in, _dR, _ib, _dib = radius_state(k, float(params.alpha0), float(params.R0_start))
    _, k_lat = _taylor(params, frame, pa, k, R_in, "kap2")
    lock, gj = _taylor(params, frame, pa, k, R_in, "tau")
    M = law.moment(P, k)
    Kin = -law.tangent_stiffness(P, k)
    _EIf, EIs, GJf = frame
    parts = {"lateral": {"frame_nmm2": EIs}, "torsion": {"frame_nmm2_per_rad": GJf},
             "lock": {"energy_slope_nmm": lock}}  # the slope itself (negative: no lock), smooth in k'
    # a negative lock torque (deep reverse bending: the braid's hoop tension gone) means no lock
    return SpatialStiffness(P, k, M, Kin, k_lat, gj, np.maximum(lock, 0.0), parts)


def lateral_stiffness_nmm2(actuator: Actuator, pressure_kpa, curvature_per_mm=None, **kw) -> np.ndarray:
    """Out-of-plane bending stiffness ``EI_lat(P, k')``, N*mm^2 (:func:`spatial_stiffness`).

    >>> import bendpam
    >>> round(float(lateral_stiffness_nmm2(bendpam.physics.presets.be_pam(), 150.0, 0.0)))    # N*mm^2
    45049
    """
    return spatial_stiffness(actuator, pressure_kpa, curvature_per_mm, **kw).lateral_stiffness_nmm2


def torsional_stiffness_nmm2_per_rad(actuator: Actuator, pressure_kpa, curvature_per_mm=None, **kw) -> np.ndarray:
    """Torsional stiffness ``GJ(P, k')`` of the twisting actuator, N*mm^2/rad (:func:`spatial_stiffness`).

    >>> import bendpam
    >>> round(float(torsional_stiffness_nmm2_per_rad(bendpam.physics.presets.be_pam(), 150.0, 0.0)))
    8762
    """
    return spatial_stiffness(actuator, pressure_kpa, curvature_per_mm, **kw).torsional_stiffness_nmm2_per_rad


def torsion_lock_torque_nmm(actuator: Actuator, pressure_kpa, curvature_per_mm=None, **kw) -> np.ndarray:
    """The torque (N*mm) the pressurised braid carries before it twists (:func:`spatial_stiffness`).

    Straight, ``2 pi R0^3 cot(alpha0) P_a``:

    >>> import bendpam
    >>> round(float(torsion_lock_torque_nmm(bendpam.physics.presets.be_pam(), 150.0, 0.0)), 1)   # N*mm
    196.4
    """
    return spatial_stiffness(actuator, pressure_kpa, curvature_per_mm, **kw).torsion_lock_torque_nmm


def section_energy_n(actuator: Actuator, pressure_kpa, curvature_per_mm, lateral_curvature_per_mm=0.0,
                     twist_rad_per_mm=0.0, *, model: str | None = None,
                     frame_shear_modulus_mpa: float | None = None) -> np.ndarray:
    """The section's potential energy ``Pi`` per unit reference length (N*mm/mm = N), real arguments.

    The twist is taken with the ``+alpha0`` fibre family taut (``Pi`` is even in the twist for a
    symmetric braid: the other family is taut for a negative twist).

    >>> import bendpam
    >>> a = bendpam.physics.presets.be_pam()
    >>> e = section_energy_n(a, 150.0, 0.008, [0.0, 1e-3])       # N: a lateral curvature of 1e-3 1/mm
    >>> round(float((e[1] - e[0]) / 0.5e-6), -1)                 # ~ EI_lat (N*mm^2)
    42790.0
    """
    law, P, k = _states(actuator, pressure_kpa, curvature_per_mm, model)
    k2 = float_array("lateral_curvature_per_mm", lateral_curvature_per_mm, "1/mm")
    tw = np.abs(float_array("twist_rad_per_mm", twist_rad_per_mm, "rad/mm"))
    P, k, k2, tw = np.broadcast_arrays(P, k, k2, tw)
    params = actuator.params
    frame = _frame_constants(actuator, frame_shear_modulus_mpa)
    pa = np.maximum(P - law.P_start_kpa, 0.0) * 1e-3  # MPa (P was checked once)
    R_in = radius_state(k, float(params.alpha0), float(params.R0_start))[1]
    return np.real(_energy(params, frame, pa, k, k2.astype(complex), tw.astype(complex), R_in))


class SpatialTable:
    """Spline tables of ``EI_lat``, ``GJ`` and the lock torque over ``k'`` in ``[k_lo, k_hi]`` at one pressure.

    For the rod solvers, which evaluate the stiffnesses at every section and every Newton step
    (complex arguments allowed: complex-step Jacobians).  A C2 cubic spline on ``knots``
    Chebyshev-Lobatto points (clustered toward the ends, where the bladder stiffens near lock-up);
    :attr:`max_rel_error` is the largest error at the midpoints between knots relative to each value
    (checked once), over the inner 90 % of the range: at the ends a crushed bladder near braid lock-up
    stiffens without bound and the spline is only good to a few per cent there.  Outside the range
    the end polynomials extrapolate.

    Examples
    --------
    >>> import bendpam
    >>> tab = SpatialTable(bendpam.physics.presets.be_pam(), 150.0, -0.0470852, 0.0337)
    >>> EI, GJ, T = tab(0.0081583)
    >>> round(float(EI)), round(float(GJ)), round(float(T), 1), tab.max_rel_error < 0.005
    (42752, 6473, 182.3, True)
    """

    def __init__(self, actuator: Actuator, pressure_kpa: float, k_lo: float, k_hi: float, *, model: str | None = None,
                 frame_shear_modulus_mpa: float | None = None, knots: int = 65):
        from scipy.interpolate import CubicSpline

        if not float(k_hi) > float(k_lo):
            raise InputError(f"k_hi = {k_hi:g} 1/mm must be above k_lo = {k_lo:g} 1/mm")
        pad = 1e-3 * (float(k_hi) - float(k_lo))  # the ends may be the lock-up limits themselves
        lo, hi = float(k_lo) + pad, float(k_hi) - pad
        kw: dict[str, Any] = dict(model=model, frame_shear_modulus_mpa=frame_shear_modulus_mpa)
        t = 0.5 * (1.0 - np.cos(np.pi * np.arange(knots) / (knots - 1)))
        self.knots = lo + t * (hi - lo)
        self._check = (actuator, float(pressure_kpa), kw, lo + 0.5 * (t[1:] + t[:-1]) * (hi - lo))
        st = spatial_stiffness(actuator, float(pressure_kpa), self.knots, **kw)
        # the lock torque's smooth slope is tabulated (its clipping at 0 is the user's: a kink a spline cannot fit)
        self._values = np.stack([st.lateral_stiffness_nmm2, st.torsional_stiffness_nmm2_per_rad,
                                 st.parts["lock"]["energy_slope_nmm"]], -1)
        self.coef = CubicSpline(self.knots, self._values).c  # (4, knots - 1, 3)

    @cached_property
    def max_rel_error(self) -> float:
        """The largest relative error at the midpoints between knots, over the inner 90 % of the range."""
        actuator, P, kw, km = self._check
        ex = spatial_stiffness(actuator, P, km, **kw)
        E = np.stack([ex.lateral_stiffness_nmm2, ex.torsional_stiffness_nmm2_per_rad,
                      ex.parts["lock"]["energy_slope_nmm"]], -1)
        F = np.stack([np.real(v) for v in self(km)], -1)
        floor = np.median(np.abs(self._values), axis=0)  # a sign change (the lock torque) is judged on the typical size
        tm = (km - self.knots[0]) / (self.knots[-1] - self.knots[0])
        inner = (tm > 0.05) & (tm < 0.95)
        return float(np.max((np.abs(F - E) / (np.abs(E) + floor))[inner]))

    def __call__(self, curvature_per_mm):
        """``(EI_lat N*mm^2, GJ N*mm^2/rad, T_lock N*mm)`` at the curvatures (any shape, complex allowed).

        ``T_lock`` here is the energy's slope, negative where there is no lock (the rod clips it at 0).
        """
        k = np.asarray(curvature_per_mm)
        j = np.clip(np.searchsorted(self.knots, np.real(k)) - 1, 0, self.knots.size - 2)
        c = self.coef[:, j]  # (4, ..., 3)
        dx = (k - self.knots[j])[..., None]
        v = ((c[0] * dx + c[1]) * dx + c[2]) * dx + c[3]
        return v[..., 0], v[..., 1], v[..., 2]
