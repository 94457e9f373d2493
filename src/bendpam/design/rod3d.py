r"""The spatial rod of a finger: a Kirchhoff rod along the frame line, three curvatures per node.

The planar rod (:mod:`bendpam.design.rod`) in three dimensions: inextensible and unshearable, of
length ``L`` on ``n`` equally spaced nodes, with directors ``d1, d2, d3`` (columns of a rotation
matrix ``D(s)``): ``d3`` the tangent, ``d2`` the in-plane bending axis (the plane's normal when
the finger is straight), ``d1 = d2 x d3`` the in-plane normal.  The unknowns are the nodal
curvatures in the director frame, ``(kappa1, k', tau)``: the lateral curvature about ``d1``
(1/mm), the paper's frame curvature ``k'`` (1/mm; the curvature about ``d2`` is ``c k'`` with
``c`` the frame side, as in the planar rod) and the twist about ``d3`` (rad/mm).  Each segment
turns by the rotation of its mean curvature vector (exact for a constant curvature: a helix;
for an in-plane curvature it is the planar rod's circular arc, so in-plane loads give the planar
shape to rounding).

The equilibrium of each section is the moment ``m(s)`` of the loads beyond ``s`` (tip force and
moment, point forces, distributed load: dead loads in world axes) in the director frame:

* in the plane: ``M(P, k') + c m.d2 = 0`` with the actuator's moment law (its stable branch);
* laterally: ``EI_lat(P, k') kappa1 = m.d1``;
* in twist: ``GJ(P, k') tau = sign(m.d3) max(|m.d3| - T_lock(P, k'), 0)``: the pressurised braid
  carries a twisting moment up to its lock torque without twisting
  (:mod:`bendpam.physics.spatial`; ``sleeve_lock=False`` drops the lock: ``GJ tau = m.d3``).

The equations are solved by the one Newton method of :mod:`bendpam.design.rod`
(:func:`~bendpam.design.rod.continuation` in the load fraction).

Units: mm, N, N*mm, rad; curvatures 1/mm, twist rad/mm.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from bendpam.design.finger3d import Finger3D, FingerLoads3D

__all__ = ["Rod3D", "hat", "segment_maps"]


def hat(w):
    """The cross-product matrices ``[w]x`` of vectors ``w`` (..., 3): ``hat(w) @ v = w x v``.

    >>> import numpy as np
    >>> (hat(np.array([0.0, 0.0, 1.0])) @ np.array([1.0, 0.0, 0.0])).tolist()
    [0.0, 1.0, 0.0]
    """
    z = np.zeros_like(w[..., 0])
    return np.stack([np.stack([z, -w[..., 2], w[..., 1]], -1),
                     np.stack([w[..., 2], z, -w[..., 0]], -1),
                     np.stack([-w[..., 1], w[..., 0], z], -1)], -2)


def _series(t2):
    """``sin t / t``, ``(1 - cos t) / t^2``, ``(t - sin t) / t^3`` of ``t^2`` (analytic; complex-step safe)."""
    small = np.abs(t2) < 1e-6
    ts2 = np.where(small, 1.0, t2)
    t = np.sqrt(ts2)
    a = np.where(small, 1.0 - t2 / 6.0 + t2 * t2 / 120.0, np.sin(t) / t)
    b = np.where(small, 0.5 - t2 / 24.0 + t2 * t2 / 720.0, (1.0 - np.cos(t)) / ts2)
    c = np.where(small, 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0, (t - np.sin(t)) / (ts2 * t))
    return a, b, c


def segment_maps(w, length):
    """Rotation ``exp(length [w]x)`` and travel ``int_0^length exp(t [w]x) e3 dt`` of constant curvatures ``w``.

    ``w`` (..., 3) in the director frame (1/mm), ``length`` (mm, broadcast).  Returns ``(Q, p)``:
    the director frame at the end relative to the start, and the end point in the start's frame.

    >>> import numpy as np
    >>> Q, p = segment_maps(np.array([0.0, 0.01, 0.0]), 100.0)     # a 1 rad arc
    >>> p.round(4).tolist()                                         # (1 - cos 1)/k, 0, sin 1 / k
    [45.9698, 0.0, 84.1471]
    """
    length = np.asarray(length)
    t2 = (w[..., 0] ** 2 + w[..., 1] ** 2 + w[..., 2] ** 2) * length ** 2
    a, b, c = _series(t2)
    W = hat(w * length[..., None] if length.ndim else w * length)
    W2 = W @ W
    eye = np.eye(3)
    Q = eye + a[..., None, None] * W + b[..., None, None] * W2
    e3 = np.array([0.0, 0.0, 1.0])
    p = length[..., None] * (e3 + b[..., None] * (W @ e3) + c[..., None] * (W2 @ e3)) if length.ndim else \
        length * (e3 + b[..., None] * (W @ e3) + c[..., None] * (W2 @ e3))
    return Q, p


def _prefix_products(Q):
    """Inclusive prefix products ``Q_0 Q_1 ... Q_j`` along axis -3 (log2(n) batched products, Hillis-Steele)."""
    C = np.array(Q)
    off = 1
    while off < C.shape[-3]:
        C[..., off:, :, :] = C[..., :-off, :, :] @ C[..., off:, :, :]
        off *= 2
    return C


class Rod3D:
    """Geometry and load moments of the discretised spatial finger (batched over leading axes).

    Built from a :class:`~bendpam.design.finger3d.Finger3D` and its :class:`~bendpam.design.finger3d.FingerLoads3D`.
    States ``U`` have the ``3 n`` unknowns on the last axis (per node ``kappa1, k', tau``); complex allowed.

    Examples
    --------
    >>> import numpy as np, bendpam
    >>> from bendpam.design.finger import Finger
    >>> from bendpam.design.finger3d import Finger3D, FingerLoads3D
    >>> rod = Rod3D(Finger3D(Finger(bendpam.physics.presets.be_pam())), FingerLoads3D())
    >>> K = np.zeros((rod.n, 3)); K[:, 1] = 0.01                   # k' = 0.01 1/mm: the planar arc
    >>> D, x, xt = rod.geometry(K.reshape(-1))
    >>> xt.round(4).tolist()                                       # 100 sin(1.45), 100 (1 - cos 1.45), 0
    [99.2713, 87.9497, 0.0]
    """

    def __init__(self, finger3d: Finger3D, loads: FingerLoads3D):
        f = finger3d.finger
        self.f3, self.f = finger3d, f
        n, L = f.nodes, f.length
        self.n, self.L = n, L
        self.s = np.linspace(0.0, L, n)
        self.h = L / (n - 1)
        self.w = np.full(n, self.h)
        self.w[[0, -1]] *= 0.5
        self.c = f.frame_side
        self.rem = L - self.s
        self.ell, self.off, self.b = f.fingertip_mm, f.fingertip_offset_mm, f.bend
        self.D0 = finger3d.base_directors()
        self.x0 = np.asarray(finger3d.base_xyz_mm, dtype=float)
        self.loads = loads
        self.F = np.asarray(loads.tip_resultant(), dtype=float)
        self.q = np.asarray(loads.distributed(), dtype=float)
        self.Mt = np.asarray(loads.tip_moment_nmm, dtype=float)
        self.points = [(float(sp), np.asarray(Fp, dtype=float)) for sp, Fp in loads.point_forces_n]
        self.couples = [(float(sp), np.asarray(Mp, dtype=float)) for sp, Mp in loads.point_moments_nmm]

    def curvatures(self, U):
        """The Darboux vectors ``(kappa1, c k', tau)`` (..., n, 3) of the states ``U`` (..., 3 n)."""
        K = U.reshape(*U.shape[:-1], self.n, 3)
        return K * np.array([1.0, self.c, 1.0])

    def geometry(self, U):
        """Directors ``D`` (..., n, 3, 3), node positions ``x`` (..., n, 3) and the fingertip point (..., 3)."""
        Om = self.curvatures(U)
        wm = 0.5 * (Om[..., 1:, :] + Om[..., :-1, :])
        Q, p = segment_maps(wm, self.h)
        C = _prefix_products(Q)  # C_j = Q_0 ... Q_j
        eye = np.broadcast_to(np.eye(3), (*U.shape[:-1], 1, 3, 3))
        D = self.D0 @ np.concatenate([eye, C], axis=-3)
        step = (D[..., :-1, :, :] @ p[..., None])[..., 0]
        zero = np.zeros((*U.shape[:-1], 1, 3), dtype=step.dtype)
        x = self.x0 + np.concatenate([zero, np.cumsum(step, axis=-2)], axis=-2)
        De = D[..., -1, :, :]
        xt = x[..., -1, :] + self.ell * De[..., :, 2] + self.b * self.off * De[..., :, 0]
        return D, x, xt

    def load_moment(self, D, x, xt, lam=1.0, U=None):
        """The moment ``m(s_j)`` (..., n, 3) of the dead loads beyond each node, world axes, N*mm."""
        m = self.Mt + np.cross(xt[..., None, :] - x, self.F)
        if np.any(self.q):
            h = self.h
            C = np.cumsum(0.5 * h * (x[..., 1:, :] + x[..., :-1, :])[..., ::-1, :], axis=-2)[..., ::-1, :]
            X = np.concatenate([C, np.zeros_like(x[..., :1, :])], axis=-2)
            m = m + np.cross(X - self.rem[:, None] * x, self.q)
        for sp, Fp in self.points:
            xp = self._at(D, x, sp, U)
            beyond = (self.s < sp)[:, None]
            m = m + np.where(beyond, np.cross(xp[..., None, :] - x, Fp), 0.0)
        for sp, Mp in self.couples:
            m = m + np.where((self.s < sp)[:, None], Mp, 0.0)
        return lam * m

    def _at(self, D, x, sp, U):
        """Position (..., 3) of the frame line at arc length ``sp`` (mm)."""
        j = min(int(sp // self.h), self.n - 2)
        Om = self.curvatures(U)
        wm = 0.5 * (Om[..., j + 1, :] + Om[..., j, :])
        _Q, p = segment_maps(wm, sp - j * self.h)
        return x[..., j, :] + (D[..., j, :, :] @ p[..., None])[..., 0]

    def scale(self, branch_moment_nmm: float) -> float:
        """Moment scale (N*mm) of Newton's tolerance: the law's and the loads' moments."""
        lever = self.L + self.ell + abs(self.off)
        load = (float(np.linalg.norm(self.Mt)) + float(np.linalg.norm(self.F)) * lever
                + float(np.linalg.norm(self.q)) * self.L ** 2
                + sum(float(np.linalg.norm(Fp)) * lever for _, Fp in self.points)
                + sum(float(np.linalg.norm(Mp)) for _, Mp in self.couples))
        return max(abs(branch_moment_nmm), load, 1.0)

