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
* **Pull-out (the grip force).**  The sphere is fixed; from the grasp the arm lifts the gripper
  base step by step (displacement control, adaptive steps).  At every step the fingers' statics
  are solved again with their moment law at the (unchanged) pressure under the contact loads: at
  each contact a normal force ``N >= 0`` along the sphere's outward normal ``n`` and a tangential
  (friction) force ``T`` along ``t = (-n_y, n_x)``.  Coulomb's law with ``mu``: a contact
  **sticks** (its material point moves with the sphere's surface, no tangential slip in the step;
  a body contact may roll) while ``|T| <= mu N``, and **slips** otherwise, with ``T = mu N``
  against the slip; a contact whose ``N`` would become negative **opens**, a part of the finger
  that would penetrate the sphere closes a contact, a flat pad rolling onto the sphere takes over
  the fingertip's contact, and a body contact that runs off the pad's end becomes the tip
  contact.  The lifting load is ``F = -fingers * sum F_y`` over the contacts of one finger
  (``F_y = N n_y + T t_y``, the sphere's force on the finger; per contact
  ``N cos beta - T sin beta`` with ``beta`` the angle of ``n`` from the downward vertical).  The
  pull stops when every contact has opened (the sphere escapes), when the load has fallen below
  half its peak (under a pulling force the sphere escapes at the peak), or when the fingers have
  no equilibrium (they snap off); the **grip force** is the peak of ``F`` (0 if it never pulls).
  Sticking contacts below the equator first load the fingers (the load rises with the lift); the
  peak is usually at the onset of slip, after which the tip slides toward the equator and the
  load falls.  The earlier estimate with the grasp's normal forces frozen,
  ``fingers * sum N (cos beta + mu sin beta)``, is kept as ``frozen_grip_force_n`` for comparison
  only.  Neglected: friction while closing, gravity on the fingers and the sphere's weight (a
  fixed sphere), rate effects and hysteresis, out-of-plane finger deformation and twisting,
  finger-finger and palm contacts, and more than one body contact per finger (the pull stops
  with a note if one would be needed).

Units: mm, N, kPa (every function takes and returns pressures in kPa, ``pressure_kpa``), degrees in
names ending ``_deg``.  Bad input raises :class:`bendpam.InputError`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from bendpam.design.finger import Finger, FingerLoads, FingerShape, solve_finger
from bendpam.design.parts import checked_pressure_kpa, checked_pressures_kpa, pressures_checked
from bendpam.design.rod import NEWTON_TOL, Rod, cross, newton
from bendpam.errors import InputError, NoEquilibrium
from bendpam.infra.accessors import figure
from bendpam.physics.actuator import Actuator
from bendpam.physics.law import MomentLaw, StableBranch
from bendpam.physics.models import normalise_model
from bendpam.validate import number

__all__ = [
    "DEFAULT_BASE_RADIUS_MM",
    "DEFAULT_FINGERTIP_MM",
    "DEFAULT_MU",
    "DEFAULT_SPLAY_DEG",
    "Grasp",
    "Gripper",
    "PullOut",
    "grasp_sweep",
    "plot_grasp",
    "solve_grasp",
]

#: default base-circle radius of the fingers' frame lines, mm (see :class:`Gripper`)
DEFAULT_BASE_RADIUS_MM = 100.0
#: default rigid fingertip (tip pad) length, mm
DEFAULT_FINGERTIP_MM = 10.0
#: default outward tilt of the open fingers from the vertical, degrees (see :class:`Gripper`)
DEFAULT_SPLAY_DEG = 15.0
#: default friction coefficient pad-sphere
DEFAULT_MU = 0.5

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
        Radius of the circle of the fingers' frame lines at the base, mm (default 100 mm).  The
        paper does not give its gripper's geometry; the defaults (100 mm, ``splay_deg`` 15,
        ``fingertip_mm`` 10, ``mu`` 0.5) were chosen so that three 130 mm fingers grasp the
        paper's whole 80-280 mm range: with the BE-PAM's energy constants every diameter from
        190 kPa (160-280 mm from 160 kPa, 180-280 mm at 130 kPa); the BC-PAM, only below its
        134 kPa fold, 120-180 and 240-260 mm at 130 kPa.  See docs/grasp.md.
    fingertip_mm : float
        Rigid fingertip (tip pad) length, mm (default 10).
    contact_offset_mm : float, optional
        Distance from the frame line to the finger's contact surface on the sphere's side, mm.
        Default: half the frame thickness for a BE-PAM, ``2 R0_start_mm`` for a BC-PAM.
    mu : float
        Coulomb friction coefficient pad-sphere for the pull-out, in [0, 5] (default 0.5: TPU on
        PLA).
    center_depth_mm : float, optional
        Depth of the sphere's centre below the base plane, mm.  Default: the placement rule in the
        module docstring.
    splay_deg : float
        Outward tilt of the open (straight) fingers from the vertical, degrees, in [-45, 45]
        (default 15; 0: pointing straight down).
    nodes : int
        Collocation nodes per finger (default 61).

    Examples
    --------
    The paper's gripper: three 130 mm BE-PAM fingers.

    >>> import bendpam
    >>> gripper = Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0))
    >>> gripper.fingers, gripper.base_radius_mm, gripper.mu
    (3, 100.0, 0.5)
    """

    actuator: Actuator
    model: str = "energy"
    fingers: int = 3
    base_radius_mm: float = DEFAULT_BASE_RADIUS_MM
    fingertip_mm: float = DEFAULT_FINGERTIP_MM
    contact_offset_mm: float | None = None
    mu: float = DEFAULT_MU
    center_depth_mm: float | None = None
    splay_deg: float = DEFAULT_SPLAY_DEG
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
    """One grasp: a gripper on a sphere at one pressure, and its pull-out.

    Attributes
    ----------
    diameter_mm, pressure_kpa : sphere diameter (mm), gauge pressure (kPa).
    contact : contact at the grasp, before the pull: ``"tip"``, ``"body"``, ``"tip+body"`` or ``"none"``.
    normal_force_n : normal (contact) force per finger at the grasp, N (sum over its contacts; 0 for none).
    grip_force_n : pull-out (gripping) force of the whole gripper, N: the peak of the lifting load
        of the quasi-static pull-out (0 without contact or when the load never pulls; NaN without
        an equilibrium).
    contact_xy : contact point(s) in the finger plane at the grasp (x radial, y up), mm.
    contact_angle_deg : angle beta of the sphere's outward normal at the (main) contact from the
        downward vertical at the grasp (0: under the sphere, 90: at the equator).
    center_depth_mm : depth of the sphere's centre below the base plane at the grasp, mm.
    equilibrium : False where the finger has no stable equilibrium at the grasp (snap-through): forces NaN.
    note : why there is no contact or no equilibrium, else empty.
    shape : the finger's :class:`FingerShape` at the grasp (free or in contact), None if not computed.
    frozen_grip_force_n : the earlier estimate ``fingers * sum N (cos beta + mu sin beta)`` with the
        grasp's normal forces frozen (a labelled comparison, not the grip force), N.
    peak_lift_mm : lift of the base at the peak of the pull, mm (NaN without a pull-out).
    pull_out : the :class:`PullOut` history, None without contact.

    Examples
    --------
    >>> import bendpam
    >>> gripper = Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0))
    >>> grasp = solve_grasp(gripper, 180.0, 150.0)        # a 180 mm sphere at 150 kPa
    >>> grasp.contact, grasp.equilibrium, grasp.grip_force_n > 0
    ('tip', True, True)
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
    frozen_grip_force_n: float = math.nan
    peak_lift_mm: float = math.nan
    pull_out: PullOut | None = field(default=None, repr=False)


def _none(D, P, depth, note, shape=None, equilibrium=True):
    f = 0.0 if equilibrium else math.nan
    return Grasp(D, P, "none", f, f, (), math.nan, depth, equilibrium, note, shape, frozen_grip_force_n=f)


def _law_moment(branch: StableBranch, k):
    """``branch.moment(k)[0]`` (N*mm); for a complex-step batch whose rows share one real part
    (a Jacobian), the spline is evaluated once and the step carried by ``dM/dk'`` (the law is
    local: ``M`` at a node depends on that node's curvature only), exactly as the complex step."""
    if np.iscomplexobj(k) and k.ndim >= 2:
        kr = np.real(k).reshape(-1, k.shape[-1])
        if np.all(kr == kr[0]):
            M, dM = branch.moment(kr[0])
            return M + 1j * np.imag(k) * dM
    return branch.moment(k)[0]


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
            xc, yc, pc = _surface_point(rod, phi, x, y, sc)
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
            M = _law_moment(branch, g["k"])
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


def _solve_at(ctx: _Ctx, mode, u, br, maxit=15):
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

    Examples
    --------
    >>> import bendpam
    >>> gripper = Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0))
    >>> solve_grasp(gripper, 180.0, 120.0).contact       # the fingers do not reach it yet
    'none'
    >>> g = solve_grasp(gripper, 180.0, 160.0)
    >>> g.contact, g.normal_force_n > 0, g.grip_force_n > 0
    ('tip', True, True)
    """
    _check_gripper(gripper)
    D = number("diameter_mm", diameter_mm, 0.0, 1e5, lo_open=True, unit="mm")
    P = checked_pressure_kpa(pressure_kpa)
    with pressures_checked():
        return _pulled(gripper, [_grasp_path(gripper, D, [P])])[0][0]


def _check_gripper(gripper) -> None:
    if not isinstance(gripper, Gripper):
        raise TypeError(f"gripper must be a bendpam.design.Gripper, got {type(gripper).__name__}")


_Item = tuple[Grasp, "_Seed | None"]


def _pulled(gripper: Gripper, paths: list[list[_Item]]) -> list[list[Grasp]]:
    """The grasps of ``paths`` with their pull-outs (all solved together, batched)."""
    seeds = [s for path in paths for _g, s in path if s is not None]
    pulls = iter(_Pull(gripper, seeds).run())
    out = []
    for path in paths:
        row = []
        for g, s in path:
            if s is not None:
                po = next(pulls)
                grip = max(po.peak_force_n, 0.0)
                note = "" if grip > 0.0 else ("the lifting load never pulls: the grasp pushes the sphere out of "
                                              "the fingers and holds no load")
                if po.end.startswith(_UNUSUAL_ENDS):  # the peak may be a lower bound: say so
                    note = f"{note}; {po.end}" if note else po.end
                g = replace(g, grip_force_n=grip, peak_lift_mm=po.peak_lift_mm if grip > 0.0 else math.nan,
                            pull_out=po, note=note)
            row.append(g)
        out.append(row)
    return out


def _grasp_path(gripper: Gripper, D: float, Ps: list[float]) -> list[_Item]:
    """Grasps of a sphere of diameter ``D`` (mm) at pressures ``Ps`` (kPa, validated), inflating
    quasi-statically (in ascending pressure), each with the seed of its pull-out (None without contact).

    The grip force of these grasps is still the frozen-normal estimate; :func:`_pulled` adds the pull-out.
    """
    order = np.argsort(Ps, kind="stable")
    out: list[_Item | None] = [None] * len(Ps)
    R = 0.5 * D
    delta = gripper.contact_offset_mm
    depth, beta0 = _landing(gripper, R)
    cone = 90.0 + math.degrees(math.atan(gripper.mu))
    if np.isfinite(beta0) and beta0 >= cone:
        note = (f"too large: the open fingers land on top of the {D:g} mm sphere (beta = {beta0:.1f} deg, beyond "
                f"the friction cone at {cone:.1f} deg): nothing holds it")
        return [(_none(D, P, depth, note), None) for P in Ps]
    finger = gripper.finger()
    act = gripper.actuator
    law = gripper.law
    cx, cy = 0.0, -depth
    lim = law.limits
    k_lock = lim.k_max if act.bend_sign > 0 else lim.k_min
    kap_c, kind, sig_c = _min_touch_curvature(finger, cx, cy, R, delta, 0.98 * abs(k_lock))
    if not np.isfinite(kap_c):
        return [(_none(D, P, depth, "too small: the fingers do not touch the sphere even fully curled"), None)
                for P in Ps]
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
            out[i] = (_none(D, P, depth, f"too small for this pressure: the fingers do not reach the sphere{on}",
                            solve_finger(finger, P)), None)
            continue
        if stuck is not None:
            out[i] = (_none(D, P, depth, stuck[0], equilibrium=stuck[1]), None)
            continue
        try:
            br_P = law.stable_branch(P)
        except NoEquilibrium as exc:
            out[i] = (_none(D, P, depth, str(exc), equilibrium=False), None)
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
            out[i] = (_none(D, P, depth, stuck[0], equilibrium=stuck[1]), None)
            continue
        # the contact needs more curvature than the free branch has (beyond the fold): direct solve
        res = _direct(ctx, gripper, D, P, depth, br_P, kind, k_c, sig0)
        if res is None:
            reason = fb.reason if not free_ok else "the contact needs more curvature than the stable branch reaches"
            res = (_none(D, P, depth, f"no stable contact equilibrium at {P:.4g} kPa ({reason}); near the "
                         "fingertip the contact moment is too small for the stable branch, so the finger snaps "
                         "through", equilibrium=False), None)
        out[i] = res
    items = [g for g in out if g is not None]
    assert len(items) == len(Ps), "the loop fills in every pressure"
    return items


def _direct(ctx: _Ctx, gripper, D, P, depth, br_P, kind, k_c, sig0) -> _Item | None:
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


def _finish(gripper: Gripper, D, P, depth, sysm: _Contact, u, br, mode) -> tuple[Grasp, _Seed]:
    """The grasp (with the frozen-normal estimate as its grip force until the pull-out) and its seed."""
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
    frozen = gripper.fingers * grip
    Nt = float(np.real(g["tip"][0][0])) if "tip" in g else 0.0
    Nb = float(np.real(g["body"][0][0])) if "body" in g else 0.0
    sig = float(np.real(g["body"][6][0])) if "body" in g else math.nan
    seed = _Seed(D, P, depth, np.asarray(k, float).copy(), Nt, Nb, sig, br)
    return Grasp(D, P, mode, total_N, frozen, tuple(pts), betas[main], depth, True, "", shape,
                 frozen_grip_force_n=frozen), seed


# ------------------------------------------------------------------------------------------------
# quasi-static pull-out
# ------------------------------------------------------------------------------------------------
_OPEN, _STICK, _SLIP = 0, 1, 2
_STATE_NAMES = ("open", "stick", "slip")
_MAX_STEPS = 400  # accepted lift steps per pull-out
_MAX_RETRIES = 8  # contact-state changes tried at one lift step before the step is halved
_SLIP_OVERSHOOT = 0.01  # a step that overshoots the onset of slip by more (|T| / mu N - 1) is halved
_FORCE_STEP = 0.2  # a step that changes the pull force by more (relative to the peak) is halved
_PAST_PEAK = 0.5  # the pull stops once the load has fallen below this fraction of its peak
#: how the pull-out ends when its peak may be only a lower bound (copied into the grasp's note)
_UNUSUAL_ENDS = ("at a lift of", "the contact state does not settle", "no escape up to")


@dataclass(frozen=True)
class PullOut:
    """History of a quasi-static pull-out (one row per accepted lift step, the grasp first).

    Each finger has at most two contacts: its fingertip point (column 0) and one body contact on
    the contact surface of the rod or the pad (column 1).

    Attributes
    ----------
    lift_mm : (steps,) lift of the gripper base above its grasping position, mm.
    pull_force_n : (steps,) vertical load the arm applies to the gripper (whole gripper, up > 0), N.
    normal_force_n : (steps, 2) normal force of the tip and the body contact per finger, N (0 when open).
    tangential_force_n : (steps, 2) friction force on the finger along the sphere's tangent
        ``t = (-n_y, n_x)`` (``n`` the sphere's outward normal at the contact), N.
    contact_angle_deg : (steps, 2) angle of the sphere's outward normal at each contact from the
        downward vertical, degrees (NaN when open).
    state : (steps, 2) ``"open"``, ``"stick"`` or ``"slip"``.
    peak_index : the row of the peak pull force.
    end : why the pull stopped (the sphere escaped, the load fell past its peak, ...).
    """

    lift_mm: np.ndarray
    pull_force_n: np.ndarray
    normal_force_n: np.ndarray
    tangential_force_n: np.ndarray
    contact_angle_deg: np.ndarray
    state: np.ndarray
    peak_index: int
    end: str

    @property
    def peak_force_n(self) -> float:
        """The peak pull force (whole gripper), N."""
        return float(self.pull_force_n[self.peak_index])

    @property
    def peak_lift_mm(self) -> float:
        """The lift at the peak, mm."""
        return float(self.lift_mm[self.peak_index])

    def to_dataframe(self):
        """The history as a :class:`pandas.DataFrame` (units in the column names)."""
        import pandas as pd

        cols = {"lift_mm": self.lift_mm, "pull_force_n": self.pull_force_n}
        for j, name in enumerate(("tip", "body")):
            cols[f"{name}_normal_force_n"] = self.normal_force_n[:, j]
            cols[f"{name}_tangential_force_n"] = self.tangential_force_n[:, j]
            cols[f"{name}_contact_angle_deg"] = self.contact_angle_deg[:, j]
            cols[f"{name}_state"] = self.state[:, j]
        return pd.DataFrame(cols)


@dataclass
class _Seed:
    """A converged grasp (the start of its pull-out): physical contact forces, N, and sigma, mm."""

    D: float
    P: float
    depth: float
    k: np.ndarray
    Nt: float
    Nb: float
    sig_mm: float
    branch: StableBranch


def _surface_point(rod: Rod, phi, x, y, sc):
    """Point of the finger's contact surface at contact coordinate ``sc`` (mm along rod and pad), batched.

    On the rod (``sc <= L``) the frame line offset by ``contact_offset_mm`` toward the sphere, on the
    rigid pad beyond it the pad's flat face.  Returns ``(x, y, angle)``: the point and the surface
    tangent's angle (rad).
    """
    b, off = rod.f.bend, rod.off
    on_rod = np.real(sc) <= rod.L
    sr = np.where(on_rod, sc, rod.L)
    xr, yr, pr = rod.point(phi, x, y, sr)
    pl = phi[..., -1]
    tau = np.where(on_rod, 0.0, sc - rod.L)
    pc = np.where(on_rod, pr, pl)
    xc = np.where(on_rod, xr, x[..., -1] + tau * np.cos(pl)) - b * off * np.sin(pc)
    yc = np.where(on_rod, yr, y[..., -1] + tau * np.sin(pl)) + b * off * np.cos(pc)
    return xc, yc, pc


class _Pull:
    """Batched quasi-static pull-out of several grasps of one gripper (displacement control).

    Unknowns of each grasp (scaled): the nodal curvatures, then the tip contact's normal and
    tangential force, then the body contact's normal and tangential force and its coordinate
    ``sigma / (L + ell)``.  Each contact is open (its forces vanish), sticks (on the sphere, no
    tangential slip in the step) or slips (on the sphere, ``T = s mu N``).
    """

    def __init__(self, gripper: Gripper, seeds: list[_Seed]):
        self.g = gripper
        finger = gripper.finger()
        self.rod = rod = Rod(finger, FingerLoads())
        self.n = n = rod.n
        self.m = n + 5
        self.Lr = rod.L + rod.ell
        self.c = rod.c
        self.mu = gripper.mu
        self.delta = float(gripper.contact_offset_mm or 0.0)
        B = len(seeds)
        self.B = B
        law = gripper.law
        self.table = seeds[0].branch.table if B else None
        self.pa = np.array([s.branch.p_active_kpa for s in seeds])
        self.fr = np.array([s.branch.friction_nmm for s in seeds])
        self.klo = np.array([s.branch.k_lo for s in seeds])
        self.khi = np.array([s.branch.k_hi for s in seeds])
        self.scale = np.array([max(abs(float(law.blocked_moment(s.P))), 1.0) for s in seeds])
        self.fs = self.scale / self.Lr  # force scale, N
        self.R = np.array([0.5 * s.D for s in seeds])
        self.cy0 = np.array([-s.depth for s in seeds])
        u = np.zeros((B, self.m))
        st = np.zeros((B, 2), dtype=int)
        for i, s in enumerate(seeds):
            u[i, :n] = s.k
            u[i, n] = s.Nt / self.fs[i]
            u[i, n + 2] = s.Nb / self.fs[i]
            u[i, n + 4] = s.sig_mm / self.Lr if np.isfinite(s.sig_mm) else 0.999
            st[i, 0] = _STICK if s.Nt > 0.0 else _OPEN
            st[i, 1] = _STICK if s.Nb > 0.0 else _OPEN
        self.u = u  # accepted state
        self.st = st  # accepted contact states
        self.sgn = np.ones((B, 2))  # slip direction sign s (T = s mu N)
        self.lift = np.zeros(B)
        self.tol_gap = _PEN_TOL * np.maximum(1.0, self.R / 50.0)

    # ---- residuals ---------------------------------------------------------------------------
    def fun(self, U, idx, cy, st, sgn, u_old, details=False, law=True):
        """Residuals of the grasps ``idx`` with centre heights ``cy``; ``U`` is (b, J, m).

        ``law=False`` leaves out the moment law (for the complex-step Jacobian: it is diagonal in
        the curvatures, :meth:`law_diagonal`).
        """
        rod, n, Lr, mu = self.rod, self.n, self.Lr, self.mu
        col = (slice(None), None)
        fs = self.fs[idx][col]
        R = self.R[idx][col]
        cyy = cy[col]
        k = U[..., :n]
        phi, x, y, xt, yt = rod.geometry(k)
        # the old (accepted) configuration: the sphere's material points move with its centre
        phio, xo, yo, xto, yto = rod.geometry(u_old[:, None, :n])
        cyo = (self.cy0[idx] - self.lift[idx])[col]
        Nt, Tt = U[..., n] * fs, U[..., n + 1] * fs
        Nb, Tb = U[..., n + 2] * fs, U[..., n + 3] * fs
        sg = U[..., n + 4]
        # tip contact: the fingertip point on the sphere
        dx, dy = xt, yt - cyy
        dt = np.sqrt(dx * dx + dy * dy)
        nx, ny = dx / dt, dy / dt
        Fx, Fy = Nt * nx - Tt * ny, Nt * ny + Tt * nx
        m = cross(xt[..., None] - x, yt[..., None] - y, Fx[..., None], Fy[..., None])
        slip_t = (-ny * (xt - xto) + nx * ((yt - yto) - (cyy - cyo))) / Lr
        # body contact: the contact surface tangent to the sphere at sigma
        sc = sg * Lr
        xc, yc, pc = _surface_point(rod, phi, x, y, sc)
        ex, ey = xc, yc - cyy
        db = np.sqrt(ex * ex + ey * ey)
        bx, by = ex / db, ey / db
        Gx, Gy = Nb * bx - Tb * by, Nb * by + Tb * bx
        # the nodes beyond which the body force acts, ramped over one node spacing (continuous in sigma)
        beyond = np.clip((sc[..., None] - rod.s) / rod.h + 0.5, 0.0, 1.0)
        m = m + beyond * cross(xc[..., None] - x, yc[..., None] - y, Gx[..., None], Gy[..., None])
        xco, yco, _ = _surface_point(rod, phio, xo, yo, sc)
        slip_b = (-by * (xc - xco) + bx * ((yc - yco) - (cyy - cyo))) / Lr
        if law:
            A, Bm, _, _ = self.table.derivatives(k)
            m = m + self.c * (self.pa[idx][:, None, None] * A - Bm - self.fr[idx][:, None, None])
        r_mom = self.c * m / self.scale[idx][:, None, None]
        s0, s1 = st[:, 0][col], st[:, 1][col]
        g0, g1 = sgn[:, 0][col], sgn[:, 1][col]
        un, ut = U[..., n], U[..., n + 1]
        vn, vt = U[..., n + 2], U[..., n + 3]
        r_t1 = np.where(s0 == _OPEN, un, (dt - R) / Lr)
        r_t2 = np.where(s0 == _OPEN, ut, np.where(s0 == _STICK, slip_t, ut - g0 * mu * un))
        r_b1 = np.where(s1 == _OPEN, vn, (db - R) / Lr)
        r_b2 = np.where(s1 == _OPEN, vt, np.cos(pc) * bx + np.sin(pc) * by)
        r_b3 = np.where(s1 == _OPEN, sg - u_old[:, None, n + 4],
                        np.where(s1 == _STICK, slip_b, vt - g1 * mu * vn))
        r = np.concatenate([r_mom, np.stack([r_t1, r_t2, r_b1, r_b2, r_b3], axis=-1)], axis=-1)
        if not details:
            return r
        return dict(x=x, y=y, phi=phi, xt=xt, yt=yt, Nt=Nt, Tt=Tt, Nb=Nb, Tb=Tb, nt=(nx, ny), nb=(bx, by),
                    gap_t=dt - R, slip=(slip_t * Lr, slip_b * Lr), sc=sc, pc=pc, Fy=Fy + Gy, cy=cyy)

    def law_diagonal(self, idx, u):
        """``dM/dk' / scale`` at the nodes of the grasps ``idx`` in the states ``u`` (b, m)."""
        _, _, dA, dB = self.table.derivatives(u[:, : self.n])
        return (self.pa[idx][:, None] * dA - dB) / self.scale[idx][:, None]

    def bounds(self, idx):
        b = idx.size
        lo = np.full((b, self.m), -np.inf)
        hi = np.full((b, self.m), np.inf)
        lo[:, : self.n] = self.klo[idx][:, None]
        hi[:, : self.n] = self.khi[idx][:, None]
        lo[:, self.n + 4], hi[:, self.n + 4] = 0.0, 1.0
        return lo, hi

    # ---- batched damped Newton -----------------------------------------------------------------
    def newton(self, idx, cy, st, sgn, u0, maxit=12):
        """Solve the grasps ``idx`` from ``u0``; returns ``(u, ok)``."""
        u_old = self.u[idx]
        lo, hi = self.bounds(idx)
        u = u0.copy()
        m = self.m

        def F(sel, V):
            return np.real(self.fun(V[:, None, :], idx[sel], cy[sel], st[sel], sgn[sel], u_old[sel]))[:, 0]

        allsel = np.arange(idx.size)
        r = F(allsel, u)
        nr = np.max(np.abs(r), axis=1)
        ok = nr < NEWTON_TOL
        live = ~ok & np.isfinite(nr)
        eye = 1j * 1e-30 * np.eye(m)
        for _ in range(maxit):
            sel = np.flatnonzero(live)
            if not sel.size:
                break
            Uc = u[sel][:, None, :] + eye[None]
            Rc = self.fun(Uc, idx[sel], cy[sel], st[sel], sgn[sel], u_old[sel], law=False)
            J = np.swapaxes(np.imag(Rc) / 1e-30, 1, 2)
            diag = np.arange(self.n)
            J[:, diag, diag] += self.law_diagonal(idx[sel], u[sel])
            rs = r[sel]
            try:
                du = np.linalg.solve(J, -rs[..., None])[..., 0]
            except np.linalg.LinAlgError:
                du = np.stack([np.linalg.lstsq(J[i], -rs[i], rcond=None)[0] for i in range(sel.size)])
            bad = ~np.all(np.isfinite(du), axis=1)
            du[bad] = 0.0
            us = u[sel]
            with np.errstate(divide="ignore", invalid="ignore"):
                a_hi = np.where(du > 0, 0.9 * (hi[sel] - us) / du, np.inf)
                a_lo = np.where(du < 0, 0.9 * (lo[sel] - us) / du, np.inf)
            alpha = np.minimum(1.0, np.minimum(a_hi.min(axis=1), a_lo.min(axis=1)))
            n2 = np.sum(rs * rs, axis=1)
            acc = np.zeros(sel.size, dtype=bool)
            un, rn = us.copy(), rs.copy()
            pend = np.flatnonzero(~bad)
            for _ls in range(30):
                if not pend.size:
                    break
                trial = us[pend] + alpha[pend, None] * du[pend]
                rt = F(sel[pend], trial)
                n2t = np.sum(rt * rt, axis=1)
                good = np.isfinite(n2t) & (n2t <= (1.0 - 1e-4 * alpha[pend]) * n2[pend])
                gi = pend[good]
                un[gi], rn[gi], acc[gi] = trial[good], rt[good], True
                pend = pend[~good]
                alpha[pend] *= 0.5
            fail = ~acc | (alpha < 1e-12)
            u[sel[acc]] = un[acc]
            r[sel[acc]] = rn[acc]
            nr[sel] = np.max(np.abs(r[sel]), axis=1)
            done = nr[sel] < NEWTON_TOL
            ok[sel[done]] = True
            live[sel[done | fail]] = False
        return u, ok

    # ---- the pull ------------------------------------------------------------------------------
    def _record(self, i, d, j):
        """History row of grasp ``i`` from the details ``d`` (row ``j`` of a batch)."""
        fingers = self.g.fingers
        N = np.array([float(np.real(d["Nt"][j, 0])), float(np.real(d["Nb"][j, 0]))])
        T = np.array([float(np.real(d["Tt"][j, 0])), float(np.real(d["Tb"][j, 0]))])
        st = self.st[i]
        N[st == _OPEN] = 0.0
        T[st == _OPEN] = 0.0
        beta = np.array([math.degrees(math.atan2(float(np.real(v[0][j, 0])), -float(np.real(v[1][j, 0]))))
                         for v in (d["nt"], d["nb"])])
        beta[st == _OPEN] = math.nan
        F = -fingers * float(np.real(d["Fy"][j, 0]))
        return (self.lift[i], F, N, T, beta, st.copy())

    def run(self) -> list[PullOut]:
        """Pull every grasp out; returns a list of :class:`PullOut`."""
        B, n, mu = self.B, self.n, self.mu
        hist: list[list] = [[] for _ in range(B)]
        end = [""] * B
        if B == 0:
            return []
        all_idx = np.arange(B)
        d = self.fun(self.u[:, None, :], all_idx, self.cy0.copy(), self.st, self.sgn, self.u, details=True)
        for i in range(B):
            hist[i].append(self._record(i, d, i))
        h = 0.002 * self.R
        h_min = 1e-7 * self.R
        h_max = 0.04 * self.R + 0.01 * self.Lr
        lift_max = 2.0 * (2.0 * self.R) + self.Lr
        Fs = self.g.fingers * self.fs  # force scale of the gripper
        tst, tsg = self.st.copy(), self.sgn.copy()  # trial contact states at the pending step
        retries = np.zeros(B, dtype=int)
        tried_slip = np.zeros(B, dtype=bool)
        du_last = np.zeros_like(self.u)
        h_last = np.zeros(B)
        live = np.ones(B, dtype=bool)
        steps = np.zeros(B, dtype=int)
        while live.any():
            idx = np.flatnonzero(live)
            cy = self.cy0[idx] - (self.lift[idx] + h[idx])
            # predictor: the last step's change, scaled, while the contact states stay the same
            same = np.all(tst[idx] == self.st[idx], axis=1) & (h_last[idx] > 0)
            u0 = self.u[idx] + np.where(same, h[idx] / np.where(h_last[idx] > 0, h_last[idx], 1.0), 0.0)[:, None] \
                * du_last[idx]
            lo, hi = self.bounds(idx)
            with np.errstate(invalid="ignore"):  # infinite bounds of the forces: no clipping
                lo = np.where(np.isfinite(lo), lo + 0.05 * (self.u[idx] - lo), -np.inf)
                hi = np.where(np.isfinite(hi), hi - 0.05 * (hi - self.u[idx]), np.inf)
            u0 = np.clip(u0, lo, hi)
            unew, ok = self.newton(idx, cy, tst[idx], tsg[idx], u0)
            dd = self.fun(unew[:, None, :], idx, cy, tst[idx], tsg[idx], self.u[idx], details=True)
            for j, i in enumerate(idx.tolist()):
                if not ok[j]:
                    stuck = tst[i] == _STICK
                    if stuck.any() and not tried_slip[i]:
                        # no sticking equilibrium (e.g. an inextensible finger dragged along its axis): slip,
                        # the friction pulling the finger along with the sphere's surface (down)
                        tried_slip[i] = True
                        nxs = (float(np.real(dd["nt"][0][j, 0])), float(np.real(dd["nb"][0][j, 0])))
                        for c in np.flatnonzero(stuck):
                            tst[i, c], tsg[i, c] = _SLIP, -math.copysign(1.0, nxs[c])
                        continue
                    tried_slip[i] = False
                    tst[i], tsg[i], retries[i] = self.st[i], self.sgn[i], 0
                    h[i] *= 0.5
                    if h[i] < h_min[i]:
                        live[i] = False
                        end[i] = (f"no equilibrium beyond a lift of {self.lift[i]:.4g} mm: the finger snaps off the "
                                  "sphere (the contact load exceeds what its stable branch holds)")
                    continue
                changed = self._events(i, j, dd, unew[j], tst, tsg, mu, n, h[i] > 1e3 * h_min[i])
                if changed == "bisect":
                    h[i] *= 0.5
                    continue
                if changed == "two-body":
                    live[i] = False
                    end[i] = (f"at a lift of {self.lift[i] + h[i]:.4g} mm a second body contact would be needed "
                              "(not modelled): the pull stops there")
                    continue
                if changed:
                    retries[i] += 1
                    if retries[i] > _MAX_RETRIES:
                        tst[i], tsg[i], retries[i] = self.st[i], self.sgn[i], 0
                        h[i] *= 0.5
                        if h[i] < h_min[i]:
                            live[i] = False
                            end[i] = f"the contact state does not settle at a lift of {self.lift[i]:.4g} mm"
                    continue
                row_F = -self.g.fingers * float(np.real(dd["Fy"][j, 0]))
                prev = hist[i][-1][1]
                peak = max(r[1] for r in hist[i])
                if abs(row_F - prev) > _FORCE_STEP * max(abs(peak), abs(prev), 0.2 * Fs[i]) and h[i] > 1e3 * h_min[i]:
                    tst[i], tsg[i], retries[i] = self.st[i], self.sgn[i], 0
                    h[i] *= 0.5
                    continue
                # accept the step
                same_states = bool(np.all(tst[i] == self.st[i]))
                du_last[i] = (unew[j] - self.u[i]) if same_states else 0.0
                h_last[i] = h[i] if same_states else 0.0
                self.u[i] = unew[j]
                self.st[i], self.sgn[i] = tst[i].copy(), tsg[i].copy()
                self.lift[i] += h[i]
                retries[i] = 0
                tried_slip[i] = False
                steps[i] += 1
                hist[i].append(self._record(i, dd, j))
                h[i] = min(2.0 * h[i], h_max[i])
                F = hist[i][-1][1]
                peak = max(r[1] for r in hist[i])
                if np.all(self.st[i] == _OPEN):
                    live[i] = False
                    end[i] = f"the sphere escapes: every contact opens at a lift of {self.lift[i]:.4g} mm"
                elif peak > 0.0 and F < _PAST_PEAK * peak and F < prev:
                    live[i] = False
                    end[i] = (f"the load falls past its peak (to {F:.3g} N at a lift of {self.lift[i]:.4g} mm): "
                              "under a pulling force the sphere escapes at the peak")
                elif self.lift[i] > lift_max[i] or steps[i] >= _MAX_STEPS:
                    live[i] = False
                    end[i] = (f"no escape up to a lift of {self.lift[i]:.4g} mm ({steps[i]} steps): the peak is a "
                              "lower bound")
        out = []
        for i in range(B):
            rows = hist[i]
            lift = np.array([r[0] for r in rows])
            F = np.array([r[1] for r in rows])
            N = np.array([r[2] for r in rows])
            T = np.array([r[3] for r in rows])
            beta = np.array([r[4] for r in rows])
            st = np.array([[_STATE_NAMES[s] for s in r[5]] for r in rows])
            out.append(PullOut(lift, F, N, T, beta, st, int(np.argmax(F)), end[i]))
        return out

    def _events(self, i, j, dd, u, tst, tsg, mu, n, locate):
        """Contact-state changes after a converged trial step of grasp ``i`` (batch row ``j``).

        Returns False (consistent), True (states changed: solve the step again) or ``"two-body"``.
        """
        ftol = 1e-9 * self.fs[i]
        changed = False
        N = (float(np.real(dd["Nt"][j, 0])), float(np.real(dd["Nb"][j, 0])))
        T = (float(np.real(dd["Tt"][j, 0])), float(np.real(dd["Tb"][j, 0])))
        slip = (float(np.real(dd["slip"][0][j, 0])), float(np.real(dd["slip"][1][j, 0])))
        for c in (0, 1):
            s = tst[i, c]
            if s == _OPEN:
                continue
            if N[c] < -ftol:
                tst[i, c] = _OPEN
                changed = True
            elif s == _STICK and abs(T[c]) > mu * N[c] * (1.0 + 1e-9) + ftol:
                if self.st[i, c] == _STICK and abs(T[c]) > mu * N[c] * (1.0 + _SLIP_OVERSHOOT) + ftol and locate:
                    return "bisect"  # locate the onset of slip (the peak is often there)
                tst[i, c], tsg[i, c] = _SLIP, math.copysign(1.0, T[c])
                changed = True
            elif s == _SLIP and slip[c] * tsg[i, c] > 1e-9 * self.Lr:
                tst[i, c] = _STICK  # the friction would not oppose the slip: it sticks
                changed = True
        if changed:
            return True
        # a body contact that runs off the pad's end becomes the tip contact
        sig = float(u[n + 4])
        if tst[i, 1] != _OPEN and sig > 0.995:
            tst[i, 1] = _OPEN
            if tst[i, 0] == _OPEN:
                tst[i, 0] = _STICK
            return True
        # penetration: an open contact closes (sticking)
        x, y = np.real(dd["x"][j, 0]), np.real(dd["y"][j, 0])
        cy = float(np.real(dd["cy"][j, 0]))
        R = self.R[i]
        tol = self.tol_gap[i]
        if tst[i, 0] == _OPEN and float(np.real(dd["gap_t"][j, 0])) < -tol:
            tst[i, 0] = _STICK
            return True
        rod = self.rod
        gap_nodes = np.hypot(x, y - cy) - R - self.delta
        pl = float(np.real(dd["phi"][j, 0, -1]))
        b = rod.f.bend
        tau = np.linspace(0.0, rod.ell, 6)[:-1] if rod.ell > 0 else np.zeros(0)
        ex = x[-1] - b * rod.off * math.sin(pl) + tau * math.cos(pl)
        ey = y[-1] + b * rod.off * math.cos(pl) + tau * math.sin(pl)
        gap_pad = np.hypot(ex, ey - cy) - R
        if tst[i, 1] != _OPEN:
            sc = float(np.real(dd["sc"][j, 0]))
            near = np.abs(rod.s - sc) <= 0.1 * self.Lr
            gap_nodes = np.where(near, np.maximum(gap_nodes, 0.0), gap_nodes)
            near_p = np.abs(rod.L + tau - sc) <= 0.1 * self.Lr
            gap_pad = np.where(near_p, np.maximum(gap_pad, 0.0), gap_pad)
        gaps = np.concatenate([gap_nodes, gap_pad])
        if gaps.size and gaps.min() < -tol:
            if tst[i, 1] != _OPEN:
                return "two-body"
            jj = int(np.argmin(gaps))
            sig_mm = rod.s[jj] if jj < n else rod.L + tau[jj - n]
            self.u[i, n + 4] = min(max(sig_mm / self.Lr, 1e-3), 0.99)  # start of the new contact
            self.u[i, n + 2] = self.u[i, n + 3] = 0.0
            if jj >= n and tst[i, 0] != _OPEN:
                # the flat pad rolls onto the sphere: its face takes over the fingertip's contact (a
                # flat face cannot touch a convex sphere at its end and inside at once)
                self.u[i, n + 2], self.u[i, n + 3] = self.u[i, n], self.u[i, n + 1]
                tst[i, 1], tsg[i, 1] = _STICK if tst[i, 0] == _STICK else _SLIP, tsg[i, 0]
                tst[i, 0] = _OPEN
            else:
                tst[i, 1] = _STICK
            return True
        return False


def _diameters_mm(value) -> np.ndarray:
    """Sphere diameters (mm) as a 1-D float array, each positive and finite, else an InputError."""
    arr = np.atleast_1d(np.asarray(value, dtype=object)).ravel()
    if arr.size == 0:
        raise InputError("diameters_mm is empty; give at least one sphere diameter (mm)")
    return np.array([number("diameters_mm", d, 0.0, 1e5, lo_open=True, unit="mm") for d in arr])


def grasp_sweep(gripper: Gripper, diameters_mm, pressures_kpa):
    """Grasps over diameters (mm) and pressures (kPa): an :class:`xarray.Dataset`.

    Dimensions ``diameter_mm`` and ``pressure_kpa``; variables ``grip_force_n`` (N, the pull-out
    force: the peak of the quasi-static pull), ``peak_lift_mm`` (lift at the peak), ``pull_end``
    (why the pull stopped), ``frozen_grip_force_n`` (N, the frozen-normal estimate, for comparison
    only), ``contact_force_n`` (N, per finger, at the grasp), ``contact`` (str),
    ``contact_angle_deg``, ``equilibrium`` and ``note``.  ``.to_dataframe()`` gives the flat table.
    All pull-outs are solved together (batched Newton), so a sweep costs little more than its grasps.

    Examples
    --------
    >>> import bendpam
    >>> gripper = Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0))
    >>> ds = grasp_sweep(gripper, [180.0], [120.0, 160.0])
    >>> list(ds.dims), ds["contact"].values.tolist()
    (['diameter_mm', 'pressure_kpa'], [['none', 'tip']])
    """
    import xarray as xr

    _check_gripper(gripper)
    Ds = _diameters_mm(diameters_mm)
    Ps = checked_pressures_kpa(pressures_kpa)
    shape = (Ds.size, Ps.size)
    grip = np.full(shape, np.nan)
    frozen = np.full(shape, np.nan)
    lift = np.full(shape, np.nan)
    end = np.full(shape, "", dtype=object)
    normal = np.full(shape, np.nan)
    beta = np.full(shape, np.nan)
    contact = np.empty(shape, dtype=object)
    eq = np.zeros(shape, dtype=bool)
    note = np.empty(shape, dtype=object)
    with pressures_checked():
        paths = _pulled(gripper, [_grasp_path(gripper, float(D), [float(p) for p in Ps]) for D in Ds])
    for i, path in enumerate(paths):
        for j, g in enumerate(path):
            grip[i, j], normal[i, j], beta[i, j] = g.grip_force_n, g.normal_force_n, g.contact_angle_deg
            frozen[i, j], lift[i, j] = g.frozen_grip_force_n, g.peak_lift_mm
            end[i, j] = g.pull_out.end if g.pull_out is not None else ""
            contact[i, j], eq[i, j], note[i, j] = g.contact, g.equilibrium, g.note
    dims = ("diameter_mm", "pressure_kpa")
    ds = xr.Dataset(
        {
            "grip_force_n": (dims, grip, {"units": "N", "long_name": "pull-out (gripping) force of the gripper"}),
            "frozen_grip_force_n": (dims, frozen, {
                "units": "N", "long_name": "frozen-normal estimate fingers * sum N (cos beta + mu sin beta), "
                                           "for comparison only"}),
            "peak_lift_mm": (dims, lift, {"units": "mm", "long_name": "lift of the base at the peak pull"}),
            "pull_end": (dims, end.astype(str)),
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
                    splay_deg=gripper.splay_deg, L0_mm=gripper.actuator.L0_mm)
    return ds


def plot_grasp(ds, ax=None, title: str | None = None):
    """Grip (pull-out) force against sphere diameter, one line per pressure (cf. the paper's Figure 8(c, d)).

    ``ds`` is a :func:`grasp_sweep` result.  Where the gripper has no contact or no equilibrium the
    line has a gap (no point, no line through it), never a 0 N point; each pressure has its own
    marker and colour.  The figure is sized for a journal column (:func:`bendpam.present.figures.figure_size`).
    Returns the figure.

    Examples
    --------
    >>> import bendpam
    >>> import matplotlib.pyplot as plt
    >>> gripper = Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0))
    >>> fig = plot_grasp(grasp_sweep(gripper, [160.0, 200.0], [160.0]))
    >>> len(fig.axes)                                     # fig.savefig("grip.png") to keep it
    1
    >>> plt.close(fig)
    """
    return figure("grasp")(ds, ax=ax, title=title)
