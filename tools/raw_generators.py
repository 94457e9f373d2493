"""Independent generators of raw four-point-bending cyclic tests (issue 23, the calibration study).

These files are what a testing machine writes (time, crosshead stroke, force, plus the pressure in the
header), made WITHOUT bendpam's loop laws (``bendpam.physics.hysteresis``) and without its virtual
machine (``bendpam.lab.simulate``), so that a fit's error bars can be checked on data whose loop and
instrument faults bendpam does not assume.  Only the quasi-static moment of the true actuator comes
from bendpam (:class:`bendpam.MomentLaw`): that is the model being identified.

The chain, per pressure ``P``:

1. Fixture (the paper's eq 6-8, written here from the paper, not from ``physics/fixture.py``): the
   crosshead stroke ``ds`` pitches the plates by ``beta`` with ``d tan(beta) + (sec(beta) - 1)(t + 2r) = ds``
   (solved by Newton's method), the frame curvature is ``k' = 2 beta / L0`` and the machine force
   balances the moment: ``F = 2 cos(beta)^2 M / (d + (2r + t) sin(beta))``.
2. Moment ``M = M_qs(P, k') + H``: ``M_qs`` from :class:`bendpam.MomentLaw` of the true actuator, ``H`` the
   friction loop of one of the laws below (``H > 0`` while the machine straightens the actuator, toward
   the blocked state; amplitude ``A = loop_fraction * M_qs(P, 0)``), driven by the bending angle
   ``theta = 2 beta`` (rad) and the time.
3. The machine finds the free state as a real one does: from the blocked state it releases the
   actuator until the force falls to the detection load (0.2 N), then runs triangular cycles
   blocked -> free -> blocked at a constant crosshead speed.
4. Instrument faults: coloured force noise (AR(1), standard deviation ``noise_fraction`` of the blocked
   force, lag-one correlation ``noise_ar1``), a small white stroke noise, and a load-cell offset that
   drifts linearly by ``drift_fraction`` of the blocked force over the test.
5. The file, in one of three dialects written here (a plain CSV with a ``#`` header, a Zwick testXpert
   text export with decimal commas, an Instron Bluehill CSV with quoted cells and a units row).

Loop laws (all written here from their textbook forms):

``maxwell-creep``
    Maxwell-slip (Iwan) elements: springs with Coulomb sliders of geometrically spaced slip angles and
    equal break forces; the sliders of the slow half creep (the spring force relaxes with a time
    constant while stuck), so the loop depends on time and dwells.
``stiction``
    One stiff spring and a slider with breakaway friction: it sticks after each reversal until the
    spring force reaches the static limit, then slides at a friction that decays from the static to
    the kinetic limit (static = 1.6 x kinetic) over a short slip.
``viscous``
    Rate-dependent: a linear dashpot plus a Maxwell (spring-dashpot) branch with a 10 s relaxation
    time, integrated exactly along the sampled time.
``backlash``
    A dead zone in the fixture's stroke (the crosshead travels 0.3 mm at each reversal before the plates
    follow) in series with an elasto-slip friction loop.
``bouc-wen``
    A non-saturating Bouc-Wen loop ``dz/dtheta = (1 - (gamma + beta_bw sgn(dtheta z)) |z|^n) / theta_c`` with
    ``theta_c`` comparable to the test's bending span, so ``z`` never reaches its bound (a lens-shaped
    loop, pointed at the reversals).
``masing``
    A Masing loop: a skeleton ``f(x) = A x / (1 + |x / theta_c|^r)^(1/r) / theta_c`` (a Richard-Abbott
    curve of sharpness ``r``), each branch the skeleton scaled by two from its last reversal
    (``H = H_rev + 2 f((u - u_rev) / 2)``): rate-independent, with a characteristic angle that does
    not follow the span.
``friction-viscous``
    A rounded Coulomb friction (``tanh`` of the rate over a small velocity) in parallel with a linear
    dashpot: part of the loop grows with the rate, part does not.
``lugre``
    The LuGre friction model (bristles with a Stribeck curve, ``dz/dt = v - sigma0 |v| z / g(v)``,
    ``F = sigma0 z + sigma1 dz/dt + sigma2 v``), integrated in time: rate-dependent friction.
``two-maxwell``
    Two Maxwell branches of different relaxation times (2 s and 40 s by default): a generalised
    Maxwell (Prony series) solid's loop.
``preisach``
    A discrete Preisach model: relays of random switching thresholds on the bending angle,
    symmetric in the mean; rate-independent, with loops that are not Prandtl-Ishlinskii's.
``fractional``
    A springpot (Scott Blair element), ``H = -c D^q u`` with a Caputo derivative of order ``q``: a power-law
    relaxation modulus, the limit of a Prony series with log-spread relaxation times (Bagley & Torvik 1983).
``iwan-lognormal``
    An Iwan model: Jenkins elements (spring and slider) of equal stiffness with lognormally distributed slip angles.
``coleman-hodgdon``
    A Duhem model of Coleman & Hodgdon's form, ``dH/du = alpha sgn(du) (f - H) + g(u)``, with a loop width that
    changes along the bending angle.
``asymmetric-stop``
    Stop operators whose yield differs with the direction: a loop wider on loading than on unloading.
``rate-state``
    Dieterich-Ruina rate-and-state friction (aging law) through a spring: healing at reversals and dwells.
``none``
    No loop (noise and drift only).

Drift shapes: linear (``drift_tau_s = 0``), or a thermal one, ``D (1 - exp(-t / tau)) / (1 - exp(-T / tau))``
that settles over ``drift_tau_s`` (a load cell warming up): a linear correction leaves part of it.
Other faults: a step of the offset halfway through a test (``drift_step_fraction``, a knocked cable) and a
force quantised to ``force_resolution_n`` (a coarse load-cell range).
Faults of :data:`HOLDOUT5` (see :class:`Case`; every one off by default, so earlier sets' files are unchanged):
a pressure leak and regulator ripple, a load cell's gain error and nonlinearity, a compliant frame in series with
the fixture, a first-order filter on the force channel only, dropped rows, a higher detection load, a force clipped
at a range limit, and a Mullins-like softening of the bladder (Miehe's continuous damage).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.signal import lfilter

import bendpam
from bendpam import presets
from bendpam.infra.atomic import atomic_write_text

__all__ = ["CASES", "HOLDOUT", "HOLDOUT2", "HOLDOUT3", "HOLDOUT4", "HOLDOUT5", "LOOPS",
           "Case", "Truth", "case_truth", "generate_set", "machine_test", "start_actuator"]

LOOPS = ("none", "maxwell-creep", "stiction", "viscous", "backlash", "bouc-wen", "masing", "friction-viscous", "lugre",
         "two-maxwell", "preisach", "fractional", "iwan-lognormal", "coleman-hodgdon", "asymmetric-stop", "rate-state")
DIALECTS = ("csv", "testxpert", "bluehill")
SUFFIX = {"csv": ".csv", "testxpert": ".txt", "bluehill": ".csv"}
DETECTION_LOAD_N = 0.2
MAX_BETA_RAD = math.radians(75.0)


# ------------------------------------------------------------------------------------------------
# the fixture, eq 6-8 (written from the paper)
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Rig:
    """The four-point fixture (mm): roller distance ``d``, roller radius ``r``, plate thickness ``t``, ``L0``."""

    d: float = 35.0
    r: float = 2.5
    t: float = 4.0
    L0: float = 145.0

    def stroke(self, beta):
        """Eq 6: the crosshead stroke (mm) at plate pitch ``beta`` (rad)."""
        return self.d * np.tan(beta) + (1.0 / np.cos(beta) - 1.0) * (self.t + 2.0 * self.r)

    def beta(self, stroke):
        """The inverse of eq 6 by Newton's method (monotone, convex on [0, pi/2): converges from atan(ds/d))."""
        s = np.asarray(stroke, dtype=float)
        b = np.arctan(np.maximum(s, 0.0) / self.d)
        c = self.t + 2.0 * self.r
        for _ in range(30):
            g = self.stroke(b) - s
            dg = self.d / np.cos(b) ** 2 + c * np.sin(b) / np.cos(b) ** 2
            step = g / dg
            b = np.clip(b - step, -0.5, 1.5)
            if np.max(np.abs(step)) < 1e-14:
                break
        return b

    def force(self, moment, beta):
        """Eq 7 solved for the machine force (N) from the moment (N*mm)."""
        return 2.0 * np.cos(beta) ** 2 * moment / (self.d + (self.t + 2.0 * self.r) * np.sin(beta))


# ------------------------------------------------------------------------------------------------
# loop laws: H (N*mm) along a path of bending angle u (rad) sampled at times t (s)
# ------------------------------------------------------------------------------------------------
def maxwell_slip(t, u, A, *, creep_tau_s: float | None = 40.0, n: int = 8, u_min=math.radians(0.3),
                 u_max=math.radians(8.0)):
    """Maxwell-slip elements (equal break forces ``A / n``, slip angles geometric); the slow half creeps."""
    r = np.geomspace(u_min, u_max, n)
    f = np.full(n, A / n)
    k = f / r
    x = u[0] + r  # after a loading (u decreasing): every spring stretched to its negative limit
    creep = np.zeros(n)
    if creep_tau_s is not None:
        creep[n // 2:] = 1.0
    out = np.empty(u.size)
    dt = np.diff(t, prepend=t[0])
    for i in range(u.size):
        x = np.clip(x, u[i] - r, u[i] + r)
        if creep_tau_s is not None and dt[i] > 0:
            x = x + creep * (u[i] - x) * (1.0 - math.exp(-dt[i] / creep_tau_s))
        out[i] = -float(k @ (u[i] - x))
    return out


def stiction(t, u, A, *, ratio: float = 1.6, stick_deg: float = 1.5, decay_deg: float = 3.0):
    """Breakaway friction: kinetic limit ``A``, static ``ratio * A`` after a stick of ``stick_deg``, decaying breakaway.

    While stuck the slider holds and the spring (stiffness ``ratio * A / stick_deg``) takes the motion; past the
    static limit it slides at ``A + (ratio - 1) A exp(-slip / decay_deg)``; a reversal sticks it again.
    """
    fs, fk = ratio * A, A
    K = fs / math.radians(stick_deg)
    delta = math.radians(decay_deg)
    x = float(u[0]) + fk / K  # after a loading: sliding toward the blocked state at the kinetic force
    sliding, direction, slip = True, -1.0, 1e3
    out = np.empty(u.size)
    for i in range(u.size):
        F = K * (u[i] - x)
        if sliding:
            limit = fk + (fs - fk) * math.exp(-slip / delta)
            if F * direction >= limit:  # it goes on sliding the same way
                new_x = u[i] - direction * limit / K
                slip += abs(new_x - x)
                x = new_x
            else:
                sliding = False  # the motion stopped or reversed: it sticks
        if not sliding and abs(F) > fs:  # breakaway
            sliding, direction, slip = True, (1.0 if F > 0 else -1.0), 0.0
            x = u[i] - direction * fs / K
        out[i] = -K * (u[i] - x)
    return out


def viscous(t, u, A, *, speed_rad_s: float, tau_s: float = 10.0, dashpot_share: float = 0.5):
    """A dashpot and a Maxwell branch (time constant ``tau_s``); together ``A`` at ``speed_rad_s`` in steady motion."""
    c = dashpot_share * A / speed_rad_s
    km = (1.0 - dashpot_share) * A / (speed_rad_s * tau_s)
    du = np.diff(u, prepend=u[0])
    dt = np.diff(t, prepend=t[0])
    dt_mean = float(np.median(dt[1:])) if t.size > 1 else 1.0
    a = math.exp(-dt_mean / tau_s)
    # exact for a velocity constant over each step of the (uniform) sampling: F_n = a F_(n-1) + km tau (1 - a) du/dt
    maxwell = lfilter([km * tau_s * (1.0 - a) / dt_mean], [1.0, -a], du)
    rate = np.gradient(u, t) if t.size > 1 else np.zeros_like(u)
    return -(c * rate + maxwell)


def play(c, width):
    """The play (backlash) operator: the output stays in ``[c - width, c]`` and moves only when pushed."""
    out = np.empty(c.size)
    a = float(c[0])
    for i in range(c.size):
        a = min(max(a, c[i] - width), c[i])
        out[i] = a
    return out


def bouc_wen(t, u, A, *, theta_c: float, n: float = 1.0, beta_bw: float = 0.6, gamma_bw: float = 0.4,
             substeps: int = 4):
    """A Bouc-Wen loop, ``H = -A z / z_ref`` with ``z_ref`` the value ``z`` reaches over the span ``theta_c``."""
    z = -0.8
    out = np.empty(u.size)
    out[0] = z
    for i in range(1, u.size):
        h = (u[i] - u[i - 1]) / theta_c / substeps
        for _ in range(substeps):
            s = 1.0 if h * z >= 0 else -1.0
            k1 = h * (1.0 - (gamma_bw + beta_bw * s) * abs(z) ** n)
            zm = z + 0.5 * k1
            s = 1.0 if h * zm >= 0 else -1.0
            z = z + h * (1.0 - (gamma_bw + beta_bw * s) * abs(zm) ** n)
        out[i] = z
    return -A * out / 0.8


def masing(t, u, A, *, theta_c: float, r: float = 2.0):
    """A Masing loop on a Richard-Abbott skeleton of amplitude ``A`` (``H`` opposes the motion, as every law here)."""
    def skeleton(x):
        return A * (x / theta_c) / (1.0 + np.abs(x / theta_c) ** r) ** (1.0 / r)

    out = np.empty(u.size)
    # start as after a long loading toward the blocked state (u decreasing): H at its positive limit
    u_rev, h_rev, direction = float(u[0]) + 50.0 * theta_c, -A, -1.0
    prev = float(u[0])
    for i in range(u.size):
        du = float(u[i]) - prev
        if du != 0.0 and math.copysign(1.0, du) != direction:  # a reversal at the previous point
            u_rev, h_rev, direction = prev, float(out[i - 1]), math.copysign(1.0, du)
        out[i] = h_rev - 2.0 * float(skeleton((float(u[i]) - u_rev) / 2.0))
        prev = float(u[i])
    return out


def lugre(t, u, A, *, speed_rad_s: float, stribeck: float = 1.5, vs_fraction: float = 0.3, bristle_deg: float = 0.5,
          damping: float = 0.3, viscous_share: float = 0.3, substeps: int = 8):
    """LuGre friction of Coulomb level ``(1 - viscous_share) A`` (static ``stribeck`` times that) and a viscous part.

    ``g(v) = Fc + (Fs - Fc) exp(-(v / vs)^2)``; bristle stiffness ``sigma0 = Fs / bristle_deg``; micro-damping
    ``sigma1 = damping sigma0 / speed``; viscous ``sigma2 = viscous_share A / speed`` (``H`` opposes the motion).
    """
    fc = (1.0 - viscous_share) * A
    fs = stribeck * fc
    vs = vs_fraction * speed_rad_s
    s0 = fs / math.radians(bristle_deg)
    s1 = damping * s0 / speed_rad_s * math.radians(bristle_deg)
    s2 = viscous_share * A / speed_rad_s
    v = np.gradient(u, t) if t.size > 1 else np.zeros_like(u)
    z = fc / s0  # after a motion toward the blocked state (v < 0): bristles at the kinetic deflection, H > 0
    out = np.empty(u.size)
    dt = np.diff(t, prepend=t[0])
    for i in range(u.size):
        vi = -float(v[i])  # friction's own coordinate: H = +F when u decreases
        g = fc + (fs - fc) * math.exp(-((vi / vs) ** 2))
        h = dt[i] / substeps
        for _ in range(substeps):
            zdot = vi - s0 * abs(vi) * z / g
            z += h * zdot
        zdot = vi - s0 * abs(vi) * z / g
        out[i] = s0 * z + s1 * zdot + s2 * vi
    return out


def two_maxwell(t, u, A, *, speed_rad_s: float, taus_s: tuple = (2.0, 40.0), shares: tuple = (0.5, 0.5)):
    """Two Maxwell branches (relaxation times ``taus_s``), each ``share`` of ``A`` in steady motion at ``speed``."""
    out = np.zeros(u.size)
    for tau, share in zip(taus_s, shares, strict=True):
        out += viscous(t, u, share * A, speed_rad_s=speed_rad_s, tau_s=tau, dashpot_share=0.0)
    return out


def preisach(t, u, A, *, n: int = 200, width_deg: float = 4.0, seed: int = 7):
    """A discrete Preisach model: ``n`` relays (up threshold ``c + w/2``, down ``c - w/2``) of equal weight.

    Centres ``c`` uniform over 0-120 deg, widths exponential of mean ``width_deg`` (a fixed draw: the law is
    the same in every test).  ``H = A mean(relay)``, less its angle-dependent part: the relays lag the motion, so
    the loop opposes it as the other laws do.
    """
    r = np.random.default_rng(seed)
    c = np.radians(r.uniform(0.0, 120.0, n))
    w = np.radians(r.exponential(width_deg, n))
    up, down = c + w / 2.0, c - w / 2.0
    state = np.where(u[0] <= down, -1.0, 1.0)  # after a motion toward the blocked state (u decreasing): from above
    def run(path, state):
        out = np.empty(path.size)
        for i in range(path.size):
            state = np.where(path[i] >= up, 1.0, np.where(path[i] <= down, -1.0, state))
            out[i] = A * float(state.mean())
        return out

    # the relays' mean state depends on the angle itself (an elastic part, which would change the quasi-static
    # curve): remove the mean of the two branches of a steady cycle over the whole range, so that the loop is
    # centred on the quasi-static moment as every other law's
    top = float(np.max(u)) * 1.05 + 1e-9
    grid = np.linspace(0.0, top, 400)
    k = grid.size - 1
    h = run(np.concatenate([grid[::-1], grid[1:], grid[::-1][1:], grid[1:]]), np.ones(n))
    rising, falling = h[-k:], h[-2 * k:-k][::-1]  # on grid[1:] and on grid[:-1]
    m = 0.5 * (np.interp(grid, grid[1:], rising) + np.interp(grid, grid[:-1], falling))
    return run(u, state) - np.interp(u, grid, m)


def friction_viscous(t, u, A, *, speed_rad_s: float, share: float = 0.5, v0_fraction: float = 0.05):
    """Rounded Coulomb friction (``share`` of ``A``) and a linear dashpot (the rest, at ``speed_rad_s``)."""
    rate = np.gradient(u, t) if t.size > 1 else np.zeros_like(u)
    v0 = v0_fraction * speed_rad_s
    return -A * (share * np.tanh(rate / v0) + (1.0 - share) * rate / speed_rad_s)


def _first_ramp_reversed(u):
    """The path before ``u``: its first ramp (up to the first reversal) run backwards, a loading into ``u[0]``."""
    du = np.diff(u)
    moving = np.flatnonzero(du != 0.0)
    if moving.size == 0:
        return u[:1]
    sign = np.sign(du[moving[0]])
    back = np.flatnonzero(np.sign(du[moving[0]:]) == -sign)
    end = moving[0] + (int(back[0]) if back.size else du.size - moving[0]) + 1
    return u[:end][::-1]


def fractional(t, u, A, *, speed_rad_s: float, order: float = 0.4, tau_ref_s: float = 20.0):
    """A springpot (Scott Blair element): ``H = -c D^q u``, the Caputo derivative of order ``q`` of the angle.

    Its relaxation modulus is the power law ``G(t) = c t^-q / Gamma(1 - q)``, the limit of a generalised
    Maxwell (Prony) series whose relaxation times are spread evenly on a log scale with weights ``tau^-q``
    (Bagley & Torvik 1983; Mainardi, *Fractional calculus and waves in linear viscoelasticity*, 2010): a
    viscoelastic bladder with no single relaxation time, relaxed (fully) to the quasi-static moment.  ``c`` is set
    so that a ramp at ``speed_rad_s`` from rest reaches ``A`` after ``tau_ref_s``: ``c = A Gamma(2 - q) /
    (v tau^(1 - q))``.  Discretised by the L1 scheme on the (uniform) sampling, with one loading ramp (the path's
    first ramp run backwards) as the history before the test.
    """
    pre = _first_ramp_reversed(u)
    path = np.concatenate([pre[:-1], u])
    h = float(np.median(np.diff(t))) if t.size > 1 else 1.0
    du = np.diff(path, prepend=path[0])
    m = np.arange(path.size, dtype=float)
    w = (m + 1.0) ** (1.0 - order) - m ** (1.0 - order)  # L1 weights of the increments, newest first
    c = A * math.gamma(2.0 - order) / (speed_rad_s * tau_ref_s ** (1.0 - order))
    d = np.convolve(du, w)[: path.size] * h ** (-order) / math.gamma(2.0 - order)
    return -c * d[pre.size - 1:]


def iwan_lognormal(t, u, A, *, median_deg: float = 1.5, sigma_ln: float = 0.9, n: int = 40):
    """An Iwan (parallel-series) model: ``n`` Jenkins elements of equal stiffness, slip angles lognormal.

    Each element is a spring ``k`` in series with a Coulomb slider that slips when the spring has stretched by its
    slip angle ``r_i`` (force ``k r_i``); the ``r_i`` are the ``n`` quantiles of a lognormal of median ``median_deg``
    and log-standard deviation ``sigma_ln`` (Iwan 1966, *J. Appl. Mech.* 33: 893; Segalman 2005), and ``k`` is such
    that all of them sliding give ``A``.  Rate-independent; Masing's rules hold.
    """
    from scipy.special import ndtri

    r = math.radians(median_deg) * np.exp(sigma_ln * ndtri((np.arange(n) + 0.5) / n))
    k = A / float(r.sum())
    lim = k * r
    h = lim.copy()  # after a loading (u decreasing): every element slipping, H = +A
    out = np.empty(u.size)
    du = np.diff(u, prepend=u[0])
    for i in range(u.size):
        h = np.clip(h - k * du[i], -lim, lim)
        out[i] = h.sum()
    return out


def coleman_hodgdon(t, u, A, *, span_rad: float, theta_c_deg: float = 4.0, kappa: float = 0.8):
    """A Duhem model of Coleman & Hodgdon's form, ``dH/du = alpha sgn(du) (f(u) - H) + g(u)``.

    (Coleman & Hodgdon 1986, *Int. J. Eng. Sci.* 24: 897; Duhem's class of rate-independent models.)  The
    anhysteretic curve ``f`` is the quasi-static moment itself (so ``f = 0`` here), ``alpha = 1 / theta_c``, and
    ``g(u) = -alpha A w(u)`` with a width ``w(u) = 1 + kappa (u / span - 1/2)`` that changes along the bending
    angle (friction that grows, ``kappa > 0``, or falls toward the free state): each branch tends to ``-+A w(u)``
    exponentially over ``theta_c``.  Integrated by the midpoint rule in ``u``.
    """
    alpha = 1.0 / math.radians(theta_c_deg)

    def g(x):
        return -alpha * A * (1.0 + kappa * (x / span_rad - 0.5))

    y = A * (1.0 + kappa * (float(u[0]) / span_rad - 0.5))  # after a loading: on the upper branch
    out = np.empty(u.size)
    out[0] = y
    for i in range(1, u.size):
        du = float(u[i] - u[i - 1])
        if du:
            s = math.copysign(1.0, du)
            xm = 0.5 * float(u[i] + u[i - 1])
            ym = y + 0.5 * du * (alpha * s * -y + g(float(u[i - 1])))
            y = y + du * (alpha * s * -ym + g(xm))
        out[i] = y
    return out


def asymmetric_stop(t, u, A, *, up: float = 1.3, down: float = 0.7, n: int = 6, u_min=math.radians(0.4),
                    u_max=math.radians(4.0)):
    """Stop operators with direction-dependent yield: a loop wider on loading than on unloading.

    ``n`` elasto-plastic (stop) elements of geometrically spaced yield angles, each of stiffness ``k_i`` and
    equal share of ``A``; element ``i`` saturates at ``+up A / n`` while the machine straightens the actuator and at
    ``-down A / n`` while it bends freely (the asymmetric play/stop operators of asymmetric Prandtl-Ishlinskii
    models, e.g. Janaideh, Rakheja & Su 2009, *Smart Mater. Struct.*, written for McKibben muscles' and
    piezo actuators' asymmetric loops).  The loop's centre lies ``(up - down) A / 2`` above the quasi-static
    moment where every element saturates.
    """
    r = np.geomspace(u_min, u_max, n)
    hi, lo = np.full(n, up * A / n), np.full(n, -down * A / n)
    k = 0.5 * (hi - lo) / r
    h = hi.copy()  # after a loading (u decreasing)
    out = np.empty(u.size)
    du = np.diff(u, prepend=u[0])
    for i in range(u.size):
        h = np.clip(h - k * du[i], lo, hi)
        out[i] = h.sum()
    return out


def rate_state(t, u, A, *, speed_rad_s: float, mu0: float = 0.6, a: float = 0.02, b: float = 0.03,
               dc_deg: float = 0.2, elastic_deg: float = 0.3, substeps: int = 4):
    """Dieterich-Ruina rate-and-state friction through a spring (a spring-slider, Ruina 1983's aging law).

    ``mu = a asinh(v / (2 v*) exp((mu0 + b ln(v* theta / Dc)) / a))`` (the regularised form of
    ``mu0 + a ln(v / v*) + b ln(v* theta / Dc)``, Rice & Ben-Zion 1996), ``dtheta/dt = 1 - |v| theta / Dc``
    (Dieterich 1979, Ruina 1983), normal load ``A / mu0``; the slider is driven by the bending angle through a
    spring that takes ``A`` over ``elastic_deg``; ``v*`` is the test's speed.  The contact heals while it is still
    (reversals, dwells), so friction peaks at breakaway and decays over ``Dc``.  Implicit Euler in time.
    """
    N = A / mu0
    k = A / math.radians(elastic_deg)
    dc = math.radians(dc_deg)
    vs = speed_rad_s
    q = -np.asarray(u, dtype=float)  # friction's own coordinate: H > 0 when u decreases
    theta = dc / vs  # steady sliding at v* toward the blocked state
    F = A
    y = float(q[0]) - F / k

    def rate(F, theta):
        c = (mu0 + b * math.log(vs * theta / dc)) / a
        x = F / (a * N)
        e1, e2 = math.exp(min(x - c, 700.0)), math.exp(min(-x - c, 700.0))
        return vs * (e1 - e2), vs * (e1 + e2) / (a * N)

    out = np.empty(q.size)
    out[0] = F
    dt = np.diff(t, prepend=t[0])
    for i in range(1, q.size):
        h = dt[i] / substeps
        for j in range(substeps):
            qn = float(q[i - 1] + (q[i] - q[i - 1]) * (j + 1) / substeps)
            T = k * (qn - y)  # the spring force if the slider did not move
            lo, hi = min(0.0, T), max(0.0, T)
            Fn = min(max(F, lo), hi)
            for _ in range(60):
                v, dv = rate(Fn, theta)
                r = Fn + k * h * v - T
                if abs(r) <= 1e-12 * A:
                    break
                if r > 0:
                    hi = Fn
                else:
                    lo = Fn
                step = Fn - r / (1.0 + k * h * dv)
                Fn = step if lo < step < hi else 0.5 * (lo + hi)
            v, _ = rate(Fn, theta)
            y += h * v
            F = Fn
            theta = (theta + h) / (1.0 + h * abs(v) / dc)
        out[i] = F
    return out


# ------------------------------------------------------------------------------------------------
# cases and truths
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Case:
    """One calibration case: the true actuator, its tests, the loop law and the instrument faults.

    preset, model : the paper's actuator (``"be-pam"``/``"bc-pam"``) and the model whose constants start the fit.
    geometry : replacements of its geometry (mm), the same in the truth and the start of the fit.
    d_alpha0_deg, mu_factor, shape : the truth: alpha0 moved, shear modulus scaled, shape ``C01/(C10 + C01)``.
    loop, loop_fraction : the loop law (:data:`LOOPS`) and its amplitude (fraction of the blocked moment).
    loop_options : the law's own settings (its keywords; ``gap_mm`` for the backlash, ``theta_c_span`` for Bouc-Wen).
    noise_fraction, noise_ar1 : force noise (fraction of the blocked force) and its lag-one correlation.
    drift_fraction : load-cell offset drift over each test (fraction of the blocked force).
    drift_tau_s : 0: the drift is linear in time; > 0: it settles exponentially with this time constant (s).
    drift_step_fraction : a step of the offset halfway through each test (fraction of the blocked force).
    force_resolution_n : the force is rounded to this resolution (N; 0: not).

    The faults below (added for :data:`HOLDOUT5`) are all off by default:

    pressure_leak_fraction : the actuator's pressure falls linearly by this fraction over the cycles (a slow leak
        of a sealed actuator); the header keeps the nominal pressure.
    pressure_ripple_fraction, pressure_ripple_period_s : the regulator's pressure oscillates by this fraction
        (amplitude) with this period, at a random phase per test.
    load_cell_gain, load_cell_nonlinearity, load_cell_range_n : the load cell reads ``(1 + gain) F`` plus a bow
        ``nonlinearity * range * 4 x (1 - |x|)``, ``x = F / range`` (a calibration error within a class).
    frame_compliance_mm_per_n : a spring in series with the fixture (the frame, the load cell, the fixture's
        rods): the crosshead's stroke, zeroed on the blocked actuator, overstates the plates' travel by the
        force's fall times this compliance.
    detection_load_n : the load at which the machine calls the actuator free (default the 0.2 N of every set).
    force_clip_n : the force saturates at +-this (the amplifier's range; 0: not).
    force_filter_tau_s : the force channel passes a first-order low-pass of this time constant (an amplifier's
        filter) that the stroke channel does not: the force lags the stroke.
    dropped_fraction : about this share of the rows is lost, in bursts of a few samples (a logger's buffer).
    softening_fraction, softening_cycles : the bladder's moduli soften by up to this fraction as the bending
        angle accumulates, ``s = s_inf (1 - exp(-arc / (softening_cycles * 2 span)))`` (Miehe's continuous
        damage, a Mullins-like softening that slows cycle by cycle); the truth is the virgin material.
    """

    name: str
    preset: str = "be-pam"
    model: str = "energy"
    pressures_kpa: tuple[float, ...] = (100.0, 150.0, 200.0)
    geometry: dict = field(default_factory=dict)
    d_alpha0_deg: float = 0.8
    mu_factor: float = 1.03
    shape: float = 0.6
    loop: str = "none"
    loop_fraction: float = 0.05
    loop_options: dict = field(default_factory=dict)
    noise_fraction: float = 0.01
    noise_ar1: float = 0.9
    drift_fraction: float = 0.0
    drift_tau_s: float = 0.0
    drift_step_fraction: float = 0.0
    force_resolution_n: float = 0.0
    dialect: str = "csv"
    cycles: int = 3
    speed_mm_min: float = 30.0
    rate_hz: float = 20.0
    dwell_s: float = 0.0
    pressure_leak_fraction: float = 0.0
    pressure_ripple_fraction: float = 0.0
    pressure_ripple_period_s: float = 6.0
    load_cell_gain: float = 0.0
    load_cell_nonlinearity: float = 0.0
    load_cell_range_n: float = 50.0
    frame_compliance_mm_per_n: float = 0.0
    detection_load_n: float = DETECTION_LOAD_N
    force_clip_n: float = 0.0
    force_filter_tau_s: float = 0.0
    dropped_fraction: float = 0.0
    softening_fraction: float = 0.0
    softening_cycles: float = 2.0


CASES = {c.name: c for c in (
    Case("none", noise_fraction=0.01, dialect="csv"),
    Case("maxwell-creep", preset="bc-pam", pressures_kpa=(50.0, 70.0, 90.0, 110.0), d_alpha0_deg=-0.6,
         loop="maxwell-creep", loop_fraction=0.06, noise_fraction=0.01, dwell_s=5.0, dialect="testxpert"),
    Case("stiction", pressures_kpa=(100.0, 125.0, 150.0, 175.0, 200.0), loop="stiction", loop_fraction=0.05,
         noise_fraction=0.005, noise_ar1=0.8, dialect="bluehill"),
    Case("viscous", preset="bc-pam", geometry={"R0_mm": 9.0, "R0_start_mm": 9.1, "t0_mm": 2.3},
         pressures_kpa=(50.0, 80.0, 110.0), d_alpha0_deg=-0.6, loop="viscous", loop_fraction=0.05,
         noise_fraction=0.02, dialect="csv"),
    Case("backlash", geometry={"R0_mm": 8.0, "L0_mm": 150.0}, pressures_kpa=(90.0, 110.0, 130.0, 150.0, 170.0, 190.0),
         d_alpha0_deg=-0.7, shape=0.4, loop="backlash", loop_fraction=0.04, noise_fraction=0.01, dialect="testxpert"),
    Case("bouc-wen", pressures_kpa=(100.0, 140.0, 180.0, 220.0), mu_factor=0.95, loop="bouc-wen", loop_fraction=0.06,
         noise_fraction=0.03, noise_ar1=0.95, dialect="bluehill"),
    Case("drift", pressures_kpa=(100.0, 150.0, 200.0), loop="none", noise_fraction=0.005, drift_fraction=0.01,
         dialect="csv"),
)}

#: Cases kept out of any tuning: other parameters of the same laws, faults combined, the other model.  A fit tuned
#: on :data:`CASES` is checked on these (``calibration_study.py --set holdout``).
HOLDOUT = {c.name: c for c in (
    Case("stiction+drift", preset="bc-pam", pressures_kpa=(45.0, 65.0, 85.0, 105.0, 125.0), d_alpha0_deg=0.5,
         shape=0.5, loop="stiction", loop_fraction=0.04, loop_options={"ratio": 1.4, "stick_deg": 1.0},
         noise_fraction=0.01, noise_ar1=0.85, drift_fraction=0.008, dialect="testxpert"),
    Case("creep+drift", geometry={"R0_mm": 9.0, "R0_start_mm": 9.1}, pressures_kpa=(110.0, 135.0, 160.0, 185.0),
         d_alpha0_deg=-0.5, mu_factor=1.06, loop="maxwell-creep", loop_fraction=0.05,
         loop_options={"creep_tau_s": 20.0, "n": 6}, noise_fraction=0.005, drift_fraction=-0.01, dwell_s=3.0,
         dialect="bluehill"),
    Case("viscous-fb", model="force_balance", pressures_kpa=(100.0, 140.0, 180.0), d_alpha0_deg=0.6, shape=0.5,
         loop="viscous", loop_fraction=0.06, loop_options={"tau_s": 3.0, "dashpot_share": 0.3}, noise_fraction=0.015,
         noise_ar1=0.9, dialect="csv"),
    Case("backlash-bc", preset="bc-pam", pressures_kpa=(40.0, 60.0, 80.0, 100.0, 120.0), d_alpha0_deg=0.7,
         loop="backlash", loop_fraction=0.05, loop_options={"gap_mm": 0.2}, noise_fraction=0.02, noise_ar1=0.8,
         dialect="csv"),
    Case("bouc-wen-n2", pressures_kpa=(90.0, 115.0, 140.0, 165.0, 190.0, 215.0), d_alpha0_deg=-0.8, mu_factor=1.08,
         loop="bouc-wen", loop_fraction=0.05, loop_options={"n": 2.0, "theta_c_span": 0.25}, noise_fraction=0.01,
         noise_ar1=0.7, dialect="testxpert"),
)}


#: A second held-out set, written on 2026-11-26 after the ensemble's model average was designed and checked on
#: :data:`CASES` and :data:`HOLDOUT` (the first held-out set had been looked at), and scored once
#: (``calibration_study.py --set holdout2``): other parameters of every law, both actuators and both models.
HOLDOUT2 = {c.name: c for c in (
    Case("bouc-wen-n3-bc", preset="bc-pam", pressures_kpa=(50.0, 75.0, 100.0, 125.0), d_alpha0_deg=0.6,
         mu_factor=0.97, loop="bouc-wen", loop_fraction=0.05, loop_options={"n": 3.0, "theta_c_span": 0.35},
         noise_fraction=0.015, noise_ar1=0.85, dialect="csv"),
    Case("stiction-strong", pressures_kpa=(110.0, 140.0, 170.0, 200.0), d_alpha0_deg=-0.5, shape=0.4,
         loop="stiction", loop_fraction=0.04, loop_options={"ratio": 2.2, "stick_deg": 2.0}, noise_fraction=0.01,
         noise_ar1=0.9, dialect="testxpert"),
    Case("creep-slow-bc", preset="bc-pam", pressures_kpa=(60.0, 80.0, 100.0, 120.0, 140.0), d_alpha0_deg=0.4,
         loop="maxwell-creep", loop_fraction=0.05, loop_options={"creep_tau_s": 60.0, "n": 4}, noise_fraction=0.01,
         dwell_s=2.0, dialect="bluehill"),
    Case("viscous-slow", pressures_kpa=(100.0, 130.0, 160.0, 190.0), d_alpha0_deg=0.7, mu_factor=1.04,
         loop="viscous", loop_fraction=0.05, loop_options={"tau_s": 20.0, "dashpot_share": 0.6},
         noise_fraction=0.01, noise_ar1=0.9, dialect="csv"),
    Case("backlash-wide", geometry={"R0_mm": 9.0, "R0_start_mm": 9.1}, pressures_kpa=(100.0, 125.0, 150.0, 175.0),
         d_alpha0_deg=0.5, loop="backlash", loop_fraction=0.05, loop_options={"gap_mm": 0.5}, noise_fraction=0.015,
         noise_ar1=0.85, dialect="bluehill"),
    Case("none-fb-bc", preset="bc-pam", model="force_balance", pressures_kpa=(50.0, 70.0, 90.0, 110.0, 130.0),
         d_alpha0_deg=-0.5, shape=0.5, loop="none", noise_fraction=0.02, noise_ar1=0.8, dialect="testxpert"),
)}

#: A third held-out set, written on 2026-11-26 before the fit was changed that day (self-similar members, the
#: doubt of an uncorrected drift) and scored once when done (``calibration_study.py --set holdout3``): two loop
#: laws no earlier set used (a Masing loop, friction with a dashpot), other exponents and a drift that settles.
HOLDOUT3 = {c.name: c for c in (
    Case("masing", pressures_kpa=(100.0, 135.0, 170.0, 205.0), d_alpha0_deg=0.6, mu_factor=1.05, loop="masing",
         loop_fraction=0.05, loop_options={"theta_c_deg": 3.0, "r": 2.0}, noise_fraction=0.01, noise_ar1=0.9,
         dialect="testxpert"),
    Case("masing-soft-bc-fb", preset="bc-pam", model="force_balance", pressures_kpa=(55.0, 75.0, 95.0, 115.0, 135.0),
         d_alpha0_deg=-0.4, shape=0.45, loop="masing", loop_fraction=0.06, loop_options={"theta_c_deg": 6.0, "r": 1.0},
         noise_fraction=0.015, noise_ar1=0.85, dialect="csv"),
    Case("friction-viscous", pressures_kpa=(120.0, 160.0, 200.0), d_alpha0_deg=-0.6, mu_factor=0.96,
         loop="friction-viscous", loop_fraction=0.05, loop_options={"share": 0.6}, noise_fraction=0.01,
         noise_ar1=0.9, cycles=5, speed_mm_min=60.0, rate_hz=25.0, dialect="bluehill"),
    Case("bouc-wen-n1.5-bc", preset="bc-pam", pressures_kpa=(45.0, 70.0, 95.0, 120.0), d_alpha0_deg=0.5,
         loop="bouc-wen", loop_fraction=0.05, loop_options={"n": 1.5, "theta_c_span": 0.3, "beta_bw": 0.7,
                                                            "gamma_bw": 0.3},
         noise_fraction=0.02, noise_ar1=0.8, dialect="testxpert"),
    Case("stiction+thermal-drift", pressures_kpa=(100.0, 130.0, 160.0, 190.0), d_alpha0_deg=0.4, shape=0.5,
         loop="stiction", loop_fraction=0.04, loop_options={"ratio": 1.3, "stick_deg": 1.2}, noise_fraction=0.008,
         noise_ar1=0.85, drift_fraction=0.008, drift_tau_s=60.0, dialect="csv"),
    Case("creep-fast-fb", model="force_balance", pressures_kpa=(90.0, 120.0, 150.0, 180.0, 210.0), d_alpha0_deg=-0.3,
         mu_factor=1.02, loop="maxwell-creep", loop_fraction=0.05, loop_options={"creep_tau_s": 10.0, "n": 10},
         noise_fraction=0.01, noise_ar1=0.9, dwell_s=1.0, dialect="bluehill"),
    Case("none+thermal-drift-bc", preset="bc-pam", pressures_kpa=(50.0, 80.0, 110.0), d_alpha0_deg=0.7,
         loop="none", noise_fraction=0.006, noise_ar1=0.9, drift_fraction=-0.01, drift_tau_s=40.0, dialect="csv"),
)}


#: A fourth held-out set, written on 2026-11-26 after the third was scored and the fit changed for it, to be scored
#: once when done (``calibration_study.py --set holdout4``): three more loop laws (LuGre friction, two Maxwell
#: branches, a discrete Preisach model) and other instrument faults (an offset step, a coarse force resolution,
#: a low sampling rate, heavy coloured noise).
HOLDOUT4 = {c.name: c for c in (
    Case("lugre", pressures_kpa=(100.0, 130.0, 160.0, 190.0), d_alpha0_deg=0.5, mu_factor=0.98, loop="lugre",
         loop_fraction=0.05, noise_fraction=0.01, noise_ar1=0.85, dialect="testxpert"),
    Case("lugre-bc-fb", preset="bc-pam", model="force_balance", pressures_kpa=(50.0, 75.0, 100.0, 125.0),
         d_alpha0_deg=-0.6, shape=0.5, loop="lugre", loop_fraction=0.06,
         loop_options={"stribeck": 2.0, "viscous_share": 0.1}, noise_fraction=0.015, noise_ar1=0.9, dialect="csv"),
    Case("two-maxwell", pressures_kpa=(110.0, 150.0, 190.0), d_alpha0_deg=-0.4, mu_factor=1.04, loop="two-maxwell",
         loop_fraction=0.06, noise_fraction=0.01, noise_ar1=0.9, dwell_s=3.0, dialect="bluehill"),
    Case("preisach-bc", preset="bc-pam", pressures_kpa=(45.0, 65.0, 85.0, 105.0, 125.0), d_alpha0_deg=0.6,
         loop="preisach", loop_fraction=0.05, noise_fraction=0.01, noise_ar1=0.8, dialect="testxpert"),
    Case("step+drift", pressures_kpa=(100.0, 140.0, 180.0), d_alpha0_deg=0.3, loop="none", noise_fraction=0.006,
         noise_ar1=0.9, drift_fraction=0.006, drift_step_fraction=0.004, dialect="csv"),
    Case("coarse-slow", pressures_kpa=(100.0, 125.0, 150.0, 175.0, 200.0), d_alpha0_deg=-0.5, loop="maxwell-creep",
         loop_fraction=0.04, loop_options={"creep_tau_s": 30.0}, noise_fraction=0.005, noise_ar1=0.5,
         force_resolution_n=0.02, rate_hz=5.0, dialect="bluehill"),
    Case("heavy-noise", pressures_kpa=(90.0, 115.0, 140.0, 165.0, 190.0, 215.0), d_alpha0_deg=0.4, shape=0.45,
         loop="stiction", loop_fraction=0.04, loop_options={"ratio": 1.5}, noise_fraction=0.03, noise_ar1=0.95,
         dialect="testxpert"),
)}


#: A fifth held-out set, written on 2026-11-26 independently of the fit (its laws and faults chosen from the physics
#: and instrumentation literature, not from bendpam's ensemble) and scored once (``calibration_study.py --set
#: holdout5``): five loop laws no earlier set used (a springpot, i.e. a power-law Prony kernel; an Iwan model with
#: lognormal slip angles; a Coleman-Hodgdon Duhem model with a width that changes along the angle; asymmetric stop
#: operators; rate-and-state friction), a Mullins-like softening, and instrument and test faults (a pressure leak,
#: regulator ripple, a load cell's gain and nonlinearity, a compliant frame, a filtered force channel, dropped rows,
#: a higher detection load, a clipped force, 5-7 cycles, other speeds).
HOLDOUT5 = {c.name: c for c in (
    Case("fractional+leak", pressures_kpa=(100.0, 130.0, 160.0, 190.0), d_alpha0_deg=0.6, mu_factor=1.04,
         loop="fractional", loop_fraction=0.04, loop_options={"order": 0.4, "tau_ref_s": 20.0}, noise_fraction=0.01,
         noise_ar1=0.85, pressure_leak_fraction=0.02, cycles=5, dialect="bluehill"),
    Case("iwan-lognormal-bc-fb+frame", preset="bc-pam", model="force_balance",
         pressures_kpa=(50.0, 70.0, 90.0, 110.0, 130.0), d_alpha0_deg=-0.5, shape=0.5, loop="iwan-lognormal",
         loop_fraction=0.05, loop_options={"median_deg": 1.5, "sigma_ln": 0.9, "n": 40}, noise_fraction=0.015,
         noise_ar1=0.8, frame_compliance_mm_per_n=0.01, dialect="csv"),
    Case("coleman-hodgdon+loadcell", pressures_kpa=(110.0, 140.0, 170.0, 200.0), d_alpha0_deg=0.5, mu_factor=0.97,
         shape=0.4, loop="coleman-hodgdon", loop_fraction=0.05, loop_options={"theta_c_deg": 4.0, "kappa": 0.8},
         noise_fraction=0.01, noise_ar1=0.9, load_cell_gain=0.005, load_cell_nonlinearity=0.0015,
         load_cell_range_n=50.0, dialect="testxpert"),
    Case("asymmetric-bc+ripple", preset="bc-pam", pressures_kpa=(45.0, 65.0, 85.0, 105.0), d_alpha0_deg=0.6,
         loop="asymmetric-stop", loop_fraction=0.05, loop_options={"up": 1.3, "down": 0.7}, noise_fraction=0.02,
         noise_ar1=0.85, pressure_ripple_fraction=0.006, pressure_ripple_period_s=6.0, dialect="bluehill"),
    Case("rate-state-fb+filter+drops", model="force_balance", pressures_kpa=(100.0, 140.0, 180.0), d_alpha0_deg=-0.6,
         mu_factor=1.05, shape=0.5, loop="rate-state", loop_fraction=0.05, noise_fraction=0.008, noise_ar1=0.9,
         dwell_s=2.0, speed_mm_min=45.0, force_filter_tau_s=0.15, dropped_fraction=0.02, dialect="csv"),
    Case("mullins-bc", preset="bc-pam", pressures_kpa=(50.0, 70.0, 90.0, 110.0, 130.0), d_alpha0_deg=0.4,
         mu_factor=1.02, loop="iwan-lognormal", loop_fraction=0.03, loop_options={"median_deg": 2.5, "sigma_ln": 0.6},
         softening_fraction=0.015, softening_cycles=2.0, cycles=6, noise_fraction=0.01, noise_ar1=0.9,
         dialect="testxpert"),
    Case("fractional-clip+preload", pressures_kpa=(90.0, 115.0, 140.0, 165.0, 190.0, 215.0), d_alpha0_deg=-0.7,
         shape=0.45, loop="fractional", loop_fraction=0.04, loop_options={"order": 0.6, "tau_ref_s": 20.0},
         noise_fraction=0.02, noise_ar1=0.9, detection_load_n=1.0, force_clip_n=20.0, dialect="csv"),
    Case("coleman-hodgdon-bc-fb-fast+leak", preset="bc-pam", model="force_balance", pressures_kpa=(55.0, 85.0, 115.0),
         d_alpha0_deg=-0.4, mu_factor=0.98, loop="coleman-hodgdon", loop_fraction=0.06,
         loop_options={"theta_c_deg": 2.5, "kappa": -0.6}, noise_fraction=0.025, noise_ar1=0.9, cycles=7,
         speed_mm_min=60.0, rate_hz=50.0, pressure_leak_fraction=0.03, dialect="testxpert"),
)}

@dataclass(frozen=True)
class Truth:
    """The true actuator of a case and the values a fit should recover (deg, kPa)."""

    actuator: object
    alpha0_deg: float
    shear_modulus_kpa: float
    shape: float


def _preset(case: Case):
    base = presets.get(case.preset, case.model)
    return base.replace(**case.geometry) if case.geometry else base


def start_actuator(case: Case):
    """The actuator a fit starts from: the case's geometry with the preset's constants."""
    return _preset(case)


def case_truth(case: Case) -> Truth:
    """The true actuator: the preset's geometry and P_start, alpha0 moved, an admissible material."""
    base = _preset(case)
    S = (base.C10_kpa + base.C01_kpa) * case.mu_factor
    act = base.replace(alpha0_deg=base.alpha0_deg + case.d_alpha0_deg, C10_kpa=S * (1.0 - case.shape),
                       C01_kpa=S * case.shape)
    return Truth(act, act.alpha0_deg, 2.0 * S, case.shape)


# ------------------------------------------------------------------------------------------------
# one test
# ------------------------------------------------------------------------------------------------
def _loop(case: Case, t, u, A, speed_rad_s: float, span_rad: float):
    """The loop's moment ``H`` (N*mm) of ``case`` along the path; ``case.loop_options`` are the law's keywords."""
    opts = dict(case.loop_options)
    opts.pop("gap_mm", None)
    if case.loop == "none" or A == 0.0:
        return np.zeros(u.size)
    rate_laws = {"viscous": viscous, "friction-viscous": friction_viscous, "lugre": lugre, "two-maxwell": two_maxwell,
                 "fractional": fractional, "rate-state": rate_state}  # f(t, u, A, speed_rad_s=..., **options)
    plain_laws = {"maxwell-creep": maxwell_slip, "stiction": stiction, "preisach": preisach,
                  "iwan-lognormal": iwan_lognormal, "asymmetric-stop": asymmetric_stop}  # f(t, u, A, **options)
    if case.loop in rate_laws:
        return rate_laws[case.loop](t, u, A, speed_rad_s=speed_rad_s, **opts)
    if case.loop in plain_laws:
        return plain_laws[case.loop](t, u, A, **opts)
    if case.loop == "backlash":
        return maxwell_slip(t, u, A, **{"creep_tau_s": None, "u_min": math.radians(0.5), "u_max": math.radians(4.0),
                                        **opts})
    if case.loop == "bouc-wen":
        span = opts.pop("theta_c_span", 0.4)
        return bouc_wen(t, u, A, theta_c=span * span_rad, **opts)
    if case.loop == "masing":
        return masing(t, u, A, theta_c=math.radians(opts.pop("theta_c_deg", 3.0)), **opts)
    if case.loop == "coleman-hodgdon":
        return coleman_hodgdon(t, u, A, span_rad=span_rad, **opts)
    raise ValueError(f"unknown loop {case.loop!r}; one of {', '.join(LOOPS)}")


def _path(s_free: float, case: Case):
    """Time (s) and crosshead stroke (mm) of the triangular cycles with their dwells, sampled at ``rate_hz``."""
    ramp = s_free / (case.speed_mm_min / 60.0)
    kt, ks = [0.0], [0.0]
    for _ in range(case.cycles):
        for target in (s_free, 0.0):
            kt.append(kt[-1] + ramp)
            ks.append(target)
            if case.dwell_s > 0:
                kt.append(kt[-1] + case.dwell_s)
                ks.append(target)
    t = np.arange(0.0, kt[-1] + 0.5 / case.rate_hz, 1.0 / case.rate_hz)
    return t, np.interp(t, kt, ks)


def machine_test(case: Case, truth: Truth, pressure_kpa: float, rng: np.random.Generator, rig: Rig):
    """One raw test: ``(time s, stroke mm, force N, info)``; ``info`` has the free stroke and the blocked force."""
    act = truth.actuator
    sign = act.bend_sign or 1
    law = bendpam.MomentLaw.of(act, case.model)

    def m_qs(k):
        return sign * law.moment(pressure_kpa, sign * np.asarray(k, dtype=float))

    Mb = float(m_qs(0.0))
    A = case.loop_fraction * Mb
    lim = bendpam.curvature_limits(act)
    k_lim = 0.98 * abs(lim.k_max if sign > 0 else lim.k_min)
    beta_hi = min(MAX_BETA_RAD, 0.5 * k_lim * rig.L0)
    speed_rad_s = 2.0 * (case.speed_mm_min / 60.0) / rig.d  # about, near the blocked state
    gap = float(case.loop_options.get("gap_mm", 0.3)) if case.loop == "backlash" else 0.0
    varying = bool(case.pressure_leak_fraction or case.pressure_ripple_fraction or case.softening_fraction)
    phase = float(rng.uniform(0.0, 2.0 * math.pi)) if case.pressure_ripple_fraction else 0.0
    soft_law = (bendpam.MomentLaw.of(act.replace(C10_kpa=act.C10_kpa * (1.0 - case.softening_fraction),
                                                 C01_kpa=act.C01_kpa * (1.0 - case.softening_fraction)), case.model)
                if case.softening_fraction else None)

    def m_varying(t, u, span_rad, cycle_end_s):
        """The quasi-static moment with the pressure's leak and ripple and the bladder's softening."""
        p = np.full(u.size, float(pressure_kpa))
        if case.pressure_ripple_fraction:
            p = p * (1.0 + case.pressure_ripple_fraction * np.sin(2.0 * math.pi * t / case.pressure_ripple_period_s
                                                                   + phase))
        if case.pressure_leak_fraction and cycle_end_s:  # the cycles (not the release that finds the free state)
            p = p * (1.0 - case.pressure_leak_fraction * (t - t[0]) / cycle_end_s)
        k = sign * u / rig.L0
        m = sign * law.moment(p, k)
        if soft_law is not None:
            arc = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(u)))]) + (span_rad if cycle_end_s else 0.0)
            frac = 1.0 - np.exp(-arc / (case.softening_cycles * 2.0 * span_rad))  # of the full softening
            m = m + frac * (sign * soft_law.moment(p, k) - m)
        return m

    def force_at(t, stroke, span_rad, cycle_end_s):
        beta = rig.beta(play(stroke, gap) if gap else stroke)
        u = 2.0 * beta
        mq = m_varying(t, u, span_rad, cycle_end_s) if varying else m_qs(u / rig.L0)
        return rig.force(mq + _loop(case, t, u, A, speed_rad_s, span_rad), beta)

    def force(t, cross, span_rad, cycle_end_s=0.0):
        f = force_at(t, cross, span_rad, cycle_end_s)
        if case.frame_compliance_mm_per_n:  # the plates travel the crosshead's stroke plus the frame's relaxation
            for _ in range(30):
                g = force_at(t, cross + case.frame_compliance_mm_per_n * (f[0] - f), span_rad, cycle_end_s)
                done = float(np.max(np.abs(g - f))) < 1e-10
                f = g
                if done:
                    break
        return f

    # 1. the machine releases the actuator from the blocked state until the force falls to the detection load
    s_hi = float(rig.stroke(beta_hi))
    s = np.linspace(0.0, s_hi, 4000)
    kk = np.linspace(0.0, 2.0 * beta_hi / rig.L0, 400)
    mq = m_qs(kk)
    span = float(kk[np.argmax(mq <= 0.0)] * rig.L0) if np.any(mq <= 0.0) else 2.0 * beta_hi  # quasi-static free angle
    f = force(s / (case.speed_mm_min / 60.0), s, span)
    load = case.detection_load_n
    below = np.flatnonzero(f <= load)
    if below.size == 0 or below[0] == 0:
        raise ValueError(f"{case.name}: at {pressure_kpa:g} kPa the force never falls to the detection load")
    j = int(below[0])
    s_free = float(s[j - 1] + (s[j] - s[j - 1]) * (f[j - 1] - load) / (f[j - 1] - f[j]))
    # 2. the cycles
    t, cross = _path(s_free, case)
    clean = force(t, cross, span, float(t[-1] - t[0]))
    F_block = float(clean[0])
    measured = clean
    if case.load_cell_gain or case.load_cell_nonlinearity:  # the load cell's calibration error
        x = clean / case.load_cell_range_n
        measured = clean * (1.0 + case.load_cell_gain) + (case.load_cell_nonlinearity * case.load_cell_range_n
                                                          * 4.0 * x * (1.0 - np.abs(x)))
    if case.force_filter_tau_s:  # the amplifier's first-order low-pass (exact for a signal linear over each step)
        a = math.exp(-float(np.median(np.diff(t))) / case.force_filter_tau_s)
        measured = lfilter([1.0 - a], [1.0, -a], measured, zi=[a * measured[0]])[0]
    w = rng.normal(0.0, 1.0, t.size)
    w[1:] *= math.sqrt(1.0 - case.noise_ar1**2)  # e_0 = w_0, e_n = phi e_(n-1) + sqrt(1 - phi^2) w_n: stationary
    noise = lfilter([1.0], [1.0, -case.noise_ar1], w)
    x = (t - t[0]) / (t[-1] - t[0])
    if case.drift_tau_s > 0:  # a thermal drift that settles
        x = -np.expm1(-(t - t[0]) / case.drift_tau_s) / -math.expm1(-(t[-1] - t[0]) / case.drift_tau_s)
    drift = case.drift_fraction * F_block * x
    if case.drift_step_fraction:
        drift = drift + case.drift_step_fraction * F_block * (t >= t[0] + 0.5 * (t[-1] - t[0]))
    force_n = measured + case.noise_fraction * F_block * noise + drift
    if case.force_clip_n > 0:
        force_n = np.clip(force_n, -case.force_clip_n, case.force_clip_n)
    if case.force_resolution_n > 0:
        force_n = np.round(force_n / case.force_resolution_n) * case.force_resolution_n
    stroke = cross + rng.normal(0.0, 0.002, t.size)
    if case.dropped_fraction:  # bursts of 1-7 lost rows (4 on average), never the first or the last
        starts = np.flatnonzero(rng.random(t.size) < case.dropped_fraction / 4.0)
        lengths = rng.integers(1, 8, starts.size)
        keep = np.ones(t.size, dtype=bool)
        for a0, n0 in zip(starts, lengths, strict=True):
            keep[a0:a0 + n0] = False
        keep[0] = keep[-1] = True
        t, stroke, force_n, drift = t[keep], stroke[keep], force_n[keep], drift[keep]
    info = {"pressure_kpa": pressure_kpa, "free_stroke_mm": s_free, "blocked_force_n": F_block,
            "blocked_moment_nmm": Mb, "loop_amplitude_nmm": A, "samples": int(t.size),
            "duration_s": float(t[-1]), "drift_n": float(drift[-1] if np.size(drift) else 0.0)}
    return t, stroke, force_n, info


# ------------------------------------------------------------------------------------------------
# files in a machine's dialect
# ------------------------------------------------------------------------------------------------
def _num(x: float, comma: bool = False) -> str:
    text = f"{x:.6g}"
    return text.replace(".", ",") if comma else text


def export_text(dialect: str, t, stroke, force, pressure_kpa: float, specimen: str) -> tuple[str, str]:
    """The text of a raw export and its encoding: ``csv``, ``testxpert`` (decimal comma) or ``bluehill``."""
    rows = np.column_stack([t, stroke, force])
    if dialect == "csv":
        head = [f"# Pressure: {pressure_kpa:g} kPa", f"# Specimen: {specimen}", "# Test speed: 30 mm/min",
                "time_s,stroke_mm,force_n"]
        body = "\n".join(f"{a:.3f},{b:.5f},{c:.5f}" for a, b, c in rows.tolist())
        return "\n".join(head) + "\n" + body + "\n", "utf-8"
    if dialect == "testxpert":
        head = ["$testXpert II ASCII-Export", f"Probe;{specimen}", f"Druck;{_num(pressure_kpa, True)};kPa",
                "Prüfgeschwindigkeit;30;mm/min", "", "Prüfzeit;Standardweg;Standardkraft", "s;mm;N"]
        body = "\r\n".join(f"{a:.3f};{b:.5f};{c:.5f}".replace(".", ",") for a, b, c in rows.tolist())
        return "\r\n".join(head) + "\r\n" + body + "\r\n", "cp1252"
    if dialect == "bluehill":
        head = ['"Specimen : ' + specimen + '"', f'"Pressure : {pressure_kpa:g} kPa"', '"Rate 1 : 30 mm/min"', "",
                '"Time","Extension","Load"', '"(s)","(mm)","(N)"']
        body = "\r\n".join(f'"{a:.3f}","{b:.5f}","{c:.5f}"' for a, b, c in rows.tolist())
        return "\r\n".join(head) + "\r\n" + body + "\r\n", "utf-8"
    raise ValueError(f"unknown dialect {dialect!r}; one of {', '.join(DIALECTS)}")


def generate_set(case: Case, seed: int, folder) -> dict:
    """Write one raw file per pressure of ``case`` into ``folder`` (noise drawn from ``seed``); returns the truth.

    Files are named ``{preset}_{P}kPa{suffix}`` and carry the pressure in their header.

    >>> import dataclasses, tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     truth = generate_set(dataclasses.replace(CASES["stiction"], pressures_kpa=(150.0,), cycles=2), 1, folder)
    ...     names = sorted(p.name for p in Path(folder).iterdir())
    >>> names, round(truth["alpha0_deg"], 2)
    (['be-pam_150kPa.csv'], 70.5)
    """
    truth = case_truth(case)
    rig = Rig(L0=truth.actuator.L0_mm)
    rng = np.random.default_rng([seed, sum(map(ord, case.name))])
    folder = Path(folder)
    files, tests = [], []
    for p in case.pressures_kpa:
        t, stroke, force, info = machine_test(case, truth, float(p), rng, rig)
        name = f"{case.preset}_{p:g}kPa{SUFFIX[case.dialect]}"
        text, encoding = export_text(case.dialect, t, stroke, force, float(p), f"{case.name}-{seed}")
        atomic_write_text(folder / name, text, encoding=encoding)
        files.append(name)
        tests.append(info)
    return {"case": case.name, "seed": seed, "alpha0_deg": truth.alpha0_deg,
            "shear_modulus_kpa": truth.shear_modulus_kpa, "shape": truth.shape, "files": files, "tests": tests,
            "fixture_L0_mm": rig.L0}
