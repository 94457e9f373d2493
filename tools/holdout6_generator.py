"""Hold-out set 6: raw four-point-bending tests made by a sceptical reviewer's machine.

An independent generator of raw testing-machine exports (time, stroke, force at one pressure per
file) for scoring bendpam's standard errors on data made in ways bendpam does not assume.  It
shares no code with bendpam's own simulators: from bendpam it takes only the truth's quasi-static
moment ``MomentLaw.moment``, the presets and the curvature limits.  The fixture (paper eq 6-8) is
written here from the paper, the testing machine, the loop laws, the instrument faults and the
export layouts are this module's own.

Truth
-----
``alpha0`` = preset + 0.4-0.8 deg, ``S = C10 + C01`` = preset x 0.95-1.05, ``shape = C01/S`` in
0.4-0.6; everything else from the preset, with the geometry changes of the case (``L0_mm``), which
:func:`start_actuator` also carries.

Fixture (paper section 2.2)
---------------------------
* eq 6  ``d tan b + (sec b - 1) c = ds``, ``c = t + 2r``.  Solved in closed form with the half-angle
  substitution ``q = tan(b/2)``: ``(2c + ds) q^2 + 2 d q - ds = 0``, whose admissible root is
  ``q = ds / (d + sqrt(d^2 + ds (2c + ds)))`` (no cancellation), so ``b = 2 atan(q)``.
* eq 7  ``M = F [d + c sin b] / (2 cos^2 b)`` (the "2 cos b^2" misprint read as cos^2, NOTES.md).
* eq 8  ``k' = 2 b / L0``.
d = 35 mm, r = 2.5 mm, t = 4 mm (paper).  :func:`check_fixture` compares eq 6 with a bracketed root.

The machine
-----------
The actuator is mounted straight (stroke 0), pressurised, held, then the crosshead releases it at a
detection speed until the machine's force reading falls to a detection load (0.05-0.5 N, per case;
the reading is the raw noisy force, so noise can stop it early, as on a real machine with a force
shut-off): that stroke is the free state.  It returns to the blocked state and cycles blocked ->
free -> blocked, with one of these stroke waveforms: a trapezoidal velocity profile (ramps with
accelerations), a haversine (sinusoidal) stroke, a cycloidal (jerk-limited) stroke, a triangular
one with different release/return speeds, and triangles with dwells at one or both ends.  Some
cases log the detection run, others log only the cycles (time then does not start at 0), one runs
an unlogged pre-cycle.  The physical signals are computed on the ADC's uniform clock; the logged
time may come from a PC clock (drift, jitter, ms rounding).

Measured moment = quasi-static ``M(P, k')`` of the truth - a loop term ``z`` (the law of the case,
driven by the plates' curvature history, positive while releasing so that the return branch lies
above the release branch and each cycle dissipates) + instrument effects.  ``loop_fraction`` is
``max|z| / M_blocked`` on a reference triangular cycle 0 -> k'_free -> 0 at the case's speed.

Loop laws (none of them a family of the earlier hold-out sets)
--------------------------------------------------------------
* ``dahl2``: Dahl's friction model with exponent i = 2, dz/dx = s |1 - z/A sgn x'|^2 sgn(...)
  (P.R. Dahl, "A solid friction model", Aerospace Corp. TOR-0158, 1968; "Solid friction damping of
  mechanical vibrations", AIAA J. 14, 1976).  Integrated in closed form along monotone stretches.
* ``berg``: Berg's smooth friction element for rubber components, f = f_s + dx (F - f_s) /
  (x2 (1 - f_s/F) + dx) after each reversal (M. Berg, "A non-linear rubber spring model for rail
  vehicle dynamics analysis", Vehicle System Dynamics 30, 1998).
* ``qlv-box``: Fung's quasi-linear viscoelasticity with the continuous box relaxation spectrum,
  G(t) = [1 + C (E1(t/t2) - E1(t/t1))]/[1 + C ln(t2/t1)] (Y.C. Fung, Biomechanics, 1981/1993),
  applied to the bladder's share of the moment (the part linear in C10, C01), discretised as a
  24-term log-spaced Prony series of the box spectrum.
* ``bergstrom-boyce``: Bergström-Boyce nonlinear viscoelastic network, flow rate
  g0 (|e_v| + xi)^-1 (|tau|/tau_b)^m with m = 4 (J.S. Bergström, M.C. Boyce, J. Mech. Phys.
  Solids 46, 1998), 1-D, backward Euler.
* ``chaboche``: elastic domain plus two Armstrong-Frederick backstresses,
  dX_i = C_i dp n - g_i X_i dp (P.J. Armstrong, C.O. Frederick, CEGB RD/B/N731, 1966;
  J.-L. Chaboche, Int. J. Plasticity 5, 1989): an elastic stretch after each reversal, then
  nonlinear kinematic hardening; return mapping.
* ``kp``: a Krasnosel'skii-Pokrovskii operator, 190 ramp hysterons with a Gaussian x exponential
  density over (centre, half-width) (M.A. Krasnosel'skii, A.V. Pokrovskii, Systems with
  Hysteresis, 1989; H.T. Banks, A.J. Kurdila, G. Webb, Math. Probl. Eng. 3, 1997), with the major
  loop's centre line removed.
* ``reid``: Reid's hysteretic (structural) damping, a friction-like term proportional to the
  distance from rest, z = h |x| w, w the direction, smoothed over a short reversal length
  (T.J. Reid, "Free vibration and hysteretic damping", J. R. Aero. Soc. 60, 1956): a loop pinched
  at the blocked end and open at the free end.
* ``jiles-atherton``: the Jiles-Atherton irreversible/reversible split with a Langevin
  anhysteretic and pinning k, adapted with the curvature as the field (D.C. Jiles, D.L. Atherton,
  J. Magn. Magn. Mater. 61, 1986); the output is the lag M_an - M.

Instrument and rig faults
-------------------------
* aliased mains hum: 50 Hz (+- grid deviation) sampled at 25 Hz aliases to ~0.01-0.04 Hz, inside
  the processing filter's pass band (H.W. Ott, Electromagnetic Compatibility Engineering, 2009).
* heteroscedastic force noise (standard deviation growing with the force, a strain-gauge
  amplifier's gain noise; ISO 376 / ASTM E4 verification practice), pink (1/f) noise (a Kellet-style
  sum of five AR(1) filters of one white noise), AR(1) noise, and a noise coloured by a 4 Hz fixture
  resonance (AR(2)) plus white noise.
* stroke zeroed off the straight state (reported stroke offset), stroke transducer quadratic
  nonlinearity, ball-screw periodic lead error (ISO 230-2 positioning error).
* roller friction: rolling/sliding resistance of the loading rollers proportional to the normal
  force, opposing the crosshead motion, F(1 - mu tanh(v/v0)).
* Kelvin-Voigt creep of the plate-roller contacts (3-D printed plates), which lets the actuator
  bend further than the crosshead says.
* bladder self-heating over the cycles: the bladder constants fall by up to 2 % (rubber's
  modulus against temperature in the 20-40 C range, heated by the loop's
  dissipation; exponential with a 400 s time constant).
* the force amplifier updates at 5 Hz while the controller logs at 20 Hz (zero-order hold).
* outlier spikes: isolated samples off by 5-15 % of the blocked force, about one per 1000 samples
  (electromagnetic interference from the valve and motor drives on the logged line; heavy-tailed
  errors, cf. Huber, Robust Statistics, 1981).  bendpam reads them without a warning (its spike
  check refuses only far larger ones).
* PC time base: a clock drifting by 150 ppm, +-3 ms jitter, time rounded to 1 ms, not starting at 0.
* linear load-cell offset drift (one case only, ``drift_fraction`` of the blocked force over the
  logged test).  The load cell was zeroed at the machine's start, before pressurising, so the drift
  runs from there: the logged test starts with an offset of the drift accumulated during the
  unlogged detection run and pre-cycle (``drift_offset_at_start_fraction`` in the returned tests),
  which a correction that takes the offset as zero at the first sample does not remove.
* self-weight of the actuator and plates (the paper, section 3.1, notes it near the free state):
  a moment m g l sin(b) and an untared constant force.
* plate pre-pitch: the plates sit 0.5 deg pitched at the machine's blocked state (assembly).
* pneumatic supply restriction: a needle valve/long line feeding the actuator's volume; the
  pressure lags the volume change, dP/dt = -dP/tau - (n P_abs/V) dV/dt with dV/dtheta from
  M_air = P dV/dtheta (paper eq 13), n = 1.2 (polytropic; J.F. Carneiro, F.G. de Almeida,
  Proc. IMechE I 220, 2006 on pneumatic chamber models).
* pressure gauge error: the file states the nominal pressure; the true one is off by a class 1.0
  gauge's error (+0.8 % + 0.8 kPa systematic, 0.4 kPa random per test, EN 837-1).
* cycle end rounded down to 0.5 mm from the detected free stroke (a lab setting the cycle limits by
  hand).

Exports (``dialect``): ``zwick-de`` (testXpert II, German names, tab, decimal comma, cp1252,
pressure in bar), ``zwick-en`` (testXpert, semicolons, decimal comma), ``bluehill`` (Instron
Bluehill 2, quoted cells, units row, compression negative), ``mts-ts`` (MTS TestSuite CSV, force
in kN), ``csv`` (plain), ``trapezium`` (Shimadzu Trapezium, Shift-JIS, Japanese names, pressure
only in the file name in MPa), ``instron-console`` (Key:<TAB>value<TAB>unit, absolute position
decreasing, time in ms, force in kN), ``mts-basic`` (MTS BasicTestWare space-aligned table).

``python tools/holdout6_generator.py OUT [SEED]`` writes one seed of every case into OUT/<case>/.
"""

from __future__ import annotations

import json
import math
import sys
import time as _time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy import optimize, signal

import bendpam
from bendpam import presets

__all__ = ["CASES", "Case6", "check_fixture", "generate_set", "start_actuator", "truth_actuator"]

D_MM, R_MM, T_MM = 35.0, 2.5, 4.0
C_MM = T_MM + 2.0 * R_MM


# ---------------------------------------------------------------------------------------------
# fixture, eq 6-8 (written from the paper)
# ---------------------------------------------------------------------------------------------
def beta_from_stroke(ds):
    """Plate pitch b (rad) from the stroke (mm) by eq 6, half-angle closed form (odd extension)."""
    s = np.asarray(ds, dtype=float)
    a = np.abs(s)
    q = a / (D_MM + np.sqrt(D_MM * D_MM + a * (2.0 * C_MM + a)))
    return np.sign(s) * 2.0 * np.arctan(q)


def stroke_from_beta(b):
    """Eq 6 evaluated directly (mm)."""
    b = np.asarray(b, dtype=float)
    ab = np.abs(b)
    return np.sign(b) * (D_MM * np.tan(ab) + (1.0 / np.cos(ab) - 1.0) * C_MM)


def lever_mm(b):
    """Moment per unit force, eq 7 with cos^2: [d + c sin b] / (2 cos^2 b) (mm)."""
    ab = np.abs(np.asarray(b, dtype=float))
    return (D_MM + C_MM * np.sin(ab)) / (2.0 * np.cos(ab) ** 2)


def check_fixture(n: int = 2000) -> float:
    """Max |b(closed form) - b(brentq on eq 6)| over strokes 0-60 mm (rad)."""
    worst = 0.0
    for ds in np.linspace(0.0, 60.0, n):
        ref = optimize.brentq(lambda b, ds=ds: float(stroke_from_beta(b)) - ds, -1e-12, 0.5 * math.pi - 1e-9,
                              xtol=1e-15, rtol=1e-15, maxiter=500) if ds > 0 else 0.0
        worst = max(worst, abs(float(beta_from_stroke(ds)) - ref))
    return worst


# ---------------------------------------------------------------------------------------------
# cases
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Case6:
    """One case: truth offsets, machine programme, loop law, noise, faults and export layout.

    The scorer's attributes: ``name, preset, model, pressures_kpa, loop, loop_fraction,
    noise_fraction`` (standard deviation / blocked force), ``noise_ar1, drift_fraction, dialect,
    cycles, rate_hz, shape``; the rest describe this generator's machine.
    """

    name: str
    preset: str
    model: str
    pressures_kpa: tuple
    loop: str
    loop_fraction: float
    noise_fraction: float
    noise_ar1: float
    drift_fraction: float
    dialect: str
    cycles: int
    rate_hz: float
    shape: float
    case_id: int
    alpha_shift_deg: float
    s_scale: float
    waveform: str  # trapvel | haversine | cycloid | tri-asym | tri-dwell | trap-hold-free
    speed_mm_min: float  # release speed (peak speed for haversine, mean for cycloid)
    return_speed_mm_min: float
    detect_speed_mm_min: float
    detect_load_n: float
    noise_kind: str  # white | hetero | pink | ar1 | resonance
    faults: tuple = ()
    L0_mm: float | None = None
    log_detection: bool = True
    dwell_s: float = 0.0
    precycle: bool = False
    loop_params: tuple = field(default_factory=tuple)
    stroke_noise_mm: float = 0.002

    @property
    def params(self) -> dict:
        return dict(self.loop_params)


CASES: dict[str, Case6] = {c.name: c for c in [
    Case6("h6-dahl2-hum", "be-pam", "energy", (100.0, 130.0, 160.0, 190.0, 220.0), "dahl2", 0.05, 0.012, 0.0, 0.0,
          "zwick-de", 4, 25.0, 0.45, 601, 0.55, 1.03, "trapvel", 40.0, 40.0, 20.0, 0.2, "hetero",
          ("mains-hum-aliased", "stroke-zero-offset", "time-offset"), loop_params=(("u_c", 0.12),)),
    Case6("h6-berg-roller", "bc-pam", "force_balance", (50.0, 80.0, 110.0, 140.0), "berg", 0.04, 0.015, 0.0, 0.0,
          "bluehill", 5, 10.0, 0.55, 602, 0.7, 0.96, "tri-dwell", 30.0, 30.0, 15.0, 0.1, "pink",
          ("roller-friction", "stroke-nonlinearity", "stroke-zero-offset"), log_detection=False, dwell_s=5.0,
          loop_params=(("u2", 0.06),)),
    Case6("h6-qlv-creep", "be-pam", "force_balance", (95.0, 125.0, 155.0, 185.0, 215.0), "qlv-box", 0.06, 0.010,
          0.85, 0.0, "mts-ts", 3, 100.0, 0.5, 603, 0.45, 1.01, "haversine", 90.0, 90.0, 30.0, 0.2, "ar1",
          ("contact-creep", "pc-clock"), L0_mm=150.0, loop_params=(("tau1", 0.5), ("tau2", 200.0), ("C", 0.6))),
    Case6("h6-bb-heating", "bc-pam", "energy", (60.0, 85.0, 110.0, 135.0), "bergstrom-boyce", 0.05, 0.010, 0.0, 0.0,
          "csv", 6, 20.0, 0.42, 604, 0.8, 1.04, "tri-asym", 30.0, 60.0, 20.0, 0.2, "white",
          ("bladder-heating", "force-zoh", "outlier-spikes"), log_detection=False,
          loop_params=(("mu", 15.0), ("xi", 0.05), ("m", 4.0))),
    Case6("h6-chaboche-drift", "be-pam", "energy", (90.0, 130.0, 170.0, 210.0), "chaboche", 0.04, 0.010, 0.6, 0.008,
          "zwick-en", 5, 20.0, 0.58, 605, 0.4, 0.97, "tri-dwell", 30.0, 30.0, 20.0, 0.5, "ar1",
          ("load-cell-drift", "lead-error", "precycle"), log_detection=False, dwell_s=2.0, precycle=True,
          loop_params=(("E", 40.0), ("sy", 0.25), ("C1", 10.0), ("g1", 20.0), ("C2", 2.5), ("g2", 5.0))),
    Case6("h6-kp-weight", "be-pam", "force_balance", (100.0, 140.0, 180.0, 220.0), "kp", 0.03, 0.020, 0.0, 0.0,
          "trapezium", 3, 5.0, 0.4, 606, 0.65, 0.95, "haversine", 30.0, 30.0, 20.0, 0.2, "hetero",
          ("self-weight", "plate-prepitch"), L0_mm=140.0, loop_params=(("a", 0.04),)),
    Case6("h6-reid-pneumatic", "bc-pam", "force_balance", (40.0, 60.0, 80.0, 100.0, 120.0), "reid", 0.03, 0.020,
          0.0, 0.0, "instron-console", 4, 50.0, 0.6, 607, 0.5, 1.0, "cycloid", 25.0, 25.0, 25.0, 0.2, "resonance",
          ("pneumatic-restriction", "time-ms"), loop_params=(("u_c", 0.05),)),
    Case6("h6-ja-gauge", "bc-pam", "energy", (55.0, 95.0, 135.0), "jiles-atherton", 0.07, 0.025, 0.0, 0.0,
          "mts-basic", 7, 25.0, 0.52, 608, 0.75, 0.99, "trap-hold-free", 50.0, 50.0, 25.0, 0.05, "pink",
          ("pressure-gauge-error", "cycle-end-rounded"), log_detection=False, dwell_s=10.0,
          loop_params=(("Ms", 1.0), ("a", 0.15), ("k", 0.1), ("c", 0.3), ("alpha", 0.05))),
]}


def _geometry(case: Case6) -> dict:
    return {} if case.L0_mm is None else {"L0_mm": float(case.L0_mm)}


def start_actuator(case: Case6):
    """The preset with the case's geometry changes (not the truth's constants)."""
    return presets.get(case.preset, case.model).replace(**_geometry(case))


def truth_actuator(case: Case6):
    base = presets.get(case.preset, case.model)
    S = (base.C10_kpa + base.C01_kpa) * case.s_scale
    return base.replace(alpha0_deg=base.alpha0_deg + case.alpha_shift_deg, C10_kpa=S * (1.0 - case.shape),
                        C01_kpa=S * case.shape, **_geometry(case))


# ---------------------------------------------------------------------------------------------
# quasi-static truth (magnitudes)
# ---------------------------------------------------------------------------------------------
class _Truth:
    def __init__(self, case: Case6):
        self.act = truth_actuator(case)
        self.sign = float(self.act.bend_sign)
        self.law = bendpam.MomentLaw.of(self.act, case.model)
        half = self.act.replace(C10_kpa=0.5 * self.act.C10_kpa, C01_kpa=0.5 * self.act.C01_kpa)
        self.law_half = bendpam.MomentLaw.of(half, case.model)
        lim = bendpam.curvature_limits(self.act)
        self.k_lim = 0.98 * (lim.k_max if self.sign > 0 else -lim.k_min)
        self.L0 = float(self.act.L0_mm)

    def m(self, P, k):
        """Quasi-static moment magnitude (N mm) at pressure P (kPa) and curvature magnitude k (1/mm)."""
        return self.sign * self.law.moment(P, self.sign * np.asarray(k, dtype=float))

    def bladder_slope(self, P, k):
        """dM/dlambda for (C10, C01) -> lambda (C10, C01); M is affine in lambda (checked)."""
        kk = self.sign * np.asarray(k, dtype=float)
        return 2.0 * self.sign * (self.law.moment(P, kk) - self.law_half.moment(P, kk))

    def dm_dp(self, P, k):
        return (self.m(np.asarray(P) + 5.0, k) - self.m(np.asarray(P) - 5.0, k)) / 10.0

    def k_free(self, P) -> float:
        grid = np.linspace(0.0, self.k_lim, 1500)
        m = self.m(P, grid)
        if not m[0] > 0:
            raise ValueError(f"moment at k'=0 is not positive at {P} kPa")
        idx = np.nonzero(m <= 0.0)[0]
        if idx.size == 0:
            raise ValueError(f"no free state within 98 % of the curvature limit at {P} kPa")
        i = int(idx[0])
        return optimize.brentq(lambda k: float(self.m(P, k)), grid[i - 1], grid[i], xtol=1e-14)


# ---------------------------------------------------------------------------------------------
# loop laws: z(t, k) shapes; the case scales them to loop_fraction * M_blocked
# ---------------------------------------------------------------------------------------------
def _segments(u):
    """Monotone stretches of u: list of (start, stop, direction); a flat step keeps the direction."""
    du = np.diff(u)
    d = np.sign(du)
    last = 1.0
    for i in range(d.size):  # carry the previous direction over flat steps
        if d[i] == 0.0:
            d[i] = last
        else:
            last = d[i]
    dirs = np.concatenate([[d[0] if d.size else 1.0], d])
    cut = np.nonzero(np.diff(dirs) != 0)[0] + 1
    starts = np.concatenate([[0], cut])
    stops = np.concatenate([cut, [u.size]])
    return [(int(a), int(b), float(dirs[a])) for a, b in zip(starts, stops, strict=True)]


def _law_dahl2(t, k, ctx, p):
    u = k / ctx["k_ref"]
    sig = 1.0 / p["u_c"]
    w = np.empty_like(u)
    w0, u0 = 0.0, u[0]
    for a, b, d in _segments(u):
        seg = u[a:b]
        if d > 0:
            w[a:b] = 1.0 - 1.0 / (1.0 / (1.0 - w0) + sig * (seg - u0))
        else:
            w[a:b] = -1.0 + 1.0 / (1.0 / (1.0 + w0) + sig * (u0 - seg))
        w0, u0 = float(w[b - 1]), float(u[b - 1])
    return w


def _law_berg(t, k, ctx, p):
    u = k / ctx["k_ref"]
    x2 = p["u2"]
    f = np.empty_like(u)
    fs, us = 0.0, u[0]
    for a, b, d in _segments(u):
        dx = np.abs(u[a:b] - us)
        if d > 0:
            f[a:b] = fs + dx * (1.0 - fs) / (x2 * (1.0 - fs) + dx + 1e-300)
        else:
            f[a:b] = fs - dx * (1.0 + fs) / (x2 * (1.0 + fs) + dx + 1e-300)
        fs, us = float(f[b - 1]), float(u[b - 1])
    return f


def _law_qlv(t, k, ctx, p):
    # elastic input: the bladder's share of the moment (resists bending), M_bl^e = -dM/dlambda
    e = -ctx["truth"].bladder_slope(ctx["P"], k)
    de = np.diff(e, prepend=e[0])
    dt = ctx["dt"]
    t1, t2, C = p["tau1"], p["tau2"], p["C"]
    lnt = np.linspace(math.log(t1), math.log(t2), 24)
    w = C * (lnt[1] - lnt[0]) * np.ones_like(lnt)
    w[[0, -1]] *= 0.5
    w /= 1.0 + C * math.log(t2 / t1)
    return prony(de, w, np.exp(lnt), dt)


def prony(de, weights, taus, dt):
    """A Prony series: the sum of Maxwell branches of weights ``weights`` and relaxation times ``taus`` driven by the
    input's increments ``de`` (one per sample, time step ``dt``), each an exact first-order filter for an input
    linear within a step (hold-outs 7 and 8 use it too)."""
    z = np.zeros_like(de)
    for wi, tau in zip(weights, taus, strict=True):
        a = math.exp(-dt / tau)
        bcoef = tau / dt * (1.0 - a)  # exact for a linear input within a step
        z += wi * signal.lfilter([bcoef], [1.0, -a], de)
    return z


def _law_bb(t, k, ctx, p):
    u = (k / ctx["k_ref"]).tolist()
    mu, xi, m = p["mu"], p["xi"], p["m"]
    g0 = 1.0 / ctx["t_half"]
    dt = ctx["dt"]
    out = np.zeros(len(u))
    tau, ev = 0.0, 0.0
    for i in range(1, len(u)):
        ts = tau + mu * (u[i] - u[i - 1])
        c = mu * dt * g0 / (abs(ev) + xi)
        # solve x + c |x|^m sgn x = ts, convex on each side: Newton from ts converges monotonically
        x = ts
        sg = 1.0 if ts >= 0 else -1.0
        ax = abs(ts)
        for _ in range(60):
            f = ax + c * ax**m - abs(ts)
            if f <= 1e-13 * (1.0 + abs(ts)):
                break
            ax -= f / (1.0 + c * m * ax ** (m - 1.0))
            ax = max(ax, 0.0)
        x = sg * ax
        ev += (ts - x) / mu
        tau = x
        out[i] = tau
    return out


def _law_chaboche(t, k, ctx, p):
    u = (k / ctx["k_ref"]).tolist()
    E, sy, C1, g1, C2, g2 = p["E"], p["sy"], p["C1"], p["g1"], p["C2"], p["g2"]
    out = np.zeros(len(u))
    s, X1, X2 = 0.0, 0.0, 0.0
    for i in range(1, len(u)):
        st = s + E * (u[i] - u[i - 1])
        r = st - X1 - X2
        if abs(r) > sy:
            n = 1.0 if r > 0 else -1.0
            dp = 0.0
            for _ in range(50):  # backward Euler: (st - E dp n - X1(dp) - X2(dp)) n = sy
                x1 = (X1 + C1 * dp * n) / (1.0 + g1 * dp)
                x2 = (X2 + C2 * dp * n) / (1.0 + g2 * dp)
                f = (st - E * dp * n - x1 - x2) * n - sy
                dx1 = (C1 * n - g1 * x1) / (1.0 + g1 * dp)
                dx2 = (C2 * n - g2 * x2) / (1.0 + g2 * dp)
                df = -E - (dx1 + dx2) * n
                step = f / df
                dp -= step
                if abs(step) < 1e-14:
                    break
            X1 = (X1 + C1 * dp * n) / (1.0 + g1 * dp)
            X2 = (X2 + C2 * dp * n) / (1.0 + g2 * dp)
            s = st - E * dp * n
        else:
            s = st
        out[i] = s
    return out


def _kp_hysterons(p):
    m, r = np.meshgrid(np.linspace(0.05, 0.95, 19), np.linspace(0.03, 0.45, 10), indexing="ij")
    m, r = m.ravel(), r.ravel()
    w = np.exp(-0.5 * ((m - 0.5) / 0.3) ** 2) * np.exp(-r / 0.15)
    return m + r, m - r, w / w.sum()  # up threshold, down threshold, weight


def _law_kp(t, k, ctx, p):
    v = k / ctx["k_free"]
    a = p["a"]
    up, dn, w = _kp_hysterons(p)

    def r_up(x):
        return -1.0 + 2.0 * np.clip((x[:, None] - up[None, :] + a) / a, 0.0, 1.0)

    def r_dn(x):
        return -1.0 + 2.0 * np.clip((x[:, None] - dn[None, :]) / a, 0.0, 1.0)

    y0 = -np.ones_like(up)
    out = np.empty_like(v)
    for s0, s1, d in _segments(v):
        y = np.maximum(y0[None, :], r_up(v[s0:s1])) if d > 0 else np.minimum(y0[None, :], r_dn(v[s0:s1]))
        out[s0:s1] = y @ w
        y0 = y[-1]
    centre = 0.5 * (r_up(v) + r_dn(v)) @ w  # the major loop's centre line
    return centre - out  # the output lags the input: as a moment term it opposes the motion


def _law_reid(t, k, ctx, p):
    u = k / ctx["k_ref"]
    uc = p["u_c"]
    w = np.empty_like(u)
    w0, u0 = 0.0, u[0]
    for a, b, d in _segments(u):
        seg = u[a:b]
        if d > 0:
            w[a:b] = 1.0 - (1.0 - w0) * np.exp(-(seg - u0) / uc)
        else:
            w[a:b] = -1.0 + (1.0 + w0) * np.exp(-(u0 - seg) / uc)
        w0, u0 = float(w[b - 1]), float(u[b - 1])
    return np.abs(u) * w


def _langevin(x):
    return 1.0 / math.tanh(x) - 1.0 / x if abs(x) > 1e-4 else x / 3.0


def _law_ja(t, k, ctx, p):
    H = (k / ctx["k_free"] - 0.5).tolist()
    Ms, a, kp, c, al = p["Ms"], p["a"], p["k"], p["c"], p["alpha"]
    Mirr = Ms * _langevin(H[0] / a)
    M = Mirr
    out = np.zeros(len(H))
    for i in range(1, len(H)):
        dH = H[i] - H[i - 1]
        nsub = 1 + int(abs(dH) / 0.002)
        h = dH / nsub
        for j in range(nsub):
            Hc = H[i - 1] + (j + 0.5) * h
            Man = Ms * _langevin((Hc + al * M) / a)
            d = 1.0 if h > 0 else -1.0
            diff = Man - Mirr
            if diff * d > 0:
                Mirr += h * diff / (d * kp - al * diff)
            M = c * Man + (1.0 - c) * Mirr
        Man = Ms * _langevin((H[i] + al * M) / a)
        out[i] = Man - M
    out[0] = 0.0
    return out


_LAWS = {"dahl2": _law_dahl2, "berg": _law_berg, "qlv-box": _law_qlv, "bergstrom-boyce": _law_bb,
         "chaboche": _law_chaboche, "kp": _law_kp, "reid": _law_reid, "jiles-atherton": _law_ja}


# ---------------------------------------------------------------------------------------------
# stroke programme
# ---------------------------------------------------------------------------------------------
def _profile(kind, x):
    if kind == "haversine":
        return 0.5 * (1.0 - np.cos(math.pi * x))
    if kind == "cycloid":
        return x - np.sin(2.0 * math.pi * x) / (2.0 * math.pi)
    if kind == "trapvel":  # trapezoidal velocity, accelerations over 10 % of the move at each end
        fa = 0.1
        vmax = 1.0 / (1.0 - fa)
        return np.where(x < fa, 0.5 * vmax / fa * x**2,
                        np.where(x > 1.0 - fa, 1.0 - 0.5 * vmax / fa * (1.0 - x) ** 2, vmax * (x - 0.5 * fa)))
    return x  # linear


def _move_time(kind, ds, speed_mm_s):
    if kind == "haversine":  # speed is the peak speed
        return math.pi * abs(ds) / (2.0 * speed_mm_s)
    if kind == "trapvel":  # speed is the plateau speed
        return abs(ds) / speed_mm_s / (1.0 / 0.9)
    return abs(ds) / speed_mm_s  # mean speed


class _Programme:
    def __init__(self):
        self.pieces = []  # (t0, T, s0, s1, kind)
        self.t = 0.0
        self.marks = {}

    def move(self, s0, s1, speed_mm_min, kind):
        T = _move_time(kind, s1 - s0, speed_mm_min / 60.0)
        self.pieces.append((self.t, T, s0, s1, kind))
        self.t += T

    def hold(self, s, T):
        if T > 0:
            self.pieces.append((self.t, T, s, s, "linear"))
            self.t += T

    def mark(self, name):
        self.marks[name] = self.t

    def sample(self, dt):
        n = math.floor(self.t / dt) + 1
        t = np.arange(n) * dt
        x = np.empty(n)
        starts = np.array([pc[0] for pc in self.pieces])
        idx = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(self.pieces) - 1)
        for j, (t0, T, s0, s1, kind) in enumerate(self.pieces):
            sel = idx == j
            if sel.any():
                xx = np.clip((t[sel] - t0) / T, 0.0, 1.0) if T > 0 else np.ones(int(sel.sum()))
                x[sel] = s0 + (s1 - s0) * _profile(kind, xx)
        return t, x


def _cycles(prog: _Programme, case: Case6, s_amp: float, n: int):
    for _ in range(n):
        if case.waveform == "tri-dwell":
            prog.move(0.0, s_amp, case.speed_mm_min, "linear")
            prog.hold(s_amp, case.dwell_s)
            prog.move(s_amp, 0.0, case.return_speed_mm_min, "linear")
            prog.hold(0.0, case.dwell_s)
        elif case.waveform == "trap-hold-free":
            prog.move(0.0, s_amp, case.speed_mm_min, "trapvel")
            prog.hold(s_amp, case.dwell_s)
            prog.move(s_amp, 0.0, case.return_speed_mm_min, "trapvel")
        elif case.waveform == "tri-asym":
            prog.move(0.0, s_amp, case.speed_mm_min, "linear")
            prog.move(s_amp, 0.0, case.return_speed_mm_min, "linear")
        else:
            prog.move(0.0, s_amp, case.speed_mm_min, case.waveform)
            prog.move(s_amp, 0.0, case.return_speed_mm_min, case.waveform)


# ---------------------------------------------------------------------------------------------
# noise (causal filters of white noise, so a prefix does not depend on the length)
# ---------------------------------------------------------------------------------------------
def _coloured(kind, white, white2, ar1, rate_hz):
    if kind in ("white", "hetero"):
        return white
    if kind == "ar1":
        y = signal.lfilter([math.sqrt(1.0 - ar1 * ar1)], [1.0, -ar1], white, zi=[ar1 * white[0]])[0]
        return y
    if kind == "pink":  # sum of AR(1) poles spread over decades (Kellet-style), unit variance
        poles = np.array([0.99886, 0.99332, 0.96900, 0.86650, 0.55000])
        gains = np.array([0.0555179, 0.0750759, 0.1538520, 0.3104856, 0.5329522])
        y = sum(g * signal.lfilter([1.0], [1.0, -a], white) for g, a in zip(gains, poles, strict=True))
        var = sum(gi * gj / (1.0 - ai * aj) for gi, ai in zip(gains, poles, strict=True)
                  for gj, aj in zip(gains, poles, strict=True))
        return y / math.sqrt(var)
    if kind == "resonance":  # 4 Hz fixture resonance (damping 0.08), half the variance, plus white
        w0 = 2.0 * math.pi * 4.0 / rate_hz
        r = math.exp(-0.08 * w0)
        a = [1.0, -2.0 * r * math.cos(w0), r * r]
        y = signal.lfilter([1.0], a, white)
        h = signal.lfilter([1.0], a, np.r_[1.0, np.zeros(4000)])
        y /= math.sqrt(float(np.sum(h * h)))
        return math.sqrt(0.5) * y + math.sqrt(0.5) * white2
    raise ValueError(kind)


# ---------------------------------------------------------------------------------------------
# the machine
# ---------------------------------------------------------------------------------------------
def _physics(case, ctx, t, x_act, noise, kappa):
    """Force (N, positive toward the blocked state) and plate curvature for a crosshead path."""
    tr: _Truth = ctx["truth"]
    faults = case.faults
    L0 = tr.L0
    b0 = math.radians(0.5) if "plate-prepitch" in faults else 0.0
    dt = ctx["dt"]
    x_pl = x_act
    lam = np.ones_like(t)
    if "bladder-heating" in faults:
        lam = 1.0 - 0.02 * (1.0 - np.exp(-t / 400.0))
    F = np.zeros_like(t)
    for _ in range(3 if "contact-creep" in faults else 1):
        beta = beta_from_stroke(x_pl) + b0
        k = 2.0 * beta / L0
        P = np.full_like(t, ctx["P"])
        if "pneumatic-restriction" in faults:
            dvdt = 1000.0 * tr.dm_dp(ctx["P"], k) * L0 * np.gradient(k, dt)  # mm^3/s
            g = 1.2 * (ctx["P"] + 101.325) / 50000.0 * dvdt  # kPa/s
            tau = 4.0
            a = math.exp(-dt / tau)
            P = P + signal.lfilter([1.0 - a], [1.0, -a], -tau * g)
        M = tr.m(P, k)
        if "bladder-heating" in faults:
            M = M + (lam - 1.0) * tr.bladder_slope(P, k)
        if kappa != 0.0:
            M = M - kappa * _LAWS[case.loop](t, k, ctx, case.params)
        if "self-weight" in faults:
            M = M - 0.05 * 9.81 * (L0 / 4.0) * np.sin(beta)
        F = M / lever_mm(beta)
        if "contact-creep" in faults:  # Kelvin-Voigt contacts, 150 N/mm, retardation 20 s
            a = math.exp(-dt / 20.0)
            x_pl = x_act + signal.lfilter([1.0 - a], [1.0, -a], F / 150.0)
    if "roller-friction" in faults:
        v = np.gradient(x_act, dt)
        F = F * (1.0 - 0.02 * np.tanh(v / 0.01))
    if "self-weight" in faults:
        F = F + 0.04
    sig = case.noise_fraction * ctx["F_b"]
    if case.noise_kind == "hetero":
        F = F + sig * (0.3 + 0.7 * np.abs(F) / ctx["F_b"]) / 0.65 * noise[: t.size]
    else:
        F = F + sig * noise[: t.size]
    if "mains-hum-aliased" in faults:
        F = F + 0.02 * np.sin(2.0 * math.pi * ctx["f_hum"] * t + ctx["hum_phase"])
    if case.drift_fraction:
        F = F + ctx["drift_rate"] * t
    return F, k


def _alias(f, fs):
    """Apparent frequency of a tone f sampled at fs (Hz)."""
    return abs(f - round(f / fs) * fs)


def _controller_stop(F, start, load):
    below = np.nonzero(F[start:] <= load)[0]
    return None if below.size == 0 else start + int(below[0])


def _simulate(case: Case6, tr: _Truth, P_nom: float, k_ref: float, rng) -> dict:
    faults = case.faults
    P = P_nom
    if "pressure-gauge-error" in faults:
        P = P_nom * 1.008 + 0.8 + 0.4 * float(rng.standard_normal())
    dt = 1.0 / case.rate_hz
    kf = tr.k_free(P)
    M_b = float(tr.m(P, 0.0))
    F_b = M_b / float(lever_mm(0.0))
    s_free = float(stroke_from_beta(0.5 * kf * tr.L0))
    t_half = _move_time("linear", s_free, case.speed_mm_min / 60.0)
    ctx = {"truth": tr, "P": P, "k_ref": k_ref, "k_free": kf, "dt": dt, "t_half": t_half, "F_b": F_b,
           "f_hum": _alias(50.0 + 0.02 * float(np.clip(rng.standard_normal(), -2, 2)), case.rate_hz)
           if "mains-hum-aliased" in faults else 0.0,
           "hum_phase": float(rng.uniform(0, 2 * math.pi))}
    # loop scale: max|z| = loop_fraction * M_b on a reference triangle 0 -> k_free -> 0 (x2)
    tref = np.arange(0.0, 4.0 * t_half, dt)
    kref = kf * (1.0 - np.abs(((tref / t_half) % 2.0) - 1.0))
    zref = _LAWS[case.loop](tref, kref, dict(ctx), case.params)
    kappa = case.loop_fraction * M_b / float(np.max(np.abs(zref)))
    # planned duration (for the drift rate): pre, cycles at the quasi-static free stroke
    plan = _Programme()
    _cycles(plan, case, s_free, case.cycles)
    T_est = plan.t
    ctx["drift_rate"] = case.drift_fraction * F_b / T_est
    pre = 5.0
    s_cap = float(stroke_from_beta(0.5 * min(1.25 * kf, tr.k_lim) * tr.L0))
    nbig = int((pre + 2 * s_cap / (case.detect_speed_mm_min / 60.0) + 3 * T_est + 60.0) / dt) + 1000
    white = rng.standard_normal((2, nbig))
    noise = _coloured(case.noise_kind, white[0], white[1], case.noise_ar1, case.rate_hz)
    stroke_noise = case.stroke_noise_mm * rng.standard_normal(nbig)
    spikes = rng.uniform(size=(3, nbig)) if "outlier-spikes" in faults else None
    # pass 1: pressurised hold, then release at the detection speed until the force reading <= load;
    # pass 2: the whole test.  With a drift, its rate is set from the logged duration, which depends
    # on the detected stroke: repeat until the detection no longer changes (once or twice).
    p1 = _Programme()
    p1.hold(0.0, pre)
    p1.move(0.0, s_cap, case.detect_speed_mm_min, "linear")
    t1, x1 = p1.sample(dt)
    last = None
    for _ in range(4):
        F1, _ = _physics(case, ctx, t1, x1, noise, kappa)
        i_stop = _controller_stop(F1, int(pre / dt), case.detect_load_n)
        if i_stop is None:
            raise RuntimeError(f"{case.name} {P_nom} kPa: detection load never reached")
        s_det = float(x1[i_stop])
        s_amp = math.floor(s_det / 0.5) * 0.5 if "cycle-end-rounded" in faults else s_det
        prog = _Programme()
        prog.hold(0.0, pre)
        prog.move(0.0, s_det, case.detect_speed_mm_min, "linear")
        prog.hold(s_det, 2.0)
        prog.move(s_det, 0.0, case.return_speed_mm_min, "linear")
        prog.hold(0.0, 3.0)
        if case.precycle:
            _cycles(prog, case, s_amp, 1)
            prog.hold(0.0, 2.0)
        prog.mark("cycles")
        _cycles(prog, case, s_amp, case.cycles)
        prog.hold(0.0, 1.0)
        t, x = prog.sample(dt)
        i0 = 0 if case.log_detection else math.ceil(prog.marks["cycles"] / dt)
        if not case.drift_fraction or i_stop == last:
            break
        last = i_stop
        ctx["drift_rate"] = case.drift_fraction * F_b / float(t[-1] - t[i0])
    F, k = _physics(case, ctx, t, x, noise, kappa)
    if not np.all(k < tr.k_lim):
        raise RuntimeError(f"{case.name} {P_nom} kPa: curvature beyond 98 % of the limit")
    if "force-zoh" in faults:  # amplifier updates at 5 Hz, controller logs at rate_hz
        m = max(1, round(case.rate_hz / 5.0))
        F = F[(np.arange(F.size) // m) * m]
    if "outlier-spikes" in faults:  # EMI on the logged line: isolated samples, 5-15 % of F_b, ~1 per 1000
        hit = spikes[0, : F.size] < 1e-3
        F = F + hit * np.sign(spikes[1, : F.size] - 0.5) * (0.05 + 0.1 * spikes[2, : F.size]) * F_b
    # reported stroke
    xr = x + stroke_noise[: x.size]
    if "stroke-nonlinearity" in faults:
        xr = xr + 0.004 * x**2 / 25.0
    if "lead-error" in faults:
        xr = xr + 0.015 * np.sin(2.0 * math.pi * x / 5.0 + ctx["hum_phase"])
    if "stroke-zero-offset" in faults:
        xr = xr + (0.3 if case.preset == "be-pam" else -0.2)
    t_log = t.copy()
    if "pc-clock" in faults:
        jit = rng.uniform(-0.003, 0.003, t.size)
        t_log = np.round(t * (1.0 + 150e-6) + jit, 3)
        t_log = np.maximum.accumulate(t_log + np.arange(t.size) * 1e-9)
    t_log, xr, F = t_log[i0:], xr[i0:], F[i0:]
    if "time-offset" in faults or "pc-clock" in faults or not case.log_detection:
        t_log = t_log + (3.217 if "pc-clock" in faults else (12.35 if case.log_detection else 0.0))
    else:
        t_log = t_log - t_log[0]
    logged_T = float(t_log[-1] - t_log[0])
    return {"time_s": t_log, "stroke_mm": xr, "force_n": F, "P_true": P, "k_free": kf, "s_det": s_det,
            "s_amp": s_amp, "M_b": M_b, "F_b": F_b,
            "drift_over_test_fraction": ctx["drift_rate"] * logged_T / F_b,
            "drift_offset_at_start_fraction": ctx["drift_rate"] * float(t[i0]) / F_b}


# ---------------------------------------------------------------------------------------------
# exports
# ---------------------------------------------------------------------------------------------
def _fmt(v, nd, comma=False):
    s = f"{v:.{nd}f}"
    return s.replace(".", ",") if comma else s


def _write(case: Case6, P_nom: float, sim: dict, folder: Path, rep: int) -> str:
    t, x, F = sim["time_s"], sim["stroke_mm"], sim["force_n"]
    d = case.dialect
    tag = f"{P_nom:g}kPa"
    if d == "zwick-de":
        name = f"{case.name}_{tag}.txt"
        lines = ['"testXpert II - Export der Messwerte"', '"Prüfer"\t"Labor 2"\t""',
                 f'"Druck"\t{_fmt(P_nom / 100.0, 2, True)}\t"bar"',
                 f'"Prüfgeschwindigkeit"\t{case.speed_mm_min:g}\t"mm/min"',
                 f'"Abschaltkraft"\t{_fmt(case.detect_load_n, 2, True)}\t"N"', "",
                 '"Prüfzeit"\t"Standardweg"\t"Standardkraft"', '"s"\t"mm"\t"N"']
        lines += [f"{_fmt(a, 2, True)}\t{_fmt(b, 4, True)}\t{_fmt(c, 4, True)}"
                  for a, b, c in zip(t, x, F, strict=True)]
        (folder / name).write_bytes(("\r\n".join(lines) + "\r\n").encode("cp1252"))
    elif d == "zwick-en":
        name = f"{case.name}_{tag}.txt"
        lines = ["$testXpert II ASCII export", f"Pressure;{P_nom:g};kPa", f"Test speed;{case.speed_mm_min:g};mm/min",
                 f"Pre-load;{_fmt(case.detect_load_n, 2, True)};N", "", "Test time;Standard travel;Standard force",
                 "s;mm;N"]
        lines += [f"{_fmt(a, 2, True)};{_fmt(b, 4, True)};{_fmt(c, 4, True)}" for a, b, c in zip(t, x, F, strict=True)]
        (folder / name).write_bytes(("\r\n".join(lines) + "\r\n").encode("cp1252"))
    elif d == "bluehill":
        name = f"{case.name}_specimen{rep}.csv"
        lines = ['"Sample : Name","BC-PAM bend",', f'Test : Pressure,"{P_nom:g}",kPa',
                 f'Test : Rate 1,"{case.speed_mm_min:g}",mm/min', "",
                 '"Time","Extension","Load"', '"(s)","(mm)","(N)"']
        lines += [f'"{a:.3f}","{b:.4f}","{-c:.4f}"' for a, b, c in zip(t, x, F, strict=True)]
        (folder / name).write_text("\n".join(lines) + "\n", encoding="utf-8")
    elif d == "mts-ts":
        name = f"{case.name}_{tag}.csv"
        lines = [f"Test Run Name,{case.name}_{tag},", f"Pressure,{P_nom:g},kPa",
                 f"Data Acquisition Rate,{case.rate_hz:g},Hz", "", '"Time","Crosshead","Force"', '"sec","mm","kN"']
        lines += [f"{a:.3f},{b:.4f},{c / 1000.0:.8f}" for a, b, c in zip(t, x, F, strict=True)]
        (folder / name).write_text("\n".join(lines) + "\n", encoding="utf-8")
    elif d == "csv":
        name = f"{case.name}_{tag}.csv"
        lines = [f"# Pressure: {P_nom:g} kPa", f"# rate: {case.rate_hz:g} Hz", "time_s,stroke_mm,force_n"]
        lines += [f"{a:.3f},{b:.4f},{c:.4f}" for a, b, c in zip(t, x, F, strict=True)]
        (folder / name).write_text("\n".join(lines) + "\n", encoding="utf-8")
    elif d == "trapezium":
        name = f"{case.name}_{P_nom / 1000.0:.2f}MPa.csv"
        lines = ['"試験名","PAM 四点曲げ"', f'"試験速度","{case.speed_mm_min:g}","mm/min"', "",
                 '"時間","ストローク","試験力"', '"sec","mm","N"']
        lines += [f"{a:.2f},{b:.4f},{c:.4f}" for a, b, c in zip(t, x, F, strict=True)]
        (folder / name).write_bytes(("\r\n".join(lines) + "\r\n").encode("shift_jis"))
    elif d == "instron-console":
        name = f"{case.name}_{tag}.txt"
        pos0 = 112.5
        lines = [f"Pressure:\t{P_nom:g}\tkPa", f"Rate:\t{case.speed_mm_min:g}\tmm/min", "Operator:\tlab\t", "",
                 "Time\tPosition\tLoad", "ms\tmm\tkN"]
        lines += [f"{a * 1000.0:.0f}\t{pos0 - b:.4f}\t{-c / 1000.0:.8f}" for a, b, c in zip(t, x, F, strict=True)]
        (folder / name).write_text("\n".join(lines) + "\n", encoding="utf-8")
    elif d == "mts-basic":
        name = f"{case.name}_{tag}.dat"
        lines = [f"Pressure : {P_nom:g} kPa", "Station Name : bend4pt", "",
                 f"{'Time':>12}  {'Ch 1 Displacement':>18}  {'Ch 1 Force':>12}",
                 f"{'Sec':>12}  {'mm':>18}  {'N':>12}"]
        lines += [f"{a:12.3f}  {b:18.4f}  {c:12.4f}" for a, b, c in zip(t, x, F, strict=True)]
        (folder / name).write_text("\n".join(lines) + "\n", encoding="utf-8")
    else:
        raise ValueError(d)
    return name


# ---------------------------------------------------------------------------------------------
# public entry points
# ---------------------------------------------------------------------------------------------
def _k_ref(case: Case6, tr: _Truth) -> float:
    return tr.k_free(float(np.median(case.pressures_kpa)))


def generate_set(case: Case6, seed: int, folder) -> dict:
    """Write one raw machine file per pressure into ``folder``; returns the truth and the file names."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng([int(seed), case.case_id])
    tr = _Truth(case)
    k_ref = _k_ref(case, tr)
    files, tests = [], []
    for i, P in enumerate(case.pressures_kpa):
        sim = _simulate(case, tr, float(P), k_ref, rng)
        files.append(_write(case, float(P), sim, folder, i + 1))
        tests.append({"pressure_kpa": float(P), "true_pressure_kpa": sim["P_true"], "samples": int(sim["time_s"].size),
                      "free_curvature_per_mm": sim["k_free"], "detected_stroke_mm": sim["s_det"],
                      "cycle_stroke_mm": sim["s_amp"], "blocked_moment_nmm": sim["M_b"],
                      "drift_over_test_fraction": sim["drift_over_test_fraction"],
                      "drift_offset_at_start_fraction": sim["drift_offset_at_start_fraction"]})
    act = tr.act
    return {"case": case.name, "seed": int(seed), "alpha0_deg": float(act.alpha0_deg),
            "shear_modulus_kpa": 2.0 * float(act.C10_kpa + act.C01_kpa), "shape": float(case.shape),
            "files": files, "fixture_L0_mm": float(act.L0_mm), "tests": tests}


def check_clean_machine(case: Case6, seed: int = 0) -> float:
    """Check 2: the machine without loop, noise or faults; its (stroke, force) converted back by eq 6-8.

    Returns the largest |M_back - M_law| / M_blocked over every sample of every pressure.
    """
    import dataclasses

    clean = dataclasses.replace(case, loop_fraction=0.0, noise_fraction=0.0, drift_fraction=0.0, faults=(),
                                stroke_noise_mm=0.0)
    tr = _Truth(clean)
    rng = np.random.default_rng([seed, case.case_id])
    worst = 0.0
    for P in clean.pressures_kpa:
        sim = _simulate(clean, tr, float(P), _k_ref(clean, tr), rng)
        beta = beta_from_stroke(sim["stroke_mm"])
        k = 2.0 * beta / tr.L0
        m_back = sim["force_n"] * lever_mm(beta)
        m_law = tr.sign * tr.law.moment(float(P), tr.sign * k)
        worst = max(worst, float(np.max(np.abs(m_back - m_law))) / sim["M_b"])
    return worst


def write_all(cases: dict, generate, argv, script: str) -> int:
    """``script OUT_FOLDER [SEED]``: one seed of every case of ``cases`` (``generate(case, seed, folder)``) and
    ``truth.json``; the command line of this generator and of those built on its machine."""
    if not argv:
        print(f"usage: python tools/{script} OUT_FOLDER [SEED]")
        return 2
    out = Path(argv[0])
    seed = int(argv[1]) if len(argv) > 1 else 0
    truths = {}
    for name, case in cases.items():
        t0 = _time.perf_counter()
        truths[name] = generate(case, seed, out / name)
        print(f"{name}: {len(truths[name]['files'])} files in {_time.perf_counter() - t0:.2f} s")
    (out / "truth.json").write_text(json.dumps(truths, indent=1), encoding="utf-8")
    return 0


def main(argv=None) -> int:
    return write_all(CASES, generate_set, sys.argv[1:] if argv is None else argv, "holdout6_generator.py")


if __name__ == "__main__":
    raise SystemExit(main())
