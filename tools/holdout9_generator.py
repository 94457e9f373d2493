"""Hold-out set 9: raw four-point-bending tests with further common loop laws and a lab's instrument faults.

A fourth independent generator of raw testing-machine exports (time, stroke, force at one pressure
per file) for scoring, once, whether bendpam's standard errors hold on data it has never seen.
Like :mod:`holdout8_generator` it reuses :mod:`holdout6_generator` (an earlier independent
generator) for everything but the loop laws, the instrument faults and the cases: the truth
(``MomentLaw`` of the preset with alpha0 + 0.4-0.8 deg, ``S`` x 0.95-1.05, ``shape = C01/S`` in
0.4-0.6), the fixture (paper eq 6-8), the machine (pressurised hold, detection of the free state at
a detection load, the stroke waveforms, the clocks), the noise filters and the export writers
(dialects).  As in hold-outs 7 and 8 the controller's force shut-off reads a causal 1 s moving
average of the force.

Measured moment = quasi-static ``M(P, k')`` of the truth - ``kappa z`` + instrument effects, ``z``
the loop law of the case driven by ``u = k'/k'_ref`` (``k'_ref`` the free curvature at the median
pressure; ``dafalias-popov`` uses the test's own free curvature, so that its loop keeps its shape
relative to each test's span) and, for the rate-dependent laws, by time in units of ``t_half`` (the
time of a release stroke at the case's speed); ``z`` is positive while releasing (``k'``
increasing), so each cycle dissipates.  ``kappa`` sets ``max|z| = loop_fraction x M_blocked`` on a
reference triangle 0 -> k'_free -> 0 (twice), as in hold-out 6.  The loop half-width (half the
gap between the return and the release branch, averaged over the middle 80 % of the stroke) is
2-6 % of the blocked moment for every law, and every law dissipates on every cycle
(:func:`check_laws`).  ``kappa`` is set per test, so each test's loop is about ``loop_fraction`` of its
own blocked moment; the linear viscoelastic laws keep their shape from test to test, while the
friction and plasticity laws, whose loops saturate in ``u`` (0.25-1.7 over a case's pressures), change
shape with the span and do not scale with it (the GMS loop's mean half-width, for one, goes from 2.0
to 3.5 % of the blocked moment from the lowest to the highest pressure).

Loop laws (``z(t, k, ctx, params)``, one small function each)
-------------------------------------------------------------
Rate dependent:

* ``frac-zener``: the fractional Zener solid (a spring in parallel with a spring in series with a
  springpot of order 1/2), whose relaxation modulus is ``E_r + dE E_a(-(t/tau)^a)`` with the
  Mittag-Leffler function ``E_a`` (R.L. Bagley, P.J. Torvik, "On the fractional calculus model of
  viscoelastic behavior", J. Rheol. 30, 133-155, 1986; F. Mainardi, Fractional Calculus and Waves
  in Linear Viscoelasticity, Imperial College Press, 2010).  ``z`` is the relaxing part (the
  equilibrium spring ``E_r u`` is single-valued and belongs to the quasi-static moment).  With
  a = 1/2, ``E_1/2(-sqrt(x)) = exp(x) erfc(sqrt(x))`` and its integral is closed form, so the
  hereditary integral is exact for a piecewise-linear input (its step kernel is the integral of
  the relaxation over a step; a power series below x = 1); tau = 0.03 t_half (its power-law tail
  reaches far beyond a cycle: the loop's mean relaxes over the test, 6 % then 3 % of max|z| between
  consecutive cycles).  (Hold-out 7's Havriliak-Negami spectrum with beta = 1 would be this family,
  the Cole-Cole one; it used beta = 0.45 and 41 branches.)
* ``kww``: stretched-exponential (Kohlrausch-Williams-Watts) relaxation ``exp(-(t/tau)^b)``,
  b = 0.5, tau = 0.15 t_half (R. Kohlrausch, "Theorie des elektrischen Rückstandes in der Leidener
  Flasche", Ann. Phys. Chem. 91, 1854; G. Williams, D.C. Watts, "Non-symmetrical dielectric
  relaxation behaviour arising from a simple empirical decay function", Trans. Faraday Soc. 66,
  80-85, 1970); the step kernel is closed form, ``Gamma(1 + 1/b) P(1/b, x^b)``, so again exact for
  a piecewise-linear input.
* ``gms``: the Generalized Maxwell-Slip friction model, six elements (a spring and a slip block
  each; presliding lengths log-spaced 0.02-0.25, slip-force shares log-spaced 1:0.3) whose slip
  forces follow a Stribeck curve ``s(v) = Fc + (Fs - Fc) exp(-(|v|/vs)^2)`` of the velocity
  ``v = du/d(t/t_half)`` (Fs/Fc = 1.5, vs = 0.8, attraction time Tc = 0.03 t_half); a sticking
  element follows ``df_i/dt = k_i v`` (``k_i = w_i Fs / d_i``, ``d_i`` its presliding length)
  until it reaches ``w_i s(v)``, a slipping one ``df_i/dt = (sgn(v) w_i s(v) - f_i)/Tc`` until the
  velocity goes through zero (a dwell sticks every element); ``z = sum f_i + sigma2 v``,
  sigma2 = 0.15 (F. Al-Bender, V. Lampaert, J. Swevers, "The generalized Maxwell-slip model: a
  novel model for friction simulation and compensation", IEEE Trans. Autom. Control 50,
  1883-1887, 2005).  Exact for a step of constant velocity.
* ``bodner-partom``: a spring in series with Bodner and Partom's unified viscoplastic flow law,
  ``de_p/dt = D0 exp(-(Z/|s|)^(2n)/2) sgn s`` with the isotropic hardening variable ``Z`` driven
  by the plastic work, ``dZ = m (Z1 - Z) dW_p`` (S.R. Bodner, Y. Partom, "Constitutive equations
  for elastic-viscoplastic strain-hardening materials", J. Appl. Mech. 42, 385-389, 1975); n = 1,
  D0 = 1000 per t_half, Z0 = 0.85, Z1 = 1, m = 5, E = 5 (the flow stress ~0.27 is reached at
  u ~ 0.05).  Implicit midpoint rule in substeps of at most 0.002 in u (a safeguarded Newton
  solve; 4e-4 of max|z| from a 20x finer run), Z updated exactly for each substep's plastic work.
  Mildly rate dependent (a 2x faster stroke raises the flow stress by ~5 %); the loop saturates.

Rate independent:

* ``ro-masing``: a Ramberg-Osgood backbone ``u = z/E + a (z0/E) (|z|/z0)^n`` (n = 10, a = 0.5,
  z0/E = 0.04) with Masing's rule (branches are the backbone scaled by 2 from the last reversal)
  and the extended-Masing memory rules (a branch that meets an earlier one follows it) (W. Ramberg,
  W.R. Osgood, "Description of stress-strain curves by three parameters", NACA TN 902, 1943;
  G. Masing, "Eigenspannungen und Verfestigung beim Messing", Proc. 2nd Int. Congr. Appl. Mech.,
  Zürich, 1926; R. Pyke, "Nonlinear soil models for irregular cyclic loadings", J. Geotech. Eng.
  Div. ASCE 105, 715-726, 1979).  Each branch is evaluated in closed form (a monotone Newton
  solve of the backbone).
* ``menegotto-pinto``: the Giuffrè-Menegotto-Pinto steel law, ``s* = b e* + (1 - b) e* /
  (1 + |e*|^R)^(1/R)`` between the last reversal and the intersection of the elastic line with the
  bilinear asymptotes, with the curvature ``R = R0 (1 - cR1 xi/(cR2 + xi))`` falling with the
  plastic excursion ``xi`` (M. Menegotto, P.E. Pinto, IABSE Symposium, Lisbon, 1973;
  F.C. Filippou, E.P. Popov, V.V. Bertero, "Effects of bond deterioration on hysteretic behavior of
  reinforced concrete joints", UCB/EERC-83/19, 1983); b = 0.02, R0 = 20, cR1 = 0.925, cR2 = 0.15,
  yield at u = 0.05.  ``z = s - b E u`` (the asymptotes' single-valued hardening line removed).
  The Bauschinger rounding (R ~ 1.6 after the first excursion) makes the loop lens-shaped.
* ``dafalias-popov``: two-surface (bounding-surface) plasticity with a vanishing elastic range
  and fixed bounds ``+-s_B``: plastic modulus ``h delta/(delta_in - delta)``, ``delta`` the
  distance to the bound in the loading direction, ``delta_in`` its value at the last reversal, so
  the tangent ``E E_p/(E + E_p)`` starts elastic at each reversal and the approach to the bound
  depends on where the reversal was (Y.F. Dafalias, E.P. Popov, "A model of nonlinearly hardening
  materials for complex loading", Acta Mech. 21, 173-192, 1975; "Plastic internal variables
  formalism of cyclic plasticity", J. Appl. Mech. 43, 645-651, 1976); E = 25, h = 5 per unit
  ``k'/k'_free``.  The branch is closed form in ``delta`` (an increasing concave equation in
  ``ln delta`` solved by Newton from the safe side).
* ``takeda-pinch``: a Takeda peak-oriented, stiffness-degrading law with pinching (T. Takeda,
  M.A. Sozen, N.N. Nielsen, "Reinforced concrete response to simulated earthquakes", J. Struct.
  Div. ASCE 96, 2557-2573, 1970; R.W. Clough, S.B. Johnston, "Effect of stiffness degradation on
  earthquake ductility requirements", Proc. Japan Earthquake Eng. Symp., 1966): a bilinear
  backbone (yield at x_y = 0.03, post-yield ratio 0.03), unloading at ``k0 (x_y/x_peak)^0.4``, and
  reloading (from zero force) toward the opposite peak through a pinch point at (0.15, 0.2) x the
  peak's (displacement, force), so the loop is narrow around its middle; k0 = 33 per unit
  ``k'/k'_ref``.  Driven by the distance from the middle of the run's range,
  ``x = (k' - max k'/2)/k'_ref``, with the pre-history of a full cycle over that range (both peaks
  at its ends, the start on the backbone at the blocked end), so the loop is steady from the first
  release.  The single-valued part of its loop (the average of the two branches of the steady loop
  at the current peaks, an odd secant-like line) is removed, as hold-out 6 does for its KP law, so
  ``z`` is the pinched loop alone.

Instrument faults (each in one case; the rest of the lab is careful: pressure as declared, load
cell tared, no self-weight, no rig faults)
--------------------------------------------------------------------------------------------------
* ``channel-skew``: the force channel lags the stroke channel by ``skew_s`` (20-80 ms; here
  60 ms, 1.5 samples at 25 Hz), the group delay of the force amplifier's anti-aliasing filter
  (a 4-pole Bessel low-pass delays by ~2.11/(2 pi f_c): 34 ms at 10 Hz, 67 ms at 5 Hz); the
  logged force is the force of ``skew_s`` earlier (the programme's stroke interpolated at
  ``t - skew_s``; the noise is not delayed).  The controller reads the lagging force.
* ``pressure-crosstalk``: the pressurised supply hose straightens (a Bourdon-tube effect) and
  pulls on the lower plates, a force ``c P`` constant within a test, ``c`` set so that it is
  ``xtalk_fraction`` = -0.5 % of the blocked force at the median pressure (a pull toward the free
  state); each test's share of its own blocked force (-0.9 ... -0.43 %) is in the returned tests.
* ``clock-error``: the controller's sample clock is off: it samples at ``rate_hz`` (the case's
  real rate) while its export states ``stated_rate_hz`` and a time column ``i / stated_rate_hz``,
  ``clock_error = rate_hz/stated_rate_hz - 1`` (-1.5 %): every logged time and duration is 1.5 %
  short, the stroke's speed seen from the file 1.5 % high.
* ``mains-spikes``: electromagnetic interference from the valve and motor drives: isolated
  single-sample spikes in the logged force, about one per ``1/spike_rate`` samples (a Bernoulli
  draw per sample), of 5-20 x the force noise's standard deviation, random sign (H.W. Ott,
  Electromagnetic Compatibility Engineering, Wiley, 2009).  They are drawn from the test's own
  stream ``[seed, case_id, test number, 9]`` and hit the log only (the shut-off's 1 s average
  does not see them).
* ``clamp-slip``: the actuator slips once in its clamp, by ``slip_mm`` (0.05-0.2 mm; here
  0.12 mm) toward bending, at the blocked turn that ends logged cycle ``slip_after_cycle``
  (where the force is largest): from then on the plates sit ``slip_mm`` further bent than the
  crosshead's stroke says (the logged stroke's zero shifts by that step).
* ``pressure-droop``: the regulator sags with the actuator's growing volume (the droop of a
  pressure regulator's flow characteristic, cf. ISO 6953-1), ``P = P_set (1 - droop k'/k'_free)``
  with droop = 2 %: at the set pressure at the blocked state, 2 % low at the free state, periodic
  with the cycle (quasi-static).

Force noise otherwise as hold-out 6 (white, AR(1), pink; 0.5-3 % of the blocked force), 2 um stroke
noise, 3-5 cycles, sampling at 10-50 Hz, eight export dialects (one per case).  ``drift_fraction``
(hold-out 6's linear drift) is 0 in every case.

Cases (8; 36 files a seed, each case's seed in 0.05-0.3 s)
-----------------------------------------------------------
==================== ====== ============= ================ =============== ================== ======= ========
case                 preset model         pressures (kPa)  law             fault              noise   dialect
==================== ====== ============= ================ =============== ================== ======= ========
h9-fraczener-skew    BE     energy        100-200 (5)      frac-zener      channel-skew       1 % w   zwick-de
h9-kww-crosstalk     BC     force_balance 50-130 (5)       kww             pressure-crosstalk 1.2 % a bluehill
h9-gms-clock         BE     force_balance 95-215 (5)       gms             clock-error        0.8 % p mts-ts
h9-bodner-spikes     BC     energy        45-145 (6)       bodner-partom   mains-spikes       1.5 % w csv
h9-romasing-clamp    BE     energy        100-200 (3)      ro-masing       clamp-slip         2 % a   trapezium
h9-menegotto-droop   BC     force_balance 50-125 (4)       menegotto-pinto pressure-droop     0.6 % w instron
h9-dafalias-popov    BE     force_balance 105-195 (4)      dafalias-popov  (none)             3 % p   zwick-en
h9-takeda-pinch      BC     energy        55-130 (4)       takeda-pinch    (none)             0.5 % w mts-basic
==================== ====== ============= ================ =============== ================== ======= ========

(w white, a AR(1), p pink.)

``python tools/holdout9_generator.py OUT [SEED]`` writes one seed of every case into OUT/<case>/
with ``truth.json``; ``python tools/holdout9_generator.py --check`` prints the laws' dissipation,
periodicity and half-width table and the clean machine's loop table.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path

import numpy as np
from scipy import signal, special

if str(Path(__file__).resolve().parent) not in sys.path:
    sys.path.insert(0, str(Path(__file__).resolve().parent))
import holdout8_generator as gen8
from holdout7_generator import h6

__all__ = ["CASES", "Case9", "check_laws", "check_machine", "generate_set", "start_actuator", "truth_actuator"]


# ---------------------------------------------------------------------------------------------
# rate-dependent loop laws: z(t, k, ctx, params), positive while k increases; scaled by the machine
# ---------------------------------------------------------------------------------------------
def _relax(u, J, h):
    """``z_n = sum_j (u_j - u_j-1) (J((n-j+1) h) - J((n-j) h)) / h``: the hereditary integral of a relaxation
    function whose integral is ``J``, exact for ``u`` linear between samples (``h`` the step in its time unit)."""
    g = np.diff(J(np.arange(u.size + 1) * h)) / h
    return signal.fftconvolve(np.diff(u, prepend=u[0]), g)[: u.size]


def _ml_half_integral(x):
    """``int_0^x E_1/2(-sqrt(s)) ds = erfcx(sqrt x) - 1 + 2 sqrt(x/pi)``; its power series below x = 1."""
    x = np.asarray(x, dtype=float)
    r = np.sqrt(x)
    out = special.erfcx(r) - 1.0 + 2.0 / math.sqrt(math.pi) * r
    small = x < 1.0
    if small.any():  # x E_1/2,2(-sqrt x) = sum_k (-1)^k x^(k/2 + 1) / Gamma(k/2 + 2): no cancellation
        rs = r[small]
        ser = np.zeros_like(rs)
        for kk in range(60, -1, -1):  # Horner in sqrt(x)
            ser = ser * -rs + 1.0 / math.gamma(0.5 * kk + 2.0)
        out[small] = x[small] * ser
    return out


def _law_frac_zener(t, k, ctx, p):
    return _relax(k / ctx["k_ref"], _ml_half_integral, ctx["dt"] / (p["tau0"] * ctx["t_half"]))


def _law_kww(t, k, ctx, p):
    b = p["beta"]

    def J(x):  # int_0^x exp(-s^b) ds
        return math.gamma(1.0 + 1.0 / b) * special.gammainc(1.0 / b, x**b)

    return _relax(k / ctx["k_ref"], J, ctx["dt"] / (p["tau0"] * ctx["t_half"]))


def _law_gms(t, k, ctx, p):
    u = (k / ctx["k_ref"]).tolist()
    dtau = ctx["dt"] / ctx["t_half"]
    n = int(p["n"])
    w = np.geomspace(1.0, p["w_ratio"], n)
    w = (w / w.sum()).tolist()
    kst = [wi * p["Fs"] / di for wi, di in zip(w, np.geomspace(p["d_min"], p["d_max"], n).tolist(), strict=True)]
    a = math.exp(-dtau / p["Tc"])
    Fc, dF, vs, de, s2 = p["Fc"], p["Fs"] - p["Fc"], p["vs"], p["delta"], p["sigma2"]
    f, slip, last = [0.0] * n, [False] * n, 0.0
    out = np.zeros(len(u))
    for i in range(1, len(u)):
        du = u[i] - u[i - 1]
        if du == 0.0:  # at rest every element sticks
            out[i], last = sum(f), 0.0
            continue
        s = 1.0 if du > 0 else -1.0
        v = du / dtau
        g = Fc + dF * math.exp(-((abs(v) / vs) ** de))
        if s != last:  # the velocity went through zero: every element sticks again
            slip, last = [False] * n, s
        for j in range(n):
            L, fj = s * w[j] * g, f[j]
            if slip[j] or s * fj >= s * L:  # slipping: first-order approach to the slip force, exact
                f[j], slip[j] = L + (fj - L) * a, True
            else:
                fj += kst[j] * du
                if s * fj >= s * L:  # reaches the slip force within the step, then stays on it
                    fj, slip[j] = L, True
                f[j] = fj
        out[i] = sum(f) + s2 * v
    return out


def _bp_stress(a, c, Z, n2):
    """Root x in (0, a] of ``x + c exp(-(Z/x)^n2 / 2) = a`` (increasing in x): Newton kept inside a bracket."""
    lo, hi, x = 0.0, a, a
    for _ in range(100):
        q = (Z / x) ** n2
        ph = math.exp(-0.5 * q)
        g = x + c * ph - a
        if g > 0.0:
            hi = x
        else:
            lo = x
        xn = x - g / (1.0 + c * ph * 0.5 * n2 * q / x)
        if not lo < xn < hi:
            xn = 0.5 * (lo + hi)
        if abs(xn - x) <= 1e-14 * a:
            return xn
        x = xn
    return x


def _law_bodner_partom(t, k, ctx, p):
    u = (k / ctx["k_ref"]).tolist()
    E, n2, Z1, m, hmax = p["E"], 2.0 * p["n"], p["Z1"], p["m"], 0.002
    cdt = E * p["D0"] * ctx["dt"] / ctx["t_half"]
    out = np.zeros(len(u))
    s, Z = 0.0, p["Z0"]
    for i in range(1, len(u)):
        du = u[i] - u[i - 1]
        nsub = 1 + int(abs(du) / hmax)  # substeps of at most hmax in u (one while at rest)
        c = 0.5 * cdt / nsub
        for _ in range(nsub):  # implicit midpoint: sm + (E dt D0 / 2) phi(sm) = s + E du / 2, s <- 2 sm - s
            tr = s + 0.5 * E * du / nsub
            a = abs(tr)
            if a == 0.0 or c * math.exp(-0.5 * (Z / a) ** n2) <= 1e-16 * a:
                sm = tr  # no flow to double precision
            else:
                sm = math.copysign(_bp_stress(a, c, Z, n2), tr)
                Z = Z1 - (Z1 - Z) * math.exp(-m * abs(sm) * 2.0 * (a - abs(sm)) / E)  # the step's plastic work
            s = 2.0 * sm - s
        out[i] = s
    return out


# ---------------------------------------------------------------------------------------------
# rate-independent loop laws
# ---------------------------------------------------------------------------------------------
def _ro_backbone(x, p):
    """z on the Ramberg-Osgood backbone at u = x (odd): x = z/E + a (z0/E) (|z|/z0)^n, Newton from above."""
    E, z0, al, n = p["E"], p["z0"], p["a"], p["n"]
    ax = np.abs(x)
    s = np.minimum(E * ax, z0 * (E * ax / (al * z0)) ** (1.0 / n))  # each term alone: an upper bound
    for _ in range(100):  # convex increasing: the iterates fall monotonically onto the root
        step = (s / E + al * z0 / E * (s / z0) ** n - ax) / (1.0 / E + al * n / E * (s / z0) ** (n - 1.0))
        s = s - step
        if np.all(step <= 1e-15 * (1.0 + s)):
            break
    return np.sign(x) * s


def _law_ro_masing(t, k, ctx, p):
    u = k / ctx["k_ref"]
    out = np.empty_like(u)
    rev = []  # reversal points (u, z); empty: on the backbone
    for a, b, d in h6._segments(u):
        if a:
            rev.append((float(u[a - 1]), float(out[a - 1])))
        i = a
        while i < b:
            if rev:  # the branch ends where it meets the earlier branch (or the backbone's mirror point)
                tu = rev[-2][0] if len(rev) > 1 else -rev[-1][0]
                past = np.flatnonzero(d * (u[i:b] - tu) > 0.0)
                j = b if past.size == 0 else i + int(past[0])
                ur, zr = rev[-1]
                out[i:j] = zr + 2.0 * _ro_backbone(0.5 * (u[i:j] - ur), p)
                if j < b:
                    del rev[-2:]
            else:
                j = b
                out[i:j] = _ro_backbone(u[i:j], p)
            i = j
    return out


def _law_menegotto_pinto(t, k, ctx, p):
    u = k / ctx["k_ref"]
    E, fy, b, R0, c1, c2 = p["E"], p["fy"], p["b"], p["R0"], p["cR1"], p["cR2"]
    ey = fy / E
    out = np.empty_like(u)
    emax, emin = ey, -ey
    for a, bb, d in h6._segments(u):
        er, sr = (float(u[0]), 0.0) if a == 0 else (float(u[a - 1]), float(out[a - 1]))
        if a and d > 0:
            emin = min(emin, er)
        elif a:
            emax = max(emax, er)
        y = d * fy
        e0 = ((1.0 - b) * y - sr + E * er) / (E * (1.0 - b))  # elastic line meets the asymptote
        s0 = b * E * e0 + (1.0 - b) * y
        xi = abs((emax if d > 0 else emin) - e0) / ey
        R = R0 * (1.0 - c1 * xi / (c2 + xi))
        span = e0 - er if abs(e0 - er) > 1e-12 else d * 1e-12
        es = (u[a:bb] - er) / span
        out[a:bb] = sr + (s0 - sr) * (b * es + (1.0 - b) * es / (1.0 + np.abs(es) ** R) ** (1.0 / R))
    return out - b * E * u


def _law_dafalias_popov(t, k, ctx, p):
    u = k / ctx["k_free"]
    E, h, sb = p["E"], p["h"], p["s_B"]
    B = (E - h) / (E * h)
    out = np.empty_like(u)
    for a, b, d in h6._segments(u):
        ur, sr = (float(u[0]), 0.0) if a == 0 else (float(u[a - 1]), float(out[a - 1]))
        din = sb - d * sr  # distance to the bound at the reversal
        if din <= 1e-15:
            out[a:b] = d * sb
            continue
        du = d * (u[a:b] - ur)
        A = din / h
        y = np.zeros_like(du)  # ln(delta/delta_in): A y - B din (e^y - 1) + du = 0, increasing and concave in y
        for _ in range(100):
            ey = np.exp(y)
            step = (A * y - B * din * (ey - 1.0) + du) / (A - B * din * ey)
            y = y - step
            if np.all(np.abs(step) <= 1e-14 * (1.0 + np.abs(y))):
                break
        out[a:b] = d * (sb - din * np.exp(y))
    return out


def _tk_rise(xr, zr, xp, zp, ku_back, pin):
    """Knots (x increasing) of a Takeda branch rising from the reversal (xr, zr) to the peak (xp, zp): unloading at
    ``ku_back`` to zero force, then toward the pinch point ``(pin[0] xp, pin[1] zp)``, then the peak; the backbone
    beyond it."""
    kn = [(xr, zr)]
    if zr < 0.0:
        kn.append((xr - zr / ku_back, 0.0))
    xpin, zpin = pin[0] * xp, pin[1] * zp
    if xpin > kn[-1][0] and zpin > kn[-1][1]:
        kn.append((xpin, zpin))
    if xp > kn[-1][0]:
        kn.append((xp, zp))
    return np.array(kn)


def _tk_eval(kn, x, slope):
    z = np.interp(x, kn[:, 0], kn[:, 1])
    return np.where(x > kn[-1, 0], kn[-1, 1] + slope * (x - kn[-1, 0]), z)


def _law_takeda(t, k, ctx, p):
    a0 = 0.5 * float(np.max(k)) / ctx["k_ref"]  # half the run's range: the element was cycled over it before
    x = k / ctx["k_ref"] - a0
    xy, k0, r, be = p["x_y"], p["k0"], p["r"], p["beta"]
    g = (p["pinch_x"], p["pinch_z"])
    zy = k0 * xy

    def bb(v):  # backbone magnitude at |x| = v >= x_y
        return zy + r * k0 * (v - xy)

    def ku(v):  # unloading stiffness after a peak at |x| = v
        return k0 * (xy / v) ** be

    pk = {1.0: max(xy, a0), -1.0: max(xy, a0)}  # peak excursions (magnitudes), from the earlier cycling
    x0 = float(x[0])  # the start: at the blocked end's peak
    z0 = math.copysign(bb(abs(x0)), x0) if abs(x0) > xy else k0 * x0
    out, cen = np.empty_like(x), np.empty_like(x)
    for a, b, d in h6._segments(x):
        xr, zr = (x0, z0) if a == 0 else (float(x[a - 1]), float(out[a - 1]))
        kn = _tk_rise(d * xr, d * zr, pk[d], bb(pk[d]), ku(pk[-d]), g)
        out[a:b] = d * _tk_eval(kn, d * x[a:b], r * k0)
        pk[d] = max(pk[d], float(np.max(d * x[a:b])))
        up = _tk_rise(-pk[-1.0], -bb(pk[-1.0]), pk[1.0], bb(pk[1.0]), ku(pk[-1.0]), g)
        dn = _tk_rise(-pk[1.0], -bb(pk[1.0]), pk[-1.0], bb(pk[-1.0]), ku(pk[1.0]), g)
        xs = x[a:b]  # the steady loop's single-valued part at the current peaks: the mean of its branches
        cen[a:b] = 0.5 * (_tk_eval(up, xs, r * k0) - _tk_eval(dn, -xs, r * k0))
    return out - cen


_LAWS = {"frac-zener": _law_frac_zener, "kww": _law_kww, "gms": _law_gms, "bodner-partom": _law_bodner_partom,
         "ro-masing": _law_ro_masing, "menegotto-pinto": _law_menegotto_pinto,
         "dafalias-popov": _law_dafalias_popov, "takeda-pinch": _law_takeda}

SOURCES = {
    "frac-zener": "R.L. Bagley, P.J. Torvik, J. Rheol. 30 (1986) 133; F. Mainardi, Fractional Calculus and Waves in "
                  "Linear Viscoelasticity (2010)",
    "kww": "R. Kohlrausch, Ann. Phys. Chem. 91 (1854); G. Williams, D.C. Watts, Trans. Faraday Soc. 66 (1970) 80",
    "gms": "F. Al-Bender, V. Lampaert, J. Swevers, IEEE Trans. Autom. Control 50 (2005) 1883",
    "bodner-partom": "S.R. Bodner, Y. Partom, J. Appl. Mech. 42 (1975) 385",
    "ro-masing": "W. Ramberg, W.R. Osgood, NACA TN 902 (1943); G. Masing (1926); R. Pyke, J. Geotech. Eng. Div. 105 "
                 "(1979) 715",
    "menegotto-pinto": "M. Menegotto, P.E. Pinto, IABSE Symp. Lisbon (1973); F.C. Filippou, E.P. Popov, V.V. Bertero, "
                       "UCB/EERC-83/19 (1983)",
    "dafalias-popov": "Y.F. Dafalias, E.P. Popov, Acta Mech. 21 (1975) 173; J. Appl. Mech. 43 (1976) 645",
    "takeda-pinch": "T. Takeda, M.A. Sozen, N.N. Nielsen, J. Struct. Div. 96 (1970) 2557; R.W. Clough, S.B. Johnston "
                    "(1966)",
}

FAULT_SOURCES = {
    "channel-skew": "force channel delayed by its amplifier's anti-aliasing filter (Bessel group delay)",
    "pressure-crosstalk": "pressurised supply hose pulling on the plates (Bourdon effect), a force c P",
    "clock-error": "sample clock off: the export's rate and time column differ from the real ones",
    "mains-spikes": "single-sample EMI spikes from valve and motor drives (H.W. Ott, EMC Engineering, 2009)",
    "clamp-slip": "the actuator slips once in its clamp at a blocked turn: the stroke zero steps",
    "pressure-droop": "regulator droop with the actuator's volume (cf. ISO 6953-1): P lower when released",
}


# ---------------------------------------------------------------------------------------------
# cases
# ---------------------------------------------------------------------------------------------
class Case9(gen8.Case8):
    """A hold-out-6 case (same attributes) whose ``loop`` names one of this module's laws and whose
    ``faults`` name this module's instrument faults, sized by ``fault_params`` (hold-out 8's case, whose
    builder it shares)."""


def _c(*args, **kw) -> Case9:
    return gen8._c(*args, cls=Case9, **kw)


CASES: dict[str, Case9] = {c.name: c for c in [
    _c("h9-fraczener-skew", "be-pam", "energy", (100, 125, 150, 175, 200), "frac-zener", 0.13, 0.010, 0.0,
       "zwick-de", 4, 25.0, 0.46, 901, 0.55, 1.02, "haversine", 45.0, 45.0, 20.0, 0.2, "white",
       {"tau0": 0.03}, faults=("channel-skew",), fault_params={"skew_s": 0.06}),
    _c("h9-kww-crosstalk", "bc-pam", "force_balance", (50, 70, 90, 110, 130), "kww", 0.11, 0.012, 0.7,
       "bluehill", 5, 20.0, 0.53, 902, 0.7, 0.97, "tri-asym", 40.0, 60.0, 20.0, 0.15, "ar1",
       {"beta": 0.5, "tau0": 0.15}, faults=("pressure-crosstalk",), fault_params={"xtalk_fraction": -0.005},
       log_detection=False),
    _c("h9-gms-clock", "be-pam", "force_balance", (95, 125, 155, 185, 215), "gms", 0.035, 0.008, 0.0,
       "mts-ts", 4, 39.4, 0.57, 903, 0.45, 1.04, "trapvel", 40.0, 40.0, 20.0, 0.25, "pink",
       {"n": 6, "w_ratio": 0.3, "d_min": 0.02, "d_max": 0.25, "Fc": 1.0, "Fs": 1.5, "vs": 0.8, "delta": 2.0,
        "Tc": 0.03, "sigma2": 0.15},
       faults=("clock-error",), fault_params={"stated_rate_hz": 40.0}, L0_mm=150.0),
    _c("h9-bodner-spikes", "bc-pam", "energy", (45, 65, 85, 105, 125, 145), "bodner-partom", 0.04, 0.015, 0.0,
       "csv", 3, 20.0, 0.42, 904, 0.8, 1.0, "cycloid", 50.0, 50.0, 25.0, 0.2, "white",
       {"E": 5.0, "n": 1.0, "D0": 1000.0, "Z0": 0.85, "Z1": 1.0, "m": 5.0},
       faults=("mains-spikes",), fault_params={"spike_rate": 0.004, "spike_min": 5.0, "spike_max": 20.0},
       log_detection=False),
    _c("h9-romasing-clamp", "be-pam", "energy", (100, 150, 200), "ro-masing", 0.05, 0.020, 0.5,
       "trapezium", 5, 10.0, 0.6, 905, 0.65, 0.98, "tri-dwell", 40.0, 40.0, 20.0, 0.3, "ar1",
       {"E": 25.0, "z0": 1.0, "a": 0.5, "n": 10.0}, faults=("clamp-slip",),
       fault_params={"slip_mm": 0.12, "slip_after_cycle": 2}, log_detection=False, dwell_s=2.0),
    _c("h9-menegotto-droop", "bc-pam", "force_balance", (50, 75, 100, 125), "menegotto-pinto", 0.05, 0.006, 0.0,
       "instron-console", 4, 25.0, 0.49, 906, 0.5, 1.05, "haversine", 50.0, 50.0, 25.0, 0.2, "white",
       {"E": 20.0, "fy": 1.0, "b": 0.02, "R0": 20.0, "cR1": 0.925, "cR2": 0.15}, faults=("pressure-droop",),
       fault_params={"droop": 0.02}),
    _c("h9-dafalias-popov", "be-pam", "force_balance", (105, 135, 165, 195), "dafalias-popov", 0.06, 0.030, 0.0,
       "zwick-en", 3, 20.0, 0.51, 907, 0.75, 0.95, "trap-hold-free", 45.0, 45.0, 20.0, 0.2, "pink",
       {"E": 25.0, "h": 5.0, "s_B": 1.0}, log_detection=False, dwell_s=3.0, L0_mm=140.0),
    _c("h9-takeda-pinch", "bc-pam", "energy", (55, 80, 105, 130), "takeda-pinch", 0.07, 0.005, 0.0,
       "mts-basic", 5, 50.0, 0.44, 908, 0.6, 1.01, "tri-dwell", 45.0, 45.0, 20.0, 0.1, "white",
       {"x_y": 0.03, "k0": 33.0, "r": 0.03, "pinch_x": 0.15, "pinch_z": 0.2, "beta": 0.4},
       log_detection=False, dwell_s=1.0, precycle=True),
]}


#: The preset with the case's geometry changes (not the truth's constants), and the truth: hold-out 8's.
start_actuator, truth_actuator = gen8.start_actuator, gen8.truth_actuator


# ---------------------------------------------------------------------------------------------
# instrument faults (hold-out 6's machine, patched for the call)
# ---------------------------------------------------------------------------------------------
_blocked_force = gen8._blocked_force


def _xtalk_n_per_kpa(case, tr) -> float:
    P = float(np.median(case.pressures_kpa))
    return case.fault_sizes["xtalk_fraction"] * _blocked_force(tr, P) / P


def _slip_index(case, x):
    """The sample of the blocked turn that ends logged cycle ``slip_after_cycle`` of the crosshead path ``x`` (the
    lowest sample of each stay near stroke 0 after the first), or None (the detection run has none)."""
    top = float(np.max(x))
    if top <= 0.0:
        return None
    low = x <= 0.02 * top
    edges = np.flatnonzero(np.diff(low.astype(np.int8))) + 1
    runs = [r for r in np.split(np.arange(x.size), edges) if low[r[0]]]
    turns = [int(r[np.argmin(x[r])]) for r in runs[1:]]  # runs[0]: the pressurised hold; turns[0]: detection's return
    j = int(case.precycle) + int(case.fault_sizes["slip_after_cycle"])
    return turns[j] if j < len(turns) else None


_PHYS0 = h6._physics
_WRITE0 = h6._write


def _physics(case, ctx, t, x_act, noise, kappa):
    """Hold-out 6's force with this module's faults: a delayed force channel, clamp slip, pressure droop, crosstalk."""
    fp, x = case.fault_sizes, x_act
    if "channel-skew" in case.faults:  # the force of skew_s earlier (the path held at its start before t = 0)
        x = np.interp(t - fp["skew_s"], t, x_act)
    if "clamp-slip" in case.faults:
        i = _slip_index(case, x_act)
        if i is not None:
            x = x + fp["slip_mm"] * (np.arange(x.size) > i)
    F, k = _PHYS0(case, ctx, t, x, noise, kappa)
    tr = ctx["truth"]
    if "pressure-droop" in case.faults:  # hold-out 6's force is M(P, k')/lever + ...: swap in the sagging pressure
        Pe = ctx["P"] * (1.0 - fp["droop"] * np.clip(k / ctx["k_free"], 0.0, None))
        F = F + (tr.m(Pe, k) - tr.m(ctx["P"], k)) / h6.lever_mm(0.5 * k * tr.L0)
    if "pressure-crosstalk" in case.faults:
        F = F + _xtalk_n_per_kpa(case, tr) * ctx["P"]
    return F, k


def _patched(case, seed, log):
    fp = case.fault_sizes

    def write(c, P_nom, sim, folder, rep):  # the logged time and force with the export's faults
        rec = {}
        if "clock-error" in c.faults:
            sim = dict(sim, time_s=sim["time_s"] * (c.rate_hz / fp["stated_rate_hz"]))
            c = dataclasses.replace(c, rate_hz=fp["stated_rate_hz"])
        if "mains-spikes" in c.faults:
            rng = np.random.default_rng([int(seed), c.case_id, rep, 9])
            F = sim["force_n"]
            hit = rng.uniform(size=F.size) < fp["spike_rate"]
            size = rng.uniform(fp["spike_min"], fp["spike_max"], F.size)
            size = np.where(rng.uniform(size=F.size) < 0.5, -size, size)  # x the noise's standard deviation
            sim = dict(sim, force_n=F + hit * size * c.noise_fraction * sim["F_b"])
            rec["spikes"] = int(hit.sum())
        log.append(rec)
        return _WRITE0(c, P_nom, sim, folder, rep)

    return gen8.machine_patches(case, _LAWS, _physics, write)


def _run(case, fn, *args, seed=0, log=None):
    return gen8.call_patched(_patched(case, seed, [] if log is None else log), fn, *args)


def _fault_record(case, tr, test, rec) -> dict:
    """What the case's fault did to one test (for the truth)."""
    fp, P = case.fault_sizes, test["pressure_kpa"]
    F_b = _blocked_force(tr, P)
    out = {}
    if "channel-skew" in case.faults:
        out = {"skew_s": fp["skew_s"], "skew_samples": fp["skew_s"] * case.rate_hz}
    if "pressure-crosstalk" in case.faults:
        out = {"crosstalk_force_n": _xtalk_n_per_kpa(case, tr) * P}
        out["crosstalk_fraction_of_blocked"] = out["crosstalk_force_n"] / F_b
    if "clock-error" in case.faults:
        out = {"real_rate_hz": case.rate_hz, "stated_rate_hz": fp["stated_rate_hz"],
               "clock_error": case.rate_hz / fp["stated_rate_hz"] - 1.0}
    if "mains-spikes" in case.faults:
        out = {"spikes": rec["spikes"], "spike_sigma_n": case.noise_fraction * F_b}
    if "clamp-slip" in case.faults:
        out = {"clamp_slip_mm": fp["slip_mm"], "slip_after_logged_cycle": int(fp["slip_after_cycle"])}
    if "pressure-droop" in case.faults:
        out = {"droop_at_free": fp["droop"], "pressure_at_free_kpa": P * (1.0 - fp["droop"])}
    return out


def generate_set(case: Case9, seed: int, folder) -> dict:
    """Write one raw machine file per pressure into ``folder``; returns the truth and the file names.

    Runs hold-out 6's machine with this module's laws, faults and shut-off filter, for the call only
    (:func:`holdout8_generator.generate_logged`).
    """
    return gen8.generate_logged(case, seed, folder, _run, _fault_record, SOURCES, FAULT_SOURCES)


# ---------------------------------------------------------------------------------------------
# checks
# ---------------------------------------------------------------------------------------------
def check_laws(n_cycles: int = 4, points: int = 2000) -> dict:
    """Hold-out 8's check of each case's law alone (:func:`holdout8_generator.check_laws`: loop areas, whether
    it dissipates on every cycle, the change between cycles, the half-width and whether it is 2-6 % of the
    blocked moment), run with this module's cases and laws."""
    return gen8.check_laws(n_cycles, points, CASES, _LAWS)


def check_machine(case: Case9, seed: int = 0) -> dict:
    """Hold-out 8's check of the clean machine's loops (:func:`holdout8_generator.check_machine`), run with this
    module's laws."""
    return gen8.check_machine(case, seed, run=_run)


def _print_checks() -> None:
    gen8.print_checks(check_laws(), CASES, check_machine, 16)


def main(argv=None) -> int:
    return gen8.command(argv, CASES, generate_set, "holdout9_generator.py", _print_checks)


if __name__ == "__main__":
    raise SystemExit(main())
