r"""An N-finger gripper closing on a sphere: contact, normal force and pull-out (gripping) force.

The set-up follows the paper's Figure 8 test: identical fingers on a base circle, pointing down,
close on a sphere; the arm then pulls the gripper vertically off the (fixed) sphere and the peak
pull is the gripping force.

Model and assumptions
---------------------
* **Geometry.**  ``fingers`` fingers (default 3) sit on a base circle of radius ``base_radius_mm``
  (their frame lines), equally spaced, pointing straight down (or tilted outward by
  ``splay_deg``), and curl toward the axis.  The
  sphere (diameter ``D``) is centred on the gripper axis, so every finger works in its own radial
  plane with the same statics; the planar finger model of :mod:`bendpam.design.finger` applies
  (coordinates: ``x`` radial outward from the axis, ``y`` up, base at ``(R_b, 0)``).
* **Contact surface.**  A BE-PAM finger bends toward its frame, so the frame faces the sphere; a
  BC-PAM finger bends away from it, so the bladder side (about ``2 R0_start_mm`` from the frame)
  faces the sphere.  ``contact_offset_mm`` (default: half the frame thickness for a BE-PAM, ``2
  R0_start_mm`` for a BC-PAM) is that distance.  The rod's frame line then touches the sphere of radius
  ``D/2 + offset`` (body contact, tangent), or the fingertip point, at the end of a rigid
  fingertip of length ``fingertip_mm`` shifted by the offset toward the sphere, touches the sphere
  itself (tip contact).
* **Placement.**  As in the test, the arm brings the open (unpressurised, straight) gripper down
  onto the sphere, which rests on a table, and stops at the first contact: the palm (the base
  plane) on the top of the sphere, the lowest point of the straight fingers on the table, or the
  open fingers' contact surface on the sphere, whichever comes first (``center_depth_mm``
  overrides this).  A sphere wider than the opening between the open fingers is met by the
  fingertips on its upper half, at the angle ``beta0`` from the downward vertical; if that lies
  beyond the friction cone (``beta0 >= 90 deg + atan(mu)``) nothing can hold it: the sphere is
  **too large**, contact ``"none"``, zero force.
* **Grasp statics.**  Quasi-static inflation from the contact onset (the free finger, a circular
  arc, first touching the sphere) to the working pressure, with frictionless contact while the
  fingers close (friction only matters in the pull).  The contact set is tracked by an
  active-set continuation in pressure: a tip contact (the fingertip point on the sphere), a body
  contact (the contact surface tangent to the sphere, on the rod or on the flat pad), or both;
  a contact is added where the finger would penetrate the sphere, dropped where it would pull, and
  a body contact that runs off the end of the pad becomes a tip contact.  Each contact carries a
  normal force ``N >= 0`` along the sphere normal; every section stays on the stable branch of its
  moment law.  If the free finger does not reach the sphere at this pressure the sphere is **too
  small**: contact ``"none"``, zero force.  If the frictionless fingertip slides up over the
  sphere (a limit point with the contact above the equator), the result is ``"none"`` with zero
  force and a note.  If the finger has no stable equilibrium in contact (the BC-PAM above its
  fold: near the fingertip the contact moment is too small for the stable branch, that part
  snaps through), the result says so (``equilibrium=False``, NaN forces), never a wrong shape.
  The structural stability of contact equilibria is not checked (the finger statics are).
* **Pull-out.**  The sphere is fixed; the arm pulls the gripper up.  Each contact keeps its normal
  force ``N`` (the fingers are compliant and the pull is quick compared with pressure changes) and
  transmits at most the edge of its friction cone; the largest upward force it can carry is
  ``N (cos beta + mu sin beta)``, where ``beta`` is the angle of the sphere's outward normal at the
  contact from the downward vertical (``cos beta = -n_y``, ``sin beta = n_x``).  A contact below
  the equator (``beta < 90 deg``) cages the sphere through its normal force; above it only friction
  holds, and a negative value counts as zero (that contact just opens).  The gripping force is the
  sum over the fingers.  This neglects the change of ``N`` and of the contact point during the pull
  and the friction-induced moment on the finger, friction while closing (a sticking fingertip
  would hold a larger force on big spheres), gravity on the fingers and the sphere's weight (a
  fixed sphere), out-of-plane finger deformation, and finger-finger and palm contacts.

Units: mm, N, kPa (every function takes and returns pressures in kPa, ``pressure_kpa``), degrees in
names ending ``_deg``.  Bad input raises :class:`bendpam.InputError`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..actuator import Actuator
from ..checks import number
from ..errors import InputError, NoEquilibrium
from ..law import MomentLaw, StableBranch
from ..models import normalise_model
from .finger import (
    NEWTON_TOL,
    Finger,
    FingerLoads,
    FingerShape,
    Rod,
    checked_pressure_kpa,
    checked_pressures_kpa,
    cross,
    newton,
    pressures_checked,
    solve_finger,
)

__all__ = [
    "DEFAULT_BASE_RADIUS_MM",
    "DEFAULT_FINGERTIP_MM",
    "Grasp",
    "Gripper",
    "grasp_sweep",
    "plot_grasp",
    "solve_grasp",
]

#: default base-circle radius of the fingers' frame lines, mm (see :class:`Gripper`)
DEFAULT_BASE_RADIUS_MM = 100.0
#: default rigid fingertip (tip pad) length, mm
DEFAULT_FINGERTIP_MM = 10.0

_PEN_TOL = 1e-3  # mm, allowed penetration from the discretisation


@dataclass(frozen=True)
class Gripper:
    """An N-finger gripper of identical bending-PAM fingers (validated, immutable).

    Parameters
    ----------
    actuator : Actuator
        The finger actuator; ``L0_mm`` is the finger's active length (the paper's grippers: 130 mm,
        ``actuator.replace(L0_mm=130)``).
    model : {"energy", "force_balance"}
    fingers : int
        Number of fingers, in [2, 12] (default 3).
    base_radius_mm : float
        Radius of the circle of the fingers' frame lines at the base, mm (default 100 mm: the
        paper does not give it; with 130 mm BE-PAM fingers it takes spheres of 80 mm (from about
        140 kPa) to 200 mm, the middle of the paper's 80-280 mm range).
    fingertip_mm : float
        Rigid fingertip (tip pad) length, mm (default 10).
    contact_offset_mm : float, optional
        Distance from the frame line to the finger's contact surface on the sphere's side, mm.
        Default: half the frame thickness for a BE-PAM, ``2 R0_start_mm`` for a BC-PAM.
    mu : float
        Friction coefficient pad-sphere for the pull-out, in [0, 5] (default 0.5).
    center_depth_mm : float, optional
        Depth of the sphere's centre below the base plane, mm.  Default: the placement rule in the
        module docstring.
    splay_deg : float
        Outward tilt of the open fingers from the vertical, degrees, in [-45, 45] (default 0:
        pointing straight down).
    nodes : int
        Collocation nodes per finger (default 61).
    """

    actuator: Actuator
    model: str = "energy"
    fingers: int = 3
    base_radius_mm: float = DEFAULT_BASE_RADIUS_MM
    fingertip_mm: float = DEFAULT_FINGERTIP_MM
    contact_offset_mm: float | None = None
    mu: float = 0.5
    center_depth_mm: float | None = None
    splay_deg: float = 0.0
    nodes: int = 61

    def __post_init__(self):
        s = object.__setattr__
        if not isinstance(self.actuator, Actuator):
            raise TypeError(f"actuator must be a bendpam.Actuator, got {type(self.actuator).__name__}")
        s(self, "model", normalise_model(self.model))
        nf = self.fingers
        if isinstance(nf, bool) or not isinstance(nf, int | np.integer) or not 2 <= int(nf) <= 12:
            raise InputError(f"fingers = {nf!r} is outside the allowed range [2, 12] (an integer)")
        s(self, "fingers", int(nf))
        s(self, "base_radius_mm", number("base_radius_mm", self.base_radius_mm, 0.0, 1e4, lo_open=True, unit="mm"))
        s(self, "fingertip_mm", number("fingertip_mm", self.fingertip_mm, 0.0, 1e4, unit="mm"))
        if self.contact_offset_mm is None:
            off = (self.actuator.frame_thickness_mm / 2.0 if self.actuator.bend_sign > 0
                   else 2.0 * self.actuator.R0_start_mm)
            s(self, "contact_offset_mm", off)
        else:
            s(self, "contact_offset_mm", number("contact_offset_mm", self.contact_offset_mm, 0.0, 1e3, unit="mm"))
        s(self, "mu", number("mu", self.mu, 0.0, 5.0))
        if self.center_depth_mm is not None:
            s(self, "center_depth_mm", number("center_depth_mm", self.center_depth_mm, unit="mm"))
        s(self, "splay_deg", number("splay_deg", self.splay_deg, -45.0, 45.0, unit="deg"))
        # the finger validates nodes and the actuator
        self.finger()

    def finger(self) -> Finger:
        """One finger in its radial plane: base at ``(R_b, 0)``, pointing down (tilted outward by
        ``splay_deg``), curling toward the axis (clockwise in the plane, ``bend=-1``)."""
        offset = self.contact_offset_mm
        assert offset is not None, "set by __post_init__ before the first call"
        return Finger(self.actuator, self.model, base_xy_mm=(self.base_radius_mm, 0.0),
                      base_angle_deg=-90.0 + self.splay_deg,
                      bend=-1, fingertip_mm=self.fingertip_mm, fingertip_offset_mm=offset,
                      nodes=self.nodes)

    @property
    def law(self) -> MomentLaw:
        """The finger actuator's shared moment law under the gripper's model (:meth:`bendpam.MomentLaw.of`)."""
        return MomentLaw.of(self.actuator, self.model)

    def center_depth(self, diameter_mm: float) -> float:
        """Depth of the sphere's centre below the base plane, mm (placement rule or the given value)."""
        D = number("diameter_mm", diameter_mm, 0.0, 1e5, lo_open=True, unit="mm")
        return _landing(self, 0.5 * D)[0]


@dataclass(frozen=True)
class Grasp:
    """One grasp: a gripper on a sphere at one pressure.

    Attributes
    ----------
    diameter_mm, pressure_kpa : sphere diameter (mm), gauge pressure (kPa).
    contact : ``"tip"``, ``"body"``, ``"tip+body"`` or ``"none"``.
    normal_force_n : normal (contact) force per finger, N (sum over its contacts; 0 for none).
    grip_force_n : pull-out force of the whole gripper, N.
    contact_xy : contact point(s) in the finger plane (x radial, y up), mm.
    contact_angle_deg : angle beta of the sphere's outward normal at the (main) contact from the
        downward vertical (0: under the sphere, 90: at the equator).
    center_depth_mm : depth of the sphere's centre below the base plane.
    equilibrium : False where the finger has no stable equilibrium (snap-through): forces NaN.
    note : why there is no contact or no equilibrium, else empty.
    shape : the finger's :class:`FingerShape` (free or in contact), None if not computed.
    """

    diameter_mm: float
    pressure_kpa: float
    contact: str
    normal_force_n: float
    grip_force_n: float
    contact_xy: tuple
    contact_angle_deg: float
    center_depth_mm: float
    equilibrium: bool
    note: str
    shape: FingerShape | None = field(default=None, repr=False)


def _none(D, P, depth, note, shape=None, equilibrium=True):
    f = 0.0 if equilibrium else math.nan
    return Grasp(D, P, "none", f, f, (), math.nan, depth, equilibrium, note, shape)


class _Contact:
    """Residuals of one finger in contact with the sphere (tip, body or both)."""

    def __init__(self, rod: Rod, cx, cy, R, delta, mode: str, scale: float):
        self.rod, self.cx, self.cy, self.R, self.delta, self.mode = rod, cx, cy, R, delta, mode
        self.scale = scale
        self.Lr = rod.L + rod.ell
        self.fscale = scale / self.Lr
        n = rod.n
        self.n = n
        self.i_tip = n if "tip" in mode else None
        self.i_body = (n + (1 if "tip" in mode else 0)) if "body" in mode else None
        self.size = n + (1 if "tip" in mode else 0) + (2 if "body" in mode else 0)

    def forces(self, U):
        """Geometry and contact forces: returns dict with the pieces (batched)."""
        rod, n = self.rod, self.n
        k = U[..., :n]
        phi, x, y, xt, yt = rod.geometry(k)
        out = {"k": k, "phi": phi, "x": x, "y": y, "xt": xt, "yt": yt}
        if self.i_tip is not None:
            N = U[..., self.i_tip] * self.fscale
            dx, dy = xt - self.cx, yt - self.cy
            d = np.sqrt(dx * dx + dy * dy)
            out["tip"] = (N, xt, yt, dx / d, dy / d, d)
        if self.i_body is not None:
            # contact coordinate sigma in (0, L + ell): on the rod's contact surface (offset by delta
            # from the frame line) for sigma <= L, on the flat fingertip pad beyond
            N = U[..., self.i_body] * self.fscale
            sc = U[..., self.i_body + 1] * self.Lr
            b, off = rod.f.bend, rod.off
            on_rod = np.real(sc) <= rod.L
            sr = np.where(on_rod, sc, rod.L)
            xr, yr, pr = rod.point(phi, x, y, sr)
            pl = phi[..., -1]
            tau = np.where(on_rod, 0.0, sc - rod.L)
            pc = np.where(on_rod, pr, pl)
            xc = np.where(on_rod, xr, x[..., -1] + tau * np.cos(pl)) - b * off * np.sin(pc)
            yc = np.where(on_rod, yr, y[..., -1] + tau * np.sin(pl)) + b * off * np.cos(pc)
            dx, dy = xc - self.cx, yc - self.cy
            d = np.sqrt(dx * dx + dy * dy)
            out["body"] = (N, xc, yc, dx / d, dy / d, d, sc, pc)
        return out

    def system(self, branch: StableBranch):
        rod, c = self.rod, self.rod.c

        def fun(U):
            g = self.forces(U)
            x, y = g["x"], g["y"]
            m = rod.load_moment(x, y, g["xt"], g["yt"])
            extra = []
            if "tip" in g:
                N, px, py, nx, ny, d = g["tip"]
                m = m + cross(px[..., None] - x, py[..., None] - y, (N * nx)[..., None], (N * ny)[..., None])
                extra.append(((d - self.R) / self.Lr)[..., None])
            if "body" in g:
                N, px, py, nx, ny, d, sc, pc = g["body"]
                beyond = (rod.s < np.real(sc)[..., None]).astype(float)
                m = m + beyond * cross(px[..., None] - x, py[..., None] - y, (N * nx)[..., None], (N * ny)[..., None])
                extra.append(((d - self.R) / self.Lr)[..., None])
                extra.append((np.cos(pc) * nx + np.sin(pc) * ny)[..., None])
            M, _ = branch.moment(g["k"])
            return np.concatenate([(M + c * m) / self.scale, *extra], axis=-1)

        lo = np.full(self.size, -np.inf)
        hi = np.full(self.size, np.inf)
        lo[: self.n], hi[: self.n] = branch.k_lo, branch.k_hi
        if self.i_body is not None:
            lo[self.i_body + 1], hi[self.i_body + 1] = 0.0, 1.0
        return fun, lo, hi

    def gaps(self, U):
        """Signed gaps of the rod nodes (to the offset sphere) and of the fingertip (to the sphere), mm."""
        g = self.forces(U[None, :])
        x, y = g["x"][0], g["y"][0]
        gap_nodes = np.hypot(x - self.cx, y - self.cy) - self.R - self.delta
        rod = self.rod
        # points along the rigid fingertip, from the rod end (offset side) to the fingertip point
        pl = g["phi"][0, -1]
        t = np.linspace(0.0, 1.0, 6)
        b = rod.f.bend
        ex = x[-1] - b * rod.off * np.sin(pl) + t * rod.ell * np.cos(pl)
        ey = y[-1] + b * rod.off * np.cos(pl) + t * rod.ell * np.sin(pl)
        gap_tip = np.hypot(ex - self.cx, ey - self.cy) - self.R
        return gap_nodes, gap_tip


def _min_touch_curvature(finger: Finger, cx, cy, R, delta, kap_max):
    """Smallest geometric curvature (toward the sphere) at which the constant-curvature finger touches.

    The contact surface is the rod's offset surface (the frame line against the sphere of radius
    ``R + delta``), the flat pad and its end point (against the sphere).  Returns ``(kappa, kind,
    sigma)`` with kind ``"tip"`` or ``"body"`` and the contact coordinate ``sigma`` (mm along rod and
    pad), or ``(nan, "", nan)`` if the finger never touches up to ``kap_max``.
    """
    L, ell = finger.length, finger.fingertip_mm
    s = np.linspace(0.0, L, 241)
    tau = np.linspace(0.0, ell, 21)[:-1] if ell > 0 else np.zeros(0)
    p0 = finger.base_angle
    b = finger.bend
    off = finger.fingertip_offset_mm
    x0, y0 = finger.base_xy_mm

    def gaps(kap):
        kap = np.atleast_1d(kap)[:, None]
        th = b * kap * s  # signed turning
        half = 0.5 * th
        sinc = np.where(np.abs(half) < 1e-12, 1.0, np.sin(half) / np.where(half == 0, 1.0, half))
        x = x0 + s * sinc * np.cos(p0 + half)
        y = y0 + s * sinc * np.sin(p0 + half)
        pl = (p0 + th[:, -1])[:, None]
        ex = x[:, -1:] - b * off * np.sin(pl)  # rod end on the contact surface
        ey = y[:, -1:] + b * off * np.cos(pl)
        px, py = ex + tau * np.cos(pl), ey + tau * np.sin(pl)
        xt, yt = ex[:, 0] + ell * np.cos(pl[:, 0]), ey[:, 0] + ell * np.sin(pl[:, 0])
        gb = np.concatenate([np.hypot(x - cx, y - cy) - R - delta, np.hypot(px - cx, py - cy) - R], axis=1)
        gt = np.hypot(xt - cx, yt - cy) - R
        return gb, gt

    sig = np.concatenate([s, L + tau])
    grid = np.linspace(0.0, kap_max, 801)
    gb, gt = gaps(grid)
    g = np.minimum(gb.min(axis=1), gt)
    hit = np.flatnonzero(g <= 1e-9)
    if not hit.size:
        return math.nan, "", math.nan
    j = hit[0]
    if j == 0:
        hi = 0.0
    else:
        lo, hi = grid[j - 1], grid[j]
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            gb, gt = gaps(mid)
            if min(gb.min(), gt[0]) <= 0.0:
                hi = mid
            else:
                lo = mid
    gb, gt = gaps(hi)
    if gt[0] <= gb.min() + 1e-9:
        return hi, "tip", L + ell
    return hi, "body", float(sig[np.argmin(gb[0])])


def _landing(gripper: Gripper, R: float):
    """Placement: depth of the sphere's centre below the base plane (mm) and the landing angle.

    The open gripper comes down until the palm touches the top of the sphere, the lowest point of
    the straight fingers reaches the table the sphere rests on, or the open fingers' contact
    surface (frame line offset by ``contact_offset_mm``, then the pad) touches the sphere, whichever
    comes first.  In the last case the second value is the angle beta (deg) of the sphere's normal at
    the landing point from the downward vertical, else NaN.
    """
    if gripper.center_depth_mm is not None:
        return gripper.center_depth_mm, math.nan
    f = gripper.finger()
    p0 = f.base_angle
    t = np.array([math.cos(p0), math.sin(p0)])
    nrm = f.bend * np.array([-math.sin(p0), math.cos(p0)])  # toward the bending side (the sphere)
    sig = np.linspace(0.0, f.length + f.fingertip_mm, 801)
    pts = np.array(f.base_xy_mm)[None, :] + sig[:, None] * t[None, :] + f.fingertip_offset_mm * nrm[None, :]
    depth = -pts[:, 1]
    d = max(R, float(np.max(-(np.array(f.base_xy_mm)[1] + sig * t[1]))) - R)
    inside = np.abs(pts[:, 0]) < R
    if np.any(inside):
        cand = depth[inside] + np.sqrt(R * R - pts[inside, 0] ** 2)
        j = int(np.argmax(cand))
        if cand[j] >= d:
            px, py = pts[inside][j]
            nx, ny = px / R, (py + cand[j]) / R
            return float(cand[j]), math.degrees(math.atan2(nx, -ny))
    return d, math.nan


def _pack(n, mode, k, Nt=0.0, Nb=0.0, sig=0.5):
    u = list(k)
    if "tip" in mode:
        u.append(Nt)
    if "body" in mode:
        u += [Nb, sig]
    return np.array(u, dtype=float)


def _unpack(n, mode, u):
    k = u[:n]
    i = n
    Nt = Nb = 0.0
    sig = math.nan
    if "tip" in mode:
        Nt = float(u[i])
        i += 1
    if "body" in mode:
        Nb, sig = float(u[i]), float(u[i + 1])
    return k, Nt, Nb, sig


class _Ctx:
    """Everything one grasp needs: the finger rod, the sphere and the moment scale."""

    def __init__(self, gripper: Gripper, rod: Rod, cx, cy, R, delta, scale):
        self.gripper, self.rod, self.cx, self.cy, self.R, self.delta, self.scale = gripper, rod, cx, cy, R, delta, scale
        self._sys: dict[str, _Contact] = {}

    def contact(self, mode) -> _Contact:
        if mode not in self._sys:
            self._sys[mode] = _Contact(self.rod, self.cx, self.cy, self.R, self.delta, mode, self.scale)
        return self._sys[mode]

    def branch(self, P) -> StableBranch:
        return self.gripper.law.stable_branch(P)


def _check(ctx: _Ctx, mode: str, u):
    """Check a converged contact state: ``("ok", None, None)`` or ``("switch", mode, u)`` or ``("bad", why, None)``."""
    sysm = ctx.contact(mode)
    n = ctx.rod.n
    k, Nt, Nb, sig = _unpack(n, mode, u)
    ftol = 1e-9 * max(1.0, sysm.fscale)
    if "tip" in mode and Nt < -ftol:
        if "body" in mode:
            return "switch", "body", _pack(n, "body", k, Nb=Nb, sig=sig)
        return "bad", "the fingertip would pull on the sphere (contact opens)", None
    if "body" in mode and Nb < -ftol:
        if "tip" in mode:
            return "switch", "tip", _pack(n, "tip", k, Nt=Nt)
        return "bad", "the body contact would pull on the sphere (contact opens)", None
    if "body" in mode and sig > 0.995:
        if "tip" in mode:
            return "switch", "tip", _pack(n, "tip", k, Nt=Nt + Nb)
        return "switch", "tip", _pack(n, "tip", k, Nt=Nb)
    gap_nodes, gap_pad = sysm.gaps(u)
    rod = ctx.rod
    if "body" in mode:
        sc = sig * sysm.Lr
        near = np.abs(rod.s - sc) <= 1.01 * rod.h
        gap_nodes = np.where(near, np.maximum(gap_nodes, 0.0), gap_nodes)
        if sc > rod.L:
            gap_pad = np.maximum(gap_pad, 0.0)  # the body contact is on the pad (tangent): not a penetration
    tol = _PEN_TOL * max(1.0, ctx.R / 50.0)
    if gap_nodes.min() < -tol:
        if "body" in mode:
            return "bad", "a second body contact would be needed (the finger wraps the sphere)", None
        j = int(np.argmin(gap_nodes))
        return "switch", "tip+body" if "tip" in mode else "body", _pack(n, mode + "+body" if "tip" in mode else "body",
                                                                         k, Nt=Nt, Nb=0.0, sig=rod.s[j] / sysm.Lr)
    if "tip" not in mode and gap_pad[-1] < -tol:
        return "switch", "tip+body", _pack(n, "tip+body", k, Nt=0.0, Nb=Nb, sig=sig)
    if gap_pad[:-1].size and gap_pad[:-1].min() < -tol and "body" not in mode:
        j = int(np.argmin(gap_pad[:-1]))
        tau = rod.ell * j / (gap_pad.size - 1)
        return "switch", "tip+body", _pack(n, "tip+body", k, Nt=Nt, Nb=0.0, sig=(rod.L + tau) / sysm.Lr)
    return "ok", None, None


def _solve_at(ctx: _Ctx, mode, u, br, maxit=40):
    fun, lo, hi = ctx.contact(mode).system(br)
    return newton(fun, u, lo, hi, NEWTON_TOL, maxit=maxit)[:2]


def _settle(ctx: _Ctx, mode, u, br, max_switch=4):
    """From a converged state, follow suggested contact changes at fixed pressure until consistent."""
    for _ in range(max_switch):
        verdict, m2, u2 = _check(ctx, mode, u)
        if verdict == "ok":
            return mode, u, ""
        if verdict == "bad":
            return None, u, m2
        un, ok = _solve_at(ctx, m2, u2, br)
        if not ok:
            return None, u, f"no equilibrium after switching to {m2} contact"
        mode, u = m2, un
    return None, u, "contact state does not settle"


_NEIGHBOURS = {"tip": ("tip+body", "body"), "body": ("tip", "tip+body"), "tip+body": ("tip", "body")}


def _track(ctx: _Ctx, P0: float, P1: float, mode: str, u):
    """Active-set continuation of the contact state in pressure from ``P0`` (a valid state) to ``P1``."""
    n = ctx.rod.n
    t, step = 0.0, 1.0
    while t < 1.0:
        step = min(step, 1.0 - t)
        Pt = P0 + (t + step) * (P1 - P0)
        br = ctx.branch(Pt)
        un, ok = _solve_at(ctx, mode, u, br)
        if ok:
            m2, u2, _why = _settle(ctx, mode, un, br)
            if m2 is not None:
                mode, u, t = m2, u2, t + step
                step *= 2.0
                continue
        elif step < 1.0 / 64:
            # near a change of contact that Newton cannot cross in this mode: try the neighbours
            k, Nt, Nb, sig = _unpack(n, mode, u)
            done = False
            for m2 in _NEIGHBOURS[mode]:
                sig2 = sig if np.isfinite(sig) else 0.999
                u2 = _pack(n, m2, k, Nt=Nt if "tip" in mode else Nb, Nb=Nb, sig=min(sig2, 0.99))
                uu, ok2 = _solve_at(ctx, m2, u2, br)
                if ok2:
                    m3, u3, _ = _settle(ctx, m2, uu, br)
                    if m3 is not None:
                        mode, u, t = m3, u3, t + step
                        done = True
                        break
            if done:
                continue
        step *= 0.5
        if step < 1.0 / 1024:
            break
    return mode, u, t


def solve_grasp(gripper: Gripper, diameter_mm, pressure_kpa) -> Grasp:
    """Grasp of a sphere of ``diameter_mm`` at ``pressure_kpa`` (kPa): contact, normal and gripping force.

    See the module docstring for the model.  A sphere that does not fit, or that the fingers do
    not reach at this pressure, gives contact ``"none"`` and zero force (not an error); where the
    fingers have no stable equilibrium in contact, ``equilibrium`` is False and the forces NaN.
    """
    _check_gripper(gripper)
    D = number("diameter_mm", diameter_mm, 0.0, 1e5, lo_open=True, unit="mm")
    P = checked_pressure_kpa(pressure_kpa)
    with pressures_checked():
        return _grasp_path(gripper, D, [P])[0]


def _check_gripper(gripper) -> None:
    if not isinstance(gripper, Gripper):
        raise TypeError(f"gripper must be a bendpam.design.Gripper, got {type(gripper).__name__}")


def _grasp_path(gripper: Gripper, D: float, Ps: list[float]) -> list[Grasp]:
    """Grasps of a sphere of diameter ``D`` (mm) at pressures ``Ps`` (kPa, validated), inflating
    quasi-statically (in ascending pressure)."""
    order = np.argsort(Ps, kind="stable")
    out: list[Grasp | None] = [None] * len(Ps)
    R = 0.5 * D
    delta = gripper.contact_offset_mm
    depth, beta0 = _landing(gripper, R)
    cone = 90.0 + math.degrees(math.atan(gripper.mu))
    if np.isfinite(beta0) and beta0 >= cone:
        note = (f"too large: the open fingers land on top of the {D:g} mm sphere (beta = {beta0:.1f} deg, beyond "
                f"the friction cone at {cone:.1f} deg): nothing holds it")
        return [_none(D, P, depth, note) for P in Ps]
    finger = gripper.finger()
    act = gripper.actuator
    law = gripper.law
    cx, cy = 0.0, -depth
    lim = law.limits
    k_lock = lim.k_max if act.bend_sign > 0 else lim.k_min
    kap_c, kind, sig_c = _min_touch_curvature(finger, cx, cy, R, delta, 0.98 * abs(k_lock))
    if not np.isfinite(kap_c):
        return [_none(D, P, depth, "too small: the fingers do not touch the sphere even fully curled") for P in Ps]
    p_on = _onset_pressure_kpa(law, kap_c)
    rod = Rod(finger, FingerLoads())
    n = rod.n
    k_c = act.bend_sign * kap_c  # frame curvature at the onset
    Lr = rod.L + rod.ell
    sig0 = min(max(sig_c, 0.02 * Lr), 0.98 * Lr) / Lr
    scale = max(abs(float(law.blocked_moment(max(Ps)))), 1.0)
    ctx = _Ctx(gripper, rod, cx, cy, R, delta, scale)
    state = (p_on, kind, _pack(n, kind, np.full(n, k_c), sig=sig0)) if np.isfinite(p_on) else None
    stuck = None  # note once the quasi-static path has no equilibrium
    for i in order:
        P = Ps[i]
        fb = law.free_curvature(P)
        free_ok = bool(fb.status != "no-equilibrium") and bool(np.isfinite(fb.curvature_per_mm))
        if free_ok and abs(float(fb.curvature_per_mm)) < kap_c:
            on = f"; contact from {p_on:.4g} kPa" if np.isfinite(p_on) else ""
            out[i] = _none(D, P, depth, f"too small for this pressure: the fingers do not reach the sphere{on}",
                           solve_finger(finger, P))
            continue
        if stuck is not None:
            out[i] = _none(D, P, depth, stuck[0], equilibrium=stuck[1])
            continue
        try:
            br_P = law.stable_branch(P)
        except NoEquilibrium as exc:
            out[i] = _none(D, P, depth, str(exc), equilibrium=False)
            continue
        if state is not None:
            P0, mode0, u0 = state
            mode, u, t = _track(ctx, P0, P, mode0, u0)
            if t >= 1.0:
                state = (P, mode, u)
                out[i] = _finish(gripper, D, P, depth, ctx.contact(mode), u, br_P, mode)
                continue
            P_reached = P0 + t * (P - P0)
            g = ctx.contact(mode).forces(u[None, :])
            beta = math.degrees(math.atan2(float(np.real(g["tip"][3][0])), -float(np.real(g["tip"][4][0])))) \
                if "tip" in g else math.nan
            if "tip" in mode and beta > 90.0:
                stuck = (f"the fingertip slides up and over the sphere at {P_reached:.4g} kPa (frictionless "
                         f"closing, contact at beta = {beta:.0f} deg): no grasp", True)
            else:
                reason = fb.reason if not free_ok else "a limit point of the contact equilibrium"
                stuck = (f"no stable contact equilibrium above {P_reached:.4g} kPa ({reason}); the finger "
                         "snaps through", False)
            out[i] = _none(D, P, depth, stuck[0], equilibrium=stuck[1])
            continue
        # the contact needs more curvature than the free branch has (beyond the fold): direct solve
        res = _direct(ctx, gripper, D, P, depth, br_P, kind, k_c, sig0)
        if res is None:
            reason = fb.reason if not free_ok else "the contact needs more curvature than the stable branch reaches"
            res = _none(D, P, depth, f"no stable contact equilibrium at {P:.4g} kPa ({reason}); near the "
                        "fingertip the contact moment is too small for the stable branch, so the finger snaps "
                        "through", equilibrium=False)
        out[i] = res
    grasps = [g for g in out if g is not None]
    assert len(grasps) == len(Ps), "the loop fills in every pressure"
    return grasps


def _direct(ctx: _Ctx, gripper, D, P, depth, br_P, kind, k_c, sig0):
    n = ctx.rod.n
    span = br_P.k_hi - br_P.k_lo
    for mode in (kind, "body" if kind == "tip" else "tip", "tip+body"):
        for nguess in (0.0, 0.5):
            u0 = _pack(n, mode, np.clip(np.full(n, k_c), br_P.k_lo + 0.05 * span, br_P.k_hi - 0.05 * span),
                       Nt=nguess, Nb=nguess, sig=sig0)
            uu, ok = _solve_at(ctx, mode, u0, br_P, maxit=60)
            if ok:
                m2, u2, _ = _settle(ctx, mode, uu, br_P)
                if m2 is not None:
                    return _finish(gripper, D, P, depth, ctx.contact(m2), u2, br_P, m2)
    return None


def _onset_pressure_kpa(law: MomentLaw, kap_c: float) -> float:
    """Gauge pressure (kPa) at which the free curvature reaches ``|k'| = kap_c`` (NaN beyond the free branch).

    From the law's sampled free-bending branch (active pressure, kPa, monotone along the branch).
    """
    br = law.free_branch()
    kt, pt = np.abs(br.k_table_per_mm), br.p_table_kpa
    ok = np.isfinite(pt)
    kt, pt = kt[ok], pt[ok]
    if kap_c > kt[-1]:
        return math.nan
    return float(law.P_start_kpa) + float(np.interp(kap_c, kt, pt))


def _finish(gripper: Gripper, D, P, depth, sysm: _Contact, u, br, mode) -> Grasp:
    g = sysm.forces(u[None, :])
    mu = gripper.mu
    total_N, grip = 0.0, 0.0
    pts, betas, forces = [], [], []
    F_tip = (0.0, 0.0)
    for key in ("tip", "body"):
        if key not in g:
            continue
        N, px, py, nx, ny = (float(np.real(v[0])) for v in g[key][:5])
        total_N += N
        grip += max(N * (-ny + mu * nx), 0.0)
        pts.append((px, py))
        betas.append(math.degrees(math.atan2(nx, -ny)))
        forces.append(N)
        if key == "tip":
            F_tip = (N * nx, N * ny)
    main = int(np.argmax(forces))
    rod = sysm.rod
    loads = FingerLoads(tip_force_n=F_tip)
    k = u[: rod.n]
    phi, x, y, xt, yt = rod.geometry(k[None, :])
    m = rod.load_moment(x, y, xt, yt)[0]
    x, y, phi = x[0], y[0], phi[0]
    for key in ("tip", "body"):
        if key in g:
            N, px, py, nx, ny = (float(np.real(v[0])) for v in g[key][:5])
            mask = np.ones(rod.n) if key == "tip" else (rod.s < float(np.real(g["body"][6][0]))).astype(float)
            m = m + mask * cross(px - x, py - y, N * nx, N * ny)
    m_act = -rod.c * m
    res = float(np.max(np.abs(gripper.law.moment(P, k) - m_act)))
    shape = FingerShape(rod.f, loads, P, rod.s.copy(), x, y, phi, k.copy(), m_act, (float(xt[0]), float(yt[0])),
                        float(phi[-1]), True, True, res, 1.0, f"in {mode} contact (normal force {total_N:.4g} N)",
                        None, br)
    return Grasp(D, P, mode, total_N, gripper.fingers * grip, tuple(pts), betas[main], depth, True, "", shape)


def _diameters_mm(value) -> np.ndarray:
    """Sphere diameters (mm) as a 1-D float array, each positive and finite, else an InputError."""
    arr = np.atleast_1d(np.asarray(value, dtype=object)).ravel()
    if arr.size == 0:
        raise InputError("diameters_mm is empty; give at least one sphere diameter (mm)")
    return np.array([number("diameters_mm", d, 0.0, 1e5, lo_open=True, unit="mm") for d in arr])


def grasp_sweep(gripper: Gripper, diameters_mm, pressures_kpa):
    """Grasps over diameters (mm) and pressures (kPa): an :class:`xarray.Dataset`.

    Dimensions ``diameter_mm`` and ``pressure_kpa``; variables ``grip_force_n`` (N),
    ``contact_force_n`` (N, per finger), ``contact`` (str), ``contact_angle_deg``, ``equilibrium``
    and ``note``.  ``.to_dataframe()`` gives the flat table.
    """
    import xarray as xr

    _check_gripper(gripper)
    Ds = _diameters_mm(diameters_mm)
    Ps = checked_pressures_kpa(pressures_kpa)
    shape = (Ds.size, Ps.size)
    grip = np.full(shape, np.nan)
    normal = np.full(shape, np.nan)
    beta = np.full(shape, np.nan)
    contact = np.empty(shape, dtype=object)
    eq = np.zeros(shape, dtype=bool)
    note = np.empty(shape, dtype=object)
    for i, D in enumerate(Ds):
        with pressures_checked():
            path = _grasp_path(gripper, float(D), [float(p) for p in Ps])
        for j, g in enumerate(path):
            grip[i, j], normal[i, j], beta[i, j] = g.grip_force_n, g.normal_force_n, g.contact_angle_deg
            contact[i, j], eq[i, j], note[i, j] = g.contact, g.equilibrium, g.note
    dims = ("diameter_mm", "pressure_kpa")
    ds = xr.Dataset(
        {
            "grip_force_n": (dims, grip, {"units": "N", "long_name": "pull-out (gripping) force of the gripper"}),
            "contact_force_n": (dims, normal, {"units": "N", "long_name": "normal contact force per finger"}),
            "contact_angle_deg": (dims, beta, {"units": "deg",
                                               "long_name": "sphere normal at the contact from the downward vertical"}),
            "contact": (dims, contact.astype(str)),
            "equilibrium": (dims, eq),
            "note": (dims, note.astype(str)),
        },
        coords={"diameter_mm": Ds, "pressure_kpa": Ps},
    )
    ds.attrs.update(actuator=gripper.actuator.name or gripper.actuator.kind, model=gripper.model,
                    fingers=gripper.fingers, base_radius_mm=gripper.base_radius_mm, mu=gripper.mu,
                    fingertip_mm=gripper.fingertip_mm, contact_offset_mm=gripper.contact_offset_mm,
                    L0_mm=gripper.actuator.L0_mm)
    return ds


def plot_grasp(ds, ax=None, title: str | None = None):
    """Grip force against sphere diameter, one line per pressure (cf. the paper's Figure 8(c, d))."""
    from .. import plots  # noqa: F401, I001  (first: the Agg backend unless chosen)
    import matplotlib.pyplot as plt

    if ax is None:
        fig, ax = plt.subplots(figsize=(6.5, 4.5))
    else:
        fig = ax.figure
    P = ds["pressure_kpa"].values
    colors = plt.cm.viridis(np.linspace(0.0, 0.9, max(P.size, 1)))
    for j, p in enumerate(P):
        ax.plot(ds["diameter_mm"].values, ds["grip_force_n"].values[:, j], "o-", color=colors[j], label=f"{p:g} kPa")
    ax.set_xlabel("sphere diameter (mm)")
    ax.set_ylabel("gripping force (N)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title or f"{ds.attrs.get('fingers', '')}-finger gripper, {ds.attrs.get('actuator', '')}")
    return fig
