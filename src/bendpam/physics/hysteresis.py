"""Rate-independent hysteresis: the loop the paper measures but leaves out of its models.

The quasi-static models give one moment per (P, k').  Real actuators show a loop (Table 2: 14-28 %
of the stored energy lost per cycle): friction between the braid fibres, and between the sleeve and
the bladder, lowers the moment while the actuator is released toward the free state and raises it
while it is pushed back to the blocked state.  bendpam adds a hysteretic moment driven by the
bending-angle path ``theta = k' L0`` (signed, bendpam's convention)::

    M(P, k', history) = M_load(P, k') - A(P, k') z(theta history)            (N*mm)

``z`` is a dimensionless internal variable in [-1, 1] that tends to ``sign(d theta)``: the
friction moment opposes the motion, for a BE-PAM (k' > 0) and a BC-PAM (k' < 0) alike.

Laws for ``z`` (both rate-independent: they depend on the path, not on its speed)
    * :class:`PrandtlIshlinskii` (default, ``"pi"``): a Prandtl-Ishlinskii sum of ``n`` stop
      (elastic-perfectly-plastic) operators, i.e. the Iwan/Masing model of distributed Coulomb
      friction elements -- the braid's many fibre contacts slipping one after the other.  The
      thresholds ``r_j = (theta_h / 2)(j - 1/2) / n`` are uniformly spread, each weighted by its
      threshold, so after a reversal ``z`` runs from -1 to +1 along a rounded (nearly parabolic)
      curve and saturates after the angle ``theta_h``.  Loops between fixed end points close
      exactly after the first cycle (the wiping-out property of play/stop operators); a loop
      narrower than ``theta_h`` keeps the memory of how its end points were reached, and bendpam's
      steady cycles start from the blocked state reached by a long loading (as in the test).
    * :class:`DahlLaw` (``"dahl"``): Dahl's first-order law, ``dz/dtheta = (s - z) / theta_c`` with
      ``s = sign(dtheta)``: exponential approach over the characteristic angle ``theta_c``; loops
      close only asymptotically (by a factor ``exp(-2 Theta / theta_c)`` per cycle).
    * :class:`BoucWen` (``"bouc_wen"``): the Bouc-Wen law with exponent 2 and ``beta = gamma = 1/2``,
      ``dz/dtheta = (s - |z| z / 2 - s z^2 / 2) / theta_c``: ``z`` runs linearly back to 0 after a
      reversal, then saturates as ``tanh`` (closed form per monotone segment).
    * :class:`MaxwellSlip` (``"maxwell_slip"``): the Maxwell-slip (Iwan) model of ``n`` parallel
      elasto-slip elements of EQUAL slip moment, their slip angles spread as the Prandtl-Ishlinskii
      thresholds: the stiff elements slip first, so the loop has a sharper corner than PI's.
    * :class:`Breakaway` (``"stiction"``): static friction above the kinetic one: after a reversal
      the contact sticks, breaks away at the static level and slides as the friction decays.

The loop laws above are rate-independent.  :class:`ViscousLoop` (``"viscous"``, a Maxwell fluid:
a spring in series with a dashpot, ``tau dz/dt + z = (dtheta/dt) / omega_ref``) depends on the
rate, and so does :class:`ZenerLoop` (``"zener"``, the standard linear solid's loop: a dashpot in
parallel with one Maxwell branch); the identification's ensemble of loop laws (:data:`ENSEMBLE`)
uses them, a saved loop does not.  :func:`play` is the play (backlash) operator: the ensemble's
``"pi_play"`` member evaluates the quasi-static moment and the Prandtl-Ishlinskii loop at the
played path of a fixture with a dead zone.

Amplitude (:class:`LoopModel`)
    * ``"linear"`` (default): ``A = a0 + a1 P_active`` with ``a0`` (N*mm) the residual friction of
      the fabric's inherent tension, which makes the loss ratio rise near P_start, and ``a1``
      (N*mm/kPa) the pressure-driven part;
    * ``"interfacial"``: ``A = a0 + a1 P_e(P, k')`` with the interfacial pressure ``P_e`` between
      bladder and braid of the force-balance model (eq 45): friction in proportion to the normal
      pressure where the sleeve slides on the bladder.

Units: ``a0_nmm`` in N*mm, ``a1_nmm_per_kpa`` in N*mm/kPa, ``theta_h_deg`` (saturation angle of
the Prandtl-Ishlinskii law, or Dahl's ``theta_c``) in degrees.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from bendpam.errors import InputError
from bendpam.physics.braid import DEFAULT_ORDER

__all__ = [
    "ENSEMBLE",
    "LAWS",
    "BoucWen",
    "Breakaway",
    "Cycle",
    "DahlLaw",
    "LoopModel",
    "MaxwellSlip",
    "PrandtlIshlinskii",
    "ViscousLoop",
    "ZenerLoop",
    "first_order_scan",
    "loop_branches",
    "loss_ratio",
    "make_law",
    "play",
    "predict_cycle",
    "predict_cycles",
]

LAWS = ("pi", "dahl")
#: The loop laws whose fits make the identification's systematic (model-form) uncertainty (the members beyond
#: :func:`make_law`'s laws are :mod:`bendpam.identify.ensemble`'s).
ENSEMBLE = ("pi", "dahl", "bouc_wen", "maxwell_slip", "stiction", "viscous", "viscous_period", "zener", "pi_play",
            "pi_maxwell", "pi_dashpot", "maxwell2", "dahl_span", "bouc_wen_span")


def _segments(theta: np.ndarray):
    """Monotone segments of a sampled path: (start, end, direction) with dwell folded in."""
    d = np.diff(theta)
    sgn = np.sign(d)
    idx = np.where(sgn != 0, np.arange(sgn.size), 0)
    np.maximum.accumulate(idx, out=idx)
    sgn = sgn[idx] if sgn.size else sgn
    starts = np.concatenate([[0], np.flatnonzero(sgn[1:] != sgn[:-1]) + 1]) if sgn.size else np.array([0])
    ends = np.concatenate([starts[1:], [sgn.size]])
    return starts, ends, sgn


def _segment_path(theta, z0: float, branch) -> np.ndarray:
    """``z`` along a sampled path, law by law: ``branch(s, z_start, dist)`` gives ``z`` at the distances ``dist``
    from the start of a monotone segment of direction ``s`` where ``z`` was ``z_start``; dwell keeps ``z``."""
    th = np.asarray(theta, dtype=float)
    z = np.empty(th.size)
    if th.size == 0:
        return z
    z[0] = z0
    starts, ends, sgn = _segments(th)
    for a, b in zip(starts, ends, strict=True):
        if b <= a:
            continue
        s = sgn[a]
        z[a + 1: b + 1] = z[a] if s == 0 else branch(s, float(z[a]), np.abs(th[a + 1: b + 1] - th[a]))
    return z


def _stops_path(theta, r: np.ndarray, weight: np.ndarray, z0: float) -> np.ndarray:
    """``z = sum_j w_j s_j / sum_j w_j r_j`` of stop operators (thresholds ``r``) along ``theta`` (rad).

    The stops start from ``s_j = z0 r_j``; within a monotone segment each is
    ``clip(s_j0 + (theta - theta0), -r_j, r_j)`` exactly, vectorised over samples and elements.
    """
    th = np.asarray(theta, dtype=float)
    norm = float(weight @ r)
    z = np.empty(th.size)
    if th.size == 0:
        return z
    s = float(np.clip(z0, -1.0, 1.0)) * r
    z[0] = float(weight @ s) / norm
    starts, ends, _ = _segments(th)
    for a, b in zip(starts, ends, strict=True):
        if b <= a:
            continue
        seg = th[a + 1: b + 1] - th[a]
        st = np.clip(s[None, :] + seg[:, None], -r, r)
        z[a + 1: b + 1] = st @ weight / norm
        s = st[-1]
    return z


@dataclass(frozen=True)
class _AngleLaw:
    """A law with one characteristic angle ``theta_c_rad`` (> 0)."""

    theta_c_rad: float = math.radians(5.0)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.theta_c_rad) and self.theta_c_rad > 0):
            raise InputError(f"theta_c_rad = {self.theta_c_rad!r} must be > 0 rad")

    @property
    def angle_rad(self) -> float:
        return self.theta_c_rad


@dataclass(frozen=True)
class DahlLaw(_AngleLaw):
    """Rate-independent Dahl law with characteristic angle ``theta_c_rad`` (> 0).

    Examples
    --------
    >>> import numpy as np
    >>> law = DahlLaw(np.radians(5.0))
    >>> law.z_path(np.radians([0.0, 5.0, 20.0, 15.0])).round(3).tolist()   # away, then back
    [0.0, 0.632, 0.982, -0.271]
    """

    name = "dahl"

    def z_path(self, theta, z0: float = 0.0) -> np.ndarray:
        """``z`` along the sampled path ``theta`` (rad), starting from ``z0``: exact per monotone segment."""
        return _segment_path(theta, z0, lambda s, zs, dist: s + (zs - s) * np.exp(-dist / self.theta_c_rad))

    def steady_branches(self, delta, span):
        """Periodic cycle between two end points ``span`` (rad) apart.

        Returns ``(z_away, z_back)`` at distances ``delta`` (rad): ``z_away`` on the branch leaving
        the first end point (the blocked state; z -> +1), ``z_back`` on the branch leaving the second
        one (z -> -1), each ``delta`` from its own starting end point.  Dahl's law forgets its
        history, so the steady cycle is symmetric: ``z`` at the turning points is
        ``-+(1 - E)/(1 + E)``, ``E = exp(-span / theta_c)``.
        """
        E = np.exp(-np.asarray(span) / self.theta_c_rad)
        zb = -(1.0 - E) / (1.0 + E)
        dd = np.asarray(delta, dtype=float)
        up = 1.0 + (zb - 1.0) * np.exp(-dd / self.theta_c_rad)
        return up, -up


@dataclass(frozen=True)
class PrandtlIshlinskii:
    """Prandtl-Ishlinskii (Iwan) law: ``n`` stop operators, saturation angle ``theta_h_rad``.

    Examples
    --------
    >>> import numpy as np
    >>> law = PrandtlIshlinskii(np.radians(10.0))
    >>> law.z_path(np.radians([0.0, 5.0, 20.0, 15.0])).round(3).tolist()   # virgin: saturates after 5 deg
    [0.0, 1.0, 1.0, -0.5]
    """

    theta_h_rad: float = math.radians(10.0)
    n: int = 32

    def __post_init__(self) -> None:
        if not (math.isfinite(self.theta_h_rad) and self.theta_h_rad > 0):
            raise InputError(f"theta_h_rad = {self.theta_h_rad!r} must be > 0 rad")
        if not 1 <= int(self.n) <= 4096:
            raise InputError(f"n = {self.n!r} stop operators is outside the allowed range [1, 4096]")

    name = "pi"

    @property
    def angle_rad(self) -> float:
        return self.theta_h_rad

    @property
    def thresholds(self) -> np.ndarray:
        return 0.5 * self.theta_h_rad * (np.arange(1, self.n + 1) - 0.5) / self.n

    def z_path(self, theta, z0: float = 0.0) -> np.ndarray:
        """``z`` along the sampled path ``theta`` (rad).

        The stop operators start from a uniform state ``s_j = z0 r_j`` (``z0 = 0``: virgin).  Within
        a monotone segment each stop output is ``clip(s_j0 + (theta - theta0), -r_j, r_j)`` exactly, so
        the evaluation is vectorised over samples and elements within each segment.
        """
        return _stops_path(theta, self.thresholds, np.ones(int(self.n)), z0)

    def steady_branches(self, delta, span):
        """Periodic cycle between end points ``span`` (rad) apart (closed form).

        The cycle is anchored at the first end point (the blocked state), which the actuator
        reached last by a long motion toward it: every element starts at ``s_j = -r_j``.  Element
        ``j`` then travels ``m_j = min(span, 2 r_j)`` each way: elements wider than the loop never
        saturate at ``+r_j`` (Prandtl-Ishlinskii operators keep that memory).  At distance ``delta``
        from each branch's starting end point::

            away from the blocked state:  s_j = -r_j + min(delta, m_j)
            back toward it:               s_j = -r_j + m_j - min(delta, m_j)

        Returns ``(z_away, z_back)`` with ``z = sum_j s_j / sum_j r_j``.  With the uniform
        thresholds ``2 r_j = c (2j - 1)``, ``c = theta_h / (2n)``, the sums are closed forms: if
        ``q(x)`` elements have ``2 r_j <= x``, ``sum_j min(x, 2 r_j) = c q^2 + x (n - q)``, so the
        cost does not grow with ``n``.
        """
        n = int(self.n)
        c = 0.5 * self.theta_h_rad / n
        span = np.asarray(span, dtype=float)
        dd = np.minimum(np.asarray(delta, dtype=float), span)

        def summin(x):  # sum_j min(x, 2 r_j) for x >= 0
            q = np.clip(np.floor(x / (2.0 * c) + 0.5), 0, n)
            # guard the rounding at the jumps: q counts 2 r_j = c (2j - 1) <= x exactly
            q = np.where(c * (2.0 * q - 1.0) > x, q - 1, q)
            q = np.where((q < n) & (c * (2.0 * q + 1.0) <= x), q + 1, q)
            with np.errstate(invalid="ignore"):
                return c * q * q + np.where(q < n, x * (n - q), 0.0)

        norm = 0.5 * c * n * n  # sum_j r_j
        m_sum = summin(span)
        step = summin(np.maximum(dd, 0.0))
        away = (step - norm) / norm
        back = (m_sum - step - norm) / norm
        return away, back


@dataclass(frozen=True)
class BoucWen(_AngleLaw):
    """Bouc-Wen law (exponent 2, ``beta = gamma = 1/2``) with characteristic angle ``theta_c_rad`` (> 0).

    ``dz/dtheta = (s - |z| z / 2 - s z^2 / 2) / theta_c``: toward ``s`` (``s z >= 0``) this is
    ``s (1 - z^2) / theta_c``, so ``z = s tanh(w)``; against it (``s z < 0``) ``dz/dtheta = s / theta_c``,
    a straight line back to 0.  With ``w = atanh(s z0)`` (``s z0 >= 0``) or ``w = s z0`` (``s z0 < 0``)
    at a segment's start, ``w`` grows by ``|d theta| / theta_c`` and ``s z = w`` while ``w < 0``,
    ``tanh(w)`` after: exact per monotone segment, saturating at ``|z| = 1``.

    Examples
    --------
    >>> import numpy as np
    >>> law = BoucWen(np.radians(4.0))
    >>> law.z_path(np.radians([0.0, 4.0, 40.0, 38.0])).round(4).tolist()   # tanh(1), saturated, back by 1/2
    [0.0, 0.7616, 1.0, 0.5]
    """

    name = "bouc_wen"

    @staticmethod
    def _g(w):
        return np.where(w < 0.0, w, np.tanh(np.maximum(w, 0.0)))

    def z_path(self, theta, z0: float = 0.0) -> np.ndarray:
        """``z`` along the sampled path ``theta`` (rad), starting from ``z0``: exact per monotone segment."""
        def branch(s, zs, dist):
            u = min(s * zs, 1.0 - 1e-16)
            return s * self._g((math.atanh(u) if u >= 0 else u) + dist / self.theta_c_rad)

        return _segment_path(theta, float(np.clip(z0, -1.0, 1.0)), branch)

    def steady_branches(self, delta, span):
        """Periodic cycle between two end points ``span`` (rad) apart: ``(z_away, z_back)`` (as :class:`DahlLaw`).

        The cycle is symmetric; its turning value ``z_b`` solves ``z_b = tanh(span / theta_c - z_b)``
        (Newton's method, vectorised), and ``z_away = g(delta / theta_c - z_b)``, ``z_back = -z_away``.
        """
        S = np.asarray(span, dtype=float) / self.theta_c_rad
        zb = np.tanh(S) * 0.5
        for _ in range(40):
            t = np.tanh(S - zb)
            zb = zb - (t - zb) / (-(1.0 - t * t) - 1.0)
        up = self._g(np.asarray(delta, dtype=float) / self.theta_c_rad - zb)
        return up, -up


@dataclass(frozen=True)
class MaxwellSlip:
    """Maxwell-slip (Iwan) law: ``n`` elasto-slip elements of equal slip moment, saturation angle ``theta_h_rad``.

    Element ``j`` is a spring that slips at ``|s_j| = r_j`` (the Prandtl-Ishlinskii thresholds
    ``r_j = (theta_h / 2)(j - 1/2) / n``); each carries the same moment at slip, so
    ``z = mean_j s_j / r_j``.  Over a cycle of amplitude ``span`` element ``j`` dissipates the area
    of its parallelogram, ``max(2 span - 4 r_j, 0)`` in (theta, z_j) units.

    Examples
    --------
    >>> import numpy as np
    >>> law = MaxwellSlip(4.0, n=2)                      # r = 0.5, 1.5 rad
    >>> law.z_path(np.array([0.0, 1.0, 3.0, 1.0])).round(4).tolist()
    [0.0, 0.8333, 1.0, -0.6667]
    """

    theta_h_rad: float = math.radians(10.0)
    n: int = 32

    def __post_init__(self) -> None:
        PrandtlIshlinskii(self.theta_h_rad, self.n)  # the same checks

    name = "maxwell_slip"

    @property
    def angle_rad(self) -> float:
        return self.theta_h_rad

    @property
    def thresholds(self) -> np.ndarray:
        return PrandtlIshlinskii(self.theta_h_rad, self.n).thresholds

    def z_path(self, theta, z0: float = 0.0) -> np.ndarray:
        """``z`` along the sampled path ``theta`` (rad) from the uniform state ``s_j = z0 r_j``."""
        r = self.thresholds
        return _stops_path(theta, r, 1.0 / r, z0)

    def steady_branches(self, delta, span):
        """Periodic cycle between end points ``span`` (rad) apart, anchored at the blocked state.

        As :meth:`PrandtlIshlinskii.steady_branches`: element ``j`` travels ``m_j = min(span, 2 r_j)``
        each way; ``z_away = mean_j (-r_j + min(delta, m_j)) / r_j``, ``z_back = mean_j (-r_j + m_j - min(delta,
        m_j)) / r_j``.
        """
        r = self.thresholds
        span = np.asarray(span, dtype=float)
        dd = np.minimum(np.asarray(delta, dtype=float), span)
        dd, span = np.broadcast_arrays(np.maximum(dd, 0.0), span)
        m = np.minimum(span[..., None], 2.0 * r)
        step = np.minimum(dd[..., None], m)
        away = ((step - r) / r).mean(axis=-1)
        back = ((m - step - r) / r).mean(axis=-1)
        return away, back


def first_order_scan(forcing, a: float) -> np.ndarray:
    """The first-order recurrence ``z_k = a z_(k-1) + f_k`` from ``z_(-1) = 0``, for ``0 <= a <= 1``.

    A prefix scan by doubling (``log2 n`` vectorised passes; every factor ``a^s <= 1``, so it is
    stable): after the pass of shift ``s`` each ``z_k`` holds ``sum_(j < 2s) a^j f_(k-j)``.  It is
    :func:`scipy.signal.lfilter` ``([1], [1, -a], f)`` to rounding, without importing
    :mod:`scipy.signal` (0.5 s, half of a ``bendpam fit``).

    Examples
    --------
    >>> first_order_scan(np.array([1.0, 0.0, 0.0, 2.0]), 0.5).tolist()
    [1.0, 0.5, 0.25, 2.125]
    """
    z = np.array(forcing, dtype=float)
    shift, factor = 1, float(a)
    while shift < z.size:
        z[shift:] = z[shift:] + factor * z[:-shift]
        shift, factor = 2 * shift, factor * factor
    return z


@dataclass(frozen=True)
class ViscousLoop:
    """A rate-dependent loop: a Maxwell fluid element (spring in series with a dashpot).

    ``tau dz/dt + z = (dtheta/dt) / omega_ref``: ``z`` is the dashpot's moment in units of the one
    at the reference rate ``omega_ref_rad_s`` (rad/s), ``tau_s`` its relaxation time (s).  At a
    constant rate ``z`` approaches ``rate / omega_ref`` exponentially over the angle
    ``tau * rate``: a faster test has a wider and rounder loop.

    Examples
    --------
    >>> import numpy as np
    >>> law = ViscousLoop(tau_s=0.5, omega_ref_rad_s=0.2)
    >>> t = np.linspace(0.0, 5.0, 501)
    >>> round(float(law.z_path(0.1 * t, t)[-1]), 4)        # 0.1 rad/s: -> 1/2 (1 - exp(-10))
    0.5
    >>> slow = ViscousLoop(tau_s=5.0, omega_ref_rad_s=0.2)   # 1 rad in 5 s: theta_c = 1 rad, z_b = tanh(1/2)
    >>> [round(float(x), 4) for x in slow.steady_branches(np.array([0.0, 1.0]), 1.0, period_s=10.0)[0]]
    [-0.4621, 0.4621]
    """

    tau_s: float = 1.0
    omega_ref_rad_s: float = 1.0

    def __post_init__(self) -> None:
        for name in ("tau_s", "omega_ref_rad_s"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"{name} = {v!r} must be > 0")

    name = "viscous"

    def z_path(self, theta, time_s, z0: float = 0.0) -> np.ndarray:
        """``z`` along ``theta`` (rad) sampled at the equally spaced times ``time_s`` (s), exact for a
        path linear between samples (a first-order filter, ``z_k = a z_(k-1) + f_k``, :func:`first_order_scan`)."""
        th, t = np.asarray(theta, dtype=float), np.asarray(time_s, dtype=float)
        if th.shape != t.shape or th.ndim != 1:
            raise InputError("theta and time_s must be 1-D arrays of the same length")
        if th.size < 2:
            return np.full(th.size, float(z0))
        dt = np.diff(t)
        if not (np.all(dt > 0) and np.ptp(dt) <= 1e-6 * float(dt.mean())):
            raise InputError("the viscous loop needs equally spaced, increasing times (time_s)")
        h = float(dt.mean())
        a = math.exp(-h / self.tau_s)
        # exact for a constant rate v over a step: z1 = a z0 + (1 - a) v / omega_ref
        forcing = (1.0 - a) * np.diff(th) / h / self.omega_ref_rad_s
        z = first_order_scan(forcing, a) + float(z0) * np.exp(-h / self.tau_s * np.arange(1, forcing.size + 1))
        return np.concatenate([[float(z0)], z])

    def steady_branches(self, delta, span, period_s):
        """The periodic cycle of a triangular drive of ``span`` (rad) in ``period_s`` (s): ``(z_away, z_back)``.

        The rate is ``2 span / period``; ``z`` approaches ``+-rate / omega_ref`` over the angle
        ``theta_c = tau rate`` (a Dahl law of that angle, scaled by the rate).
        """
        span = np.asarray(span, dtype=float)
        rate = 2.0 * span / np.asarray(period_s, dtype=float)
        level = rate / self.omega_ref_rad_s
        theta_c = self.tau_s * rate
        E = np.exp(-span / theta_c)
        zb = -(1.0 - E) / (1.0 + E)
        up = level * (1.0 + (zb - 1.0) * np.exp(-np.asarray(delta, dtype=float) / theta_c))
        return up, -up


@dataclass(frozen=True)
class ZenerLoop:
    """The loop of a standard linear solid: a dashpot in parallel with one Maxwell branch (generalised Maxwell, n = 1).

    ``z = share z_d + (1 - share) z_m`` with the dashpot's ``z_d = (dtheta/dt) / omega_ref`` and the Maxwell
    branch's ``tau dz_m/dt + z_m = (dtheta/dt) / omega_ref`` (:class:`ViscousLoop`): in steady motion at the
    reference rate both parts reach 1.  :meth:`components` gives the two parts apart (a fit weighs them
    with amplitudes of their own).

    Examples
    --------
    >>> import numpy as np
    >>> law = ZenerLoop(tau_s=2.0, omega_ref_rad_s=0.1, share=0.5)
    >>> t = np.linspace(0.0, 2.0, 201)
    >>> round(float(law.z_path(0.1 * t, t)[-1]), 4)       # 1/2 + 1/2 (1 - exp(-1)) at the reference rate
    0.8161
    >>> [round(float(x), 4) for x in law.components(0.05 * t, t)[:, -1]]   # half the rate: 1/2, 1/2 (1 - e^-1)
    [0.5, 0.3161]
    """

    tau_s: float = 1.0
    omega_ref_rad_s: float = 1.0
    share: float = 0.5

    def __post_init__(self) -> None:
        ViscousLoop(self.tau_s, self.omega_ref_rad_s)  # the same checks
        if not (math.isfinite(self.share) and 0.0 <= self.share <= 1.0):
            raise InputError(f"share = {self.share!r} is outside the allowed range [0, 1]")

    name = "zener"

    def components(self, theta, time_s, z0: float = 0.0) -> np.ndarray:
        """``(z_d, z_m)`` (2 x n) along ``theta`` (rad) at the equally spaced ``time_s`` (s); ``z_m`` starts at ``z0``.

        ``z_d`` is the rate of each step (the path is linear between samples; the first sample takes the
        first step's rate).
        """
        th, t = np.asarray(theta, dtype=float), np.asarray(time_s, dtype=float)
        z_m = ViscousLoop(self.tau_s, self.omega_ref_rad_s).z_path(th, t, z0)
        rate = np.diff(th) / np.diff(t) if th.size > 1 else np.zeros(0)
        z_d = np.concatenate([rate[:1], rate]) / self.omega_ref_rad_s if th.size > 1 else np.zeros(th.size)
        return np.vstack([z_d, z_m])

    def z_path(self, theta, time_s, z0: float = 0.0) -> np.ndarray:
        """``z`` along ``theta`` (rad) sampled at the equally spaced times ``time_s`` (s)."""
        z_d, z_m = self.components(theta, time_s, z0)
        return self.share * z_d + (1.0 - self.share) * z_m


def play(path, width: float, start: float | None = None) -> np.ndarray:
    """The play (backlash) operator: the output stays in ``[x - width, x]`` and moves only when pushed.

    A fixture with a dead zone of ``width`` (the path's unit): the driven side follows the driving one
    only once the gap is closed.  ``start`` is the output at the first sample (default: the path's,
    the gap open on the side the path leaves to).

    Examples
    --------
    >>> play(np.array([0.0, 1.0, 3.0, 2.5, 1.0, 2.0]), 1.0).tolist()   # lags by 1 going up, follows going down
    [0.0, 0.0, 2.0, 2.0, 1.0, 1.0]
    """
    x = np.asarray(path, dtype=float)
    w = float(width)
    if not (math.isfinite(w) and w >= 0.0):
        raise InputError(f"width = {width!r} must be >= 0")
    out = np.empty(x.size)
    a = float(x[0]) if start is None else float(start)
    for i, xi in enumerate(x.tolist()):  # a scalar recursion (a path of a few thousand samples)
        a = min(max(a, xi - w), xi)
        out[i] = a
    return out


@dataclass(frozen=True)
class Breakaway:
    """Breakaway friction (stiction): static friction ``ratio`` times the kinetic one, ``z`` in units of the kinetic.

    After a reversal the contact sticks: ``z`` runs linearly with slope ``ratio / theta_s`` (rad^-1)
    until it reaches the static level ``ratio`` (an elastic stick); then it slides and the friction
    decays to the kinetic level, ``z = 1 + (ratio - 1) exp(-(slip) / theta_d)`` with the decay angle
    ``theta_d = decay * theta_s``.  Exact per monotone segment; ``z`` may exceed 1 (by ``ratio - 1``).

    Examples
    --------
    >>> import numpy as np
    >>> law = Breakaway(0.1, ratio=1.5, decay=2.0)   # from z = -1: stick at slope 15 /rad for 1/6 rad, then slide
    >>> law.z_path(np.array([0.0, 0.1, 0.25, 2.0]), z0=-1.0).round(4).tolist()   # 1 + 0.5 exp(-(0.25 - 1/6) / 0.2)
    [-1.0, 0.5, 1.3296, 1.0001]
    """

    theta_s_rad: float = math.radians(2.0)
    ratio: float = 1.5
    decay: float = 2.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.theta_s_rad) and self.theta_s_rad > 0):
            raise InputError(f"theta_s_rad = {self.theta_s_rad!r} must be > 0 rad")
        if not (math.isfinite(self.ratio) and self.ratio >= 1.0 and math.isfinite(self.decay) and self.decay > 0):
            raise InputError(f"ratio = {self.ratio!r} must be >= 1 and decay = {self.decay!r} > 0")

    name = "stiction"

    @property
    def angle_rad(self) -> float:
        return self.theta_s_rad

    def _branch(self, start, dist):
        """``s z`` at the distances ``dist`` from a reversal where ``s z`` was ``start`` (<= ratio)."""
        g = self.ratio / self.theta_s_rad
        d_b = np.maximum(self.ratio - start, 0.0) / g  # the stick ends at the static level
        stick = start + g * dist
        slide = 1.0 + (self.ratio - 1.0) * np.exp(-np.maximum(dist - d_b, 0.0) / (self.decay * self.theta_s_rad))
        return np.where(dist < d_b, stick, slide)

    def z_path(self, theta, z0: float = 0.0) -> np.ndarray:
        """``z`` along the sampled path ``theta`` (rad) from ``z0``."""
        return _segment_path(theta, float(z0), lambda s, zs, dist: s * self._branch(min(s * zs, self.ratio), dist))

    def steady_branches(self, delta, span):
        """Periodic cycle between end points ``span`` (rad) apart: ``(z_away, z_back)``, symmetric.

        Each branch starts at minus the value the other one ended at: the turning value ``z_b`` is the
        fixed point of ``z_b = branch(-z_b, span)``, found by the damped iteration
        ``z_b <- (z_b + branch(-z_b, span)) / 2`` (40 steps, vectorised; exact in one step when the loop
        is too narrow to break away, ``z_b = ratio span / (2 theta_s)``).
        """
        span = np.asarray(span, dtype=float)
        spans, inverse = np.unique(span, return_inverse=True)  # the fixed point once per distinct span
        zb = np.ones(spans.shape)
        for _ in range(40):
            zb = 0.5 * (zb + self._branch(-zb, spans))
        zb = zb[inverse].reshape(span.shape)
        up = self._branch(-zb, np.minimum(np.asarray(delta, dtype=float), span))
        return up, -up


def make_law(name: str, angle_deg: float):
    """A rate-independent law by name (``"pi"``, ``"dahl"``, ``"bouc_wen"``, ``"maxwell_slip"``), its angle in degrees.

    Examples
    --------
    >>> make_law("dahl", 5.0)
    DahlLaw(theta_c_rad=0.08726646259971647)
    >>> make_law("pi", 10.0).n
    32
    """
    key = str(name).strip().lower().replace("-", "_")
    if key in ("pi", "prandtl_ishlinskii", "iwan"):
        return PrandtlIshlinskii(math.radians(float(angle_deg)))
    if key == "dahl":
        return DahlLaw(math.radians(float(angle_deg)))
    if key in ("bouc_wen", "boucwen", "bw"):
        return BoucWen(math.radians(float(angle_deg)))
    if key in ("maxwell_slip", "maxwell"):
        return MaxwellSlip(math.radians(float(angle_deg)))
    if key in ("stiction", "breakaway"):
        return Breakaway(math.radians(float(angle_deg)))
    raise InputError(f"hysteresis law {name!r} is not known; choose 'pi' (Prandtl-Ishlinskii), 'dahl', "
                     "'bouc_wen', 'maxwell_slip' or 'stiction'")


@dataclass(frozen=True)
class LoopModel:
    """Hysteretic moment ``M_h = -A z``: the law, its angle and the amplitude parameters.

    Parameters
    ----------
    law : ``"pi"`` (Prandtl-Ishlinskii / Iwan, default) or ``"dahl"``.
    a0_nmm : constant part of the amplitude (N*mm), >= 0.
    a1_nmm_per_kpa : pressure part (N*mm per kPa of active pressure), >= 0.
    theta_h_deg : saturation angle (PI) or characteristic angle (Dahl), degrees, > 0.
    amplitude : ``"linear"`` (``A = a0 + a1 P_active``) or ``"interfacial"``
        (``A = a0 + a1 P_e``, force-balance interfacial pressure, eq 45).

    Examples
    --------
    >>> import bendpam
    >>> loop = LoopModel(a0_nmm=2.0, a1_nmm_per_kpa=0.1, theta_h_deg=8.0)
    >>> float(loop.amplitude_nmm(bendpam.physics.presets.be_pam(), 168.0))     # 2 + 0.1 x 100 kPa active
    12.0
    >>> LoopModel.from_dict({"law": "dahl", "theta_h_deg": 5.0}).z_law.name
    'dahl'
    """

    law: str = "pi"
    a0_nmm: float = 0.0
    a1_nmm_per_kpa: float = 0.0
    theta_h_deg: float = 10.0
    amplitude: str = "linear"

    def __post_init__(self) -> None:
        make_law(self.law, self.theta_h_deg if math.isfinite(self.theta_h_deg) and self.theta_h_deg > 0 else 1.0)
        for name in ("a0_nmm", "a1_nmm_per_kpa"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0):
                raise InputError(f"{name} = {v!r} must be >= 0")
        if not (math.isfinite(self.theta_h_deg) and 0 < self.theta_h_deg <= 360):
            raise InputError(f"theta_h_deg = {self.theta_h_deg!r} is outside the allowed range (0, 360] deg")
        if self.amplitude not in ("linear", "interfacial"):
            raise InputError(f"amplitude = {self.amplitude!r}; choose 'linear' or 'interfacial'")

    @property
    def z_law(self):
        return make_law(self.law, self.theta_h_deg)

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_toml(cls, path) -> LoopModel | None:
        """The ``[hysteresis]`` table of an actuator TOML file (as ``bendpam fit --hysteresis`` writes), or None."""
        from bendpam.infra.budgets import loads_toml, read_input_bytes

        try:
            data = loads_toml(read_input_bytes(path, "actuator file").decode("utf-8"), str(path))
        except (OSError, UnicodeDecodeError) as exc:
            raise InputError(f"{path}: cannot read the hysteresis table ({exc})") from None
        table = data.get("hysteresis")
        return None if table is None else cls.from_dict(table, source=f"{path} [hysteresis]")

    @classmethod
    def from_dict(cls, d: dict, *, source: str = "hysteresis") -> LoopModel:
        known = set(cls.__dataclass_fields__)
        if not isinstance(d, dict):
            raise InputError(f"{source}: expected a table of loop parameters ({', '.join(sorted(known))}), "
                             f"got {type(d).__name__} {d!r}")
        unknown = [k for k in d if k not in known]
        if unknown:
            raise InputError(f"{source}: unknown hysteresis parameter(s) {unknown}; known: {', '.join(sorted(known))}")
        try:
            return cls(**d)
        except (TypeError, ValueError) as exc:
            raise InputError(f"{source}: {exc}") from None

    def amplitude_nmm(self, actuator, pressure_kpa, curvature_per_mm=0.0):
        """``A(P, k')`` in N*mm (pressure in kPa, curvature in 1/mm), broadcasting."""
        from bendpam.validate import pressure_kpa as check_pressure

        pa = np.maximum(check_pressure(pressure_kpa, limit_kpa=actuator.max_pressure_kpa) - actuator.P_start_kpa, 0.0)
        if self.amplitude == "linear":
            return self.a0_nmm + self.a1_nmm_per_kpa * np.broadcast_to(
                pa, np.broadcast_shapes(np.shape(pa), np.shape(curvature_per_mm)))
        from bendpam.physics.models import force_balance

        k = np.asarray(curvature_per_mm, dtype=float)
        pa_b, k_b = np.broadcast_arrays(pa * 1e-3, k)
        st = force_balance.stress_state(actuator.params, pa_b, k_b, np.zeros(1))
        return self.a0_nmm + self.a1_nmm_per_kpa * np.maximum(st["P_e"] * 1e3, 0.0)

    def moment_path(self, actuator, pressure_kpa, curvature_path_per_mm, model: str | None = None, z0: float = 0.0):
        """``M`` (N*mm) along a sampled curvature path (1/mm) at ``pressure_kpa``, from state ``z0``."""
        from bendpam.physics.law import MomentLaw

        k = np.asarray(curvature_path_per_mm, dtype=float)
        z = self.z_law.z_path(k * actuator.L0_mm, z0)
        law = MomentLaw.of(actuator, model)
        return law.moment(pressure_kpa, k) - self.amplitude_nmm(actuator, pressure_kpa, k) * z


def loss_ratio(k_mag, upper, lower, L0_mm: float) -> tuple[float, float, float]:
    """Energy-loss ratio of a loop given on a common curvature grid (magnitudes).

    Loss = loop area in M-theta, stored = area under the mean of the branches (Table 2's
    definition, as in :mod:`bendpam.lab.processing`).  Returns ``(ratio, loss, stored)``.

    Examples
    --------
    >>> import numpy as np
    >>> k = np.linspace(0.0, 0.01, 11)                   # 1/mm
    >>> ratio, loss, stored = loss_ratio(k, 110.0 - 10000.0 * k, 90.0 - 10000.0 * k, 145.0)
    >>> round(ratio, 3), round(loss, 2), round(stored, 2)   # loss and stored energy in N*mm
    (0.4, 29.0, 72.5)
    """
    from bendpam.validate import float_array, number

    k_mag, upper, lower = (float_array(n, v, u) for n, v, u in (("k_mag", k_mag, "1/mm"), ("upper", upper, "N*mm"),
                                                                 ("lower", lower, "N*mm")))
    th = k_mag * number("L0_mm", L0_mm, 0.0, lo_open=True, unit="mm")
    loss = float(np.trapezoid(np.asarray(upper) - np.asarray(lower), th))
    stored = float(np.trapezoid(0.5 * (np.asarray(upper) + np.asarray(lower)), th))
    return (loss / stored if stored > 0 else math.nan), loss, stored


def _cycle_branches(actuator, loop: LoopModel, law, P, k_free, k):
    """Steady-cycle branches, broadcasting: ``P`` and ``k_free`` (kPa, 1/mm) against ``k`` (1/mm)."""
    s = actuator.bend_sign or 1
    A, B = law.coefficients(s * k)
    Mqs = s * (np.maximum(P - actuator.P_start_kpa, 0.0) * A - B)
    L0 = actuator.L0_mm
    z_unl, _ = loop.z_law.steady_branches(k * L0, k_free * L0)
    _, z_load = loop.z_law.steady_branches(np.maximum(k_free - k, 0.0) * L0, k_free * L0)
    amp = loop.amplitude_nmm(actuator, P, s * k)
    return Mqs - amp * z_load, Mqs - amp * z_unl


def loop_branches(actuator, loop: LoopModel, pressure_kpa, k_free, k, model: str | None = None, *,
                  order: int = DEFAULT_ORDER, eq19_factor: bool = True):
    """Steady-cycle branches between the blocked state and ``k_free`` (magnitudes, 1/mm).

    Returns ``(loading, unloading)``: the upper and the lower branch (N*mm, magnitudes) at the
    curvature magnitudes ``k``.  ``pressure_kpa`` and ``k_free`` may be arrays that broadcast
    against ``k`` (one row per test).

    Examples
    --------
    >>> import numpy as np, bendpam
    >>> a = bendpam.physics.presets.be_pam()
    >>> loop = LoopModel(a1_nmm_per_kpa=0.1, theta_h_deg=8.0)
    >>> up, low = loop_branches(a, loop, 150.0, 0.007, np.array([0.0, 0.0035, 0.007]))
    >>> up.round(1).tolist(), low.round(1).tolist()      # N*mm: the loop closes at both ends
    ([201.0, 108.5, 14.5], [201.0, 92.1, 14.5])
    """
    from bendpam.physics.law import MomentLaw

    law = MomentLaw.of(actuator, model, order=order, eq19_factor=eq19_factor)
    return _cycle_branches(actuator, loop, law, np.asarray(pressure_kpa, dtype=float),
                           np.asarray(k_free, dtype=float), np.asarray(k, dtype=float))


@dataclass(frozen=True)
class Cycle:
    """A predicted steady loop between the blocked state and the free state reached on unloading.

    Examples
    --------
    >>> import bendpam
    >>> a = bendpam.physics.presets.be_pam()
    >>> c = predict_cycle(a, LoopModel(a1_nmm_per_kpa=0.1, theta_h_deg=8.0), 200.0)
    >>> round(c.blocked_moment_nmm, 1), round(c.free_curvature_per_mm, 5), c.curvature_per_mm.shape
    (323.5, 0.01274, (201,))
    """

    pressure_kpa: float
    free_curvature_per_mm: float  # magnitude, where the unloading branch reaches M = 0 (NaN if never)
    curvature_per_mm: np.ndarray  # magnitudes
    loading_nmm: np.ndarray
    unloading_nmm: np.ndarray
    energy_loss_ratio: float
    note: str = ""

    @property
    def blocked_moment_nmm(self) -> float:
        """The cycle's largest moment: the loading branch at the blocked state (N*mm, NaN if no cycle)."""
        return float(self.loading_nmm[0]) if self.loading_nmm.size else math.nan


_NO_CYCLE = "the unloading branch does not reach zero moment before lock-up: no free-bending cycle"
_FLAT = "the actuator does not bend at this pressure (the cycle collapses onto the straight state)"


def predict_cycles(actuator, loop: LoopModel, pressures_kpa, model: str | None = None, *, n: int = 201,
                   order: int = DEFAULT_ORDER, eq19_factor: bool = True) -> list[Cycle]:
    """The loops free-bending cycles trace at several pressures: blocked -> free -> blocked.

    The free state is where the unloading (lower) branch reaches zero moment; friction lowers that
    branch, so it is reached before the quasi-static free curvature.  The steady branches depend on
    the loop's span, so the free state is found by a short fixed-point iteration (at most 8 steps,
    to a relative change of 1e-12) on a grid of 2001 curvatures up to the lock-up limit.  Where the
    unloading branch never reaches zero before the lock-up limit, the cycle is empty (NaN) with a
    note.  This is the one computation behind ``bendpam predict --cycle``, the loss ratios and the
    loop metrics of ``bendpam fit`` and Figure 7.

    Parameters
    ----------
    actuator : the :class:`~bendpam.Actuator`.
    loop : the :class:`LoopModel`.
    pressures_kpa : gauge pressures, kPa (scalar or 1-D).
    model : ``"energy"``, ``"force_balance"`` or None (default): the actuator's own model (energy when
        unknown); another than the actuator's warns (:class:`~bendpam.errors.ModelMismatchWarning`).
    n : points of each returned branch, from 0 to the free curvature.

    Returns
    -------
    list of :class:`Cycle`, one per pressure.

    Examples
    --------
    >>> import bendpam
    >>> from bendpam.physics.hysteresis import LoopModel, predict_cycles
    >>> a = bendpam.physics.presets.be_pam()
    >>> c = predict_cycles(a, LoopModel(a1_nmm_per_kpa=0.1, theta_h_deg=8.0), [150.0, 200.0])
    >>> [round(100 * x.energy_loss_ratio, 1) for x in c]
    [15.9, 17.0]
    """
    from bendpam.physics.law import MomentLaw

    law = MomentLaw.of(actuator, model, order=order, eq19_factor=eq19_factor)
    P = np.atleast_1d(np.asarray(law.check_pressure(pressures_kpa), dtype=float)).ravel()
    kf, flat = _free_states(actuator, loop, law, P)
    return _cycles(actuator, loop, law, P, kf, flat, int(n))


def _free_states(actuator, loop: LoopModel, law, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(k_free, flat)``: where each pressure's unloading branch reaches zero moment (magnitudes, 1/mm; NaN
    if never), by the fixed-point iteration of :func:`predict_cycles`, and where it collapsed onto ``k' = 0``."""
    from bendpam.physics.braid import curvature_limits

    lim = curvature_limits(actuator)
    sgn = actuator.bend_sign or 1
    k_lim = abs(lim.k_max if sgn > 0 else lim.k_min) * 0.999
    grid = np.linspace(0.0, k_lim, 2001)
    A, B = law.coefficients(sgn * grid)
    Mqs = sgn * (np.maximum(P - actuator.P_start_kpa, 0.0)[:, None] * A - B)
    amp = np.broadcast_to(loop.amplitude_nmm(actuator, P[:, None], sgn * grid), Mqs.shape)
    L0 = actuator.L0_mm
    span = np.full(P.size, k_lim)
    kf = np.full(P.size, math.nan)
    active = np.ones(P.size, dtype=bool)
    for _ in range(8):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        z_unl, _ = loop.z_law.steady_branches(grid * L0, span[idx, None] * L0)
        low = Mqs[idx] - amp[idx] * z_unl
        neg = low <= 0.0
        j = np.argmax(neg, axis=1)
        stop = ~neg.any(axis=1) | (j == 0)
        active[idx[stop]] = False
        go = ~stop
        ii, jj = idx[go], j[go]
        lo_a, lo_b = low[go, jj - 1], low[go, jj]
        new = grid[jj - 1] + (grid[jj] - grid[jj - 1]) * lo_a / (lo_a - lo_b)
        old = kf[ii]
        done = np.isfinite(old) & (np.abs(new - old) <= 1e-12 * np.maximum(np.abs(new), 1e-30))
        kf[ii] = new
        span[ii] = new
        active[ii[done]] = False
    flat = np.isfinite(kf) & (kf <= 1e-9 * k_lim)  # the fixed point collapsed onto the straight state
    kf[flat] = math.nan
    return kf, flat


def _cycles(actuator, loop: LoopModel, law, P: np.ndarray, kf: np.ndarray, flat: np.ndarray, n: int) -> list[Cycle]:
    """The :class:`Cycle` of each pressure from its free curvature ``kf`` (NaN: an empty cycle with a note)."""
    ok = np.isfinite(kf)
    out: list[Cycle] = []
    if ok.any():
        k = np.linspace(0.0, 1.0, n)[None, :] * kf[ok, None]
        up, low = _cycle_branches(actuator, loop, law, P[ok, None], kf[ok, None], k)
        th = k * actuator.L0_mm
        loss = np.trapezoid(up - low, th, axis=-1)
        stored = np.trapezoid(0.5 * (up + low), th, axis=-1)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(stored > 0, loss / stored, math.nan)
    row = 0
    for i, p in enumerate(P):
        if ok[i]:
            out.append(Cycle(float(p), float(kf[i]), k[row], up[row], low[row], float(ratio[row])))
            row += 1
        else:
            out.append(Cycle(float(p), math.nan, np.zeros(0), np.zeros(0), np.zeros(0), math.nan,
                             _FLAT if flat[i] else _NO_CYCLE))
    return out


def predict_cycle(actuator, loop: LoopModel, pressure_kpa: float, model: str | None = None, *, n: int = 201,
                  order: int = DEFAULT_ORDER, eq19_factor: bool = True) -> Cycle:
    """The loop a free-bending cycle traces at ``pressure_kpa``: :func:`predict_cycles` at one pressure.

    Examples
    --------
    >>> import bendpam
    >>> a = bendpam.physics.presets.be_pam()
    >>> round(100 * predict_cycle(a, LoopModel(a1_nmm_per_kpa=0.1, theta_h_deg=8.0), 150.0).energy_loss_ratio, 1)
    15.9
    """
    return predict_cycles(actuator, loop, [pressure_kpa], model, n=n, order=order, eq19_factor=eq19_factor)[0]
