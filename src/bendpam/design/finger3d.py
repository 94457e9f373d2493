r"""A bending-PAM finger under loads in any direction: the spatial rod, its equilibrium and its tip pose.

The finger of :mod:`bendpam.design.finger` as a Kirchhoff rod in three dimensions
(:mod:`bendpam.design.rod3d`): in its bending plane the constitutive law is the actuator's moment
law on its stable branch (:class:`bendpam.MomentLaw`, exactly as the planar finger), out of the
plane the lateral stiffness ``EI_lat(P, k')`` and in twist the torsional stiffness ``GJ(P, k')``
with the braid's lock torque (:mod:`bendpam.physics.spatial`, docs/out-of-plane.md).  Loads are
dead loads in world axes: a tip force and a tip moment (three components each), a tip mass and
the self-weight along a gravity direction, a distributed load and point forces at given arc
lengths.

The finger's own frame: the planar :class:`~bendpam.design.finger.Finger` (base point, base angle,
bending direction, fingertip) lies in the local ``xy`` plane with ``z`` out of it;
:class:`Finger3D` places that frame in the world (``origin_mm`` and a rotation matrix).  With the
identity (default) world and local axes coincide and in-plane loads give the planar finger's shape
(to rounding; tested to 1e-6 of the length).

Solved by continuation in the load fraction from the free shape with the one Newton method of
:mod:`bendpam.design.rod`; when the loads ask for more than the stable branch of the law supplies
(snap-through), or the path reaches a limit point, the result has ``equilibrium=False``, NaN arrays,
a note and the last equilibrium reached in ``limit``, as the planar finger.  Unlike the planar
finger there is no separate structural-stability check of the equilibrium (the second variation):
a limit point on the load path stops the continuation; a bifurcation off it is not detected.
Contacts are loads of known force (point forces), not unilateral constraints.

Units: mm, N, N*mm, kPa, g; angles in degrees in names ending ``_deg``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from bendpam.design.finger import Finger, FingerLoads
from bendpam.design.parts import G_N_PER_G, checked_pressure_kpa, checked_vector, json_number, pressures_checked
from bendpam.design.rod import NEWTON_TOL, continuation, newton
from bendpam.design.rod3d import Rod3D
from bendpam.errors import InputError, NoEquilibrium
from bendpam.infra.accessors import figure
from bendpam.infra.atomic import atomic_write_text
from bendpam.infra.display import summary_html, summary_text
from bendpam.physics.law import StableBranch
from bendpam.physics.spatial import SpatialTable
from bendpam.validate import number

__all__ = [
    "Finger3D",
    "Finger3DShape",
    "FingerLoads3D",
    "plot_finger3d",
    "solve_finger3d",
]


@dataclass(frozen=True)
class Finger3D:
    """A planar :class:`~bendpam.design.finger.Finger` placed in space, with its out-of-plane laws.

    Parameters
    ----------
    finger : Finger
        The actuator and its mounting in the finger's own ``xy`` plane (base point, base angle, bend
        direction, fingertip, nodes).
    origin_mm : (x, y, z)
        Where the finger's local origin lies in the world, mm.
    rotation : 3x3 rotation matrix or None
        World components of the local axes (columns: local x, y, z); None: the identity.
    sleeve_lock : bool
        Keep the braid's lock torque in the twist law (default); False: ``GJ tau = m.d3`` (a linear
        twist law, as a linear-elastic rod).
    frame_shear_modulus_mpa : float or None
        Shear modulus of the frame strip, MPa (default ``E_f / 2.6``).

    Examples
    --------
    >>> import bendpam
    >>> f3 = Finger3D(Finger(bendpam.physics.presets.be_pam()), origin_mm=(0.0, 0.0, 10.0))
    >>> f3.base_xyz_mm
    (0.0, 0.0, 10.0)
    """

    finger: Finger
    origin_mm: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rotation: Any = None
    sleeve_lock: bool = True
    frame_shear_modulus_mpa: float | None = None

    def __post_init__(self):
        s = object.__setattr__
        if not isinstance(self.finger, Finger):
            raise TypeError(f"finger must be a bendpam.design.Finger, got {type(self.finger).__name__}")
        s(self, "origin_mm", checked_vector("origin_mm", self.origin_mm, "mm"))
        if self.rotation is None:
            R = np.eye(3)
        else:
            try:
                R = np.array(self.rotation, dtype=float)
            except (TypeError, ValueError):
                raise InputError("rotation must be a 3x3 rotation matrix (numbers)") from None
            if R.shape != (3, 3) or not np.all(np.isfinite(R)) or not np.allclose(R.T @ R, np.eye(3), atol=1e-9) \
                    or np.linalg.det(R) < 0:
                raise InputError("rotation must be a 3x3 proper rotation matrix (orthonormal, det = +1)")
        R.setflags(write=False)
        s(self, "rotation", R)
        s(self, "sleeve_lock", bool(self.sleeve_lock))
        if self.frame_shear_modulus_mpa is not None:
            s(self, "frame_shear_modulus_mpa", number("frame_shear_modulus_mpa", self.frame_shear_modulus_mpa,
                                                      0.0, lo_open=True, unit="MPa"))

    @property
    def base_xyz_mm(self) -> tuple[float, float, float]:
        """The base of the frame line in the world, mm."""
        bx, by = self.finger.base_xy_mm
        p = np.asarray(self.origin_mm) + self.rotation @ np.array([bx, by, 0.0])
        return float(p[0]), float(p[1]), float(p[2])

    @property
    def plane_normal(self) -> np.ndarray:
        """The normal of the finger's bending plane in the world (the local z axis)."""
        return np.asarray(self.rotation[:, 2], dtype=float)

    def base_directors(self) -> np.ndarray:
        """Directors at the base (columns ``d1, d2, d3``: in-plane normal, plane normal, tangent), world axes."""
        a = self.finger.base_angle
        local = np.array([[-math.sin(a), 0.0, math.cos(a)], [math.cos(a), 0.0, math.sin(a)], [0.0, 1.0, 0.0]])
        return self.rotation @ local


@dataclass(frozen=True)
class FingerLoads3D:
    """Dead loads on a spatial finger, world axes.

    Parameters
    ----------
    tip_force_n : (Fx, Fy, Fz)
        Force on the fingertip point, N.
    tip_moment_nmm : (Mx, My, Mz)
        Moment on the tip, N*mm.
    tip_mass_g : float
        Point mass at the fingertip point, g (its weight acts along ``gravity``).
    mass_per_length_g_per_mm : float
        Self-weight of the actuator, g/mm.
    distributed_n_per_mm : (qx, qy, qz)
        A further uniform load per length, N/mm.
    point_forces_n : sequence of (s_mm, (Fx, Fy, Fz))
        Forces at arc lengths ``s_mm`` along the active length (contacts of known force), N.
    point_moments_nmm : sequence of (s_mm, (Mx, My, Mz))
        Moments at arc lengths ``s_mm`` (a force applied off the frame line, moved onto it), N*mm.
    gravity : (gx, gy, gz)
        Direction of gravity (normalised here); default ``(0, -1, 0)``.

    Examples
    --------
    >>> loads = FingerLoads3D(tip_force_n=(0.0, 0.0, 0.3), tip_mass_g=10.0)
    >>> [round(v, 5) for v in loads.tip_resultant()]                 # N: the force plus 10 g of weight
    [0.0, -0.09807, 0.3]
    """

    tip_force_n: tuple[float, float, float] = (0.0, 0.0, 0.0)
    tip_moment_nmm: tuple[float, float, float] = (0.0, 0.0, 0.0)
    tip_mass_g: float = 0.0
    mass_per_length_g_per_mm: float = 0.0
    distributed_n_per_mm: tuple[float, float, float] = (0.0, 0.0, 0.0)
    point_forces_n: tuple = ()
    gravity: tuple[float, float, float] = (0.0, -1.0, 0.0)
    point_moments_nmm: tuple = ()

    def __post_init__(self):
        s = object.__setattr__
        s(self, "tip_force_n", checked_vector("tip_force_n", self.tip_force_n, "N"))
        s(self, "tip_moment_nmm", checked_vector("tip_moment_nmm", self.tip_moment_nmm, "N*mm"))
        s(self, "tip_mass_g", number("tip_mass_g", self.tip_mass_g, 0.0, unit="g"))
        s(self, "mass_per_length_g_per_mm",
          number("mass_per_length_g_per_mm", self.mass_per_length_g_per_mm, 0.0, unit="g/mm"))
        s(self, "distributed_n_per_mm", checked_vector("distributed_n_per_mm", self.distributed_n_per_mm, "N/mm"))
        for key, unit in (("point_forces_n", "N"), ("point_moments_nmm", "N*mm")):
            pts = []
            for i, item in enumerate(getattr(self, key)):
                try:
                    sp, Fp = item
                except (TypeError, ValueError):
                    raise InputError(f"{key}[{i}] must be (s_mm, (X, Y, Z)) ({unit})") from None
                pts.append((number(f"{key}[{i}] s_mm", sp, 0.0, unit="mm"), checked_vector(f"{key}[{i}]", Fp, unit)))
            s(self, key, tuple(pts))
        g = np.asarray(checked_vector("gravity", self.gravity, "direction"))
        ng = float(np.linalg.norm(g))
        if ng == 0.0:
            raise InputError("gravity = (0, 0, 0) has no direction; give a non-zero vector, e.g. (0, -1, 0)")
        s(self, "gravity", tuple(float(v) for v in g / ng))

    @classmethod
    def from_planar(cls, loads: FingerLoads) -> FingerLoads3D:
        """The same loads as a planar :class:`~bendpam.design.finger.FingerLoads` (in the local xy plane).

        >>> FingerLoads3D.from_planar(FingerLoads(tip_force_n=(0.0, -0.5), tip_moment_nmm=2.0)).tip_moment_nmm
        (0.0, 0.0, 2.0)
        """
        return cls(tip_force_n=(*loads.tip_force_n, 0.0), tip_moment_nmm=(0.0, 0.0, loads.tip_moment_nmm),
                   tip_mass_g=loads.tip_mass_g, mass_per_length_g_per_mm=loads.mass_per_length_g_per_mm,
                   gravity=(*loads.gravity, 0.0))

    @property
    def is_zero(self) -> bool:
        return (not any(self.tip_force_n) and not any(self.tip_moment_nmm) and self.tip_mass_g == 0.0
                and self.mass_per_length_g_per_mm == 0.0 and not any(self.distributed_n_per_mm)
                and not any(any(F) for _, F in self.point_forces_n)
                and not any(any(M) for _, M in self.point_moments_nmm))

    def tip_resultant(self) -> tuple[float, float, float]:
        """Total force at the fingertip point (force + weight of the tip mass), N."""
        w = self.tip_mass_g * G_N_PER_G
        return tuple(float(f + w * g) for f, g in zip(self.tip_force_n, self.gravity, strict=True))  # type: ignore

    def distributed(self) -> tuple[float, float, float]:
        """Total distributed load per length (self-weight + ``distributed_n_per_mm``), N/mm."""
        w = self.mass_per_length_g_per_mm * G_N_PER_G
        return tuple(float(q + w * g) for q, g in zip(self.distributed_n_per_mm, self.gravity, strict=True))  # type: ignore


@dataclass(frozen=True)
class Finger3DShape:
    """Equilibrium of a spatial finger (arrays over the nodes; world axes).

    Attributes
    ----------
    pressure_kpa : kPa.  s : arc length, mm.  xyz : (n, 3) frame-line points, mm.
    directors : (n, 3, 3) columns ``d1`` (in-plane normal), ``d2`` (bending axis), ``d3`` (tangent).
    curvature : the paper's frame curvature ``k'`` (1/mm).  lateral_curvature : about ``d1`` (1/mm).
    twist : rad/mm.  moment : (n, 3) the loads' moment in the director frame (``m.d1, m.d2, m.d3``), N*mm.
    tip_xyz : fingertip point, mm.  equilibrium, residual_nmm, load_fraction, note, limit, branch:
    as :class:`~bendpam.design.finger.FingerShape`.  stable : every section on the stable branch of its
    law (the 3-D finger has no separate structural-stability check: a structural limit point shows as
    the load continuation stopping, ``equilibrium=False``).

    Examples
    --------
    >>> import bendpam
    >>> f3 = Finger3D(Finger(bendpam.physics.presets.be_pam(), nodes=21))
    >>> sh = solve_finger3d(f3, 150.0, FingerLoads3D(tip_force_n=(0.0, 0.0, 0.2)))
    >>> sh.equilibrium, round(sh.tip_z_mm, 2), round(sh.twist_deg, 2)   # the twist moment is below the lock torque
    (True, 3.59, 0.0)
    """

    finger3d: Finger3D
    loads: FingerLoads3D
    pressure_kpa: float
    s: np.ndarray
    xyz: np.ndarray
    directors: np.ndarray
    curvature: np.ndarray
    lateral_curvature: np.ndarray
    twist: np.ndarray
    moment: np.ndarray
    tip_xyz: tuple[float, float, float]
    equilibrium: bool
    stable: bool
    residual_nmm: float
    load_fraction: float
    note: str
    limit: Finger3DShape | None = field(default=None, repr=False)
    branch: StableBranch | None = field(default=None, repr=False)

    @property
    def tip_z_mm(self) -> float:
        """Tip displacement out of the finger's bending plane (along its normal), mm."""
        f3 = self.finger3d
        return float(np.dot(np.asarray(self.tip_xyz) - np.asarray(f3.origin_mm), f3.plane_normal))

    @property
    def out_of_plane_deg(self) -> float:
        """Angle of the tip tangent out of the bending plane, degrees."""
        d3 = self.directors[-1, :, 2]
        return math.degrees(math.asin(max(-1.0, min(1.0, float(np.dot(d3, self.finger3d.plane_normal))))))

    @property
    def twist_deg(self) -> float:
        """Total twist of the tip section about the frame line, ``int tau ds``, degrees."""
        w = np.full(self.s.size, self.s[1] - self.s[0])
        w[[0, -1]] *= 0.5
        return math.degrees(float(w @ self.twist))

    @property
    def bend_angle_deg(self) -> float:
        """In-plane rotation of the tip from the base direction (projected on the plane), degrees."""
        f3 = self.finger3d
        t = f3.rotation.T @ self.directors[-1, :, 2]
        return math.degrees(f3.finger.bend * (math.atan2(float(t[1]), float(t[0])) - f3.finger.base_angle))

    def _summary(self):
        d = self.to_dict()
        return (f"Finger3DShape at {self.pressure_kpa:g} kPa ({'equilibrium' if self.equilibrium else 'no equilibrium'}"
                f"{', ' + self.note if self.note else ''})",
                [(k, d[k]) for k in ("tip_x_mm", "tip_y_mm", "tip_z_mm", "bend_angle_deg", "out_of_plane_deg",
                                     "twist_deg", "residual_nmm")], [], [])

    def __repr__(self) -> str:
        return summary_text(*self._summary())

    def _repr_html_(self) -> str:
        return summary_html(*self._summary())

    def to_dict(self) -> dict[str, Any]:
        """Tip pose, angles, base moment and residual as a JSON-ready dict (units in the names; null: undefined).

        >>> import bendpam
        >>> d = solve_finger3d(Finger3D(Finger(bendpam.physics.presets.be_pam())), 150.0).to_dict()
        >>> round(d["tip_x_mm"], 2), d["tip_z_mm"], d["twist_deg"]
        (113.47, 0.0, 0.0)
        """
        ok = self.equilibrium
        tx, ty, _ = self.tip_xyz
        return {"pressure_kpa": float(self.pressure_kpa), "tip_x_mm": json_number(tx), "tip_y_mm": json_number(ty),
                "tip_z_mm": json_number(self.tip_z_mm if ok else math.nan),
                "bend_angle_deg": json_number(self.bend_angle_deg if ok else math.nan),
                "out_of_plane_deg": json_number(self.out_of_plane_deg if ok else math.nan),
                "twist_deg": json_number(self.twist_deg if ok else math.nan),
                "base_moment_nmm": [json_number(v) for v in self.moment[0]],
                "equilibrium": bool(ok), "note": self.note or None, "residual_nmm": json_number(self.residual_nmm),
                "load_fraction": float(self.load_fraction)}

    def to_dataframe(self):
        """The shape along the finger as a :class:`pandas.DataFrame` (units in the column names)."""
        import pandas as pd

        return pd.DataFrame({"s_mm": self.s, "x_mm": self.xyz[:, 0], "y_mm": self.xyz[:, 1], "z_mm": self.xyz[:, 2],
                             "curvature_per_mm": self.curvature, "lateral_curvature_per_mm": self.lateral_curvature,
                             "twist_rad_per_mm": self.twist, "moment_d1_nmm": self.moment[:, 0],
                             "moment_d2_nmm": self.moment[:, 1], "moment_d3_nmm": self.moment[:, 2]})

    def plot(self, ax=None, title: str | None = None):
        """A 3-D figure of the shape (:func:`plot_finger3d`)."""
        return plot_finger3d([self], ax=ax, title=title)

    def save(self, out_dir, *, figures: bool = True, figure_format: str = "png") -> dict[str, str]:
        """Write finger3d.json, finger3d.csv and (optionally) the figure into ``out_dir``; ``{name: path}``.

        Each file is written atomically (for a whole set use :class:`bendpam.infra.outputs.OutputSet`).
        """
        import json

        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        files = {}
        for name, text in (("finger3d.json", json.dumps(self.to_dict(), indent=2) + "\n"),
                           ("finger3d.csv", self.to_dataframe().to_csv(index=False))):
            atomic_write_text(out / name, text)
            files[name] = str(out / name)
        if figures:
            target = out / f"finger3d.{figure_format}"
            figure("save_figure")(self.plot(), target, format=figure_format)
            files[target.name] = str(target)
        return files


# ------------------------------------------------------------------------------------------------
# the solver
# ------------------------------------------------------------------------------------------------
def _compliance_twist(m3, lock):
    """``sign(m3) max(|m3| - lock, 0)``, complex-step safe (the kink decided on the real part)."""
    re = np.real(m3)
    lr = np.real(lock)
    return np.where(re > lr, m3 - lock, np.where(re < -lr, m3 + lock, 0.0 * m3))


class _System:
    """Residuals of the spatial finger at load fraction ``lam`` (moments over a scale)."""

    def __init__(self, rod: Rod3D, branch: StableBranch, table: SpatialTable, lock: bool):
        self.rod, self.br, self.tab, self.lock = rod, branch, table, lock
        self.scale = rod.scale(float(branch.moment(0.0)[0]))

    def moments(self, U, lam):
        """The loads' moments in the director frame (..., n, 3) and the geometry."""
        rod = self.rod
        D, x, xt = rod.geometry(U)
        m = rod.load_moment(D, x, xt, lam, U)
        md = np.einsum("...ij,...i->...j", D, m)  # components along d1, d2, d3
        return md, D, x, xt

    def __call__(self, U, lam):
        rod = self.rod
        K = U.reshape(*U.shape[:-1], rod.n, 3)
        k1, kp, tw = K[..., 0], K[..., 1], K[..., 2]
        md = self.moments(U, lam)[0]
        M, _ = self.br.moment(kp)
        EI, GJ, T = self.tab(kp)
        T = np.where(np.real(T) > 0.0, T, 0.0 * T) if self.lock else 0.0 * T  # no lock where the slope is negative
        r = np.stack([EI * k1 - md[..., 0], M + rod.c * md[..., 1],
                      GJ * tw - _compliance_twist(md[..., 2], T)], -1)
        return r.reshape(U.shape) / self.scale


def _bounds(br: StableBranch, n: int):
    lo = np.tile([-np.inf, br.k_lo, -np.inf], n)
    hi = np.tile([np.inf, br.k_hi, np.inf], n)
    return lo, hi


def _shape(f3, rod, sys_, U, P, loads, lam=1.0, equilibrium=True, note="", limit=None):
    md, D, x, xt = sys_.moments(U, lam)
    K = U.reshape(rod.n, 3)
    M = f3.finger.law.moment(P, K[:, 1])
    res = float(np.max(np.abs(M + rod.c * md[:, 1])))
    return Finger3DShape(f3, loads, P, rod.s.copy(), x, D, K[:, 1].copy(), K[:, 0].copy(), K[:, 2].copy(), md,
                         (float(xt[0]), float(xt[1]), float(xt[2])), equilibrium, equilibrium, res, lam, note, limit,
                         sys_.br)


def _failure(f3, rod, br, P, loads, note, limit=None, lam=0.0):
    nan = np.full(rod.n, np.nan)
    return Finger3DShape(f3, loads, P, rod.s.copy(), np.full((rod.n, 3), np.nan), np.full((rod.n, 3, 3), np.nan),
                         nan, nan.copy(), nan.copy(), np.full((rod.n, 3), np.nan), (math.nan,) * 3, False, False,
                         math.nan, lam, note, limit, br)


def solve_finger3d(finger3d: Finger3D, pressure_kpa, loads: FingerLoads3D | None = None) -> Finger3DShape:
    """Equilibrium of the spatial finger ``finger3d`` at ``pressure_kpa`` (kPa) under ``loads``.

    Continuation in the load fraction from the free shape; see the module notes.  Never a shape on
    the unstable part of the law: without an equilibrium the result says why (``equilibrium=False``,
    ``note``, the last equilibrium in ``limit``).

    Examples
    --------
    >>> import bendpam
    >>> f3 = Finger3D(Finger(bendpam.physics.presets.be_pam(), nodes=21))
    >>> sh = solve_finger3d(f3, 150.0, FingerLoads3D(tip_force_n=(0.0, 0.0, 4.0)))     # 4 N sideways
    >>> round(sh.tip_z_mm, 1), round(sh.out_of_plane_deg, 1), round(sh.twist_deg, 1), sh.equilibrium
    (64.3, 34.7, 3.0, True)
    """
    if not isinstance(finger3d, Finger3D):
        raise TypeError(f"finger3d must be a bendpam.design.finger3d.Finger3D, got {type(finger3d).__name__}")
    loads = FingerLoads3D() if loads is None else loads
    if isinstance(loads, FingerLoads):
        loads = FingerLoads3D.from_planar(loads)
    if not isinstance(loads, FingerLoads3D):
        raise TypeError(f"loads must be a FingerLoads3D, got {type(loads).__name__}")
    f = finger3d.finger
    P = checked_pressure_kpa(pressure_kpa, actuator=f.actuator)
    for sp, _F in loads.point_forces_n + loads.point_moments_nmm:
        if sp > f.length:
            raise InputError(f"point loads: s_mm = {sp:g} mm is beyond the active length {f.length:g} mm")
    with pressures_checked():
        return _solve(finger3d, P, loads)


@lru_cache(maxsize=32)
def _table(actuator, P: float, k_lo: float, k_hi: float, model, shear) -> SpatialTable:
    """The stiffness table at one pressure and stable branch (shared by repeated solves: load steps, sweeps)."""
    return SpatialTable(actuator, P, k_lo, k_hi, model=model, frame_shear_modulus_mpa=shear)


def _solve(f3: Finger3D, P: float, loads: FingerLoads3D) -> Finger3DShape:
    f = f3.finger
    rod = Rod3D(f3, loads)
    try:
        br = f.branch(P)
    except NoEquilibrium as exc:
        return _failure(f3, rod, None, P, loads, str(exc))
    table = _table(f.actuator, P, br.k_lo, br.k_hi, f.model, f3.frame_shear_modulus_mpa)
    sys_ = _System(rod, br, table, f3.sleeve_lock)
    lo, hi = _bounds(br, rod.n)
    kf = br.free_curvature
    fb = f.law.free_curvature(P)
    if np.isfinite(kf) and fb.status != "no-equilibrium" and np.isfinite(fb.curvature_per_mm):
        kf = float(fb.curvature_per_mm)
    U0 = np.zeros(3 * rod.n)
    if np.isfinite(kf):
        U0[1::3] = kf
        if loads.is_zero:
            return _shape(f3, rod, sys_, U0, P, loads)
        U, lam = continuation(lambda t: ((lambda V: sys_(V, t)), lo, hi), U0)
        lam = max(lam, 0.0)
        if lam >= 1.0:
            return _shape(f3, rod, sys_, U, P, loads)
        last = _shape(f3, rod, sys_, U, P, loads, lam=lam, equilibrium=False)
        note = (f"no equilibrium: the load path stops at load fraction {lam:.3g} (snap-through at the end of the "
                "stable branch of the moment law, or a structural limit point)")
        return _failure(f3, rod, br, P, loads, note, limit=last, lam=lam)
    if loads.is_zero:
        return _failure(f3, rod, br, P, loads, f"no free-bending equilibrium: {fb.reason or br.describe_end(+1)}")
    span = br.k_hi - br.k_lo
    sgn = f.actuator.bend_sign
    k_end, k_other = (br.k_hi, br.k_lo) if sgn > 0 else (br.k_lo, br.k_hi)
    for g in [k_end - sgn * fr * span for fr in (0.02, 0.1, 0.3)] + [0.0, k_other + sgn * 0.1 * span]:
        U0[1::3] = g
        U, ok, _ = newton(lambda V: sys_(V, 1.0), U0, lo, hi, NEWTON_TOL, maxit=60)
        if ok:
            return _shape(f3, rod, sys_, U, P, loads, note="no free shape at this pressure (fold of the moment law): "
                          "the equilibrium exists only under these loads")
    return _failure(f3, rod, br, P, loads, f"no equilibrium: at {P:.4g} kPa the stable branch supplies only M in "
                    f"[{br.moment_min:.4g}, {br.moment_max:.4g}] N*mm, not M = 0")


def plot_finger3d(shapes, ax=None, title: str | None = None):
    """A 3-D figure of spatial finger shapes (frame line, tip, the plane's trace); returns the figure.

    Drawn by :func:`bendpam.present.figures.design.plot_finger3d`, loaded on first use.

    >>> import bendpam, matplotlib.pyplot as plt
    >>> f3 = Finger3D(Finger(bendpam.physics.presets.be_pam(), nodes=11))
    >>> fig = plot_finger3d([solve_finger3d(f3, 150.0)])
    >>> len(fig.axes)
    1
    >>> plt.close(fig)
    """
    return figure("finger3d")(shapes, ax=ax, title=title)
