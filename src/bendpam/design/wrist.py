r"""A wrist of four bending PAMs around a column (the paper's Figure 9(d)): bend angle, holding load.

Model and assumptions
---------------------
* Four identical actuators (default: the paper's BC-PAM) sit at ``positions_deg`` (0, 90, 180,
  270 deg) around a column, at ``radius_mm`` from its axis.  Each is mounted so that inflating it
  bends the wrist toward its own side: a BC-PAM has its frame toward the column (it bends away
  from the frame), a BE-PAM its frame outward.
* **Shared curvature.**  The wrist bends as one uniform arc of curvature ``kappa`` (1/mm) toward
  the direction ``psi`` in the cross-section; the bending angle is ``theta = kappa L``.  Actuator
  ``i`` at angle ``theta_i`` has the in-plane frame curvature ``k'_i = s kappa cos(psi - theta_i)``
  (``s`` = ``bend_sign``: the sign of its free bending) and the out-of-plane curvature
  ``kappa sin(psi - theta_i)``.
* **Moments add.**  The wrist's bending moment (a vector along the bending direction) is::

      m(kappa, psi) = sum_i [ s M(P_i, k'_i) e_i  -  EI_lat kappa sin(psi - theta_i) e_i_perp ]  -  EI_col kappa e_psi

  with ``M`` the paper's moment law (:class:`bendpam.MomentLaw`; an inactive actuator gives its
  passive moment at ``P = 0``), ``EI_lat`` the out-of-plane (lateral) bending stiffness of one
  actuator and ``EI_col`` that of the column.  The default ``EI_lat`` is the actuator's lateral
  stiffness unpressurised and straight, :func:`bendpam.physics.spatial.lateral_stiffness_nmm2` at
  ``P = 0, k' = 0``: the frame strip about its strong axis plus the bladder tube (45 100 N*mm^2 for
  the paper's BC-PAM, of which the frame's ``E_f t w^3 / 12`` is 35 400).  The actuators that bend
  out of their plane are the passive ones beside the inflated actuator, hence ``P = 0``; the
  pressure raises it by a few per cent (docs/out-of-plane.md).  ``lateral_stiffness_nmm2=0``
  gives the brief's simplest model (only in-plane moments).  The default column is a free joint
  (``EI_col = 0``).
* The radius does not enter the moment balance: the actuators are taken to slide axially at the
  end plate, so that each keeps its inextensible frame length ``L``.  It fixes where the actuators
  sit (reported with the geometry).
* Each actuator must stay on the stable branch of its own moment law (``dM/dk' < 0``); the
  combined equilibrium must be stable (the 2x2 stiffness negative definite).  Otherwise the
  result says ``equilibrium=False`` (a snap-through: the BC-PAM's fold).  The passive actuators
  stiffen the wrist, so the active BC-PAM stays far from its fold curvature and the wrist has an
  equilibrium well above the single actuator's fold pressure (134 kPa with the energy constants).
  The solution is continued in pressure (and load) from the straight wrist.
* **Holding a load** (Figure 9(b), (d) i-ii): the forearm is horizontal, the hand sticks out along
  the wrist, one actuator is on top.  A mass ``load_g`` (default 335 g: the paper's bottle) at
  ``lever_mm`` beyond the end plate (default 100 mm: roughly palm to bottle axis; the paper does
  not say) and an optional hand mass pull down.  With the uniform arc the load point rises by
  ``z(kappa) = (1 - cos kappa L)/kappa + lever sin(kappa L)``, and virtual work gives the equilibrium
  ``L m(kappa) = W dz/dkappa`` (at ``kappa = 0``: the load moment about the wrist's mid-length,
  ``W (L/2 + lever)``).

Units: mm, N, N*mm, kPa (every function takes and returns pressures in kPa), grams, degrees in
names ending ``_deg``.  Bad input raises :class:`bendpam.InputError`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from bendpam.design.parts import G_N_PER_G, checked_pressure_kpa, checked_pressures_kpa, json_number, pressures_checked
from bendpam.design.rod import newton_batch
from bendpam.errors import InputError
from bendpam.infra.accessors import figure
from bendpam.physics import presets
from bendpam.physics.actuator import Actuator
from bendpam.physics.law import MomentLaw, StableBranch
from bendpam.physics.models import normalise_model, resolve_model
from bendpam.physics.spatial import lateral_stiffness_nmm2
from bendpam.validate import number

__all__ = [
    "BOTTLE_G",
    "DEFAULT_LEVER_MM",
    "DEFAULT_RADIUS_MM",
    "Wrist",
    "WristHold",
    "WristState",
    "plot_wrist",
    "wrist_bend",
    "wrist_hold",
    "wrist_moment",
    "wrist_pressures",
    "wrist_sweep",
]

#: default mounting radius of the actuators around the column, mm
DEFAULT_RADIUS_MM = 20.0
#: default lever of the held mass beyond the wrist's end plate, mm
DEFAULT_LEVER_MM = 100.0
#: the paper's bottle of water held horizontally (Figure 9(d) i-ii), g
BOTTLE_G = 335.0


@dataclass(frozen=True)
class Wrist:
    """Four actuators around a column (validated, immutable).

    Parameters
    ----------
    actuator : Actuator
        The actuators (default: the paper's BC-PAM with the model's constants).
    model : {"energy", "force_balance"} or None
        None (default): the actuator's own model (energy when unknown); another than the actuator's warns.
    radius_mm : float
        Mounting radius of the actuators around the column axis, mm (default 20: four tubes of
        17 mm diameter around a thin column).  Geometry only (see the module docstring).
    length_mm : float, optional
        Active length of the wrist, mm (default: the actuator's ``L0_mm``, 145 mm for the presets).
    lateral_stiffness_nmm2 : float, optional
        Out-of-plane bending stiffness of one actuator, N*mm^2 (default: the actuator's, unpressurised
        and straight: :func:`bendpam.physics.spatial.lateral_stiffness_nmm2`).
    column_stiffness_nmm2 : float
        Bending stiffness of the column, N*mm^2 (default 0: a free joint).
    positions_deg : tuple of 4 floats
        Angular positions of the actuators (default 0, 90, 180, 270).

    Examples
    --------
    >>> w = Wrist()                                       # the paper's BC-PAMs around a column
    >>> w.actuator.name, w.radius_mm, w.positions_deg
    ('BC-PAM (paper, energy constants)', 20.0, (0.0, 90.0, 180.0, 270.0))
    """

    actuator: Actuator | None = None
    model: str | None = None
    radius_mm: float = DEFAULT_RADIUS_MM
    length_mm: float | None = None
    lateral_stiffness_nmm2: float | None = None
    column_stiffness_nmm2: float = 0.0
    positions_deg: tuple = (0.0, 90.0, 180.0, 270.0)

    def __post_init__(self):
        s = object.__setattr__
        if self.actuator is None:
            s(self, "actuator", presets.bc_pam(normalise_model(self.model or "energy")))
        if not isinstance(self.actuator, Actuator):
            raise TypeError(f"actuator must be a bendpam.Actuator, got {type(self.actuator).__name__}")
        s(self, "model", resolve_model(self.actuator, self.model))
        if self.actuator.bend_sign == 0:
            raise InputError("the actuator has the neutral braid angle (54.74 deg): it does not bend")
        s(self, "radius_mm", number("radius_mm", self.radius_mm, 0.0, 1e3, unit="mm"))
        L = self.actuator.L0_mm if self.length_mm is None else self.length_mm
        s(self, "length_mm", number("length_mm", L, 0.0, 1e4, lo_open=True, unit="mm"))
        if self.lateral_stiffness_nmm2 is None:
            s(self, "lateral_stiffness_nmm2",
              float(lateral_stiffness_nmm2(self.actuator, 0.0, 0.0, model=self.model)))
        else:
            s(self, "lateral_stiffness_nmm2",
              number("lateral_stiffness_nmm2", self.lateral_stiffness_nmm2, 0.0, unit="N*mm^2"))
        s(self, "column_stiffness_nmm2",
          number("column_stiffness_nmm2", self.column_stiffness_nmm2, 0.0, unit="N*mm^2"))
        pos = tuple(number("positions_deg", p, -360.0, 360.0, unit="deg") for p in self.positions_deg)
        if len(pos) != 4:
            raise InputError(f"positions_deg = {self.positions_deg!r} must give 4 angles (deg)")
        s(self, "positions_deg", pos)

    # actuator and length_mm default to None and are always set by __post_init__: typed views of them
    @property
    def _actuator(self) -> Actuator:
        assert self.actuator is not None, "set by __post_init__"
        return self.actuator

    @property
    def _length_mm(self) -> float:
        assert self.length_mm is not None, "set by __post_init__"
        return self.length_mm

    @property
    def law(self) -> MomentLaw:
        """The actuators' shared moment law under the wrist's model (:meth:`bendpam.MomentLaw.of`)."""
        return MomentLaw.of(self._actuator, self.model)

    @property
    def directions(self) -> np.ndarray:
        """Unit vectors e_i of the actuators' positions, shape (4, 2)."""
        t = np.radians(self.positions_deg)
        return np.stack([np.cos(t), np.sin(t)], axis=1)


@dataclass(frozen=True)
class WristState:
    """Equilibrium of the wrist.

    Attributes
    ----------
    pressures_kpa : the four pressures, kPa.
    curvature : kappa, 1/mm (>= 0).
    direction_deg : bending direction psi in the cross-section, deg (NaN when straight).
    angle_deg : bending angle theta = kappa L, deg.
    actuator_curvatures : the four in-plane frame curvatures k'_i, 1/mm.
    load_moment_nmm : the external moment vector balanced (N*mm, 2 components).
    equilibrium : a stable equilibrium was found on every actuator's stable branch.
    note : why not, else empty.

    Examples
    --------
    >>> state = wrist_bend(Wrist(), (0.0, 150.0, 0.0, 0.0))
    >>> round(state.angle_deg, 1), state.direction_deg, state.equilibrium
    (22.3, 90.0, True)
    """

    pressures_kpa: tuple
    curvature: float
    direction_deg: float
    angle_deg: float
    actuator_curvatures: tuple
    load_moment_nmm: tuple
    equilibrium: bool
    note: str

    def to_dict(self) -> dict[str, Any]:
        """The state as a JSON-ready dict (units in the key names; null: not defined).

        >>> d = wrist_bend(Wrist(), (0.0, 150.0, 0.0, 0.0)).to_dict()
        >>> round(d["angle_deg"], 1), d["direction_deg"], d["pressures_kpa"]
        (22.3, 90.0, [0.0, 150.0, 0.0, 0.0])
        """
        return {"pressures_kpa": [float(p) for p in self.pressures_kpa],
                "curvature_per_mm": json_number(self.curvature), "direction_deg": json_number(self.direction_deg),
                "angle_deg": json_number(self.angle_deg),
                "actuator_curvatures_per_mm": [json_number(k) for k in self.actuator_curvatures],
                "load_moment_nmm": [json_number(m) for m in self.load_moment_nmm],
                "equilibrium": bool(self.equilibrium), "note": self.note or None}


def wrist_pressures(direction_deg: float, pressure_kpa, positions_deg=(0.0, 90.0, 180.0, 270.0)) -> tuple:
    """The four pressures (kPa) that bend the wrist toward ``direction_deg``: the actuator there at
    ``pressure_kpa``, or the two neighbours at that pressure for a direction halfway between them
    (multiples of 45 deg).

    >>> wrist_pressures(90.0, 150.0), wrist_pressures(45.0, 150.0)
    ((0.0, 150.0, 0.0, 0.0), (150.0, 150.0, 0.0, 0.0))
    """
    P = checked_pressure_kpa(pressure_kpa)
    return _wrist_pressures(direction_deg, P, positions_deg)


def _wrist_pressures(direction_deg, P: float, positions_deg) -> tuple:
    d = number("direction_deg", direction_deg, -720.0, 720.0, unit="deg") % 360.0
    pos = np.mod(np.asarray(positions_deg, dtype=float), 360.0)
    diff = np.abs((pos - d + 180.0) % 360.0 - 180.0)
    on = diff < 1e-9
    if np.any(on):
        return tuple(P if o else 0.0 for o in on)
    two = np.argsort(diff)[:2]
    if abs(diff[two[0]] - diff[two[1]]) > 1e-9:
        raise InputError(f"direction_deg = {direction_deg:g} is neither an actuator's direction nor halfway between "
                         f"two (actuators at {', '.join(f'{p:g}' for p in positions_deg)} deg)")
    return tuple(P if i in two else 0.0 for i in range(4))


class _WristLaw:
    def __init__(self, wrist: Wrist, pressures):
        self.w = wrist
        self.s = wrist._actuator.bend_sign
        self.e = wrist.directions
        self.ep = np.stack([-self.e[:, 1], self.e[:, 0]], axis=1)
        self.P = tuple(float(p) for p in pressures)
        law = wrist.law
        self.br: list[StableBranch] = [law.stable_branch(p) for p in self.P]

    def kprime(self, b):
        return self.s * (self.e @ b)

    def moment(self, b):
        """Wrist moment vector m(b) (N*mm) and its Jacobian (N*mm^2) at curvature vector b (1/mm)."""
        kp = self.kprime(b)
        M = np.empty(4)
        dM = np.empty(4)
        for i, br in enumerate(self.br):
            m, d = br.moment(kp[i])
            M[i], dM[i] = float(m), float(d)
        klat = self.ep @ b
        EIl, EIc = self.w.lateral_stiffness_nmm2, self.w.column_stiffness_nmm2
        m = self.s * (M @ self.e) - EIl * (klat @ self.ep) - EIc * b
        J = (self.e.T * dM) @ self.e - EIl * (self.ep.T @ self.ep) - EIc * np.eye(2)  # s^2 = 1
        return m, J

    def inside(self, b) -> tuple[bool, str]:
        kp = self.kprime(b)
        for i, br in enumerate(self.br):
            if not br.k_lo < kp[i] < br.k_hi:
                side = +1 if kp[i] >= br.k_hi else -1
                return False, (f"actuator {i} (at {self.w.positions_deg[i]:g} deg, {self.P[i]:g} kPa) "
                               f"leaves its stable branch: {br.describe_end(side)}")
        return True, ""


def _four_pressures_kpa(pressures_kpa) -> np.ndarray:
    """The four actuator pressures (kPa), validated, as a float array of shape (4,)."""
    P = checked_pressures_kpa(pressures_kpa, "pressures_kpa")
    if P.shape != (4,):
        raise InputError(f"pressures_kpa has {P.size} values; give 4 pressures (kPa), one per actuator")
    return P


def _solve(wrist: Wrist, P: np.ndarray, load_fn=None, b0=None):
    """Newton with continuation in the pressures (kPa, validated) and the load from the straight,
    unpressurised wrist."""
    b = np.zeros(2) if b0 is None else np.array(b0, dtype=float)
    t, step = 0.0, 1.0
    law = None
    note = ""
    scale = max(1.0, float(np.max(np.abs(wrist.law.blocked_moment(P)))))
    while t < 1.0:
        step = min(step, 1.0 - t)
        tt = t + step
        law_t = _WristLaw(wrist, tuple(tt * P))
        total = _balance(law_t, load_fn, tt)
        bb, ok = _equilibrium(law_t, total, b, scale)
        if ok:
            J = total(bb)[1]
            ev = np.linalg.eigvals(0.5 * (J + J.T))
            ok = bool(np.all(ev.real < 0))
        if ok:
            b, t, law = bb, tt, law_t
            step *= 2.0
        else:
            step *= 0.5
            if step < 1.0 / 2048:
                _inside, why = law_t.inside(bb)
                note = (f"no equilibrium: the wrist snaps through at {t:.3g} of the load/pressure path"
                        + (f" ({why})" if why else " (its combined moment law folds)"))
                break
    return b, t, law, note


def _balance(law: _WristLaw, load_fn, t: float):
    """The wrist's moment plus the load's (N*mm) and its Jacobian (N*mm^2) at curvature b, path parameter ``t``."""

    def total(b):
        m, J = law.moment(b)
        if load_fn is not None:
            ml, Jl = load_fn(b, t)
            m, J = m + ml, J + Jl
        return m, J

    return total


def _equilibrium(law: _WristLaw, total, b: np.ndarray, scale: float) -> tuple[np.ndarray, bool]:
    """Newton (:func:`bendpam.design.rod.newton_batch`) on ``total(b) = 0`` from ``b`` (moments over ``scale``),
    every step on the actuators' stable branches; returns the last state and whether it converged."""

    def fun(rows, U):
        return np.array([[total(v)[0] / scale for v in row] for row in U])

    def jac(rows, u):
        return np.array([total(v)[1] / scale for v in u])

    def inside(rows, u):
        return np.array([law.inside(v)[0] for v in u])

    u, ok, _ = newton_batch(fun, b[None, :], -np.inf, np.inf, maxit=50, jac=jac, admissible=inside)
    return u[0], bool(ok[0])


def _state(wrist: Wrist, P, b, t, law, note, load_moment=(0.0, 0.0)) -> WristState:
    if t < 1.0:
        nan = math.nan
        return WristState(tuple(float(p) for p in P), nan, nan, nan, (nan,) * 4, tuple(load_moment), False, note)
    kap = float(np.hypot(*b))
    psi = math.degrees(math.atan2(b[1], b[0])) % 360.0 if kap > 1e-15 else math.nan
    if psi > 360.0 - 1e-6:
        psi = 0.0
    return WristState(tuple(float(p) for p in P), kap, psi, math.degrees(kap * wrist._length_mm),
                      tuple(float(k) for k in law.kprime(b)), tuple(load_moment), True, note)


def _check_wrist(wrist) -> None:
    if not isinstance(wrist, Wrist):
        raise TypeError(f"wrist must be a bendpam.design.Wrist, got {type(wrist).__name__}")


def wrist_bend(wrist: Wrist, pressures_kpa=None, *, direction_deg=None, pressure_kpa=None) -> WristState:
    """Free bending of the wrist.

    Give the four ``pressures_kpa`` (kPa), or ``direction_deg`` and ``pressure_kpa`` (kPa) to inflate
    the actuator(s) of that direction (:func:`wrist_pressures`).

    Examples
    --------
    >>> state = wrist_bend(Wrist(), direction_deg=90.0, pressure_kpa=150.0)
    >>> state.pressures_kpa, round(state.angle_deg, 1)    # kPa, deg
    ((0.0, 150.0, 0.0, 0.0), 22.3)
    """
    _check_wrist(wrist)
    if pressures_kpa is None:
        if direction_deg is None or pressure_kpa is None:
            raise InputError("give the four pressures_kpa, or direction_deg and pressure_kpa")
        P = np.array(_wrist_pressures(direction_deg, checked_pressure_kpa(pressure_kpa), wrist.positions_deg))
    elif direction_deg is not None or pressure_kpa is not None:
        raise InputError("give either the four pressures_kpa or direction_deg and pressure_kpa, not both")
    else:
        P = _four_pressures_kpa(pressures_kpa)
    wrist._actuator.outside_tested(P[P > 0])  # an actuator left unpressurised is not an extrapolation
    return _bend(wrist, P)


def _bend(wrist: Wrist, P: np.ndarray) -> WristState:
    with pressures_checked():
        b, t, law, note = _solve(wrist, P)
    return _state(wrist, P, b, t, law, note)


def wrist_moment(wrist: Wrist, pressures_kpa, angle_deg, direction_deg):
    """The moment the wrist exerts when held at ``angle_deg`` toward ``direction_deg`` (N*mm vector).

    ``pressures_kpa``: the four pressures (kPa).  This is the load it holds there: an external
    moment ``-m`` keeps it at that angle.  Returns ``(m, on_branch, note)``; ``on_branch`` is False
    (with a note) where an actuator is beyond its stable branch at that curvature.

    Examples
    --------
    Held at 10 deg, short of its free 22.3 deg, the wrist pushes on toward 90 deg:

    >>> m, on_branch, note = wrist_moment(Wrist(), (0.0, 150.0, 0.0, 0.0), 10.0, 90.0)
    >>> bool(abs(m[0]) < 1e-9), round(float(m[1]), 1), on_branch    # N*mm
    (True, 340.0, True)
    """
    _check_wrist(wrist)
    P = _four_pressures_kpa(pressures_kpa)
    kap = math.radians(number("angle_deg", angle_deg, unit="deg")) / wrist._length_mm
    d = math.radians(number("direction_deg", direction_deg, unit="deg"))
    with pressures_checked():
        law = _WristLaw(wrist, P)
    b = kap * np.array([math.cos(d), math.sin(d)])
    ok, why = law.inside(b)
    m, _ = law.moment(b)
    return m, ok, why


@dataclass(frozen=True)
class WristHold:
    """The wrist holding a mass horizontally (forearm horizontal, one actuator on top).

    Attributes
    ----------
    pressure_kpa : gauge pressure of the upper actuator, kPa.
    load_g, lever_mm, hand_mass_g, hand_lever_mm : the load case.
    angle_deg : equilibrium bending angle, deg: > 0 the hand is raised above horizontal, < 0 it droops.
    holds_horizontal : ``angle_deg >= 0`` (the wrist keeps the hand at or above horizontal).
    capacity_g : the largest mass at ``lever_mm`` it holds with the hand horizontal (with the hand mass).
    pressure_needed_kpa : pressure of the upper actuator that holds the load exactly horizontal.
    load_moment_nmm : the load's moment at kappa = 0, ``W (L/2 + lever)`` summed, N*mm.
    equilibrium, note : as in :class:`WristState`.

    Examples
    --------
    >>> hold = wrist_hold(Wrist(), 150.0)                 # the paper's 335 g bottle, 100 mm out
    >>> hold.holds_horizontal, round(hold.pressure_needed_kpa)       # kPa
    (True, 140)
    """

    pressure_kpa: float
    load_g: float
    lever_mm: float
    hand_mass_g: float
    hand_lever_mm: float
    angle_deg: float
    holds_horizontal: bool
    capacity_g: float
    pressure_needed_kpa: float
    load_moment_nmm: float
    equilibrium: bool
    note: str

    def to_dict(self) -> dict[str, Any]:
        """The load case and how the wrist holds it, as a JSON-ready dict (units in the key names; null: not defined).

        >>> d = wrist_hold(Wrist(), 150.0).to_dict()
        >>> d["holds_horizontal"], round(d["angle_deg"], 1), round(d["capacity_g"])
        (True, 1.9, 367)
        """
        return {"pressure_kpa": float(self.pressure_kpa), "angle_deg": json_number(self.angle_deg),
                "holds_horizontal": bool(self.holds_horizontal), "capacity_g": json_number(self.capacity_g),
                "equilibrium": bool(self.equilibrium), "note": self.note or None, "load_g": float(self.load_g),
                "lever_mm": float(self.lever_mm), "hand_mass_g": float(self.hand_mass_g),
                "hand_lever_mm": float(self.hand_lever_mm), "load_moment_nmm": json_number(self.load_moment_nmm),
                "pressure_needed_kpa": json_number(self.pressure_needed_kpa)}


def _dz(kap, L, lever):
    """d z / d kappa for the load point of a uniform arc (z = (1 - cos kL)/k + lever sin kL), and its derivative."""
    x = kap * L
    if abs(x) < 1e-4:
        d1 = L * L / 2.0 - L ** 4 * kap ** 2 / 8.0 + lever * L * math.cos(x)
        d2 = -L ** 4 * kap / 4.0 - lever * L * L * math.sin(x)
        return d1, d2
    d1 = (x * math.sin(x) - (1.0 - math.cos(x))) / kap ** 2 + lever * L * math.cos(x)
    d2 = (L * math.sin(x) + x * L * math.cos(x) - L * math.sin(x)) / kap ** 2 \
        - 2.0 * (x * math.sin(x) - (1.0 - math.cos(x))) / kap ** 3 - lever * L * L * math.sin(x)
    return d1, d2


def wrist_hold(wrist: Wrist, pressure_kpa, *, load_g: float = BOTTLE_G, lever_mm: float = DEFAULT_LEVER_MM,
               hand_mass_g: float = 0.0, hand_lever_mm: float = 50.0, up_deg: float = 90.0) -> WristHold:
    """The wrist, forearm horizontal, holding ``load_g`` at ``lever_mm``, upper actuator at ``pressure_kpa`` (kPa).

    The actuator at ``up_deg`` (default 90) is on top and inflated; the others are at P = 0.
    Gravity acts toward ``up_deg + 180``.  See the module docstring for the model.

    Examples
    --------
    >>> w = Wrist()
    >>> wrist_hold(w, 100.0).holds_horizontal, wrist_hold(w, 150.0).holds_horizontal
    (False, True)
    """
    _check_wrist(wrist)
    P = checked_pressure_kpa(pressure_kpa, actuator=wrist._actuator)
    mL = number("load_g", load_g, 0.0, unit="g")
    lev = number("lever_mm", lever_mm, 0.0, unit="mm")
    mh = number("hand_mass_g", hand_mass_g, 0.0, unit="g")
    levh = number("hand_lever_mm", hand_lever_mm, 0.0, unit="mm")
    # which actuator is on top (a pressure of 1 kPa marks it: the layout does not depend on P)
    top = _wrist_pressures(up_deg, 1.0, wrist.positions_deg)
    if sum(p > 0 for p in top) != 1:
        raise InputError(f"up_deg = {up_deg:g} must be the direction of one actuator ({wrist.positions_deg} deg)")
    L = wrist._length_mm
    u = np.array([math.cos(math.radians(up_deg)), math.sin(math.radians(up_deg))])
    W1, W2 = mL * G_N_PER_G, mh * G_N_PER_G

    def load_fn(b, t):
        # generalised load moment along u (virtual work): -(W dz/dkappa)/L, for the bending component along u
        kap = float(b @ u)
        d1a, d2a = _dz(kap, L, lev)
        d1b, d2b = _dz(kap, L, levh)
        ml = -t * (W1 * d1a + W2 * d1b) / L
        dml = -t * (W1 * d2a + W2 * d2b) / L
        return ml * u, dml * np.outer(u, u)

    pressures = np.array([P if p > 0 else 0.0 for p in top])
    with pressures_checked():
        b, t, _, note = _solve(wrist, pressures, load_fn)
    M0 = (W1 * (L / 2 + lev) + W2 * (L / 2 + levh))
    # capacity and pressure needed: at kappa = 0 only the upper actuator's blocked moment acts
    law = wrist.law
    act = wrist._actuator
    s = act.bend_sign
    with pressures_checked():
        m_block = s * float(law.blocked_moment(P))  # the upper actuator's blocked moment magnitude
        # dM_blocked/dP (N*mm per kPa of active pressure): the blocked moment is linear in P_a (eq 50)
        slope = abs(float(law.blocked_moment(act.P_start_kpa + 1.0)))
    cap = max((m_block - W2 * (L / 2 + levh)) / (G_N_PER_G * (L / 2 + lev)), 0.0)
    p_need = act.P_start_kpa + M0 / slope
    if t < 1.0:
        return WristHold(P, mL, lev, mh, levh, math.nan, False, cap, p_need, M0, False, note)
    ang = math.degrees(float(b @ u) * L)
    return WristHold(P, mL, lev, mh, levh, ang, ang >= -1e-9, cap, p_need, M0, True, "")


def wrist_sweep(wrist: Wrist, pressures_kpa, directions_deg=(0.0, 90.0, 180.0, 270.0)):
    """Free bending against pressure (kPa) in each direction: a :class:`pandas.DataFrame`.

    Columns ``direction_deg``, ``pressure_kpa``, ``angle_deg``, ``bend_direction_deg``,
    ``curvature_per_mm``, ``equilibrium``, ``note``.

    Examples
    --------
    >>> table = wrist_sweep(Wrist(), [100.0, 150.0], directions_deg=(0.0, 90.0))
    >>> table[["direction_deg", "pressure_kpa", "angle_deg"]].round(1).values.tolist()
    [[0.0, 100.0, 13.4], [0.0, 150.0, 22.3], [90.0, 100.0, 13.4], [90.0, 150.0, 22.3]]
    """
    import pandas as pd

    _check_wrist(wrist)
    Ps = checked_pressures_kpa(pressures_kpa, actuator=wrist._actuator)
    dirs = [number("directions_deg", d, -720.0, 720.0, unit="deg")
            for d in np.atleast_1d(np.asarray(directions_deg, dtype=object)).ravel()]
    rows = []
    for d in dirs:
        for p in Ps:
            st = _bend(wrist, np.array(_wrist_pressures(d, float(p), wrist.positions_deg)))
            rows.append({"direction_deg": d, "pressure_kpa": float(p), "angle_deg": st.angle_deg,
                         "bend_direction_deg": st.direction_deg, "curvature_per_mm": st.curvature,
                         "equilibrium": st.equilibrium, "note": st.note})
    return pd.DataFrame(rows)


def plot_wrist(table, holds=(), ax=None, title: str | None = None, positions_deg=(0.0, 90.0, 180.0, 270.0)):
    """Bending angle against pressure per inflated actuator: :func:`bendpam.present.figures.design.plot_wrist`,
    reached lazily (its parameters and figure are documented there).

    Examples
    --------
    >>> fig = plot_wrist(wrist_sweep(Wrist(), [100.0, 150.0], directions_deg=(90.0,)))
    >>> len(fig.axes) >= 1                                # fig.savefig("wrist.png") to keep it
    True
    """
    return figure("wrist")(table, holds, ax=ax, title=title, positions_deg=positions_deg)
