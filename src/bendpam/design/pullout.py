"""The quasi-static pull-out of grasps: the gripper lifted off a fixed sphere, its peak load the grip force.

From each grasp (:class:`bendpam.design.contact.Seed`) the arm lifts the gripper base step by step
(displacement control, adaptive steps); at every step the fingers' statics are solved again under
the contact loads, with Coulomb stick/slip at each contact (see :mod:`bendpam.design.grasp` for the
model).  All the pull-outs of a sweep are solved together: one batched Newton
(:func:`bendpam.design.rod.newton_batch`) per lift step.

Units: mm, N.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from bendpam.design.contact import PEN_TOL, Seed, surface_point
from bendpam.design.finger import FingerLoads
from bendpam.design.gripper import Grasp, Gripper
from bendpam.design.rod import NEWTON_TOL, Rod, cross, newton_batch

__all__ = [
    "PullOut",
    "pull_grasps",
]

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

    Examples
    --------
    >>> import bendpam
    >>> from bendpam.design import Gripper, solve_grasp
    >>> po = solve_grasp(Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0)), 180.0, 160.0).pull_out
    >>> po.state[0].tolist(), po.peak_force_n > 0         # at the grasp: the fingertip on the sphere
    (['stick', 'open'], True)
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


class _Pull:
    """Batched quasi-static pull-out of several grasps of one gripper (displacement control).

    Unknowns of each grasp (scaled): the nodal curvatures, then the tip contact's normal and
    tangential force, then the body contact's normal and tangential force and its coordinate
    ``sigma / (L + ell)``.  Each contact is open (its forces vanish), sticks (on the sphere, no
    tangential slip in the step) or slips (on the sphere, ``T = s mu N``).
    """

    def __init__(self, gripper: Gripper, seeds: list[Seed]):
        if not seeds:
            raise ValueError("a pull-out needs at least one grasp (seed)")
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
        self.table = seeds[0].branch.table  # the law's table (the same for every pressure)
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
        self.tol_gap = PEN_TOL * np.maximum(1.0, self.R / 50.0)

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
        xc, yc, pc = surface_point(rod, phi, x, y, sc)
        ex, ey = xc, yc - cyy
        db = np.sqrt(ex * ex + ey * ey)
        bx, by = ex / db, ey / db
        Gx, Gy = Nb * bx - Tb * by, Nb * by + Tb * bx
        # the nodes beyond which the body force acts, ramped over one node spacing (continuous in sigma)
        beyond = np.clip((sc[..., None] - rod.s) / rod.h + 0.5, 0.0, 1.0)
        m = m + beyond * cross(xc[..., None] - x, yc[..., None] - y, Gx[..., None], Gy[..., None])
        xco, yco, _ = surface_point(rod, phio, xo, yo, sc)
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

    # ---- Newton (the design layer's one Newton method, batched) ---------------------------------
    def newton(self, idx, cy, st, sgn, u0, maxit=12):
        """Solve the grasps ``idx`` from ``u0`` (:func:`bendpam.design.rod.newton_batch`); returns ``(u, ok)``.

        The Jacobian is the complex step of the residuals without the moment law, plus the law's
        diagonal ``dM/dk'`` (:meth:`law_diagonal`).
        """
        u_old = self.u[idx]
        lo, hi = self.bounds(idx)
        eye = 1j * 1e-30 * np.eye(self.m)
        diag = np.arange(self.n)

        def fun(rows, V, law=True):
            return self.fun(V, idx[rows], cy[rows], st[rows], sgn[rows], u_old[rows], law=law)

        def jac(rows, v):
            J = np.swapaxes(np.imag(fun(rows, v[:, None, :] + eye[None], law=False)) / 1e-30, 1, 2)
            J[:, diag, diag] += self.law_diagonal(idx[rows], v)
            return J

        u, ok, _ = newton_batch(fun, u0, lo, hi, tol=NEWTON_TOL, maxit=maxit, jac=jac)
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
        self._begin()
        while self.live.any():
            idx = np.flatnonzero(self.live)
            cy = self.cy0[idx] - (self.lift[idx] + self.h[idx])
            tst, tsg = self.tst, self.tsg
            unew, ok = self.newton(idx, cy, tst[idx], tsg[idx], self._predict(idx))
            dd = self.fun(unew[:, None, :], idx, cy, tst[idx], tsg[idx], self.u[idx], details=True)
            for j, i in enumerate(idx.tolist()):
                if ok[j]:
                    self._converged(i, j, dd, unew[j])
                else:
                    self._not_converged(i, j, dd)
        return [self._history(i) for i in range(self.B)]

    def _begin(self) -> None:
        """The first row of each history (the grasp) and the step control of the pull."""
        B = self.B
        d = self.fun(self.u[:, None, :], np.arange(B), self.cy0.copy(), self.st, self.sgn, self.u, details=True)
        self.hist: list[list] = [[self._record(i, d, i)] for i in range(B)]
        self.end = [""] * B
        self.h = 0.002 * self.R
        self.h_min = 1e-7 * self.R
        self.h_max = 0.04 * self.R + 0.01 * self.Lr
        self.lift_max = 2.0 * (2.0 * self.R) + self.Lr
        self.Fs = self.g.fingers * self.fs  # force scale of the gripper
        self.tst, self.tsg = self.st.copy(), self.sgn.copy()  # trial contact states at the pending step
        self.retries = np.zeros(B, dtype=int)
        self.tried_slip = np.zeros(B, dtype=bool)
        self.du_last = np.zeros_like(self.u)
        self.h_last = np.zeros(B)
        self.live = np.ones(B, dtype=bool)
        self.steps = np.zeros(B, dtype=int)

    def _predict(self, idx):
        """Start of the step of the grasps ``idx``: the last step's change, scaled, while the contact
        states stay the same, kept inside the bounds."""
        h, h_last = self.h, self.h_last
        same = np.all(self.tst[idx] == self.st[idx], axis=1) & (h_last[idx] > 0)
        u0 = self.u[idx] + np.where(same, h[idx] / np.where(h_last[idx] > 0, h_last[idx], 1.0), 0.0)[:, None] \
            * self.du_last[idx]
        lo, hi = self.bounds(idx)
        with np.errstate(invalid="ignore"):  # infinite bounds of the forces: no clipping
            lo = np.where(np.isfinite(lo), lo + 0.05 * (self.u[idx] - lo), -np.inf)
            hi = np.where(np.isfinite(hi), hi - 0.05 * (hi - self.u[idx]), np.inf)
        return np.clip(u0, lo, hi)

    def _reset_trial(self, i: int) -> None:
        """Back to the accepted contact states of grasp ``i``, with half the lift step."""
        self.tst[i], self.tsg[i], self.retries[i] = self.st[i], self.sgn[i], 0
        self.h[i] *= 0.5

    def _not_converged(self, i: int, j: int, dd) -> None:
        """No equilibrium at the trial step of grasp ``i``: try slipping, else halve the step (or stop)."""
        tst, tsg = self.tst, self.tsg
        stuck = tst[i] == _STICK
        if stuck.any() and not self.tried_slip[i]:
            # no sticking equilibrium (e.g. an inextensible finger dragged along its axis): slip,
            # the friction pulling the finger along with the sphere's surface (down)
            self.tried_slip[i] = True
            nxs = (float(np.real(dd["nt"][0][j, 0])), float(np.real(dd["nb"][0][j, 0])))
            for c in np.flatnonzero(stuck):
                tst[i, c], tsg[i, c] = _SLIP, -math.copysign(1.0, nxs[c])
            return
        self.tried_slip[i] = False
        self._reset_trial(i)
        if self.h[i] < self.h_min[i]:
            self.live[i] = False
            self.end[i] = (f"no equilibrium beyond a lift of {self.lift[i]:.4g} mm: the finger snaps off the "
                           "sphere (the contact load exceeds what its stable branch holds)")

    def _converged(self, i: int, j: int, dd, u) -> None:
        """A converged trial step of grasp ``i``: check the contact states and the load change, then accept it."""
        h, h_min = self.h, self.h_min
        changed = self._events(i, j, dd, u, self.tst, self.tsg, self.mu, self.n, h[i] > 1e3 * h_min[i])
        if changed == "bisect":
            h[i] *= 0.5
            return
        if changed == "two-body":
            self.live[i] = False
            self.end[i] = (f"at a lift of {self.lift[i] + h[i]:.4g} mm a second body contact would be needed "
                           "(not modelled): the pull stops there")
            return
        if changed:
            self.retries[i] += 1
            if self.retries[i] > _MAX_RETRIES:
                self._reset_trial(i)
                if h[i] < h_min[i]:
                    self.live[i] = False
                    self.end[i] = f"the contact state does not settle at a lift of {self.lift[i]:.4g} mm"
            return
        row_F = -self.g.fingers * float(np.real(dd["Fy"][j, 0]))
        prev = self.hist[i][-1][1]
        peak = max(r[1] for r in self.hist[i])
        if abs(row_F - prev) > _FORCE_STEP * max(abs(peak), abs(prev), 0.2 * self.Fs[i]) and h[i] > 1e3 * h_min[i]:
            self._reset_trial(i)
            return
        self._accept(i, j, dd, u, prev)

    def _accept(self, i: int, j: int, dd, u, prev: float) -> None:
        """Accept the trial step of grasp ``i`` (its history row), then stop the pull where it ends."""
        tst, tsg = self.tst, self.tsg
        same_states = bool(np.all(tst[i] == self.st[i]))
        self.du_last[i] = (u - self.u[i]) if same_states else 0.0
        self.h_last[i] = self.h[i] if same_states else 0.0
        self.u[i] = u
        self.st[i], self.sgn[i] = tst[i].copy(), tsg[i].copy()
        self.lift[i] += self.h[i]
        self.retries[i] = 0
        self.tried_slip[i] = False
        self.steps[i] += 1
        self.hist[i].append(self._record(i, dd, j))
        self.h[i] = min(2.0 * self.h[i], self.h_max[i])
        F = self.hist[i][-1][1]
        peak = max(r[1] for r in self.hist[i])
        if np.all(self.st[i] == _OPEN):
            self.live[i] = False
            self.end[i] = f"the sphere escapes: every contact opens at a lift of {self.lift[i]:.4g} mm"
        elif peak > 0.0 and F < _PAST_PEAK * peak and F < prev:
            self.live[i] = False
            self.end[i] = (f"the load falls past its peak (to {F:.3g} N at a lift of {self.lift[i]:.4g} mm): "
                           "under a pulling force the sphere escapes at the peak")
        elif self.lift[i] > self.lift_max[i] or self.steps[i] >= _MAX_STEPS:
            self.live[i] = False
            self.end[i] = (f"no escape up to a lift of {self.lift[i]:.4g} mm ({self.steps[i]} steps): the peak is a "
                           "lower bound")

    def _history(self, i: int) -> PullOut:
        """The :class:`PullOut` of grasp ``i`` from its history rows."""
        rows = self.hist[i]
        lift = np.array([r[0] for r in rows])
        F = np.array([r[1] for r in rows])
        N = np.array([r[2] for r in rows])
        T = np.array([r[3] for r in rows])
        beta = np.array([r[4] for r in rows])
        st = np.array([[_STATE_NAMES[s] for s in r[5]] for r in rows])
        return PullOut(lift, F, N, T, beta, st, int(np.argmax(F)), self.end[i])

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


def pull_grasps(gripper: Gripper, paths: list[list[tuple[Grasp, Seed | None]]]) -> list[list[Grasp]]:
    """The grasps of ``paths`` (:func:`bendpam.design.contact.grasp_path`) with their pull-outs.

    Every grasp with a seed is pulled out (all together, batched); its grip force becomes the peak
    of the pull (0 when the load never pulls), with the lift at the peak and the :class:`PullOut`.

    Examples
    --------
    >>> import bendpam
    >>> from bendpam.design import Gripper
    >>> from bendpam.design.contact import grasp_path
    >>> gripper = Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0))
    >>> g = pull_grasps(gripper, [grasp_path(gripper, 180.0, [160.0])])[0][0]
    >>> g.grip_force_n == g.pull_out.peak_force_n > 0
    True
    """
    seeds = [s for path in paths for _g, s in path if s is not None]
    pulls = iter(_Pull(gripper, seeds).run() if seeds else [])
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
