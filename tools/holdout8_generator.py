"""Hold-out set 8: raw four-point-bending tests with common loop laws and a lab's instrument faults.

A third independent generator of raw testing-machine exports (time, stroke, force at one pressure
per file) for scoring whether bendpam's standard errors hold on data it has never seen.  Like
:mod:`holdout7_generator` it reuses :mod:`holdout6_generator` (an earlier independent generator)
for everything but the loop laws, the instrument faults and the cases: the truth (``MomentLaw``
of the preset with alpha0 + 0.4-0.8 deg, ``S`` x 0.95-1.05, ``shape = C01/S`` in 0.4-0.6), the
fixture (paper eq 6-8), the machine (pressurised hold, detection of the free state at a detection
load, the stroke waveforms, the clocks), the noise filters and the export writers (dialects).
As in hold-out 7, the controller's force shut-off reads a causal 1 s moving average of the force.

Measured moment = quasi-static ``M(P, k')`` of the truth - ``kappa z`` + instrument effects, ``z``
the loop law of the case driven by ``u = k'/k'_ref`` (``k'_ref`` the free curvature at the median
pressure) and, for the rate-dependent laws, by time in units of ``t_half`` (the time of a release
stroke at the case's speed); ``z`` is positive while releasing (``k'`` increasing), so each cycle
dissipates.  ``kappa`` sets ``max|z| = loop_fraction x M_blocked`` on a reference triangle
0 -> k'_free -> 0 (twice), as in hold-out 6.  The loop half-width (half the gap between the
return and the release branch, averaged over the middle 80 % of the stroke) is 2-6 % of the
blocked moment for every law (:func:`check_laws`).

Loop laws (``z(t, k, ctx, params)``, one small function each)
-------------------------------------------------------------
* ``stribeck``: static Coulomb + viscous friction with the Stribeck dip, driven by the rate
  ``v = du/d(t/t_half)``: ``z = [Fc + (Fs - Fc) exp(-|v/vs|^delta)] tanh(v/v_eps) + sigma2 v``
  (R. Stribeck, "Die wesentlichen Eigenschaften der Gleit- und Rollenlager", Z. VDI 46, 1902;
  B. Armstrong-Hélouvry, P. Dupont, C. Canudas de Wit, "A survey of models, analysis tools and
  compensation methods for the control of machines with friction", Automatica 30, 1083-1138,
  1994); the sign is smoothed over ``v_eps`` (the usual regularisation of the Coulomb jump).
* ``lugre``: the LuGre dynamic friction model, ``dz/dt = v - sigma0 |v| z / g(v)``,
  ``F = sigma0 z + sigma1 dz/dt + sigma2 v`` with the Stribeck curve ``g`` (C. Canudas de Wit,
  H. Olsson, K.J. Åström, P. Lischinsky, "A new model for control of systems with friction",
  IEEE Trans. Autom. Control 40, 419-425, 1995); driven by time, the bristle state is updated
  exactly for a step of constant rate.
* ``wiechert``: a generalised Maxwell (Wiechert) body, three branches with relaxation times
  0.1, 0.3 and 0.8 t_half (E. Wiechert, "Gesetze der elastischen Nachwirkung für constante
  Temperatur", Ann. Phys. 286, 1893; C. Zener, Elasticity and Anelasticity of Metals, 1948);
  linear viscoelastic, exact for a piecewise-linear input.
* ``bouc-wen``: the Bouc-Wen model with n = 2 and beta:gamma = 3:1 (softening, fat loop),
  ``dz/du = A - beta sgn(du) |z|^(n-1) z - gamma |z|^n`` (R. Bouc, "Forced vibration of
  mechanical systems with hysteresis", Proc. 4th Conf. Nonlinear Oscillation, Prague, 1967;
  Y.K. Wen, "Method for random vibration of hysteretic systems", J. Eng. Mech. Div. ASCE 102,
  249-263, 1976); rate independent, midpoint rule in u.
* ``maxwell-slip``: an Iwan / Maxwell-slip parallel bank of 16 elastic-perfectly-slipping
  elements (spring in series with a Coulomb slider) whose slip deflections follow a log-normal
  distribution (median 0.06, sigma_ln 0.6) (W.D. Iwan, "A distributed-element model for
  hysteresis and its steady-state dynamic response", J. Appl. Mech. 33, 893-900, 1966); rate
  independent, Masing loops.
* ``preisach``: the classical Preisach operator, 97 x 24 relays over (interaction centre,
  coercive half-width), density Gaussian in the centre and log-normal in the half-width
  (F. Preisach, "Über die magnetische Nachwirkung", Z. Phys. 94, 277-302, 1935;
  I.D. Mayergoyz, Mathematical Models of Hysteresis, 1991); the output's single-valued centre
  (each relay's ramp between its switching thresholds) is removed.
* ``gpi-asym``: a generalised Prandtl-Ishlinskii operator, a weighted sum of 12 generalised play
  operators ``y = max(gamma_l(u) - r, min(gamma_r(u) + r, y_prev))`` whose loading and
  unloading envelopes differ: ``gamma_l(u) = tanh(a_l u)/a_l``, ``gamma_r(u) = tanh(a_r u)/a_r``
  with a_l = 0.9, a_r = 0.2 (M. Al Janaideh, S. Rakheja, C.-Y. Su, "An analytical generalized
  Prandtl-Ishlinskii model inversion for hysteresis compensation in micropositioning control",
  IEEE/ASME Trans. Mechatronics 16, 734-744, 2011); ``z = (gamma_l + gamma_r)/2 - Y``.  The loop
  widens toward the free end and its loading and unloading corners differ.
* ``duhem-hardening``: a Duhem-type (Coleman-Hodgdon) rate-independent law,
  ``dz/du = g0 + alpha (f(u) - z) sgn(du)`` with the non-saturating, stiffening anhysteretic
  ``f(u) = h1 u + h3 u^3`` (P. Duhem, "Die dauernden Aenderungen und die Thermodynamik",
  Z. Phys. Chem. 22, 1897; B.D. Coleman, M.L. Hodgdon, "A constitutive relation for
  rate-independent hysteresis in ferromagnetically soft materials", Int. J. Eng. Sci. 24,
  897-919, 1986; J.W. Macki, P. Nistri, P. Zecca, "Mathematical models for hysteresis", SIAM
  Rev. 35, 94-123, 1993).  The branches follow ``f(u) +- (g0 - f'(u))/alpha``: they keep
  rising (hardening) instead of saturating, so ``z`` carries a single-valued part ``f(u)``
  besides the loop (about 0.15 of max|z| ... 0.75 of max|z| at the free end, by design).

Instrument faults (each in one case; the rest of the lab is careful: pressure as declared, no
self-weight, no rig faults)
---------------------------------------------------------------------------------------------
* ``load-cell-tare``: a constant force offset from the first sample, the load cell tared with the
  fixture hanging differently (the lower plates' weight partly carried by the actuator at tare).
  The offset is a fixed force in N for the whole case (the same fixture), ``tare_fraction`` x the
  blocked force at the case's median pressure; each test's share of its own blocked force
  (1-3 %) is in the returned tests (``tare_fraction_of_blocked``).  The controller's shut-off reads
  the offset reading, so the detected free stroke shifts with it.
* ``load-cell-warmup``: the thermal warm-up of a strain-gauge load cell and its amplifier after the
  bridge excitation is switched on, an offset ``D (1 - exp(-t/tau))`` (a first-order thermal time
  constant; cf. the zero-drift/warm-up requirements of OIML R 60 and ISO 376), ``tau`` one cycle of
  the test (its free stroke at the case's speeds), ``D = warmup_fraction`` x each test's blocked
  force (the amplifier range is set per test).  That case logs from the machine's start, so the
  drift starts at the log's first sample.
* ``offset-wander``: a slow sinusoidal load-cell offset from the room's temperature cycling (an air
  conditioner's on/off cycle), amplitude ``wander_fraction`` x each test's blocked force, period
  ``wander_periods`` x the test's planned length (its actual ratio to the logged length is in
  the returned tests), a random phase per test (the test's own random stream).
* ``stroke-zero-pitch``: the crosshead's stroke zero was set with the plates pitched by
  ``pitch_deg`` toward bending, so the logged stroke is the true stroke minus eq 6 at that pitch
  (0.1-0.3 mm); the machine itself moves between the true straight state and the detected free
  state, only the logged stroke is offset (negative at the blocked state).
* ``force-quantised``: the force reading is quantised to a step of ``quant_fraction`` x each test's
  blocked force (a 12-bit-like converter on a range set per test), with white noise below one step
  (``noise_fraction`` < ``quant_fraction``; the total error's standard deviation, noise and
  quantisation together, is ~0.5 % of the blocked force).  The controller reads the quantised force.

Force noise otherwise as hold-out 6 (white, AR(1), pink; 0.5-3 % of the blocked force), 2 um stroke
noise, 3-5 cycles, sampling at 10-50 Hz.  ``drift_fraction`` (hold-out 6's linear drift) is 0 in
every case.

``python tools/holdout8_generator.py OUT [SEED]`` writes one seed of every case into OUT/<case>/;
``python tools/holdout8_generator.py --check`` prints the laws' periodicity/dissipation table and
the clean machine's loop table.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path
from unittest import mock

import numpy as np

if str(Path(__file__).resolve().parent) not in sys.path:
    sys.path.insert(0, str(Path(__file__).resolve().parent))
from holdout7_generator import averaged_stop, h6, midpoint_in_u, reference_cycles

__all__ = ["CASES", "Case8", "check_laws", "check_machine", "generate_set", "start_actuator", "truth_actuator"]


# ---------------------------------------------------------------------------------------------
# loop laws: z(t, k, ctx, params), positive while k increases; scaled by the machine
# ---------------------------------------------------------------------------------------------
def _rate(u, ctx):
    """du/d(t/t_half): central differences (one-sided at the ends)."""
    if u.size < 2:
        return np.zeros_like(u)
    return np.gradient(u, ctx["dt"]) * ctx["t_half"]


def _stribeck_curve(v, p):
    return p["Fc"] + (p["Fs"] - p["Fc"]) * np.exp(-np.abs(v / p["vs"]) ** p["delta"])


def _law_stribeck(t, k, ctx, p):
    v = _rate(k / ctx["k_ref"], ctx)
    return _stribeck_curve(v, p) * np.tanh(v / p["v_eps"]) + p["sigma2"] * v


def _law_lugre(t, k, ctx, p):
    u = (k / ctx["k_ref"]).tolist()
    s0, s1, s2 = p["sigma0"], p["sigma1"], p["sigma2"]
    dtau = ctx["dt"] / ctx["t_half"]
    out = np.zeros(len(u))
    z = 0.0
    for i in range(1, len(u)):
        du = u[i] - u[i - 1]
        v = du / dtau
        if du != 0.0:  # exact for a step of constant rate: dz/du = 1 - sigma0 z sgn(du) / g(v)
            g = float(_stribeck_curve(v, p))
            zss = math.copysign(g / s0, du)
            zn = zss + (z - zss) * math.exp(-s0 * abs(du) / g)
        else:
            zn = z
        out[i] = s0 * zn + s1 * (zn - z) / dtau + s2 * v
        z = zn
    return out


def _law_wiechert(t, k, ctx, p):
    u = k / ctx["k_ref"]
    du = np.diff(u, prepend=u[0])
    return h6.prony(du, p["weights"], [c * ctx["t_half"] for c in p["taus"]], ctx["dt"])


def _law_bouc_wen(t, k, ctx, p):
    u = (k / ctx["k_ref"]).tolist()
    n, A = p["n"], p["A"]
    beta, gamma = p["beta_share"] * p["beta_plus_gamma"], (1.0 - p["beta_share"]) * p["beta_plus_gamma"]
    hmax = 0.002

    def rate(z, x, s):
        az = abs(z)
        return A - beta * s * az ** (n - 1.0) * z - gamma * az**n

    return midpoint_in_u(u, rate, hmax)


def _law_maxwell_slip(t, k, ctx, p):
    u = k / ctx["k_ref"]
    N = int(p["n"])
    q = (np.arange(N) + 0.5) / N
    from scipy.stats import norm

    d = p["median"] * np.exp(p["sigma_ln"] * norm.ppf(q))  # slip deflections, log-normal quantiles
    s = np.zeros(N)
    out = np.empty_like(u)
    for a, b, _ in h6._segments(u):  # along a monotone stretch each spring follows clip(s0 + du)
        du = u[a:b] - (u[a - 1] if a else u[0])
        y = np.clip(s[None, :] + du[:, None], -d[None, :], d[None, :])
        out[a:b] = y.mean(axis=1)
        s = y[-1]
    return out


def _preisach_relays(p):
    hi, hc = np.meshgrid(np.linspace(-0.1, 1.1, 97), np.geomspace(0.01, 0.4, 24), indexing="ij")
    hi, hc = hi.ravel(), hc.ravel()
    w = np.exp(-0.5 * ((hi - 0.5) / p["centre_sd"]) ** 2)
    w = w * np.exp(-0.5 * (np.log(hc / p["hc_median"]) / p["hc_sigma_ln"]) ** 2)
    return hi + hc, hi - hc, w / w.sum()  # up threshold, down threshold, weight


def _law_preisach(t, k, ctx, p):
    u = k / ctx["k_ref"]
    up, dn, w = _preisach_relays(p)
    state = np.where(up <= u[0], 1.0, -1.0)  # history: rising from negative saturation to u[0]
    out = np.empty_like(u)
    for a, b, d in h6._segments(u):
        for c0 in range(a, b, 1000):  # chunks bound the memory
            c1 = min(b, c0 + 1000)
            seg = u[c0:c1]
            if d > 0:
                y = np.where(np.maximum.accumulate(seg)[:, None] >= up[None, :], 1.0, state[None, :])
            else:
                y = np.where(np.minimum.accumulate(seg)[:, None] <= dn[None, :], -1.0, state[None, :])
            out[c0:c1] = y @ w
            state = y[-1]
    centre = np.clip(2.0 * (u[:, None] - dn[None, :]) / (up - dn)[None, :] - 1.0, -1.0, 1.0) @ w
    return centre - out


def _gpi_env(u, a):
    return np.tanh(a * u) / a


def _law_gpi(t, k, ctx, p):
    u = k / ctx["k_ref"]
    r = np.linspace(p["r_min"], p["r_max"], 12)
    w = np.exp(-r / p["r_scale"])
    w /= w.sum()
    gl, gr = _gpi_env(u, p["a_l"]), _gpi_env(u, p["a_r"])
    y0 = np.clip(0.0, gl[0] - r, gr[0] + r)
    out = np.empty_like(u)
    for a, b, d in h6._segments(u):
        if d > 0:  # loading: the play's output is pushed up by gamma_l - r
            y = np.maximum(y0[None, :], gl[a:b, None] - r[None, :])
        else:  # unloading: pushed down by gamma_r + r
            y = np.minimum(y0[None, :], gr[a:b, None] + r[None, :])
        out[a:b] = y @ w
        y0 = y[-1]
    return 0.5 * (gl + gr) - out


def _law_duhem(t, k, ctx, p):
    u = (k / ctx["k_ref"]).tolist()
    al, g0, h1, h3 = p["alpha"], p["g0"], p["h1"], p["h3"]
    hmax = 0.002

    def rate(z, x, s):
        return g0 + al * (h1 * x + h3 * x**3 - z) * s

    return midpoint_in_u(u, rate, hmax)


_LAWS = {"stribeck": _law_stribeck, "lugre": _law_lugre, "wiechert": _law_wiechert, "bouc-wen": _law_bouc_wen,
         "maxwell-slip": _law_maxwell_slip, "preisach": _law_preisach, "gpi-asym": _law_gpi,
         "duhem-hardening": _law_duhem}

SOURCES = {
    "stribeck": "R. Stribeck, Z. VDI 46 (1902); B. Armstrong-Hélouvry, P. Dupont, C. Canudas de Wit, "
                "Automatica 30 (1994) 1083",
    "lugre": "C. Canudas de Wit, H. Olsson, K.J. Åström, P. Lischinsky, IEEE Trans. Autom. Control 40 (1995) 419",
    "wiechert": "E. Wiechert, Ann. Phys. 286 (1893); C. Zener, Elasticity and Anelasticity of Metals (1948)",
    "bouc-wen": "R. Bouc (1967); Y.K. Wen, J. Eng. Mech. Div. 102 (1976) 249",
    "maxwell-slip": "W.D. Iwan, J. Appl. Mech. 33 (1966) 893",
    "preisach": "F. Preisach, Z. Phys. 94 (1935) 277; I.D. Mayergoyz, Mathematical Models of Hysteresis (1991)",
    "gpi-asym": "M. Al Janaideh, S. Rakheja, C.-Y. Su, IEEE/ASME Trans. Mechatronics 16 (2011) 734",
    "duhem-hardening": "P. Duhem, Z. Phys. Chem. 22 (1897); B.D. Coleman, M.L. Hodgdon, Int. J. Eng. Sci. 24 (1986) "
                       "897; J.W. Macki, P. Nistri, P. Zecca, SIAM Rev. 35 (1993) 94",
}

FAULT_SOURCES = {
    "load-cell-tare": "constant offset from a tare with the fixture hanging differently",
    "load-cell-warmup": "first-order thermal warm-up of the load cell (cf. OIML R 60, ISO 376)",
    "offset-wander": "room-temperature cycling of the load-cell zero",
    "stroke-zero-pitch": "stroke zero set with the plates pitched (eq 6 at the pitch)",
    "force-quantised": "12-bit-like force resolution with sub-step white noise",
}


# ---------------------------------------------------------------------------------------------
# cases
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Case8(h6.Case6):
    """A hold-out-6 case (same attributes) whose ``loop`` names one of this module's laws and whose
    ``faults`` name this module's instrument faults, sized by ``fault_params``."""

    fault_params: tuple = field(default_factory=tuple)

    @property
    def fault_sizes(self) -> dict:
        return dict(self.fault_params)


def _c(name, preset, model, pressures, loop, loop_fraction, noise_fraction, noise_ar1, dialect, cycles, rate_hz,
       shape, case_id, alpha_shift, s_scale, waveform, speed, return_speed, detect_speed, detect_load, noise_kind,
       params, faults=(), fault_params=None, cls=None, **kw):
    """One case of ``cls`` (default :class:`Case8`; hold-out 9 builds its own cases with it)."""
    return (cls or Case8)(name, preset, model, tuple(float(x) for x in pressures), loop, loop_fraction, noise_fraction,
                 noise_ar1, 0.0, dialect, cycles, rate_hz, shape, case_id, alpha_shift, s_scale, waveform, speed,
                 return_speed, detect_speed, detect_load, noise_kind, faults=tuple(faults),
                 loop_params=tuple(params.items()), fault_params=tuple((fault_params or {}).items()), **kw)


CASES: dict[str, Case8] = {c.name: c for c in [
    _c("h8-maxwellslip-tare", "be-pam", "energy", (140, 155, 170, 185, 200), "maxwell-slip", 0.04, 0.010, 0.0,
       "mts-basic", 4, 20.0, 0.47, 801, 0.65, 1.03, "cycloid", 40.0, 40.0, 20.0, 0.2, "white",
       {"n": 16, "median": 0.06, "sigma_ln": 0.6}, faults=("load-cell-tare",),
       fault_params={"tare_fraction": -0.02}, log_detection=False),
    _c("h8-lugre-warmup", "bc-pam", "force_balance", (50, 70, 90, 110, 130), "lugre", 0.045, 0.012, 0.7,
       "zwick-de", 4, 25.0, 0.53, 802, 0.5, 0.98, "trapvel", 45.0, 45.0, 20.0, 0.15, "ar1",
       {"sigma0": 25.0, "sigma1": 0.1, "sigma2": 0.2, "Fc": 1.0, "Fs": 1.4, "vs": 0.3, "delta": 2.0},
       faults=("load-cell-warmup",), fault_params={"warmup_fraction": 0.008}),
    _c("h8-wiechert-wander", "be-pam", "force_balance", (110, 130, 150, 170, 190, 210), "wiechert", 0.07, 0.015,
       0.0, "bluehill", 5, 20.0, 0.56, 803, 0.45, 0.96, "tri-asym", 40.0, 60.0, 20.0, 0.3, "pink",
       {"taus": (0.1, 0.3, 0.8), "weights": (0.3, 0.45, 0.25)}, faults=("offset-wander",),
       fault_params={"wander_fraction": 0.004, "wander_periods": 3.0}, log_detection=False),
    _c("h8-boucwen-zero", "bc-pam", "energy", (45, 70, 95, 120), "bouc-wen", 0.035, 0.020, 0.0,
       "csv", 3, 50.0, 0.44, 804, 0.75, 1.01, "haversine", 50.0, 50.0, 25.0, 0.1, "white",
       {"n": 2.0, "A": 1.0, "beta_plus_gamma": 70.0, "beta_share": 0.75}, faults=("stroke-zero-pitch",),
       fault_params={"pitch_deg": 0.3}, L0_mm=145.0),
    _c("h8-preisach-quant", "be-pam", "energy", (100, 150, 200), "preisach", 0.05, 0.0048, 0.0,
       "trapezium", 5, 10.0, 0.59, 805, 0.55, 1.05, "trapvel", 40.0, 40.0, 20.0, 0.2, "white",
       {"centre_sd": 0.35, "hc_median": 0.08, "hc_sigma_ln": 0.7}, faults=("force-quantised",),
       fault_params={"quant_fraction": 0.005}, log_detection=False),
    _c("h8-stribeck", "bc-pam", "energy", (40, 60, 80, 100, 120, 140), "stribeck", 0.04, 0.008, 0.5,
       "mts-ts", 4, 50.0, 0.41, 806, 0.6, 0.99, "haversine", 60.0, 60.0, 20.0, 0.2, "ar1",
       {"Fc": 1.0, "Fs": 1.5, "vs": 0.35, "delta": 2.0, "sigma2": 0.25, "v_eps": 0.03}),
    _c("h8-gpi-asym", "be-pam", "force_balance", (95, 130, 165, 200), "gpi-asym", 0.10, 0.006, 0.0,
       "zwick-en", 3, 20.0, 0.5, 807, 0.7, 1.0, "tri-dwell", 35.0, 35.0, 20.0, 0.25, "pink",
       {"a_l": 0.9, "a_r": 0.2, "r_min": 0.01, "r_max": 0.15, "r_scale": 0.08},
       log_detection=False, dwell_s=2.0, L0_mm=150.0),
    _c("h8-duhem-hardening", "bc-pam", "force_balance", (55, 80, 105, 130), "duhem-hardening", 0.12, 0.025, 0.0,
       "instron-console", 5, 25.0, 0.48, 808, 0.4, 1.04, "trap-hold-free", 50.0, 50.0, 25.0, 0.2, "white",
       {"alpha": 15.0, "g0": 1.0, "h1": 0.1, "h3": 0.05}, log_detection=False, dwell_s=4.0),
]}


def start_actuator(case: Case8):
    """The preset with the case's geometry changes (not the truth's constants)."""
    return h6.start_actuator(case)


def truth_actuator(case: Case8):
    return h6.truth_actuator(case)


# ---------------------------------------------------------------------------------------------
# instrument faults (added to hold-out 6's force, on the ADC clock from the machine's start)
# ---------------------------------------------------------------------------------------------
def _blocked_force(tr, P) -> float:
    return float(tr.m(P, 0.0)) / float(h6.lever_mm(0.0))


def _planned(case, ctx) -> tuple[float, float]:
    """(one cycle's duration, the logged test's planned length) at the quasi-static free stroke (s)."""
    tr = ctx["truth"]
    s_free = float(h6.stroke_from_beta(0.5 * ctx["k_free"] * tr.L0))
    one = h6._Programme()
    h6._cycles(one, case, s_free, 1)
    prog = h6._Programme()
    if case.log_detection:
        prog.hold(0.0, 5.0)
        prog.move(0.0, s_free, case.detect_speed_mm_min, "linear")
        prog.hold(s_free, 2.0)
        prog.move(s_free, 0.0, case.return_speed_mm_min, "linear")
        prog.hold(0.0, 3.0)
    h6._cycles(prog, case, s_free, case.cycles)
    prog.hold(0.0, 1.0)
    return one.t, prog.t


def _fault_tare(case, ctx, t):
    tr = ctx["truth"]
    return case.fault_sizes["tare_fraction"] * _blocked_force(tr, float(np.median(case.pressures_kpa)))


def _fault_warmup(case, ctx, t):
    tau, _ = _planned(case, ctx)
    return case.fault_sizes["warmup_fraction"] * ctx["F_b"] * (1.0 - np.exp(-t / tau))


def _fault_wander(case, ctx, t):
    _, T = _planned(case, ctx)
    per = case.fault_sizes["wander_periods"] * T
    return case.fault_sizes["wander_fraction"] * ctx["F_b"] * np.sin(2.0 * math.pi * t / per + ctx["hum_phase"])


_FORCE_FAULTS = {"load-cell-tare": _fault_tare, "load-cell-warmup": _fault_warmup, "offset-wander": _fault_wander}

_PHYS0 = h6._physics
_WRITE0 = h6._write


def _physics(case, ctx, t, x_act, noise, kappa):
    F, k = _PHYS0(case, ctx, t, x_act, noise, kappa)
    for name in case.faults:
        if name in _FORCE_FAULTS:
            F = F + _FORCE_FAULTS[name](case, ctx, t)
    if "force-quantised" in case.faults:  # the reading, as the controller and the log see it
        q = case.fault_sizes["quant_fraction"] * ctx["F_b"]
        F = q * np.round(F / q)
    return F, k


def _stroke_zero(case) -> float:
    return float(h6.stroke_from_beta(math.radians(case.fault_sizes["pitch_deg"])))


def _patched(case, spans):
    def write(case, P_nom, sim, folder, rep):  # the logged stroke with the zero error; the logged length
        if "stroke-zero-pitch" in case.faults:
            sim = dict(sim, stroke_mm=sim["stroke_mm"] - _stroke_zero(case))
        spans.append(float(sim["time_s"][-1] - sim["time_s"][0]))
        return _WRITE0(case, P_nom, sim, folder, rep)

    return machine_patches(case, _LAWS, _physics, write)


def machine_patches(case, laws: dict, physics, write) -> list:
    """The patches of hold-out 6's machine for hold-outs 8-10: the module's ``laws`` made known to it, its force
    shut-off reading a 1 s moving average (:func:`holdout7_generator.averaged_stop`), and its ``physics`` and
    ``write`` steps."""
    return [mock.patch.dict(h6._LAWS, laws), mock.patch.object(h6, "_controller_stop", averaged_stop(case.rate_hz)),
            mock.patch.object(h6, "_physics", physics), mock.patch.object(h6, "_write", write)]


def call_patched(patches, fn, *args):
    """``fn(*args)`` with the ``mock`` patches started, and stopped again whatever happens."""
    for pt in patches:
        pt.start()
    try:
        return fn(*args)
    finally:
        for pt in reversed(patches):
            pt.stop()


def _run(case, fn, *args, spans=None):
    return call_patched(_patched(case, [] if spans is None else spans), fn, *args)


def described(out: dict, case, sources: dict, fault_sources: dict) -> dict:
    """``out`` (hold-out 6's truth of a set) with the case's loop law, faults and their sources."""
    out["loop"] = case.loop
    out["loop_source"] = sources[case.loop]
    out["faults"] = list(case.faults)
    out["fault_params"] = case.fault_sizes
    out["fault_sources"] = [fault_sources[f] for f in case.faults]
    return out


def generate_set(case: Case8, seed: int, folder) -> dict:
    """Write one raw machine file per pressure into ``folder``; returns the truth and the file names.

    Runs hold-out 6's machine with this module's laws, faults and shut-off filter, for the call only.
    """
    spans = []
    out = described(_run(case, h6.generate_set, case, seed, folder, spans=spans), case, SOURCES, FAULT_SOURCES)
    tr = h6._Truth(case)
    for test, span in zip(out["tests"], spans, strict=True):
        F_b = _blocked_force(tr, test["pressure_kpa"])
        if "load-cell-tare" in case.faults:
            test["tare_offset_n"] = _fault_tare(case, {"truth": tr}, None)
            test["tare_fraction_of_blocked"] = test["tare_offset_n"] / F_b
        if "stroke-zero-pitch" in case.faults:
            test["stroke_zero_offset_mm"] = -_stroke_zero(case)
        if "force-quantised" in case.faults:
            test["force_step_n"] = case.fault_sizes["quant_fraction"] * F_b
        ctx = {"truth": tr, "k_free": test["free_curvature_per_mm"]}
        if "load-cell-warmup" in case.faults:
            test["warmup_offset_n"] = case.fault_sizes["warmup_fraction"] * F_b
            test["warmup_tau_s"] = _planned(case, ctx)[0]
        if "offset-wander" in case.faults:
            test["wander_amplitude_n"] = case.fault_sizes["wander_fraction"] * F_b
            test["wander_period_s"] = case.fault_sizes["wander_periods"] * _planned(case, ctx)[1]
            test["wander_period_over_logged_length"] = test["wander_period_s"] / span
    return out


# ---------------------------------------------------------------------------------------------
# checks
# ---------------------------------------------------------------------------------------------
def check_laws(n_cycles: int = 4, points: int = 2000, cases=None, laws=None) -> dict:
    """Each case's law alone on a triangle u: 0 -> 1 -> 0, ``n_cycles`` times, half-cycle time 1.

    Per law: the loop areas (integral of z du per cycle, over max|z|), ``dissipates`` (every area > 0), the
    largest change of z between consecutive cycles (over max|z|; cycle 2 vs 1, 3 vs 2, ...), and the last
    cycle's half-width (half the gap between the branches, mean and max over u in [0.1, 0.9]) as a fraction of
    the blocked moment (``loop_fraction`` x half-width / max|z| of the first two cycles, as the machine scales
    it), with ``half_width_ok`` (the mean in 2-6 %).  ``cases`` and ``laws`` default to this module's (hold-out
    9 passes its own).
    """
    res = {}
    laws = _LAWS if laws is None else laws
    for case in (CASES if cases is None else cases).values():
        _, u, z = reference_cycles(laws[case.loop], case.params, n_cycles, points)
        m = 2 * points
        zmax = float(np.max(np.abs(z[: 2 * m])))
        areas, changes = [], []
        for c in range(n_cycles):
            seg = slice(c * m, (c + 1) * m + 1)
            zz, uu = z[seg], u[seg]
            areas.append(float(np.sum(0.5 * (zz[1:] + zz[:-1]) * np.diff(uu))) / zmax)
            if c:  # interior samples: the shared end points carry the virgin start and one-sided rates
                prev = z[(c - 1) * m: c * m + 1]
                changes.append(float(np.max(np.abs(zz[1:-1] - prev[1:-1]))) / zmax)
        c = n_cycles - 1
        i = np.arange(points // 10, points - points // 10 + 1)
        gap = 0.5 * (z[c * m + i] - z[c * m + 2 * points - i]) / zmax * case.loop_fraction
        hw = float(np.mean(gap))
        res[case.loop] = {"areas": areas, "dissipates": min(areas) > 0.0, "changes": changes,
                          "half_width_mean": hw, "half_width_max": float(np.max(gap)),
                          "half_width_ok": 0.02 <= hw <= 0.06}
    return res


def check_machine(case: Case8, seed: int = 0, run=None) -> dict:
    """The machine with the loop but no noise and no fault: per test, per logged cycle, the loop's mean
    half-width ``(closed integral of (M_law - M_back) dk') / (2 range of k') / M_blocked``.

    Cycles are cut at the stroke's minima between releases.  Returns per pressure the list, and the detected
    stroke over the quasi-static free stroke.  ``run`` is the module's ``_run`` (hold-out 9 passes its own).
    """
    run = run or _run
    clean = dataclasses.replace(case, noise_fraction=0.0, faults=(), stroke_noise_mm=0.0, fault_params=())
    tr = h6._Truth(clean)
    k_ref = h6._k_ref(clean, tr)
    rng = np.random.default_rng([seed, case.case_id])
    out = {}
    for P in clean.pressures_kpa:
        sim = run(clean, h6._simulate, clean, tr, float(P), k_ref, rng)
        x = sim["stroke_mm"]
        beta = h6.beta_from_stroke(x)
        k = 2.0 * beta / tr.L0
        z = (tr.m(float(P), k) - sim["force_n"] * h6.lever_mm(beta)) / sim["M_b"]
        low = x <= 0.02 * sim["s_amp"]  # near the blocked state; each run's lowest sample ends a cycle
        edges = np.flatnonzero(np.diff(low.astype(int))) + 1
        runs = np.split(np.arange(x.size), edges)
        ends = [int(r[np.argmin(x[r])]) for r in runs if low[r[0]]]
        hw = []
        for a, b in itertools.pairwise(ends):
            if np.max(x[a:b]) < 0.5 * sim["s_amp"]:
                continue
            kk, zz = k[a: b + 1], z[a: b + 1]
            area = float(np.sum(0.5 * (zz[1:] + zz[:-1]) * np.diff(kk)))
            hw.append(area / (2.0 * float(np.max(kk) - np.min(kk))))
        s_free = float(h6.stroke_from_beta(0.5 * sim["k_free"] * tr.L0))
        out[float(P)] = {"half_widths": hw, "detected_over_free": sim["s_det"] / s_free}
    return out


def _print_checks() -> None:
    print(f"{'law':16s} {'areas/max|z| per cycle':34s} {'change c2-1, c3-2, c4-3':26s} hw mean/max (x M_b)")
    for law, r in check_laws().items():
        a = " ".join(f"{v:6.3f}" for v in r["areas"])
        c = " ".join(f"{v:6.3f}" for v in r["changes"])
        print(f"{law:16s} {a:34s} {c:26s} {r['half_width_mean']:.4f} / {r['half_width_max']:.4f}")
    print()
    print_machine(CASES, check_machine)


def print_machine(cases, check) -> None:
    """Print ``check(case)`` (:func:`check_machine`) of every case: the clean machine's loops, test by test."""
    print(f"{'case':22s} {'P kPa':>6s} {'det/free':>8s}  mean half-width / M_b per logged cycle")
    for case in cases.values():
        for P, r in check(case).items():
            hw = " ".join(f"{v:.4f}" for v in r["half_widths"])
            print(f"{case.name:22s} {P:6.0f} {r['detected_over_free']:8.3f}  {hw}")


def generate_logged(case, seed: int, folder, run, fault_record, sources: dict, fault_sources: dict) -> dict:
    """Hold-outs 9 and 10's ``generate_set``: hold-out 6's machine run by ``run`` (which logs each test's fault
    record), the truth :func:`described`, and each test's ``fault_record(case, truth, test, record)`` added."""
    log: list = []
    out = described(run(case, h6.generate_set, case, seed, folder, seed=seed, log=log), case, sources, fault_sources)
    tr = h6._Truth(case)
    for test, rec in zip(out["tests"], log, strict=True):
        test.update(fault_record(case, tr, test, rec))
    return out


def print_checks(checks: dict, cases, check, width: int = 16) -> None:
    """Print the laws' checks (:func:`check_laws`' result, with whether each passes) and the clean machine's loops
    (:func:`print_machine`): hold-outs 9 and 10's ``--check``."""
    print(f"{'law':{width}s} {'areas/max|z| per cycle':30s} {'change c2-1, c3-2, c4-3':24s} hw mean/max (x M_b)  ok")
    for law, r in checks.items():
        a = " ".join(f"{v:6.3f}" for v in r["areas"])
        c = " ".join(f"{v:7.4f}" for v in r["changes"])
        ok = "yes" if r["dissipates"] and r["half_width_ok"] else "NO"
        print(f"{law:{width}s} {a:30s} {c:24s} {r['half_width_mean']:.4f} / {r['half_width_max']:.4f}    {ok}")
    print()
    print_machine(cases, check)


def command(argv, cases, generate_set, name: str, checks) -> int:
    """A generator's command line: ``--check`` runs ``checks()``; else ``OUT [SEED]`` writes a seed of every case."""
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["--check"]:
        checks()
        return 0
    return h6.write_all(cases, generate_set, argv, name)


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["--check"]:
        _print_checks()
        return 0
    return h6.write_all(CASES, generate_set, argv, "holdout8_generator.py")


if __name__ == "__main__":
    raise SystemExit(main())
