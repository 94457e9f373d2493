"""Rate-independent hysteresis laws driven by the bending-angle path.

The quasi-static models give one moment per (P, k').  Real actuators show a loop: friction between
the braid fibres and between the sleeve and the bladder makes the moment lower while the actuator
is released (unloading, blocked -> free) and higher while it is pushed back (loading, free ->
blocked).  A law here returns the dimensionless internal variable ``z`` in [-1, 1] along a path of
bending angles ``theta``; the hysteretic moment is ``M_h = -A z`` with an amplitude ``A`` (N*mm),
so that::

    M(P, k', history) = M_load(P, k') - A(P) z(theta history)

``z -> +1`` while theta grows (unloading: lower branch) and ``z -> -1`` while it falls (loading:
upper branch).

:class:`DahlLaw` is the smooth first-order law of Dahl (1968) in its rate-independent form::

    dz/dtheta = (sign(dtheta) - z) / theta_c * sign(dtheta)

i.e. after each reversal ``z`` relaxes exponentially toward ``sign(dtheta)`` over the
characteristic angle ``theta_c`` (rad), which rounds the reversals as in the paper's Figure 4.  It
depends only on the path, not on its rate.  On a monotone segment starting at ``(theta0, z0)`` the
exact solution is ``z = s + (z0 - s) exp(-|theta - theta0| / theta_c)``; the evaluation is exact
for piecewise-monotone paths and vectorised within each segment.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["DahlLaw"]


@dataclass(frozen=True)
class DahlLaw:
    """Rate-independent Dahl law with characteristic angle ``theta_c_rad`` (> 0)."""

    theta_c_rad: float = math.radians(5.0)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.theta_c_rad) and self.theta_c_rad > 0):
            raise ValueError(f"theta_c_rad = {self.theta_c_rad!r} must be > 0 rad")

    def z_path(self, theta, z0: float = 0.0) -> np.ndarray:
        """Internal variable along the sampled path ``theta`` (rad), starting from ``z0``."""
        th = np.asarray(theta, dtype=float)
        n = th.size
        z = np.empty(n)
        if n == 0:
            return z
        z[0] = z0
        d = np.diff(th)
        sgn = np.sign(d)
        # forward-fill zero steps with the previous direction (dwell does not change z)
        idx = np.where(sgn != 0, np.arange(sgn.size), 0)
        np.maximum.accumulate(idx, out=idx)
        sgn = sgn[idx]
        # segment starts: where the direction changes
        starts = np.concatenate([[0], np.flatnonzero(sgn[1:] != sgn[:-1]) + 1])
        ends = np.concatenate([starts[1:], [sgn.size]])
        zs = z0
        for a, b in zip(starts, ends):
            s = sgn[a]
            seg = th[a + 1 : b + 1]
            if s == 0:
                z[a + 1 : b + 1] = zs
            else:
                z[a + 1 : b + 1] = s + (zs - s) * np.exp(-np.abs(seg - th[a]) / self.theta_c_rad)
            zs = z[b]
        return z

    def branch(self, theta, direction: int, z0: float) -> np.ndarray:
        """``z`` on a monotone branch starting at ``theta[0]`` with ``z0``, moving in ``direction`` (+1/-1)."""
        th = np.asarray(theta, dtype=float)
        return direction + (z0 - direction) * np.exp(-np.abs(th - th[0]) / self.theta_c_rad)
