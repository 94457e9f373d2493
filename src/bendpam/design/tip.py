r"""The fingertip of a finger held or pushed: blocked tip force and tip stiffness.

* :func:`blocked_tip_force`: the force that holds the fingertip point at a target (a roller along
  a direction, as a force sensor, or a pin), found by continuation from the free or unpressurised
  finger to the target (:func:`bendpam.design.rod.continuation`).
* :func:`tip_stiffness`: the 3x3 tangent stiffness of the tip pose at an equilibrium, from the
  exact (complex-step) Jacobian of the finger's equations; :func:`linear_tip_compliance` is its
  linear beam-theory reference for the free finger.

The finger, its loads and its equilibrium shape are those of :mod:`bendpam.design.finger`.

Units: mm, N, N*mm, kPa (``pressure_kpa``), rad inside (degrees in names ending ``_deg``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from bendpam.design.finger import Finger, FingerLoads, FingerShape, check_finger, solve_finger
from bendpam.design.parts import checked_pair, checked_pressure_kpa, json_number, pressures_checked
from bendpam.design.rod import Rod, complex_jacobian, continuation, cross
from bendpam.errors import NoEquilibrium
from bendpam.validate import number

__all__ = [
    "BlockedTipForce",
    "TipStiffness",
    "blocked_tip_force",
    "linear_tip_compliance",
    "tip_stiffness",
]


@dataclass(frozen=True)
class BlockedTipForce:
    """The force that holds the fingertip point at a target.

    Attributes
    ----------
    force_n : (Fx, Fy) applied to the tip by the holder, N (the finger pushes with the opposite).
    target_xy : the target point, mm.
    constraint : ``"roller"`` (only the tip's coordinate along ``direction`` is held, the force acts
        along ``direction``) or ``"pin"`` (both coordinates held).
    direction : unit vector of the roller (None for a pin).
    shape : the held :class:`FingerShape` (its ``loads`` include the holding force).
    equilibrium, note : as in :class:`FingerShape`.

    Examples
    --------
    >>> import bendpam
    >>> held = blocked_tip_force(Finger(bendpam.physics.presets.be_pam()), 150.0)
    >>> held.constraint, [round(f, 3) for f in held.force_n], held.equilibrium    # N
    ('roller', [0.0, -2.053], True)
    """

    force_n: tuple[float, float]
    target_xy: tuple[float, float]
    constraint: str
    direction: tuple[float, float] | None
    shape: FingerShape
    equilibrium: bool
    note: str

    @property
    def magnitude_n(self) -> float:
        """The holding force's magnitude, N."""
        return math.hypot(*self.force_n)

    def to_dict(self) -> dict[str, Any]:
        """The holding force as a JSON-ready dict (``force_n`` null without an equilibrium).

        >>> import bendpam
        >>> blocked_tip_force(Finger(bendpam.physics.presets.be_pam()), 150.0).to_dict()["force_n"]
        [0.0, -2.053...]
        """
        return {"force_n": [json_number(f) for f in self.force_n] if self.equilibrium else None,
                "target_xy_mm": [json_number(v) for v in self.target_xy], "constraint": self.constraint,
                "direction": None if self.direction is None else [float(v) for v in self.direction],
                "equilibrium": bool(self.equilibrium), "note": self.note or None}


def _straight_tip(finger: Finger) -> tuple[float, float]:
    p = finger.base_angle
    x0, y0 = finger.base_xy_mm
    L = finger.length + finger.fingertip_mm
    o = finger.bend * finger.fingertip_offset_mm
    return x0 + L * math.cos(p) - o * math.sin(p), y0 + L * math.sin(p) + o * math.cos(p)


def blocked_tip_force(finger: Finger, pressure_kpa, target_xy_mm=None, direction_deg=None,
                      loads: FingerLoads | None = None) -> BlockedTipForce:
    """Force needed to hold the fingertip at a target point.

    Parameters
    ----------
    finger : Finger
    pressure_kpa : float, kPa.
    target_xy_mm : (x, y), optional
        Target point, mm.  Default: the straight (unpressurised) tip position, held by a roller
        normal to the base direction, as a force sensor measures a blocked force (a pin there would
        need an infinite force: an inextensible rod reaches distance L only when exactly straight).
    direction_deg : float, optional
        Hold only the tip coordinate along this direction (degrees counterclockwise from +x) with a
        frictionless roller; the force acts along it.  Default with ``target_xy_mm``: a pin (both
        coordinates held, any force direction).
    loads : FingerLoads, optional
        Further loads acting together with the holding force.

    Notes
    -----
    The force components are extra unknowns and the held coordinates extra equations; the target
    is reached by continuation from the free (or loaded) tip.  If the holder cannot be reached on
    the stable branch (a fold: snap-through), ``equilibrium`` is False with a note.

    Examples
    --------
    The force a sensor at the straight tip position measures at 150 kPa:

    >>> import bendpam
    >>> held = blocked_tip_force(Finger(bendpam.physics.presets.be_pam()), 150.0)
    >>> round(held.force_n[1], 3)                         # N, on the tip (the finger pushes up)
    -2.053
    """
    loads = check_finger(finger, loads)
    P = checked_pressure_kpa(pressure_kpa, actuator=finger.actuator)
    if target_xy_mm is None:
        target = _straight_tip(finger)
        if direction_deg is None:
            p = finger.base_angle
            direction = (-finger.bend * math.sin(p), finger.bend * math.cos(p))
        else:
            d = math.radians(number("direction_deg", direction_deg, unit="deg"))
            direction = (math.cos(d), math.sin(d))
    else:
        target = checked_pair("target_xy_mm", target_xy_mm, "mm")
        if direction_deg is None:
            direction = None
        else:
            d = math.radians(number("direction_deg", direction_deg, unit="deg"))
            direction = (math.cos(d), math.sin(d))
    with pressures_checked():
        return _blocked_tip_force(finger, P, target, direction, target_xy_mm is not None, loads)


def _blocked_tip_force(finger: Finger, P: float, target, direction, given_target: bool,
                       loads: FingerLoads) -> BlockedTipForce:
    """:func:`blocked_tip_force` with validated arguments (P in kPa, ``direction`` a unit vector or None)."""
    constraint = "pin" if direction is None else "roller"
    start = solve_finger(finger, P, loads)
    rod = Rod(finger, loads)
    try:
        br = finger.branch(P)
    except NoEquilibrium as exc:
        return BlockedTipForce((math.nan, math.nan), target, constraint, direction, start, False, str(exc))
    n = rod.n
    c = rod.c
    Lr = rod.L + rod.ell
    scale = rod.moment_scale(br)
    fscale = max(scale / Lr, 1e-3)
    nf = 2 if direction is None else 1

    def make(P_t, tx, ty):
        b = finger.branch(P_t)

        def fun(U):
            k = U[..., :n]
            if direction is None:
                gx, gy = U[..., n] * fscale, U[..., n + 1] * fscale
            else:
                gx, gy = U[..., n] * fscale * direction[0], U[..., n] * fscale * direction[1]
            _phi, x, y, xt, yt = rod.geometry(k)
            m = rod.load_moment(x, y, xt, yt) + cross(xt[..., None] - x, yt[..., None] - y,
                                                      gx[..., None], gy[..., None])
            M, _ = b.moment(k)
            r1 = (M + c * m) / scale
            if direction is None:
                extra = [((xt - tx) / Lr)[..., None], ((yt - ty) / Lr)[..., None]]
            else:
                extra = [(((xt - tx) * direction[0] + (yt - ty) * direction[1]) / Lr)[..., None]]
            return np.concatenate([r1, *extra], axis=-1)

        lo = np.concatenate([np.full(n, b.k_lo), np.full(nf, -np.inf)])
        hi = np.concatenate([np.full(n, b.k_hi), np.full(nf, np.inf)])
        return fun, lo, hi

    tgt = np.array(target)
    straight = np.array(_straight_tip(finger))
    P0 = min(P, finger.actuator.P_start_kpa)
    paths: list[tuple[np.ndarray, Callable[[float], Any]]] = []
    if given_target and start.equilibrium:
        # move the holder from the free tip to the target at the working pressure
        t0 = np.array(start.tip_xy)

        def toward_target(t: float, t0: np.ndarray = t0):
            return make(P, *(t0 + t * (tgt - t0)))

        paths.append((np.concatenate([start.curvature, np.zeros(nf)]), toward_target))
    # as a test rig does: hold the tip from the straight, unpressurised state while the pressure rises
    # (first move the holder to the target at P0, then raise the pressure)
    paths.append((np.zeros(n + nf),
                  lambda t: make(P0, *(straight + min(2 * t, 1.0) * (tgt - straight))) if t <= 0.5
                  else make(P0 + (2 * t - 1.0) * (P - P0), *tgt)))
    t_best = 0.0
    for u0, system in paths:
        u, t_reached = continuation(system, u0)
        t_best = max(t_best, t_reached)
        if t_reached >= 1.0:
            break
    else:
        what = "roller" if direction is not None else "pin"
        why = "" if start.equilibrium else f" (no unloaded equilibrium: {start.note})"
        note = (f"no equilibrium holds the tip with a {what} at ({target[0]:.4g}, {target[1]:.4g}) mm: the finger "
                f"snaps through on the way (continuation stops at {t_best:.3g} of the path){why}")
        sh = FingerShape.failure(rod, br, P, loads, note, lam=t_best)
        return BlockedTipForce((math.nan, math.nan), target, constraint, direction, sh, False, note)
    if direction is None:
        F = (float(u[n] * fscale), float(u[n + 1] * fscale))
    else:
        F = (float(u[n] * fscale * direction[0]), float(u[n] * fscale * direction[1]))
    total = replace(loads, tip_force_n=(loads.tip_force_n[0] + F[0], loads.tip_force_n[1] + F[1]))
    sh = FingerShape.from_curvature(Rod(finger, total), u[:n], br, P, total)
    return BlockedTipForce(F, target, constraint, direction, sh, True, "")


@dataclass(frozen=True)
class TipStiffness:
    """Tangent stiffness of the fingertip at an equilibrium.

    ``matrix`` maps small changes of the tip load ``(dFx, dFy, dM)`` (N, N, N*mm) to the tip pose
    ``(dx, dy, dphi)`` (mm, mm, rad) by ``compliance``; ``matrix = inv(compliance)``.  Both include the
    geometric stiffness of the loads already acting; for dead loads they are symmetric.

    Examples
    --------
    >>> import numpy as np, bendpam
    >>> ts = tip_stiffness(Finger(bendpam.physics.presets.be_pam()), 150.0)
    >>> ts.matrix.shape, bool(np.allclose(ts.matrix @ ts.compliance, np.eye(3)))
    ((3, 3), True)
    """

    matrix: np.ndarray
    compliance: np.ndarray
    shape: FingerShape


def tip_stiffness(finger: Finger, pressure_kpa, loads: FingerLoads | None = None) -> TipStiffness:
    """Tip stiffness matrix (3x3) at the equilibrium at ``pressure_kpa`` (kPa) under ``loads``.

    From the exact (complex-step) Jacobian.  Raises :class:`~bendpam.errors.NoEquilibrium` where the
    finger has no stable equilibrium under these loads.

    Examples
    --------
    Unloaded, it agrees with linear beam theory (:func:`linear_tip_compliance`):

    >>> import numpy as np, bendpam
    >>> finger = Finger(bendpam.physics.presets.be_pam())
    >>> ts = tip_stiffness(finger, 150.0)
    >>> bool(np.allclose(ts.compliance, linear_tip_compliance(finger, 150.0), rtol=1e-3, atol=1e-6))
    True
    """
    loads = check_finger(finger, loads)
    P = checked_pressure_kpa(pressure_kpa, actuator=finger.actuator)
    with pressures_checked():
        sh = solve_finger(finger, P, loads)
    br = sh.branch
    if not sh.equilibrium or br is None:
        raise NoEquilibrium(f"no equilibrium at pressure_kpa = {P:g} kPa under these loads: {sh.note}")
    rod = Rod(finger, loads)
    n = rod.n
    c = rod.c
    k = sh.curvature

    def fun(U):  # unknowns k, then the load increment (dFx, dFy, dM)
        kk = U[..., :n]
        _phi, x, y, xt, yt = rod.geometry(kk)
        dF = U[..., n:]
        m = rod.load_moment(x, y, xt, yt) + dF[..., 2:3] + cross(xt[..., None] - x, yt[..., None] - y,
                                                                  dF[..., 0:1], dF[..., 1:2])
        M, _ = br.moment(kk)
        return M + c * m

    def pose(U):
        phi, _x, _y, xt, yt = rod.geometry(U[..., :n])
        return np.stack([xt, yt, phi[..., -1]], axis=-1)

    u = np.concatenate([k, np.zeros(3)])
    J = complex_jacobian(fun, u)
    Jk, JF = J[:, :n], J[:, n:]
    try:
        dk = -np.linalg.solve(Jk, JF)
        Q = complex_jacobian(pose, u)
        C = Q[:, :n] @ dk
        K = np.linalg.inv(C)
    except np.linalg.LinAlgError:
        raise NoEquilibrium(
            f"pressure_kpa = {sh.pressure_kpa:g}: the tip compliance is singular (the finger is straight and "
            "inextensible, so its tip stiffness along its axis is unbounded); use linear_tip_compliance or a "
            "pressure that bends it") from None
    return TipStiffness(K, C, sh)


def linear_tip_compliance(finger: Finger, pressure_kpa) -> np.ndarray:
    """Linear beam-theory compliance (3x3) of the free finger: reference for the nonlinear solver.

    With the free (constant) curvature and the tangent stiffness ``K = dM/dk'`` there (negative), a
    small tip load changes the curvature by ``dk' = dM_ext / K`` and the tip pose by the integral of
    the rotations, with no geometric stiffness (the finger is unloaded).  Integrated on 1001 nodes.
    Pressure in kPa; raises :class:`~bendpam.errors.NoEquilibrium` above the free branch.

    Examples
    --------
    >>> import bendpam
    >>> c = linear_tip_compliance(Finger(bendpam.physics.presets.be_pam()), 150.0)
    >>> round(float(c[1, 1]), 2)                          # mm of tip travel per N of vertical tip force
    26.96
    """
    check_finger(finger, None)
    P = checked_pressure_kpa(pressure_kpa, actuator=finger.actuator)
    law = finger.law
    with pressures_checked():
        fb = law.free_curvature(P)
        if fb.status == "no-equilibrium":
            raise NoEquilibrium(f"pressure_kpa = {P:g} kPa has no free-bending equilibrium: {fb.reason}")
        k = float(fb.curvature_per_mm)
        K = float(law.tangent_stiffness(P, k))
    fine = replace(finger, nodes=1001)
    rod = Rod(fine, FingerLoads())
    _phi, x, y, xt, yt = rod.geometry(np.full((1, rod.n), k))
    x, y, xt, yt = x[0], y[0], float(xt[0]), float(yt[0])
    ax, ay = xt - x, yt - y  # lever from each section to the tip
    # unit loads: Fx, Fy, M -> m(s) (counterclockwise moment) -> dkappa = c dk' = c (-c m)/K = -m/K
    ms = [cross(ax, ay, 1.0, 0.0), cross(ax, ay, 0.0, 1.0), np.ones_like(ax)]
    C = np.zeros((3, 3))
    for j, m in enumerate(ms):
        dkap = -m / K
        w = rod.w
        C[0, j] = np.sum(w * dkap * -ay)  # rotation about s moves the tip by dtheta * z x (tip - r)
        C[1, j] = np.sum(w * dkap * ax)
        C[2, j] = np.sum(w * dkap)
    return C
