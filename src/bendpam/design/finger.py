r"""A bending-PAM finger under in-plane loads: equilibrium shape, tip pose, blocked force, stiffness.

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
Collocation on ``n`` equally spaced nodes (default 81): the unknowns are the nodal curvatures;
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
import sys
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from types import FrameType
from typing import TYPE_CHECKING, Any

import numpy as np

from bendpam.errors import InputError, NoEquilibrium
from bendpam.physics.actuator import Actuator
from bendpam.physics.law import MomentLaw, StableBranch
from bendpam.physics.models import normalise_model
from bendpam.validate import UnitWarning, number
from bendpam.validate import pressure_kpa as _check_pressures

if TYPE_CHECKING:
    from bendpam.physics.hysteresis import LoopModel

__all__ = [
    "G_N_PER_G",
    "BlockedTipForce",
    "Finger",
    "FingerLimits",
    "FingerLoads",
    "FingerShape",
    "StableBranch",
    "TipStiffness",
    "blocked_tip_force",
    "finger_limits",
    "finger_sweep",
    "free_tip_trajectory",
    "linear_tip_compliance",
    "plot_finger_shapes",
    "solve_finger",
    "stable_branch",
    "tip_stiffness",
]

#: weight of one gram, N (standard gravity 9.80665 m/s^2)
G_N_PER_G = 9.80665e-3

NEWTON_TOL = 1e-10  # on the residual divided by the moment scale
_MAX_NEWTON = 40
_MIN_STEP = 1.0 / 2048
_PACKAGE = __name__.rpartition(".")[0]  # "bendpam.design": warnings point at the first frame outside it


# ------------------------------------------------------------------------------------------------
# validation shared by the design modules (public within bendpam.design, not exported)
# ------------------------------------------------------------------------------------------------
def _pair(name: str, value, unit: str) -> tuple[float, float]:
    if isinstance(value, str | bytes):
        raise InputError(f"{name} = {value!r} must be two numbers ({unit})")
    try:
        a = np.asarray(value, dtype=float).ravel()
    except (TypeError, ValueError):
        raise InputError(f"{name} = {value!r} must be two numbers ({unit})") from None
    if a.size != 2 or not np.all(np.isfinite(a)):
        raise InputError(f"{name} = {value!r} must be two finite numbers ({unit})")
    return float(a[0]), float(a[1])


def _user_stacklevel() -> int:
    """``stacklevel`` (for a ``warnings.warn`` in the caller) of the first frame outside bendpam.design."""
    level = 1
    frame: FrameType | None = sys._getframe(1)
    while frame is not None and frame.f_globals.get("__name__", "").startswith(_PACKAGE):
        frame, level = frame.f_back, level + 1
    return level


def _numeric_pressures(value, name: str) -> np.ndarray:
    """:func:`bendpam.validate.pressure_kpa`, refusing strings and bools inside a list too ([100, "150"]).

    Its :class:`~bendpam.validate.UnitWarning` is reported at the user's call, not inside bendpam.design.
    """
    try:
        kind = np.asarray(value).dtype.kind
    except (TypeError, ValueError):  # ragged: left to the check's own message
        kind = "O"
    if kind in "USb":
        raise InputError(f"{name} = {value!r} is not numeric (kPa expected)")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        p = _check_pressures(value, name)
    if caught:
        level = _user_stacklevel()
        for w in caught:
            warnings.warn(w.message, stacklevel=level)
    return p


def checked_pressure_kpa(value, name: str = "pressure_kpa") -> float:
    """One gauge pressure in kPa as a float (:func:`bendpam.validate.pressure_kpa`, and a single value).

    A negative, non-finite or non-numeric value raises :class:`~bendpam.errors.InputError`; a
    nonzero value below 5 kPa warns with :class:`~bendpam.validate.UnitWarning` (MPa passed as kPa?).
    """
    p = _numeric_pressures(value, name)
    if p.size != 1:
        raise InputError(f"{name} has {p.size} values; give one pressure (kPa)")
    return float(p.reshape(()))


def checked_pressures_kpa(value, name: str = "pressures_kpa") -> np.ndarray:
    """Gauge pressures in kPa as a 1-D float array (at least one), validated as :func:`checked_pressure_kpa`."""
    p = np.atleast_1d(_numeric_pressures(value, name)).ravel()
    if p.size == 0:
        raise InputError(f"{name} is empty; give at least one pressure (kPa)")
    return p


@contextmanager
def pressures_checked() -> Iterator[None]:
    """Run the numerics of a public function whose pressures were already validated.

    The entry point validates (and warns about a suspected MPa value) once; inside, the law is
    evaluated many times at the same pressures and must not repeat the
    :class:`~bendpam.validate.UnitWarning`.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UnitWarning)
        yield


# ------------------------------------------------------------------------------------------------
# the moment law on its stable branch
# ------------------------------------------------------------------------------------------------
def stable_branch(actuator: Actuator, pressure_kpa, model: str = "energy",
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
    P = checked_pressure_kpa(pressure_kpa)
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
    model : {"energy", "force_balance"}
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
    model: str = "energy"
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
        s(self, "model", normalise_model(self.model))
        s(self, "base_xy_mm", _pair("base_xy_mm", self.base_xy_mm, "mm"))
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
        s(self, "tip_force_n", _pair("tip_force_n", self.tip_force_n, "N"))
        s(self, "tip_moment_nmm", number("tip_moment_nmm", self.tip_moment_nmm, unit="N*mm"))
        s(self, "tip_mass_g", number("tip_mass_g", self.tip_mass_g, 0.0, unit="g"))
        s(self, "mass_per_length_g_per_mm",
          number("mass_per_length_g_per_mm", self.mass_per_length_g_per_mm, 0.0, unit="g/mm"))
        g = _pair("gravity", self.gravity, "direction")
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

    def limits(self) -> FingerLimits:
        """The structural limits along this shape, worst section (:func:`finger_limits`)."""
        return finger_limits(self)

    def to_dataframe(self):
        """The shape as a :class:`pandas.DataFrame` (units in the column names)."""
        import pandas as pd

        return pd.DataFrame({"s_mm": self.s, "x_mm": self.x, "y_mm": self.y, "angle_deg": np.degrees(self.angle),
                             "curvature_per_mm": self.curvature, "moment_ext_nmm": self.moment_ext})


# ------------------------------------------------------------------------------------------------
# the discretised rod
# ------------------------------------------------------------------------------------------------
def _sinc(x):
    """sin(x)/x, analytic (complex-step safe)."""
    small = np.abs(x) < 1e-3
    xs = np.where(small, 1.0, x)
    x2 = x * x
    return np.where(small, 1.0 - x2 / 6.0 + x2 * x2 / 120.0, np.sin(xs) / xs)


def cross(ax, ay, bx, by):
    """z-component of the planar cross product ``a x b`` (batched; complex-step safe)."""
    return ax * by - ay * bx


class Rod:
    """Geometry and load moments of the discretised finger (batched over leading axes).

    Shared by :mod:`bendpam.design.grasp`; not part of the public API of :mod:`bendpam.design`.
    """

    def __init__(self, finger: Finger, loads: FingerLoads):
        self.f = finger
        n = finger.nodes
        L = finger.length
        self.n, self.L = n, L
        self.s = np.linspace(0.0, L, n)
        self.h = L / (n - 1)
        self.w = np.full(n, self.h)
        self.w[[0, -1]] *= 0.5
        self.c = finger.frame_side
        self.x0, self.y0 = finger.base_xy_mm
        self.phi0 = finger.base_angle
        self.ell, self.off = finger.fingertip_mm, finger.fingertip_offset_mm
        self.loads = loads
        self.F = loads.tip_resultant()
        self.q = loads.distributed()
        self.Mt = loads.tip_moment_nmm
        self.rem = L - self.s  # length beyond each node

    def geometry(self, k):
        h = self.h
        kap = self.c * k
        inc = 0.5 * h * (kap[..., 1:] + kap[..., :-1])
        zero = np.zeros((*k.shape[:-1], 1), dtype=k.dtype)
        phi = self.phi0 + np.concatenate([zero, np.cumsum(inc, axis=-1)], axis=-1)
        mid = 0.5 * (phi[..., 1:] + phi[..., :-1])
        sc = h * _sinc(0.5 * inc)
        x = self.x0 + np.concatenate([zero, np.cumsum(np.cos(mid) * sc, axis=-1)], axis=-1)
        y = self.y0 + np.concatenate([zero, np.cumsum(np.sin(mid) * sc, axis=-1)], axis=-1)
        pl = phi[..., -1]
        b = self.f.bend
        xt = x[..., -1] + self.ell * np.cos(pl) - b * self.off * np.sin(pl)
        yt = y[..., -1] + self.ell * np.sin(pl) + b * self.off * np.cos(pl)
        return phi, x, y, xt, yt

    def point(self, phi, x, y, sc):
        """Position and angle at arc length ``sc`` (batched scalar) on the arcs between nodes."""
        h = self.h
        jr = np.clip(np.floor(np.real(sc) / h).astype(int), 0, self.n - 2)
        idx = jr[..., None]
        p0 = np.take_along_axis(phi, idx, -1)[..., 0]
        p1 = np.take_along_axis(phi, idx + 1, -1)[..., 0]
        x0 = np.take_along_axis(x, idx, -1)[..., 0]
        y0 = np.take_along_axis(y, idx, -1)[..., 0]
        tau = sc - jr * h
        dp = (p1 - p0) * tau / h
        pm = p0 + 0.5 * dp
        ln = tau * _sinc(0.5 * dp)
        return x0 + ln * np.cos(pm), y0 + ln * np.sin(pm), p0 + dp

    def load_moment(self, x, y, xt, yt, lam=1.0):
        """Counterclockwise moment m(s_j) of the dead loads beyond each node, N*mm."""
        Fx, Fy = self.F
        m = lam * (self.Mt + cross(xt[..., None] - x, yt[..., None] - y, Fx, Fy))
        qx, qy = self.q
        if qx or qy:
            w = self.h
            # X_j = int_{s_j}^L x du by the trapezoidal rule
            cx = np.cumsum(0.5 * w * (x[..., 1:] + x[..., :-1])[..., ::-1], axis=-1)[..., ::-1]
            cy = np.cumsum(0.5 * w * (y[..., 1:] + y[..., :-1])[..., ::-1], axis=-1)[..., ::-1]
            zero = np.zeros((*x.shape[:-1], 1), dtype=x.dtype)
            X = np.concatenate([cx, zero], axis=-1)
            Y = np.concatenate([cy, zero], axis=-1)
            m = m + lam * cross(X - self.rem * x, Y - self.rem * y, qx, qy)
        return m


def _complex_jacobian(fun, u):
    """Exact Jacobian of a real-analytic vector function by the complex step (one batched call)."""
    m = u.size
    eps = 1e-30
    U = u[None, :] + 1j * eps * np.eye(m)
    return (np.imag(fun(U)) / eps).T


def newton(fun, u0, lo, hi, tol, maxit=_MAX_NEWTON):
    """Damped Newton on ``fun(u) = 0`` keeping ``lo < u < hi``.  Returns ``(u, ok, |r|_inf)``."""
    u = np.array(u0, dtype=float)
    r = np.real(fun(u[None, :]))[0]
    nr = float(np.max(np.abs(r)))
    for _ in range(maxit):
        if not np.isfinite(nr):
            return u, False, nr
        if nr < tol:
            return u, True, nr
        J = _complex_jacobian(fun, u)
        try:
            du = np.linalg.solve(J, -r)
        except np.linalg.LinAlgError:
            du = np.linalg.lstsq(J, -r, rcond=None)[0]
        if not np.all(np.isfinite(du)):
            return u, False, nr
        # stay strictly inside the bounds (the stable branch): at most 90 % of the way to a bound
        with np.errstate(divide="ignore", invalid="ignore"):
            a_hi = np.where(du > 0, 0.9 * (hi - u) / du, np.inf)
            a_lo = np.where(du < 0, 0.9 * (lo - u) / du, np.inf)
        alpha = float(min(1.0, np.min(a_hi), np.min(a_lo)))
        n2 = float(np.sum(r * r))
        for _ in range(30):
            un = u + alpha * du
            rn = np.real(fun(un[None, :]))[0]
            n2n = float(np.sum(rn * rn))
            if np.isfinite(n2n) and n2n <= (1.0 - 1e-4 * alpha) * n2:
                break
            alpha *= 0.5
        else:
            return u, False, nr
        if alpha < 1e-12:
            return u, False, nr
        u, r = un, rn
        nr = float(np.max(np.abs(r)))
    return u, nr < tol, nr


def _moment_scale(branch: StableBranch, rod: Rod) -> float:
    """Moment scale for the Newton tolerance: blocked moment, fold moments and load moments (not lock-up)."""
    load = abs(rod.Mt) + math.hypot(*rod.F) * (rod.L + rod.ell) + math.hypot(*rod.q) * rod.L ** 2
    folds = [abs(m) for m, e in ((branch.moment_max, branch.end_lo), (branch.moment_min, branch.end_hi)) if e == "fold"]
    return max([abs(float(branch.moment(0.0)[0])), load, 1.0, *folds])


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
    J = _complex_jacobian(fun, k)
    sw = np.sqrt(w)
    H = -(sw[:, None] * J / sw[None, :])
    H = 0.5 * (H + H.T)
    ev = np.linalg.eigvalsh(H)
    return float(ev[0] / max(abs(ev[-1]), 1e-300))


def _shape(rod: Rod, k, branch, P, loads, *, lam=1.0, equilibrium=True, stable=True, note="", exact=True):
    f = rod.f
    phi, x, y, xt, yt = rod.geometry(k)
    m_act = -rod.c * rod.load_moment(x, y, xt, yt, lam)
    res = float(np.max(np.abs(f.law.moment(P, k) - m_act))) if exact else math.nan
    return FingerShape(f, loads, P, rod.s.copy(), x, y, phi, np.asarray(k, float), m_act, (float(xt), float(yt)),
                       float(phi[-1]), equilibrium, stable, res, lam, note, None, branch)


def _failed(rod: Rod, branch, P, loads, note, limit=None, lam=0.0):
    nan = np.full(rod.n, np.nan)
    return FingerShape(rod.f, loads, P, rod.s.copy(), nan, nan.copy(), nan.copy(), nan.copy(), nan.copy(),
                       (math.nan, math.nan), math.nan, False, False, math.nan, lam, note, limit, branch)


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


def _continue(system, u0):
    """Continuation in a path parameter t in [0, 1]: ``system(t) -> (fun, lo, hi)``.

    ``u0`` must be (close to) the solution at t = 0.  Adaptive steps (doubling on success, halving
    on failure down to 1/2048).  Returns the last solution and the parameter reached (1.0 on
    success; -1.0 if even the start does not converge).
    """
    fun, lo, hi = system(0.0)
    u, ok, _ = newton(fun, np.asarray(u0, dtype=float), lo, hi, NEWTON_TOL)
    if not ok:
        return np.asarray(u0, dtype=float), -1.0
    t, step = 0.0, 1.0
    while t < 1.0:
        step = min(step, 1.0 - t)
        fun, lo, hi = system(t + step)
        un, ok, _ = newton(fun, u, lo, hi, NEWTON_TOL)
        if ok:
            u, t = un, t + step
            step *= 2.0
        else:
            step *= 0.5
            if step < _MIN_STEP:
                break
    return u, t


def _check_finger(finger, loads) -> FingerLoads:
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
    loads = _check_finger(finger, loads)
    P = checked_pressure_kpa(pressure_kpa)
    with pressures_checked():
        return _solve_finger(finger, P, loads)


def _solve_finger(finger: Finger, P: float, loads: FingerLoads) -> FingerShape:
    """:func:`solve_finger` with validated arguments (P in kPa)."""
    rod = Rod(finger, loads)
    try:
        br = finger.branch(P)
    except NoEquilibrium as exc:
        return _failed(rod, None, P, loads, str(exc))
    scale = _moment_scale(br, rod)
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
            return _failed(rod, br, P, loads, f"no free-bending equilibrium: {fb.reason or br.describe_end(+1)}")
        return _shape(rod, np.full(rod.n, kf), br, P, loads)

    def finish(k, lam_note=""):
        st = _stability(lambda U: fun(U, 1.0), k, rod.w)
        if st < -1e-7:
            sh = _shape(rod, k, br, P, loads, stable=False)
            return _failed(rod, br, P, loads, "unstable equilibrium (a structural limit or bifurcation: the "
                           "finger buckles under these loads)" + lam_note, limit=sh, lam=1.0)
        return _shape(rod, k, br, P, loads, note=lam_note)

    if free_ok:
        # continuation in the load fraction from the free shape (exact at fraction 0)
        k, lam = _continue(lambda t: ((lambda U: fun(U, t)), lo, hi), np.full(rod.n, kf))
        lam = max(lam, 0.0)
        if lam >= 1.0:
            return finish(k)
        last = _shape(rod, k, br, P, loads, lam=lam, equilibrium=False)
        where = _near_end_note(br, k, rod.s)
        if where:
            note = (f"no equilibrium: snap-through at load fraction {lam:.3g} ({where}); the loads need more "
                    "moment than the stable branch supplies")
        else:
            note = (f"no equilibrium: the load path reaches a structural limit point at load fraction {lam:.3g} "
                    "(the finger would snap to another configuration)")
        return _failed(rod, br, P, loads, note, limit=last, lam=lam)
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
    return _failed(rod, br, P, loads, note)


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

    loads = _check_finger(finger, loads)
    P = checked_pressures_kpa(pressures_kpa)
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
    P = checked_pressures_kpa(pressures_kpa)
    with pressures_checked():
        fb = finger.law.free_curvature(P)
    k = fb.curvature_per_mm
    kap = finger.frame_side * k
    L = finger.length
    th = kap * L
    p0 = finger.base_angle
    ln = L * _sinc(0.5 * th)
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
# blocked tip force and tip stiffness
# ------------------------------------------------------------------------------------------------
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
        return math.hypot(*self.force_n)


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
    loads = _check_finger(finger, loads)
    P = checked_pressure_kpa(pressure_kpa)
    if target_xy_mm is None:
        target = _straight_tip(finger)
        if direction_deg is None:
            p = finger.base_angle
            direction = (-finger.bend * math.sin(p), finger.bend * math.cos(p))
        else:
            d = math.radians(number("direction_deg", direction_deg, unit="deg"))
            direction = (math.cos(d), math.sin(d))
    else:
        target = _pair("target_xy_mm", target_xy_mm, "mm")
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
    start = _solve_finger(finger, P, loads)
    rod = Rod(finger, loads)
    try:
        br = finger.branch(P)
    except NoEquilibrium as exc:
        return BlockedTipForce((math.nan, math.nan), target, constraint, direction, start, False, str(exc))
    n = rod.n
    c = rod.c
    Lr = rod.L + rod.ell
    scale = _moment_scale(br, rod)
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
        u, t_reached = _continue(system, u0)
        t_best = max(t_best, t_reached)
        if t_reached >= 1.0:
            break
    else:
        what = "roller" if direction is not None else "pin"
        why = "" if start.equilibrium else f" (no unloaded equilibrium: {start.note})"
        note = (f"no equilibrium holds the tip with a {what} at ({target[0]:.4g}, {target[1]:.4g}) mm: the finger "
                f"snaps through on the way (continuation stops at {t_best:.3g} of the path){why}")
        sh = _failed(rod, br, P, loads, note, lam=t_best)
        return BlockedTipForce((math.nan, math.nan), target, constraint, direction, sh, False, note)
    if direction is None:
        F = (float(u[n] * fscale), float(u[n + 1] * fscale))
    else:
        F = (float(u[n] * fscale * direction[0]), float(u[n] * fscale * direction[1]))
    total = replace(loads, tip_force_n=(loads.tip_force_n[0] + F[0], loads.tip_force_n[1] + F[1]))
    sh = _shape(Rod(finger, total), u[:n], br, P, total)
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
    loads = _check_finger(finger, loads)
    P = checked_pressure_kpa(pressure_kpa)
    with pressures_checked():
        sh = _solve_finger(finger, P, loads)
    if not sh.equilibrium:
        raise NoEquilibrium(f"no equilibrium at pressure_kpa = {P:g} kPa under these loads: {sh.note}")
    rod = Rod(finger, loads)
    br = sh.branch
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
    J = _complex_jacobian(fun, u)
    Jk, JF = J[:, :n], J[:, n:]
    try:
        dk = -np.linalg.solve(Jk, JF)
        Q = _complex_jacobian(pose, u)
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
    _check_finger(finger, None)
    P = checked_pressure_kpa(pressure_kpa)
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


# ------------------------------------------------------------------------------------------------
# figure
# ------------------------------------------------------------------------------------------------
def plot_finger_shapes(shapes, ax=None, title: str | None = None):
    """Draw finger shapes (frame line, fingertip, tip point) on ``ax``; returns the figure.

    Shapes without equilibrium are drawn dashed from their last equilibrium (``limit``) if any.

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
    from bendpam.present import figures as plots  # noqa: F401, I001  (first: selects the Agg backend unless the caller chose one)
    import matplotlib.pyplot as plt

    if ax is None:
        fig, ax = plt.subplots(figsize=(6.0, 5.0))
    else:
        fig = ax.figure
    shapes = list(shapes)
    colors = plt.cm.viridis(np.linspace(0.0, 0.9, max(len(shapes), 1)))
    for sh, col in zip(shapes, colors, strict=False):
        draw, style = (sh, "-") if sh.equilibrium else (sh.limit, "--")
        label = f"{sh.pressure_kpa:g} kPa" + ("" if sh.equilibrium else " (no equilibrium)")
        if draw is None:
            ax.plot([], [], style, color=col, label=label)
            continue
        ax.plot(draw.x, draw.y, style, color=col, label=label)
        ax.plot([draw.x[-1], draw.tip_xy[0]], [draw.y[-1], draw.tip_xy[1]], style, color=col, lw=3, alpha=0.6)
        ax.plot(*draw.tip_xy, "o", color=col, ms=4)
    if shapes:
        x0, y0 = shapes[0].finger.base_xy_mm
        ax.plot(x0, y0, "ks", ms=6)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    if title:
        ax.set_title(title)
    return fig
