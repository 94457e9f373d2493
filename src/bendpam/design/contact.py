"""A gripper's finger in contact with a sphere while it closes: the contact statics and the inflation path.

One finger in its radial plane (:meth:`bendpam.design.gripper.Gripper.finger`) against the sphere:
a tip contact (the fingertip point on the sphere), a body contact (the contact surface tangent to
the sphere, on the rod or on the flat pad), or both, each with a normal force ``N >= 0``, solved
with the rod of :mod:`bendpam.design.rod` on the stable branch of the moment law.
:func:`grasp_path` inflates the gripper on one sphere through a list of pressures (an active-set
continuation in pressure from the contact onset) and hands each grasp, with its :class:`Seed`, to
the pull-out (:mod:`bendpam.design.pullout`).  The model and its assumptions are in
:mod:`bendpam.design.grasp`.

Units: mm, N, kPa, degrees in names ending ``_deg``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bendpam.design.finger import Finger, FingerLoads, FingerShape, solve_finger
from bendpam.design.gripper import Grasp, Gripper
from bendpam.design.rod import NEWTON_TOL, Rod, cross, newton
from bendpam.errors import NoEquilibrium
from bendpam.physics.law import MomentLaw, StableBranch

__all__ = [
    "PEN_TOL",
    "Seed",
    "grasp_path",
    "surface_point",
]

#: allowed penetration of the sphere from the discretisation, mm (scaled up for spheres over 100 mm)
PEN_TOL = 1e-3


@dataclass
class Seed:
    """A converged grasp (the start of its pull-out): physical contact forces, N, and sigma, mm.

    Attributes
    ----------
    D, P, depth : sphere diameter (mm), pressure (kPa), depth of the sphere's centre (mm).
    k : (nodes,) the finger's frame curvatures, 1/mm.
    Nt, Nb : normal force of the tip and the body contact, N (0 when open).
    sig_mm : the body contact's coordinate along rod and pad, mm (NaN without one).
    branch : the stable branch of the moment law at ``P``.

    Examples
    --------
    >>> import bendpam
    >>> from bendpam.design import Gripper
    >>> gripper = Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0))
    >>> grasp, seed = grasp_path(gripper, 180.0, [160.0])[0]
    >>> seed.P, seed.Nt > 0, seed.Nb                      # kPa; a tip contact
    (160.0, True, 0.0)
    """

    D: float
    P: float
    depth: float
    k: np.ndarray
    Nt: float
    Nb: float
    sig_mm: float
    branch: StableBranch


_Item = tuple[Grasp, "Seed | None"]


def surface_point(rod: Rod, phi, x, y, sc):
    """Point of the finger's contact surface at contact coordinate ``sc`` (mm along rod and pad), batched.

    On the rod (``sc <= L``) the frame line offset by ``contact_offset_mm`` toward the sphere, on the
    rigid pad beyond it the pad's flat face.  Returns ``(x, y, angle)``: the point and the surface
    tangent's angle (rad).

    Examples
    --------
    The straight finger of a gripper, at the end of its rod (its frame line at x = 100 mm, tilted
    outward by 15 deg, the contact surface half the frame thickness, 0.25 mm, toward the axis):

    >>> import numpy as np, bendpam
    >>> from bendpam.design import FingerLoads, Gripper
    >>> from bendpam.design.rod import Rod
    >>> rod = Rod(Gripper(bendpam.physics.presets.be_pam()).finger(), FingerLoads())
    >>> phi, x, y, _, _ = rod.geometry(np.zeros((1, rod.n)))
    >>> xc, yc, pc = surface_point(rod, phi, x, y, np.array([rod.L]))
    >>> round(float(xc[0]), 3), round(float(yc[0]), 3), round(float(np.degrees(pc[0])), 1)
    (137.287, -140.124, -75.0)
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
            xc, yc, pc = surface_point(rod, phi, x, y, sc)
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
    tol = PEN_TOL * max(1.0, ctx.R / 50.0)
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


def grasp_path(gripper: Gripper, D: float, Ps: list[float]) -> list[tuple[Grasp, Seed | None]]:
    """Grasps of a sphere of diameter ``D`` (mm) at pressures ``Ps`` (kPa, validated), inflating
    quasi-statically (in ascending pressure), each with the seed of its pull-out (None without contact).

    The grip force of these grasps is still the frozen-normal estimate;
    :func:`bendpam.design.pullout.pull_grasps` adds the pull-out.

    Examples
    --------
    >>> import bendpam
    >>> from bendpam.design import Gripper
    >>> gripper = Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0))
    >>> [(g.contact, seed is not None) for g, seed in grasp_path(gripper, 180.0, [160.0, 120.0])]
    [('tip', True), ('none', False)]
    """
    R = 0.5 * D
    depth, beta0 = gripper.landing(R)
    cone = 90.0 + math.degrees(math.atan(gripper.mu))
    if np.isfinite(beta0) and beta0 >= cone:
        note = (f"too large: the open fingers land on top of the {D:g} mm sphere (beta = {beta0:.1f} deg, beyond "
                f"the friction cone at {cone:.1f} deg): nothing holds it")
        return [(Grasp.no_contact(D, P, depth, note), None) for P in Ps]
    finger = gripper.finger()
    lim = gripper.law.limits
    k_lock = lim.k_max if gripper.actuator.bend_sign > 0 else lim.k_min
    kap_c, kind, sig_c = _min_touch_curvature(finger, 0.0, -depth, R, gripper.contact_offset_mm, 0.98 * abs(k_lock))
    if not np.isfinite(kap_c):
        note = "too small: the fingers do not touch the sphere even fully curled"
        return [(Grasp.no_contact(D, P, depth, note), None) for P in Ps]
    path = _Path(gripper, D, depth, kap_c, kind, sig_c, max(Ps))
    out: list[_Item | None] = [None] * len(Ps)
    for i in np.argsort(Ps, kind="stable"):
        out[i] = path.grasp(Ps[i])
    items = [g for g in out if g is not None]
    assert len(items) == len(Ps), "the loop fills in every pressure"
    return items


class _Path:
    """The quasi-static inflation of a gripper on one sphere: the contact state carried from pressure to pressure."""

    def __init__(self, gripper: Gripper, D: float, depth: float, kap_c: float, kind: str, sig_c: float,
                 P_max: float):
        self.gripper, self.D, self.depth, self.kap_c, self.kind = gripper, D, depth, kap_c, kind
        self.finger = gripper.finger()
        self.law = law = gripper.law
        self.p_on = _onset_pressure_kpa(law, kap_c)
        rod = Rod(self.finger, FingerLoads())
        n = rod.n
        self.k_c = gripper.actuator.bend_sign * kap_c  # frame curvature at the onset
        Lr = rod.L + rod.ell
        self.sig0 = min(max(sig_c, 0.02 * Lr), 0.98 * Lr) / Lr
        scale = max(abs(float(law.blocked_moment(P_max))), 1.0)
        self.ctx = _Ctx(gripper, rod, 0.0, -depth, 0.5 * D, gripper.contact_offset_mm, scale)
        self.state: tuple[float, str, np.ndarray] | None = (
            (self.p_on, kind, _pack(n, kind, np.full(n, self.k_c), sig=self.sig0)) if np.isfinite(self.p_on) else None)
        self.stuck: tuple[str, bool] | None = None  # note once the quasi-static path has no equilibrium

    def grasp(self, P: float) -> _Item:
        """The grasp at the next pressure ``P`` (kPa) of the path."""
        D, depth = self.D, self.depth
        fb = self.law.free_curvature(P)
        free_ok = bool(fb.status != "no-equilibrium") and bool(np.isfinite(fb.curvature_per_mm))
        if free_ok and abs(float(fb.curvature_per_mm)) < self.kap_c:
            on = f"; contact from {self.p_on:.4g} kPa" if np.isfinite(self.p_on) else ""
            note = f"too small for this pressure: the fingers do not reach the sphere{on}"
            return (Grasp.no_contact(D, P, depth, note, solve_finger(self.finger, P)), None)
        if self.stuck is not None:
            return (Grasp.no_contact(D, P, depth, self.stuck[0], equilibrium=self.stuck[1]), None)
        try:
            br_P = self.law.stable_branch(P)
        except NoEquilibrium as exc:
            return (Grasp.no_contact(D, P, depth, str(exc), equilibrium=False), None)
        if self.state is not None:
            return self._tracked(P, br_P, str(fb.reason) if not free_ok else "a limit point of the contact equilibrium")
        # the contact needs more curvature than the free branch has (beyond the fold): direct solve
        res = _direct(self.ctx, self.gripper, D, P, depth, br_P, self.kind, self.k_c, self.sig0)
        if res is None:
            reason = fb.reason if not free_ok else "the contact needs more curvature than the stable branch reaches"
            res = (Grasp.no_contact(D, P, depth, f"no stable contact equilibrium at {P:.4g} kPa ({reason}); near the "
                                    "fingertip the contact moment is too small for the stable branch, so the finger "
                                    "snaps through", equilibrium=False), None)
        return res

    def _tracked(self, P: float, br_P: StableBranch, reason: str) -> _Item:
        """Continue the contact state from the last pressure to ``P``; on failure the path is stuck from here."""
        assert self.state is not None, "called with a contact state"
        P0, mode0, u0 = self.state
        mode, u, t = _track(self.ctx, P0, P, mode0, u0)
        if t >= 1.0:
            self.state = (P, mode, u)
            return _finish(self.gripper, self.D, P, self.depth, self.ctx.contact(mode), u, br_P, mode)
        P_reached = P0 + t * (P - P0)
        g = self.ctx.contact(mode).forces(u[None, :])
        beta = math.degrees(math.atan2(float(np.real(g["tip"][3][0])), -float(np.real(g["tip"][4][0])))) \
            if "tip" in g else math.nan
        if "tip" in mode and beta > 90.0:
            self.stuck = (f"the fingertip slides up and over the sphere at {P_reached:.4g} kPa (frictionless "
                          f"closing, contact at beta = {beta:.0f} deg): no grasp", True)
        else:
            self.stuck = (f"no stable contact equilibrium above {P_reached:.4g} kPa ({reason}); the finger "
                          "snaps through", False)
        return (Grasp.no_contact(self.D, P, self.depth, self.stuck[0], equilibrium=self.stuck[1]), None)


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


def _finish(gripper: Gripper, D, P, depth, sysm: _Contact, u, br, mode) -> tuple[Grasp, Seed]:
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
    seed = Seed(D, P, depth, np.asarray(k, float).copy(), Nt, Nb, sig, br)
    return Grasp(D, P, mode, total_N, frozen, tuple(pts), betas[main], depth, True, "", shape,
                 frozen_grip_force_n=frozen), seed
