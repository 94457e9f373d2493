r"""A bending-PAM finger under in-plane loads: equilibrium shape, tip pose, structural limits.

The fingertip held at a target (blocked force) and the tip stiffness are in
:mod:`bendpam.design.tip`; the discretised rod and the Newton method all of them share are in
:mod:`bendpam.design.rod`.

Model
-----
The actuator is an inextensible rod along its frame line, of length ``L0`` (the active length).
With arc length ``s`` (mm), tangent angle ``phi(s)`` (rad, counterclockwise from +x) and position
``(x(s), y(s))`` (mm)::

    dx/ds = cos phi,   dy/ds = sin phi,   dphi/ds = c k'(s)

where ``k'`` is the frame curvature of the paper (1/mm, > 0 toward the frame) and ``c = +-1`` is the
*frame side* of the mounting (below).  At each ``s`` the section is in equilibrium::

    M_load(P, k'(s)) = M_ext(s)

``M_load`` is the actuator's output moment (the moment law, :class:`bendpam.MomentLaw`) and
``M_ext`` is the moment of every load beyond ``s`` about the point ``(x(s), y(s))``, written in the
actuator's sign convention: ``M_ext = -c m(s)`` where ``m(s)`` is the counterclockwise moment of
those loads.  A load that resists bending gives ``M_ext`` of the sign of the blocked moment and a
smaller ``|k'|``.  The loads are a tip force in any in-plane direction, a tip moment, a point mass
at the fingertip, a distributed self-weight (mass per length), and the contact forces of
:mod:`bendpam.design.grasp`.  A rigid fingertip of length ``fingertip_mm`` continues the rod along
its end tangent; its end point, shifted ``fingertip_offset_mm`` toward the bending side, is where
tip loads act and is reported as the tip.

Mounting and signs
------------------
``bend = +1`` (``"ccw"``) makes the finger curl counterclockwise when inflated, ``-1`` (``"cw"``)
clockwise.  A BE-PAM bends toward its frame and a BC-PAM away from it, so the frame side is
``c = bend * actuator.bend_sign``: a BC-PAM finger is mounted with its frame on the other side and
then bends the same geometric way as a BE-PAM finger with the same ``bend``.  Mirroring the base,
``bend`` and all loads about a line mirrors the shape (tested).

Numerics
--------
(:mod:`bendpam.design.rod`.)  Collocation on ``n`` equally spaced nodes (default 81): the unknowns
are the nodal curvatures;
``phi`` is their trapezoidal integral and every segment is integrated exactly as a circular arc of
linearly varying angle, so a constant-curvature (free) shape is exact.  The moment law is the
actuator's shared :class:`bendpam.MomentLaw` (``MomentLaw.of(actuator, model)``); the solver uses
its **stable branch** (:meth:`bendpam.MomentLaw.stable_branch`, from the law's spline table: a C2
cubic spline on Chebyshev-Lobatto knots, relative error below 1e-6): the interval of ``k'`` around
the straight state on which ``dM/dk' < 0``.  It ends at a fold of the moment law (the BC-PAM's
N-shaped law, and the BE-PAM's at large curvature) or at braid lock-up.  Every Newton step is kept
inside that interval, so a curvature on the unstable (snapped) part of the law is never returned.

The nonlinear equations are solved by a damped Newton method with an exact (complex-step)
Jacobian, by continuation in the load fraction from the free shape (constant free curvature).
When the loads ask for more moment than the stable branch can supply anywhere along the finger,
the continuation stops at a load fraction below one: the result has ``equilibrium=False``, NaN
shape arrays and a note (snap-through at the fold, or lock-up); the last equilibrium reached is in
``.limit``.  Above the BC-PAM's fold pressure there is no free shape; the solver then looks for a
loaded equilibrium on the stable branch directly and says so in the note.  Each equilibrium is also
checked for structural stability (the weighted, symmetrised Jacobian must be negative definite:
the second variation of the potential energy of dead loads).  The reported ``residual_nmm`` is
``max |M(P, k'(s)) - M_ext(s)|`` along ``s`` with the exact law (:meth:`bendpam.MomentLaw.moment`,
not the table).

Units: mm, N, N*mm, kPa (every function takes and returns pressures in kPa, ``pressure_kpa``), rad
inside (degrees in names ending ``_deg``).  Masses are given in grams, weights use
g = 9.80665 m/s^2.  Bad input raises :class:`bendpam.InputError`; a pressure given in MPa by
mistake (every nonzero value below 5 kPa) warns with :class:`bendpam.UnitWarning`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from bendpam.design.parts import (
    G_N_PER_G,
    checked_pair,
    checked_pressure_kpa,
    checked_pressures_kpa,
    json_number,
    pressures_checked,
)
from bendpam.design.rod import NEWTON_TOL, Rod, complex_jacobian, continuation, newton, sinc
from bendpam.errors import InputError, NoEquilibrium
from bendpam.infra.accessors import figure
from bendpam.infra.display import summary_html, summary_text
from bendpam.physics.actuator import Actuator
from bendpam.physics.law import MomentLaw, StableBranch
from bendpam.physics.models import resolve_model
from bendpam.validate import number

if TYPE_CHECKING:
    from bendpam.physics.hysteresis import LoopModel

__all__ = [
    "Finger",
    "FingerLimits",
    "FingerLoads",
    "FingerShape",
    "StableBranch",
    "check_finger",
    "finger_limits",
    "finger_sweep",
    "free_tip_trajectory",
    "plot_finger_shapes",
    "solve_finger",
    "stable_branch",
]


# ------------------------------------------------------------------------------------------------
# the moment law on its stable branch
# ------------------------------------------------------------------------------------------------
def stable_branch(actuator: Actuator, pressure_kpa, model: str | None = None,
                  friction_nmm: float = 0.0) -> StableBranch:
    """The stable branch of the moment law at ``pressure_kpa`` (kPa): see :class:`bendpam.StableBranch`.

    Shorthand for ``MomentLaw.of(actuator, model).stable_branch(pressure_kpa, friction_nmm)``.
    ``friction_nmm`` shifts the law by a saturated hysteretic moment, ``M = M_load - friction``
    (signed, bendpam's convention): see :meth:`Finger.friction_nmm`.  Raises
    :class:`~bendpam.errors.NoEquilibrium` when the straight state is unstable at that pressure.

    Examples
    --------
    >>> import bendpam
    >>> sb = stable_branch(bendpam.physics.presets.be_pam(), 150.0)
    >>> round(sb.k_hi, 5), sb.end_hi, round(sb.free_curvature, 5)     # 1/mm
    (0.03371, 'fold', 0.00816)
    """
    if not isinstance(actuator, Actuator):
        raise TypeError(f"actuator must be a bendpam.Actuator, got {type(actuator).__name__}")
    P = checked_pressure_kpa(pressure_kpa, actuator=actuator)
    fr = number("friction_nmm", friction_nmm, unit="N*mm")
    with pressures_checked():
        return MomentLaw.of(actuator, model).stable_branch(P, fr)


# ------------------------------------------------------------------------------------------------
# finger, loads, results
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Finger:
    """A bending-PAM finger and its mounting (validated, immutable).

    Parameters
    ----------
    actuator : Actuator
        The actuator; its ``L0_mm`` is the finger's active length.
    model : {"energy", "force_balance"} or None
        None (default): the actuator's own model (energy when unknown); another than the actuator's warns.
    base_xy_mm : (float, float)
        Position of the frame line's base, mm.
    base_angle_deg : float
        Direction of the finger at its base, degrees counterclockwise from +x (default 0:
        horizontal, pointing along +x).
    bend : {+1, -1} or {"ccw", "cw"}
        Direction in which the finger curls when inflated (default counterclockwise).  The
        frame side follows: ``frame_side = bend * actuator.bend_sign``.
    fingertip_mm : float
        Length of a rigid fingertip along the end tangent, mm, >= 0.
    fingertip_offset_mm : float
        Lateral offset of the fingertip point toward the bending side, mm.
    nodes : int
        Collocation nodes along the active length, in [11, 1001] (default 81).
    loop : bendpam.physics.hysteresis.LoopModel, optional
        A fitted hysteresis loop (``bendpam fit --hysteresis``).  With it the moment law is shifted
        by the saturated friction moment ``A(P)`` against the motion: ``motion="unloading"`` (the
        finger opening toward its free shape, the lower branch) or ``"loading"`` (being pushed
        back, the upper branch), so loading and unloading shapes differ.  Saturation assumes the
        finger moved more than the loop's angle since the last reversal.
    motion : {"unloading", "loading"}

    Examples
    --------
    >>> import bendpam
    >>> finger = Finger(bendpam.physics.presets.be_pam(), base_angle_deg=-90.0)   # hanging, curling counterclockwise
    >>> shape = solve_finger(finger, 150.0)
    >>> [round(v, 2) for v in shape.tip_xy]                   # mm
    [76.22, -113.47]
    """

    actuator: Actuator
    model: str | None = None
    base_xy_mm: tuple[float, float] = (0.0, 0.0)
    base_angle_deg: float = 0.0
    bend: int = 1
    fingertip_mm: float = 0.0
    fingertip_offset_mm: float = 0.0
    nodes: int = 81
    loop: LoopModel | None = None
    motion: str = "unloading"

    def __post_init__(self):
        s = object.__setattr__
        if not isinstance(self.actuator, Actuator):
            raise TypeError(f"actuator must be a bendpam.Actuator, got {type(self.actuator).__name__}")
        if self.actuator.bend_sign == 0:
            raise InputError(f"alpha0_deg = {self.actuator.alpha0_deg:g} deg is the neutral braid angle: "
                             "the actuator does not bend, so it cannot be a finger")
        s(self, "model", resolve_model(self.actuator, self.model))
        s(self, "base_xy_mm", checked_pair("base_xy_mm", self.base_xy_mm, "mm"))
        s(self, "base_angle_deg", number("base_angle_deg", self.base_angle_deg, -720.0, 720.0, unit="deg"))
        b = self.bend
        if isinstance(b, str):
            key = b.strip().lower()
            if key not in ("ccw", "cw"):
                raise InputError(f"bend = {b!r} is not allowed; choose 'ccw' (+1) or 'cw' (-1)")
            b = 1 if key == "ccw" else -1
        if isinstance(b, bool) or b not in (1, -1):
            raise InputError(f"bend = {b!r} is not allowed; choose +1 (ccw) or -1 (cw)")
        s(self, "bend", int(b))
        s(self, "fingertip_mm", number("fingertip_mm", self.fingertip_mm, 0.0, 1e4, unit="mm"))
        s(self, "fingertip_offset_mm", number("fingertip_offset_mm", self.fingertip_offset_mm, -1e4, 1e4, unit="mm"))
        n = self.nodes
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or not 11 <= int(n) <= 1001:
            raise InputError(f"nodes = {n!r} is outside the allowed range [11, 1001] (an integer)")
        s(self, "nodes", int(n))
        if self.motion not in ("unloading", "loading"):
            raise InputError(f"motion = {self.motion!r}; choose 'unloading' or 'loading'")
        if self.loop is not None and not hasattr(self.loop, "amplitude_nmm"):
            raise TypeError("loop must be a bendpam.physics.hysteresis.LoopModel")

    def friction_nmm(self, pressure_kpa) -> float:
        """Signed saturated friction moment ``A(P) z`` (N*mm) at ``pressure_kpa`` (kPa); 0 without a loop.

        ``z = bend_sign`` while the actuator opens toward its free shape (unloading) and
        ``-bend_sign`` while it is pushed back (loading); the law becomes ``M_load - A z``.
        """
        P = checked_pressure_kpa(pressure_kpa)
        if self.loop is None:
            return 0.0
        z = self.actuator.bend_sign * (1.0 if self.motion == "unloading" else -1.0)
        with pressures_checked():
            return float(self.loop.amplitude_nmm(self.actuator, P, 0.0)) * z

    @property
    def law(self) -> MomentLaw:
        """The actuator's shared moment law under the finger's model (:meth:`bendpam.MomentLaw.of`)."""
        return MomentLaw.of(self.actuator, self.model)

    def branch(self, pressure_kpa: float) -> StableBranch:
        """The stable branch the finger rests on at ``pressure_kpa`` (kPa), shifted by its friction moment.

        Raises :class:`~bendpam.errors.NoEquilibrium` when the straight state is unstable.
        """
        P = checked_pressure_kpa(pressure_kpa)
        with pressures_checked():
            return self.law.stable_branch(P, self.friction_nmm(P))

    @property
    def length(self) -> float:
        """Active length L0, mm."""
        return self.actuator.L0_mm

    @property
    def frame_side(self) -> int:
        """+1 if the frame lies on the counterclockwise side of the rod, -1 otherwise."""
        return self.bend * self.actuator.bend_sign

    @property
    def base_angle(self) -> float:
        return math.radians(self.base_angle_deg)

    def mirrored(self, axis_angle_deg: float = 0.0) -> Finger:
        """The mirror image about the line through the origin at ``axis_angle_deg``."""
        a = math.radians(axis_angle_deg)
        x, y = self.base_xy_mm
        c2, s2 = math.cos(2 * a), math.sin(2 * a)
        return replace(self, base_xy_mm=(c2 * x + s2 * y, s2 * x - c2 * y),
                       base_angle_deg=2 * axis_angle_deg - self.base_angle_deg, bend=-self.bend)


@dataclass(frozen=True)
class FingerLoads:
    """In-plane loads on a finger (dead loads: fixed directions).

    Parameters
    ----------
    tip_force_n : (Fx, Fy)
        Force on the fingertip point, N, in the plane's axes.
    tip_moment_nmm : float
        Moment on the tip, N*mm, counterclockwise positive.
    tip_mass_g : float
        Point mass at the fingertip point, g (its weight acts along ``gravity``).
    mass_per_length_g_per_mm : float
        Self-weight of the actuator, g/mm, uniform along the active length.
    gravity : (gx, gy)
        Direction of gravity in the plane (normalised here); default ``(0, -1)``.

    Examples
    --------
    >>> import bendpam
    >>> loads = FingerLoads(tip_force_n=(0.0, -0.5), tip_mass_g=20.0)   # 0.5 N down and a 20 g mass
    >>> shape = solve_finger(Finger(bendpam.physics.presets.be_pam()), 150.0, loads)
    >>> shape.equilibrium, shape.loads.tip_mass_g
    (True, 20.0)
    """

    tip_force_n: tuple[float, float] = (0.0, 0.0)
    tip_moment_nmm: float = 0.0
    tip_mass_g: float = 0.0
    mass_per_length_g_per_mm: float = 0.0
    gravity: tuple[float, float] = (0.0, -1.0)

    def __post_init__(self):
        s = object.__setattr__
        s(self, "tip_force_n", checked_pair("tip_force_n", self.tip_force_n, "N"))
        s(self, "tip_moment_nmm", number("tip_moment_nmm", self.tip_moment_nmm, unit="N*mm"))
        s(self, "tip_mass_g", number("tip_mass_g", self.tip_mass_g, 0.0, unit="g"))
        s(self, "mass_per_length_g_per_mm",
          number("mass_per_length_g_per_mm", self.mass_per_length_g_per_mm, 0.0, unit="g/mm"))
        g = checked_pair("gravity", self.gravity, "direction")
        ng = math.hypot(*g)
        if ng == 0.0:
            raise InputError("gravity = (0, 0) has no direction; give a non-zero vector, e.g. (0, -1)")
        s(self, "gravity", (g[0] / ng, g[1] / ng))

    @property
    def is_zero(self) -> bool:
        return (self.tip_force_n == (0.0, 0.0) and self.tip_moment_nmm == 0.0 and self.tip_mass_g == 0.0
                and self.mass_per_length_g_per_mm == 0.0)

    def tip_resultant(self) -> tuple[float, float]:
        """Total force at the fingertip point (force + weight of the tip mass), N."""
        w = self.tip_mass_g * G_N_PER_G
        return self.tip_force_n[0] + w * self.gravity[0], self.tip_force_n[1] + w * self.gravity[1]

    def distributed(self) -> tuple[float, float]:
        """Distributed load per length, N/mm."""
        w = self.mass_per_length_g_per_mm * G_N_PER_G
        return w * self.gravity[0], w * self.gravity[1]

    def mirrored(self, axis_angle_deg: float = 0.0) -> FingerLoads:
        a = math.radians(axis_angle_deg)
        c2, s2 = math.cos(2 * a), math.sin(2 * a)

        def m(v):
            return (c2 * v[0] + s2 * v[1], s2 * v[0] - c2 * v[1])

        return replace(self, tip_force_n=m(self.tip_force_n), tip_moment_nmm=-self.tip_moment_nmm,
                       gravity=m(self.gravity))


@dataclass(frozen=True)
class FingerShape:
    """Equilibrium shape of a finger (arrays over the ``nodes`` collocation points).

    Attributes
    ----------
    pressure_kpa : gauge pressure, kPa.
    s : arc length, mm.
    x, y : frame-line position, mm.
    angle : tangent angle phi, rad (counterclockwise from +x).
    curvature : frame curvature k', 1/mm (paper's sign: > 0 toward the frame).
    moment_ext : M_ext(s), N*mm, in the actuator's sign convention (equal to M_load(P, k')).
    tip_xy : fingertip point, mm.  tip_angle : tip orientation phi(L), rad.
    equilibrium : a stable equilibrium was found for the full load.
    stable : the structural stability check passed.
    residual_nmm : max |M(P, k'(s)) - M_ext(s)| with the exact model, N*mm.
    load_fraction : fraction of the load reached by the continuation (1 on success).
    note : empty on a plain success, else what happened (snap-through, no free shape, ...).
    limit : on failure, the last equilibrium reached (a FingerShape at ``load_fraction``), else None.
    branch : the :class:`bendpam.StableBranch` used.

    Examples
    --------
    >>> import numpy as np, bendpam
    >>> shape = solve_finger(Finger(bendpam.physics.presets.be_pam()), 150.0)     # unloaded: a circular arc
    >>> float(shape.s[-1]), round(float(np.degrees(shape.tip_angle)), 2)  # mm, deg
    (145.0, 67.78)
    >>> bool(np.allclose(shape.curvature, shape.curvature[0])), shape.equilibrium
    (True, True)
    """

    finger: Finger
    loads: FingerLoads
    pressure_kpa: float
    s: np.ndarray
    x: np.ndarray
    y: np.ndarray
    angle: np.ndarray
    curvature: np.ndarray
    moment_ext: np.ndarray
    tip_xy: tuple[float, float]
    tip_angle: float
    equilibrium: bool
    stable: bool
    residual_nmm: float
    load_fraction: float
    note: str
    limit: FingerShape | None = field(default=None, repr=False)
    branch: StableBranch | None = field(default=None, repr=False)

    @property
    def tip_angle_deg(self) -> float:
        return math.degrees(self.tip_angle)

    @property
    def bend_angle(self) -> float:
        """Rotation of the tip from the base direction, rad, positive in the finger's bending direction."""
        return self.finger.bend * (self.tip_angle - self.finger.base_angle)

    @property
    def bend_angle_deg(self) -> float:
        return math.degrees(self.bend_angle)

    @classmethod
    def from_curvature(cls, rod: Rod, k, branch: StableBranch | None, P: float, loads: FingerLoads, *,
                       lam: float = 1.0, equilibrium: bool = True, stable: bool = True, note: str = "",
                       exact: bool = True) -> FingerShape:
        """The shape of ``rod`` at the nodal curvatures ``k`` (1/mm) under ``lam`` times its loads (a solver's result).

        ``residual_nmm`` is taken with the exact law (not the branch's table) unless ``exact`` is False (NaN).
        """
        f = rod.f
        phi, x, y, xt, yt = rod.geometry(k)
        m_act = -rod.c * rod.load_moment(x, y, xt, yt, lam)
        res = float(np.max(np.abs(f.law.moment(P, k) - m_act))) if exact else math.nan
        return cls(f, loads, P, rod.s.copy(), x, y, phi, np.asarray(k, float), m_act, (float(xt), float(yt)),
                   float(phi[-1]), equilibrium, stable, res, lam, note, None, branch)

    @classmethod
    def failure(cls, rod: Rod, branch: StableBranch | None, P: float, loads: FingerLoads, note: str,
                limit: FingerShape | None = None, lam: float = 0.0) -> FingerShape:
        """A result without equilibrium: NaN arrays, the ``note`` why, the last equilibrium reached in ``limit``."""
        nan = np.full(rod.n, np.nan)
        return cls(rod.f, loads, P, rod.s.copy(), nan, nan.copy(), nan.copy(), nan.copy(), nan.copy(),
                   (math.nan, math.nan), math.nan, False, False, math.nan, lam, note, limit, branch)

    def _summary(self) -> tuple[str, list[tuple[str, Any]], list[str], list[list[Any]]]:
        d = self.to_dict()
        return (f"FingerShape at {self.pressure_kpa:g} kPa ({'equilibrium' if self.equilibrium else 'no equilibrium'}"
                f"{', ' + self.note if self.note else ''})",
                [(k, d[k]) for k in ("tip_x_mm", "tip_y_mm", "tip_angle_deg", "bend_angle_deg", "base_moment_nmm",
                                     "residual_nmm")], [], [])

    def __repr__(self) -> str:
        """A short summary: the tip pose and the base moment (the arrays are in :meth:`to_dataframe`)."""
        return summary_text(*self._summary())

    def _repr_html_(self) -> str:
        """The summary of :meth:`__repr__` for a notebook (HTML)."""
        return summary_html(*self._summary())

    def limits(self) -> FingerLimits:
        """The structural limits along this shape, worst section (:func:`finger_limits`)."""
        return finger_limits(self)

    def to_dict(self) -> dict[str, Any]:
        """The tip pose, base moment and residual as a JSON-ready dict (units in the key names; null: not defined).

        The arrays along the finger are in :meth:`to_dataframe`.

        >>> import bendpam
        >>> d = solve_finger(Finger(bendpam.physics.presets.be_pam()), 150.0).to_dict()
        >>> round(d["tip_x_mm"], 2), round(d["bend_angle_deg"], 2), d["note"]
        (113.47, 67.78, None)
        """
        return {"pressure_kpa": float(self.pressure_kpa), "tip_x_mm": json_number(self.tip_xy[0]),
                "tip_y_mm": json_number(self.tip_xy[1]), "tip_angle_deg": json_number(self.tip_angle_deg),
                "equilibrium": bool(self.equilibrium), "note": self.note or None,
                "bend_angle_deg": json_number(self.bend_angle_deg), "base_moment_nmm": json_number(self.moment_ext[0]),
                "residual_nmm": json_number(self.residual_nmm)}

    def to_dataframe(self):
        """The shape as a :class:`pandas.DataFrame` (units in the column names)."""
        import pandas as pd

        return pd.DataFrame({"s_mm": self.s, "x_mm": self.x, "y_mm": self.y, "angle_deg": np.degrees(self.angle),
                             "curvature_per_mm": self.curvature, "moment_ext_nmm": self.moment_ext})


# ------------------------------------------------------------------------------------------------
# the solver (the rod and its Newton method: bendpam.design.rod)
# ------------------------------------------------------------------------------------------------
def _k_bounds(branch: StableBranch, n: int):
    return np.full(n, branch.k_lo), np.full(n, branch.k_hi)


def _dead_load_system(rod: Rod, branch: StableBranch, scale: float):
    c = rod.c

    def fun(U, lam):
        _phi, x, y, xt, yt = rod.geometry(U)
        m_act = -c * rod.load_moment(x, y, xt, yt, lam)
        M, _ = branch.moment(U)
        return (M - m_act) / scale

    return fun


def _stability(fun, k, w):
    """Smallest eigenvalue of the symmetrised, weighted Hessian (relative to the largest)."""
    J = complex_jacobian(fun, k)
    sw = np.sqrt(w)
    H = -(sw[:, None] * J / sw[None, :])
    H = 0.5 * (H + H.T)
    ev = np.linalg.eigvalsh(H)
    return float(ev[0] / max(abs(ev[-1]), 1e-300))


def _near_end_note(branch: StableBranch, k, s):
    """Which end of the stable branch the last equilibrium was approaching, as a note."""
    span = branch.k_hi - branch.k_lo
    d_hi = (branch.k_hi - k) / span
    d_lo = (k - branch.k_lo) / span
    j_hi, j_lo = int(np.argmin(d_hi)), int(np.argmin(d_lo))
    if min(d_hi[j_hi], d_lo[j_lo]) > 0.05:
        return None
    if d_hi[j_hi] <= d_lo[j_lo]:
        return f"at s = {s[j_hi]:.3g} mm the section reaches {branch.describe_end(+1)}"
    return f"at s = {s[j_lo]:.3g} mm the section reaches {branch.describe_end(-1)}"


def check_finger(finger, loads) -> FingerLoads:
    """Check that ``finger`` is a :class:`Finger`; ``loads`` as :class:`FingerLoads` (None: no load).

    >>> import bendpam
    >>> check_finger(Finger(bendpam.physics.presets.be_pam()), None).is_zero
    True
    """
    if not isinstance(finger, Finger):
        raise TypeError(f"finger must be a bendpam.design.Finger, got {type(finger).__name__}")
    loads = FingerLoads() if loads is None else loads
    if not isinstance(loads, FingerLoads):
        raise TypeError(f"loads must be a FingerLoads, got {type(loads).__name__}")
    return loads


def solve_finger(finger: Finger, pressure_kpa, loads: FingerLoads | None = None) -> FingerShape:
    """Equilibrium shape of ``finger`` at ``pressure_kpa`` (kPa) under ``loads``.

    Returns a :class:`FingerShape`.  With no load the shape is the free shape (constant free
    curvature).  Otherwise the solution is continued in the load fraction from the free shape.  If
    no stable equilibrium exists (the loads need more moment than the stable branch supplies, or
    a structural limit point), ``equilibrium`` is False, the arrays are NaN, the note says why and
    ``limit`` holds the last equilibrium reached.  Never a shape on the unstable branch.

    Examples
    --------
    >>> import numpy as np, bendpam
    >>> finger = Finger(bendpam.physics.presets.be_pam())
    >>> free = solve_finger(finger, 150.0)
    >>> loaded = solve_finger(finger, 150.0, FingerLoads(tip_force_n=(0.0, -0.5)))
    >>> [round(v, 2) for v in free.tip_xy], [round(v, 2) for v in loaded.tip_xy]    # mm
    ([113.47, 76.22], [125.45, 60.5])
    >>> loaded.equilibrium, loaded.residual_nmm < 1e-6
    (True, True)
    """
    loads = check_finger(finger, loads)
    P = checked_pressure_kpa(pressure_kpa, actuator=finger.actuator)
    with pressures_checked():
        return _solve_finger(finger, P, loads)


def _solve_finger(finger: Finger, P: float, loads: FingerLoads) -> FingerShape:
    """:func:`solve_finger` with validated arguments (P in kPa)."""
    rod = Rod(finger, loads)
    try:
        br = finger.branch(P)
    except NoEquilibrium as exc:
        return FingerShape.failure(rod, None, P, loads, str(exc))
    scale = rod.moment_scale(br)
    fun = _dead_load_system(rod, br, scale)
    lo, hi = _k_bounds(br, rod.n)
    kf = br.free_curvature
    free_ok = np.isfinite(kf)
    fb = finger.law.free_curvature(P)
    if free_ok and fb.status != "no-equilibrium" and np.isfinite(fb.curvature_per_mm):
        # agree with the law's free curvature (same root, without the table's interpolation error)
        kf = float(fb.curvature_per_mm)
    if loads.is_zero:
        if not free_ok:
            why = fb.reason or br.describe_end(+1)
            return FingerShape.failure(rod, br, P, loads, f"no free-bending equilibrium: {why}")
        return FingerShape.from_curvature(rod, np.full(rod.n, kf), br, P, loads)

    def finish(k, lam_note=""):
        st = _stability(lambda U: fun(U, 1.0), k, rod.w)
        if st < -1e-7:
            sh = FingerShape.from_curvature(rod, k, br, P, loads, stable=False)
            return FingerShape.failure(rod, br, P, loads, "unstable equilibrium (a structural limit or bifurcation: "
                                       "the finger buckles under these loads)" + lam_note, limit=sh, lam=1.0)
        return FingerShape.from_curvature(rod, k, br, P, loads, note=lam_note)

    if free_ok:
        # continuation in the load fraction from the free shape (exact at fraction 0)
        k, lam = continuation(lambda t: ((lambda U: fun(U, t)), lo, hi), np.full(rod.n, kf))
        lam = max(lam, 0.0)
        if lam >= 1.0:
            return finish(k)
        last = FingerShape.from_curvature(rod, k, br, P, loads, lam=lam, equilibrium=False)
        where = _near_end_note(br, k, rod.s)
        if where:
            note = (f"no equilibrium: snap-through at load fraction {lam:.3g} ({where}); the loads need more "
                    "moment than the stable branch supplies")
        else:
            note = (f"no equilibrium: the load path reaches a structural limit point at load fraction {lam:.3g} "
                    "(the finger would snap to another configuration)")
        return FingerShape.failure(rod, br, P, loads, note, limit=last, lam=lam)
    # no free shape (pressure above the fold): look for a loaded equilibrium on the stable branch
    span = br.k_hi - br.k_lo
    sgn = finger.actuator.bend_sign
    k_end, k_other = (br.k_hi, br.k_lo) if sgn > 0 else (br.k_lo, br.k_hi)
    guesses = [k_end - sgn * f * span for f in (0.02, 0.1, 0.3)] + [0.0, k_other + sgn * 0.1 * span]
    for g in guesses:
        k, ok, _ = newton(lambda U: fun(U, 1.0), np.full(rod.n, g), lo, hi, NEWTON_TOL, maxit=60)
        if ok:
            return finish(k, "; no free shape at this pressure (fold of the moment law): the equilibrium exists "
                          "only under these loads")
    note = (f"no equilibrium: at {P:.4g} kPa the stable branch supplies only M in [{br.moment_min:.4g}, "
            f"{br.moment_max:.4g}] N*mm, not M = 0 (above the fold: {br.describe_end(sgn)}); where the load moment is "
            "smaller (toward the tip) the finger snaps through")
    return FingerShape.failure(rod, br, P, loads, note)


def finger_sweep(finger: Finger, pressures_kpa, loads: FingerLoads | None = None):
    """Solve ``finger`` at each pressure of ``pressures_kpa`` (kPa).

    Returns ``(table, shapes)``: a :class:`pandas.DataFrame` with ``pressure_kpa``, ``tip_x_mm``,
    ``tip_y_mm``, ``tip_angle_deg``, ``bend_angle_deg``, ``base_moment_nmm``, ``residual_nmm``,
    ``equilibrium`` and ``note``, and the list of :class:`FingerShape`.

    Examples
    --------
    >>> import bendpam
    >>> table, shapes = finger_sweep(Finger(bendpam.physics.presets.be_pam()), [100.0, 150.0])
    >>> table[["pressure_kpa", "tip_x_mm", "tip_y_mm", "bend_angle_deg"]].round(2).values.tolist()
    [[100.0, 140.34, 31.49, 25.29], [150.0, 113.47, 76.22, 67.78]]
    """
    import pandas as pd

    loads = check_finger(finger, loads)
    P = checked_pressures_kpa(pressures_kpa, actuator=finger.actuator)
    with pressures_checked():
        shapes = [_solve_finger(finger, float(p), loads) for p in P]
    return pd.DataFrame({
        "pressure_kpa": P,
        "tip_x_mm": [sh.tip_xy[0] for sh in shapes],
        "tip_y_mm": [sh.tip_xy[1] for sh in shapes],
        "tip_angle_deg": [sh.tip_angle_deg for sh in shapes],
        "bend_angle_deg": [sh.bend_angle_deg for sh in shapes],
        "base_moment_nmm": [float(sh.moment_ext[0]) for sh in shapes],
        "residual_nmm": [sh.residual_nmm for sh in shapes],
        "equilibrium": [sh.equilibrium for sh in shapes],
        "note": [sh.note for sh in shapes],
    }), shapes


@dataclass(frozen=True)
class FingerLimits:
    """The structural limits along a solved finger: :mod:`bendpam.physics.limits` at every section.

    Each section is checked at its own curvature ``k'(s)`` with the axial force the loads beyond it
    put on the frame line (a section's compression is assumed along the whole frame for buckling:
    conservative).  The lock-up margin is the stable branch's end (lock-up or a fold of the loaded
    law, :class:`bendpam.StableBranch`) over ``|k'(s)|``.  The scalar fields are the worst section's
    (every margin a safety factor: >= 1 within the limit, inf without demand or without a limit).

    Attributes
    ----------
    pressure_kpa : kPa.  s_mm : (nodes,) arc length.
    sections : per-section arrays (``axial_force_n``, ``stress_mpa``, ``buckling_margin``,
        ``lockup_margin``, ``bladder_stretch``, ``stretch_margin``, ``external_axial_force_n`` ...,
        see :func:`bendpam.physics.limits.section_limits`).
    frame_axial_force_n : the section force with the largest ``|N|`` (N, tension > 0).
    frame_stress_mpa, bladder_stretch_max : largest along the finger.
    frame_strength_margin, buckling_margin, lockup_margin, bladder_stretch_margin, min_margin : smallest.
    worst_s_mm : where ``min_margin`` occurs.
    violations : one line per margin below 1, e.g. ``"frame buckling: margin 0.8 at s = 0 mm (150 kPa)"``.

    Examples
    --------
    >>> import bendpam
    >>> from bendpam.design import Finger, FingerLoads, solve_finger
    >>> sh = solve_finger(Finger(bendpam.physics.presets.bc_pam()), 100.0, FingerLoads(tip_force_n=(0.0, -2.0)))
    >>> lim = sh.limits()
    >>> round(lim.min_margin, 2), lim.worst_s_mm, lim.violations
    (1.67, 145.0, ())
    """

    pressure_kpa: float
    s_mm: np.ndarray
    frame_axial_force_n: float
    frame_stress_mpa: float
    frame_strength_margin: float
    buckling_margin: float
    lockup_margin: float
    bladder_stretch_max: float
    bladder_stretch_margin: float
    min_margin: float
    worst_s_mm: float
    violations: tuple[str, ...]
    sections: dict[str, np.ndarray] = field(repr=False, compare=False)

    def to_dict(self) -> dict[str, Any]:
        """The worst section's numbers as a JSON-ready dict (margins: "inf" where there is no demand or no limit).

        >>> import bendpam
        >>> from bendpam.design import Finger, solve_finger
        >>> d = solve_finger(Finger(bendpam.physics.presets.be_pam()), 150.0).limits().to_dict()
        >>> round(d["lockup_margin"], 1), d["buckling_margin"], d["violations"]
        (4.1, 'inf', [])
        """
        return {k: json_number(getattr(self, k)) for k in (
            "frame_axial_force_n", "frame_stress_mpa", "frame_strength_margin", "buckling_margin", "lockup_margin",
            "bladder_stretch_max", "bladder_stretch_margin", "min_margin", "worst_s_mm")} | {
            "violations": list(self.violations)}


def finger_limits(shape: FingerShape) -> FingerLimits:
    """The margins along the solved finger ``shape`` (worst section): see :class:`FingerLimits`.

    Raises :class:`~bendpam.errors.NoEquilibrium` for a shape without an equilibrium.

    >>> import bendpam
    >>> from bendpam.design import Finger, solve_finger
    >>> lim = finger_limits(solve_finger(Finger(bendpam.physics.presets.be_pam()), 150.0))
    >>> round(lim.lockup_margin, 1), lim.buckling_margin
    (4.1, inf)
    """
    from bendpam.physics.limits import MARGINS, section_limits

    if not isinstance(shape, FingerShape):
        raise TypeError(f"shape must be a FingerShape, got {type(shape).__name__}")
    if not shape.equilibrium or shape.branch is None:
        raise NoEquilibrium(f"at {shape.pressure_kpa:g} kPa the finger has no equilibrium shape to check "
                            f"({shape.note or 'no equilibrium'})")
    rod = Rod(shape.finger, shape.loads)
    lam = shape.load_fraction
    Fx, Fy = rod.F
    qx, qy = rod.q
    # tension along the frame line from the dead loads beyond each section
    tension = lam * ((Fx + qx * rod.rem) * np.cos(shape.angle) + (Fy + qy * rod.rem) * np.sin(shape.angle))
    k = shape.curvature
    br = shape.branch
    sec = section_limits(shape.finger.actuator, shape.pressure_kpa, k, external_axial_force_n=tension,
                         lockup_curvature_per_mm=np.where(k >= 0.0, br.k_hi, br.k_lo))
    sec["external_axial_force_n"] = tension
    margin = {"frame_strength_margin": sec["strength_margin"], "buckling_margin": sec["buckling_margin"],
              "lockup_margin": sec["lockup_margin"], "bladder_stretch_margin": sec["stretch_margin"]}
    worst_each = {name: float(np.min(v)) for name, v in margin.items()}
    overall = np.minimum.reduce(list(margin.values()))
    j = int(np.argmin(overall))
    P = shape.pressure_kpa
    lines = []
    for name, label in MARGINS.items():
        v = worst_each[name]
        if v < 1.0:
            i = int(np.argmin(margin[name]))
            if name == "lockup_margin" and (br.end_hi if k[i] >= 0.0 else br.end_lo) == "fold":
                label = "fold of the loaded moment law (snap-through)"
            lines.append(f"{label}: margin {v:.2f} at s = {shape.s[i]:.4g} mm ({P:g} kPa)")
    N = sec["axial_force_n"]
    return FingerLimits(
        pressure_kpa=P, s_mm=shape.s.copy(), frame_axial_force_n=float(N[int(np.argmax(np.abs(N)))]),
        frame_stress_mpa=float(np.max(sec["stress_mpa"])), bladder_stretch_max=float(np.max(sec["bladder_stretch"])),
        **worst_each, min_margin=float(overall[j]), worst_s_mm=float(shape.s[j]), violations=tuple(lines),
        sections=sec)


def free_tip_trajectory(finger: Finger, pressures_kpa):
    """Tip pose of the unloaded finger against pressure (kPa), vectorised.

    The free shape is a circular arc of the free curvature (:meth:`bendpam.MomentLaw.free_curvature`) plus the
    rigid fingertip.  Returns a :class:`pandas.DataFrame` with ``pressure_kpa``,
    ``free_curvature_per_mm``, ``tip_x_mm``, ``tip_y_mm``, ``tip_angle_deg``, ``bend_angle_deg``,
    ``status`` and ``note`` (NaN pose where there is no free equilibrium).

    Examples
    --------
    >>> import bendpam
    >>> t = free_tip_trajectory(Finger(bendpam.physics.presets.be_pam()), [100.0, 150.0, 200.0])
    >>> t[["tip_x_mm", "tip_y_mm", "bend_angle_deg"]].round(2).values.tolist()     # mm, mm, deg
    [[140.34, 31.49, 25.29], [113.47, 76.22, 67.78], [68.36, 102.07, 112.38]]
    """
    import pandas as pd

    if not isinstance(finger, Finger):
        raise TypeError(f"finger must be a bendpam.design.Finger, got {type(finger).__name__}")
    P = checked_pressures_kpa(pressures_kpa, actuator=finger.actuator)
    with pressures_checked():
        fb = finger.law.free_curvature(P)
    k = fb.curvature_per_mm
    kap = finger.frame_side * k
    L = finger.length
    th = kap * L
    p0 = finger.base_angle
    ln = L * sinc(0.5 * th)
    x0, y0 = finger.base_xy_mm
    pl = p0 + th
    b = finger.bend
    ell, off = finger.fingertip_mm, finger.fingertip_offset_mm
    xt = x0 + ln * np.cos(p0 + 0.5 * th) + ell * np.cos(pl) - b * off * np.sin(pl)
    yt = y0 + ln * np.sin(p0 + 0.5 * th) + ell * np.sin(pl) + b * off * np.cos(pl)
    return pd.DataFrame({
        "pressure_kpa": P,
        "free_curvature_per_mm": k,
        "tip_x_mm": xt,
        "tip_y_mm": yt,
        "tip_angle_deg": np.degrees(pl),
        "bend_angle_deg": np.degrees(b * th),
        "status": fb.status,
        "note": fb.reason,
    })


# ------------------------------------------------------------------------------------------------
# figure (drawn by bendpam.present.figures.design, reached by name)
# ------------------------------------------------------------------------------------------------
def plot_finger_shapes(shapes, ax=None, title: str | None = None, free=None):
    """Draw finger shapes (frame line, fingertip, tip point) on ``ax``; returns the figure.

    Shapes without equilibrium are drawn dashed from their last equilibrium (``limit``) if any;
    ``free``, the unloaded shapes at the same pressures, are drawn dotted beside them.
    The figure is :func:`bendpam.present.figures.design.plot_finger_shapes`, loaded on first use.

    Examples
    --------
    >>> import bendpam
    >>> import matplotlib.pyplot as plt
    >>> finger = Finger(bendpam.physics.presets.be_pam())
    >>> fig = plot_finger_shapes([solve_finger(finger, p) for p in (100.0, 150.0)])
    >>> len(fig.axes)                                     # fig.savefig("shapes.png") to keep it
    1
    >>> plt.close(fig)
    """
    return figure("finger_shapes")(shapes, ax=ax, title=title, free=free)
