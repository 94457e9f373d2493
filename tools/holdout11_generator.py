"""Hold-out set 11: raw four-point-bending tests with new loop physics and a lab's instrument and handling faults.

A sixth independent generator of raw testing-machine exports (time, stroke, force at one pressure
per file) for scoring, once, whether bendpam's standard errors hold on data it has never seen.
Like :mod:`holdout10_generator` it reuses :mod:`holdout6_generator` (an earlier independent
generator) for everything but the loop laws, the faults and the cases: the truth (``MomentLaw`` of
the preset with alpha0 + 0.45-0.8 deg, ``S`` x 0.95-1.05, ``shape = C01/S`` in 0.43-0.59), the
fixture (paper eq 6-8), the machine (pressurised hold, detection of the free state at a detection
load, the stroke waveforms, the clocks), the noise filters and the export writers (dialects); and
from :mod:`holdout8_generator` its case builder, its rate ``du/d(t/t_half)``, its law and machine
checks and its patching helpers.  As in hold-outs 7-10 the controller's force shut-off reads a
causal 1 s moving average of the force.

Measured moment = quasi-static ``M(P, k')`` of the truth - ``kappa z`` + instrument effects, ``z``
the loop law of the case driven by ``u = k'/k'_ref`` (``k'_ref`` the free curvature at the median
pressure; ``landau-khalatnikov``, ``liang-rogers`` and ``jkr-adhesion`` use the test's own free
curvature ``k'_free``, so that their thresholds keep their place in each test's span) and, for the
rate-dependent laws, by time in units of ``t_half`` (the time of a release stroke at the case's
speed); ``z`` is positive while releasing (``k'`` increasing), so each cycle dissipates.  ``kappa``
sets ``max|z| = loop_fraction x M_blocked`` on a reference triangle 0 -> k'_free -> 0 (twice), per
test, as in hold-out 6.  The loop half-width (half the gap between the return and the release
branch, averaged over the middle 80 % of the stroke) is 3.1-3.5 % of the blocked moment for every
law on the reference triangle (the band :data:`HALF_WIDTH_BAND`, 2.8-4.0 %, is hold-out 10's), and
every law dissipates on every cycle (:func:`check_laws`); on the machine's own strokes and speeds it
is 2.1-5.2 % (:func:`check_machine`; the high end is ``hunt-crossley`` at the lowest pressure, whose
span in ``u`` is short, so its weight ``delta^1.5`` varies less than on the reference triangle).

The laws and faults were chosen outside the families of the earlier sets (the list of main and
hold-outs 1-10 it was given; hold-outs 6-10 read here): no friction model of the Dahl, LuGre,
Maxwell-slip, Stribeck, Bliman-Sorine, rate-and-state or Prandtl-Tomlinson kinds, no hysteron
population of the Preisach, Krasnosel'skii-Pokrovskii or Stoner-Wohlfarth kinds, no Masing, Bouc-Wen,
Duhem, plasticity, linear-spectrum viscoelastic, Mullins, Payne/Kraus or thixotropic law.  The
faults avoid load-cell offsets, gains, nonlinearity and quantisation, every clock and row fault,
the pressure faults of hold-outs 5-10 and the rig faults of hold-out 6.

Loop laws (``z(t, k, ctx, params)``, one small function each)
-------------------------------------------------------------
Rate dependent (``v = du/d(t/t_half)``, ``tau = t/t_half``):

* ``giesekus``: the lubricant (a silicone oil, a polymer liquid) sheared in the film between the
  bladder and the braid, Giesekus' fluid in simple shear (H. Giesekus, "A simple constitutive
  equation for polymer fluids based on the concept of deformation-dependent tensorial mobility",
  J. Non-Newtonian Fluid Mech. 11, 69-109, 1982; R.B. Bird, R.C. Armstrong, O. Hassager, Dynamics
  of Polymeric Liquids, Vol. 1, 2nd ed., Wiley, 1987): the upper-convected stresses ``tau_xx,
  tau_xy, tau_yy`` with the quadratic mobility term ``alpha/G tau.tau``, shear rate ``g = Gamma v``;
  ``z = tau_xy``.  lam = 0.5 t_half, Gamma = 4 (Weissenberg number 2 at the reference speed),
  alpha = 0.4, at rest at the start; Runge-Kutta at a constant rate over each step.  Shear
  thinning, normal stresses that feed back on the shear stress, a stress overshoot after a start
  from rest.
* ``schallamach-bonds``: the adhesive friction of the bladder's rubber on the yarns, molecular bonds
  that attach unstretched, are stretched by the sliding and break under their force (A. Schallamach,
  "A theory of dynamic rubber friction", Wear 6, 375-382, 1963; Y.B. Chernyak, A.I. Leonov, "On the
  theory of the adhesive friction of elastomers", Wear 108, 105-138, 1986), with Bell's
  force-activated rupture (G.I. Bell, "Models for the specific adhesion of cells to cells", Science
  200, 618-627, 1978): cohorts of bonds born at the rate ``k_on (1 - N)``, each with stretch ``s``
  (``ds = du``) and rupture rate ``k0 exp(|s|/s_b)``; ``z = sum n s``.  k_on = 30, k0 = 2 per
  t_half, s_b = 0.03, rested at the start; each step exact at its mid-step stretch.  At rest the
  stretched bonds relax, the unstretched ones come back; after each reversal the friction turns
  over within ~0.07 of ``u``.
* ``landau-khalatnikov``: the wrinkles of the bladder's wall on the compressed side as bistable
  elements with viscous relaxation, Landau-Khalatnikov (time-dependent Ginzburg-Landau) dynamics
  in a double well (L.D. Landau, I.M. Khalatnikov, "On the anomalous absorption of sound near a
  second order phase transition point", Dokl. Akad. Nauk SSSR 96, 469-472, 1954; P. Jung, G. Gray,
  R. Roy, P. Mandel, "Scaling law for dynamical hysteresis", Phys. Rev. Lett. 65, 1873-1876, 1990):
  ``eta dq_i/dtau = f - b_i + q_i - q_i^3``, ``f = H (2 k'/k'_free - 1)``, 8 elements with biases
  ``b_i`` evenly over -0.25..0.25, H = 0.8, eta = 0.05; ``z`` = the mean over the elements of the
  quasi-static major loop's centre (closed form, Cardano) - ``q_i``.  Each element snaps at its
  spinodal ``|f - b_i| = 2/(3 sqrt 3)``, delayed by the viscosity (wider when faster); backward
  Euler (one real root, Cardano).
* ``hunt-crossley``: contact damping of the braid's yarns pressed into the bladder (K.H. Hunt,
  F.R.E. Crossley, "Coefficient of restitution interpreted as damping in vibroimpact", J. Appl. Mech.
  42, 440-445, 1975): ``z = delta^n v`` with the indentation ``delta = d0 + (1 - d0) u``, n = 1.5
  (Hertz), d0 = 0.3 (the Hertzian elastic part is single-valued and belongs to the quasi-static
  moment).  A lens 6 x wider at the free end than at the blocked one (on the reference triangle),
  closed at every turn.
* ``grosch-friction``: the viscoelastic (hysteresis) friction of rubber sliding over the yarns'
  asperities, a bell over the logarithm of the sliding speed (K.A. Grosch, "The relation between the
  friction and visco-elastic properties of rubber", Proc. R. Soc. Lond. A 274, 21-39, 1963, whose
  master curve is shifted by the WLF equation: M.L. Williams, R.F. Landel, J.D. Ferry, J. Am. Chem.
  Soc. 77, 3701-3707, 1955): ``z = mu(|v|) tanh(v/v_eps)``, ``mu = mu_min + (1 - mu_min) exp(-(log10
  (|v|/v_peak))^2/(2 w^2))``, v_peak = 1.5 (the room's temperature shift folded in), w = 0.8
  decades, mu_min = 0.15, v_eps = 0.02.  On its case's haversine stroke the friction follows the
  speed through its bell.

Rate independent:

* ``liang-rogers``: strain-induced crystallisation of a natural-rubber (latex) bladder, which
  crystallises on stretching at a larger stretch than it melts on retraction (S. Toki, T. Fujimaki,
  M. Okuyama, "Strain-induced crystallization of natural rubber as detected real-time by wide-angle
  X-ray diffraction technique", Polymer 41, 5423-5429, 2000), with the cosine transformation
  kinetics of Liang and Rogers (C. Liang, C.A. Rogers, "One-dimensional thermomechanical
  constitutive relations for shape memory materials", J. Intell. Mater. Syst. Struct. 1, 207-234,
  1990) scaled from each reversal as Brinson does (L.C. Brinson, J. Intell. Mater. Syst. Struct. 4,
  229-242, 1993): ``s = k'/k'_free``, crystallising between s = 0.3 and 0.95, melting between 0.7
  and 0.05, amorphous at the start; ``z`` = the major loop's centre - the crystallised share.
  Closed at both ends, wide open over the middle (half-gap up to the whole of max|z|).
* ``jkr-adhesion``: the folds of the bladder on the compressed side touch and stick as it bends, each
  a JKR adhesive contact (K.L. Johnson, K. Kendall, A.D. Roberts, "Surface energy and the contact of
  elastic solids", Proc. R. Soc. Lond. A 324, 301-313, 1971; D. Maugis, "Adhesion of spheres: the
  JKR-DMT transition using a Dugdale model", J. Colloid Interface Sci. 150, 243-269, 1992, for the
  dimensionless form): under a fixed approach a fold jumps into contact at zero approach and holds on
  to the pull-off approach -0.908 (force -0.833 x pi w R), the force on Maugis' curve ``P = A^3 -
  A sqrt(6A)``, ``delta = A^2 - (2/3) sqrt(6A)`` in between.  40 folds touching at ``u = k'/k'_free``
  = 0.1-1.0, 0.25 of ``u`` per unit approach; ``z`` = the mean of (force - the centre of its two
  branches): a saw-tooth band (each fold's jump 1/40 of the sum).
* ``burridge-knopoff``: the braid's yarn crossings as a ring of stick-slip sites coupled through the
  yarns, the quasi-static spring-block model of Burridge and Knopoff in the cellular form of Olami,
  Feder and Christensen (R. Burridge, L. Knopoff, "Model and theoretical seismicity", Bull. Seismol.
  Soc. Am. 57, 341-371, 1967; Z. Olami, H.J.S. Feder, K. Christensen, "Self-organized criticality in
  a continuous, nonconservative cellular automaton modeling earthquakes", Phys. Rev. Lett. 68,
  1244-1247, 1992): 32 sites loaded by the drive (stiffness 25 per unit u), thresholds 0.85-1.15
  (golden-ratio order round the ring), a slipping site drops to half its threshold and passes 0.8
  of the drop to its two neighbours, which may slip in turn (an avalanche); ``z`` = the mean stress.
  A stick-slip band with avalanche steps, presliding over ~0.07 of ``u`` after each reversal.

Instrument and lab faults (each in one case; the rest of the lab is careful: pressure as declared,
load cell tared, no self-weight, no rig faults)
------------------------------------------------------------------------------------------------------
* ``load-cell-creep``: the load cell's output creeps under load (the creep test of OIML R 60): the
  reading is ``F + C`` x ``F`` low-passed with ``tau`` from the machine's start (the cell zeroed
  unloaded), C = +0.3 %, tau = 120 s (a low-grade cell, at the high end); the controller reads it.
  ``creep_share_at_last_row`` is ``1 - exp(-t_last/tau)``.
* ``load-cell-hysteresis``: the cell's own hysteresis (reversibility) error (OIML R 60, ISO 376):
  ``E (y - F)/r`` added, ``y`` a play of half-width ``r`` on the force, so the reading is ``E`` low
  on a rising force, ``E`` high on a falling one; ``E`` = 0.2 %, ``r`` = 10 % of the blocked force at
  the case's median pressure (the same cell for the series; 0.12-0.64 % of each test's own blocked
  force).  Reading high on the release (a falling force), it narrows the actuator's loop.  The
  controller reads it.
* ``operator-pause``: the operator pauses the test during the release of logged cycle 2 at 55 % of
  the stroke, for 25 s, then resumes (``pause_start_s`` on the log's clock, ``pause_stroke_mm``):
  the rate-dependent loop relaxes during the stop.
* ``results-block``: the export (MTS TestSuite) appends the software's per-cycle results table after
  the series, a second block with its own header and units (cycle, largest stroke, force there).
* ``fixture-expansion``: the fixture and the frame warm by 8 K (a climate chamber not yet
  equilibrated) with a 600 s time constant from the machine's start: 300 mm x 20e-6/K grows by up
  to 0.048 mm, so the plates sit that much further bent than the crosshead's stroke says
  (``expansion_at_first_row_mm``, ``expansion_at_last_row_mm``).
* ``speed-misset``: the operator set 40 mm/min at the console while the method (and the export's
  header) says 50 mm/min: the machine ran at the real speed, the file states the method's.
* ``regulator-hysteresis``: the regulator's outlet pressure depends on the direction of the flow (the
  hysteresis of its flow characteristic, cf. ISO 6953-1): ``P (1 - band tanh(q/q_eps))``,
  band = 0.6 %, ``q`` the rate of the actuator's volume (``dM/dP dk'/dt``, paper eq 13) over its
  value at the reference stroke, q_eps = 0.05; at the set pressure while the stroke stands.  The
  file states the set pressure.

Force noise otherwise as hold-out 6 (white, AR(1), pink; 0.5-3 % of the blocked force), 2 um stroke
noise, 3-5 cycles, sampling at 10-50 Hz, eight export dialects (one per case).  ``drift_fraction``
(hold-out 6's linear drift) is 0 in every case.

Cases (8; 35 files a seed, each case's seed in 0.04-3.2 s)
-----------------------------------------------------------
======================== ====== ============= ================ ================== ==================== ======= =========
case                     preset model         pressures (kPa)  law                fault                noise   dialect
======================== ====== ============= ================ ================== ==================== ======= =========
h11-giesekus-creep       BE     energy        100-200 (5)      giesekus           load-cell-creep      1 % w   zwick-de
h11-schallamach-hyst     BC     force_balance 50-130 (5)       schallamach-bonds  load-cell-hysteresis 1.2 % a bluehill
h11-lk-pause             BE     force_balance 95-215 (4)       landau-khalatnikov operator-pause       0.8 % p csv
h11-huntcrossley-results BC     energy        45-145 (6)       hunt-crossley      results-block        1.5 % w mts-ts
h11-liangrogers-thermal  BE     energy        100-200 (3)      liang-rogers       fixture-expansion    2 % a   trapezium
h11-jkr-adhesion         BC     force_balance 50-125 (4)       jkr-adhesion       (none)               0.6 % w mts-basic
h11-bk-regulator         BE     force_balance 105-195 (4)      burridge-knopoff   regulator-hysteresis 3 % p   zwick-en
h11-grosch-speed         BC     energy        55-130 (4)       grosch-friction    speed-misset         0.5 % w instron
======================== ====== ============= ================ ================== ==================== ======= =========

(w white, a AR(1), p pink.)  Waveforms: trapvel, haversine, tri-asym (with the pause), trapvel,
tri-dwell, haversine, trap-hold-free, haversine.

``python tools/holdout11_generator.py OUT [SEED]`` writes one seed of every case into OUT/<case>/
with ``truth.json``; ``python tools/holdout11_generator.py --check`` prints the laws' dissipation,
periodicity and half-width table and the clean machine's loop table.
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
import math
import sys
from pathlib import Path
from unittest import mock

import numpy as np
from scipy import signal

if str(Path(__file__).resolve().parent) not in sys.path:
    sys.path.insert(0, str(Path(__file__).resolve().parent))
import holdout8_generator as gen8
from holdout7_generator import h6

__all__ = ["CASES", "Case11", "check_laws", "check_machine", "generate_set", "start_actuator", "truth_actuator"]


# ---------------------------------------------------------------------------------------------
# rate-dependent loop laws: z(t, k, ctx, params), positive while k increases; scaled by the machine
# ---------------------------------------------------------------------------------------------
def _giesekus_rate(x, g, p):
    """d(tau_xx, tau_xy, tau_yy)/d(t/t_half) of Giesekus' fluid in simple shear at the shear rate ``g`` (the modulus
    1, the relaxation time ``lam``, the mobility ``alpha``)."""
    xx, xy, yy = x
    lam, al = p["lam"], p["alpha"]
    return (2.0 * g * xy - (xx + al * (xx * xx + xy * xy)) / lam,
            g * (yy + 1.0) - (xy + al * xy * (xx + yy)) / lam,
            -(yy + al * (xy * xy + yy * yy)) / lam)


def _law_giesekus(t, k, ctx, p):
    u = (k / ctx["k_ref"]).tolist()
    dtau = ctx["dt"] / ctx["t_half"]
    n_sub = max(1, math.ceil(dtau / (0.05 * p["lam"])))
    h = dtau / n_sub
    x = (0.0, 0.0, 0.0)  # at rest at the start
    out = [0.0]
    for a, b in itertools.pairwise(u):
        g = p["gamma"] * (b - a) / dtau  # the shear rate over the step (per t_half)
        for _ in range(n_sub):  # classical Runge-Kutta
            k1 = _giesekus_rate(x, g, p)
            k2 = _giesekus_rate([xi + 0.5 * h * ki for xi, ki in zip(x, k1, strict=True)], g, p)
            k3 = _giesekus_rate([xi + 0.5 * h * ki for xi, ki in zip(x, k2, strict=True)], g, p)
            k4 = _giesekus_rate([xi + h * ki for xi, ki in zip(x, k3, strict=True)], g, p)
            x = tuple(xi + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
                      for xi, a1, a2, a3, a4 in zip(x, k1, k2, k3, k4, strict=True))
        out.append(x[1])
    return np.array(out)


def _law_schallamach(t, k, ctx, p):
    u = k / ctx["k_ref"]
    dtau = ctx["dt"] / ctx["t_half"]
    kon, k0, sb = p["k_on"], p["k0"], p["s_b"]
    w = np.array([kon / (kon + k0)])  # rested: the equilibrium share of bonds, unstretched
    s = np.zeros(1)
    born_share = 1.0 - math.exp(-kon * dtau)
    out = np.zeros(u.size)
    for i in range(1, u.size):
        du = float(u[i] - u[i - 1])
        s_mid = s + 0.5 * du
        w = w * np.exp(-k0 * dtau * np.exp(np.minimum(np.abs(s_mid) / sb, 60.0)))  # Bell: rupture under force
        s = s + du
        born = (1.0 - float(w.sum())) * born_share
        if s[-1] == 0.0:  # at rest: the new bonds join the unstretched cohort
            w[-1] += born
        else:
            w, s = np.append(w, born), np.append(s, 0.0)
        if i % 64 == 0:
            keep = w > 1e-12
            keep[-1] = True
            w, s = w[keep], s[keep]
        out[i] = float(w @ s)
    return out


@functools.lru_cache(maxsize=4)
def _lk_biases(n, spread):
    return np.linspace(-spread, spread, int(n))


def _lk_branches(f, b):
    """The quasi-static branches of ``q^3 - q = f - b``: the rising one (the lowest root while it exists) and the
    falling one (the highest), as arrays over (samples, elements)."""
    s = f[:, None] - b[None, :]
    c = 2.0 / math.sqrt(3.0)
    x = 1.5 * math.sqrt(3.0) * s
    th = np.arccos(np.clip(x, -1.0, 1.0))
    hi3, lo3 = c * np.cos(th / 3.0), c * np.cos(th / 3.0 + 2.0 * math.pi / 3.0)
    one = np.sign(s) * c * np.cosh(np.arccosh(np.maximum(np.abs(x), 1.0)) / 3.0)  # the single root
    three = np.abs(x) <= 1.0
    return np.where(three, lo3, one), np.where(three, hi3, one)


def _law_landau_khalatnikov(t, k, ctx, p):
    f = p["H"] * (2.0 * k / ctx["k_free"] - 1.0)
    b = _lk_biases(p["n"], p["spread"])
    dtau = ctx["dt"] / ctx["t_half"]
    n_sub = max(1, math.ceil(2.0 * dtau / p["eta"]))
    h = dtau / n_sub
    c = p["eta"] / h - 1.0  # > 0: backward Euler's cubic has one real root
    rising, _ = _lk_branches(f[:1], b)
    q = rising[0].copy()  # from the lower branch at the start
    out = np.empty((f.size, b.size))
    out[0] = q
    for i in range(1, f.size):
        for j in range(n_sub):
            fi = f[i - 1] + (f[i] - f[i - 1]) * (j + 1) / n_sub
            r = fi - b + p["eta"] / h * q  # q^3 + c q = r (Cardano, one real root)
            d = np.sqrt(0.25 * r * r + (c / 3.0) ** 3)
            q = np.cbrt(0.5 * r + d) + np.cbrt(0.5 * r - d)
        out[i] = q
    rising, falling = _lk_branches(f, b)
    return (0.5 * (rising + falling) - out).mean(axis=1)


def _law_hunt_crossley(t, k, ctx, p):
    u = k / ctx["k_ref"]
    delta = p["d0"] + (1.0 - p["d0"]) * np.clip(u, 0.0, None)  # the yarns' indentation into the bladder
    return delta ** p["n"] * gen8._rate(u, ctx)


def _law_grosch(t, k, ctx, p):
    v = gen8._rate(k / ctx["k_ref"], ctx)
    decades = np.log10(np.abs(v) / p["v_peak"] + 1e-12)
    mu = p["mu_min"] + (1.0 - p["mu_min"]) * np.exp(-0.5 * (decades / p["width"]) ** 2)
    return mu * np.tanh(v / p["v_eps"])


# ---------------------------------------------------------------------------------------------
# rate-independent loop laws
# ---------------------------------------------------------------------------------------------
def _lr_up(s, p):
    """Liang-Rogers' crystallised share on the major rising branch (cosine kinetics from ``s_cs`` to ``s_cf``)."""
    x = np.clip((s - p["s_cs"]) / (p["s_cf"] - p["s_cs"]), 0.0, 1.0)
    return 0.5 * (1.0 - np.cos(math.pi * x))


def _lr_down(s, p):
    """The share on the major falling branch (melting from ``s_ms`` down to ``s_mf``)."""
    x = np.clip((p["s_ms"] - s) / (p["s_ms"] - p["s_mf"]), 0.0, 1.0)
    return 0.5 * (1.0 + np.cos(math.pi * x))


def _law_liang_rogers(t, k, ctx, p):
    s = np.clip(k / ctx["k_free"], 0.0, None)
    xi = np.empty_like(s)
    x0 = 0.0  # amorphous at the start
    for a, b, d in h6._segments(s):
        s0 = float(s[a - 1]) if a else float(s[0])
        seg = s[a:b]
        if d > 0:  # crystallising: the rest of the way to 1, scaled from the reversal (Brinson)
            g0 = float(_lr_up(s0, p))
            xi[a:b] = x0 + (1.0 - x0) * (_lr_up(seg, p) - g0) / (1.0 - g0) if g0 < 1.0 else x0
        else:  # melting: in proportion to the falling branch from the reversal
            h0 = float(_lr_down(s0, p))
            xi[a:b] = x0 * _lr_down(seg, p) / h0 if h0 > 0.0 else x0
        x0 = float(xi[b - 1])
    return 0.5 * (_lr_up(s, p) + _lr_down(s, p)) - xi


@functools.lru_cache(maxsize=2)
def _jkr_table():
    """Maugis' dimensionless JKR curve on its branch stable under a fixed approach, (approach, force), from the
    pull-off point (contact radius ``A = 6^(-1/3)``, where the approach is least) up."""
    A = np.linspace((math.sqrt(6.0) / 6.0) ** (2.0 / 3.0), 3.0, 4001)
    return A * A - 2.0 / 3.0 * np.sqrt(6.0 * A), A**3 - A * np.sqrt(6.0 * A)


def _law_jkr(t, k, ctx, p):
    d_tab, f_tab = _jkr_table()
    off = float(d_tab[0])  # the pull-off approach, -0.908
    ui = np.linspace(p["u_min"], p["u_max"], int(p["n"]))
    D = (k / ctx["k_free"])[:, None] / p["scale"] - (ui / p["scale"])[None, :]  # each fold's approach
    state = D[0] >= 0.0  # apart at the start (no fold touches at u = 0)
    touch = np.empty(D.shape, dtype=bool)
    for a, b, d in h6._segments(k):
        if d > 0:  # closing: a fold jumps into contact at zero approach
            y = state[None, :] | (np.maximum.accumulate(D[a:b], axis=0) >= 0.0)
        else:  # opening: it holds on until the pull-off approach
            y = state[None, :] & (np.minimum.accumulate(D[a:b], axis=0) > off)
        touch[a:b] = y
        state = y[-1]
    F = np.interp(D, d_tab, f_tab)
    window = (D >= off) & (D < 0.0)  # where the two branches differ
    return np.where(window, np.where(touch, 0.5 * F, -0.5 * F), 0.0).mean(axis=1)


@functools.lru_cache(maxsize=2)
def _bk_sites(n, spread):
    """The sites' slip thresholds: evenly spread, placed round the ring by the golden ratio."""
    q = np.linspace(1.0 - spread, 1.0 + spread, int(n))
    return q[np.argsort((np.arange(int(n)) * 0.6180339887498949) % 1.0)]


def _law_burridge_knopoff(t, k, ctx, p):
    u = (k / ctx["k_ref"]).tolist()
    th = _bk_sites(p["n"], p["spread"])
    res, kd, share = p["residual"] * th, p["k_drive"], 0.5 * p["alpha"]
    sig = np.zeros(th.size)  # unloaded at the start
    out = [0.0]
    for a, b in itertools.pairwise(u):
        sig = sig + kd * (b - a)
        over = np.abs(sig) > th
        while over.any():  # an avalanche: each slipping site drops to its residual, its neighbours take a share
            drop = np.where(over, sig - np.sign(sig) * res, 0.0)
            sig = sig - drop + share * (np.roll(drop, 1) + np.roll(drop, -1))
            over = np.abs(sig) > th
        out.append(float(sig.mean()))
    return np.array(out)


_LAWS = {"giesekus": _law_giesekus, "schallamach-bonds": _law_schallamach,
         "landau-khalatnikov": _law_landau_khalatnikov, "hunt-crossley": _law_hunt_crossley,
         "grosch-friction": _law_grosch, "liang-rogers": _law_liang_rogers, "jkr-adhesion": _law_jkr,
         "burridge-knopoff": _law_burridge_knopoff}

SOURCES = {
    "giesekus": "H. Giesekus, J. Non-Newtonian Fluid Mech. 11 (1982) 69; R.B. Bird, R.C. Armstrong, O. Hassager, "
                "Dynamics of Polymeric Liquids, Vol. 1, 2nd ed. (1987)",
    "schallamach-bonds": "A. Schallamach, Wear 6 (1963) 375; Y.B. Chernyak, A.I. Leonov, Wear 108 (1986) 105; "
                         "G.I. Bell, Science 200 (1978) 618",
    "landau-khalatnikov": "L.D. Landau, I.M. Khalatnikov, Dokl. Akad. Nauk SSSR 96 (1954) 469; P. Jung, G. Gray, "
                          "R. Roy, P. Mandel, Phys. Rev. Lett. 65 (1990) 1873",
    "hunt-crossley": "K.H. Hunt, F.R.E. Crossley, J. Appl. Mech. 42 (1975) 440",
    "grosch-friction": "K.A. Grosch, Proc. R. Soc. Lond. A 274 (1963) 21; M.L. Williams, R.F. Landel, J.D. Ferry, "
                       "J. Am. Chem. Soc. 77 (1955) 3701",
    "liang-rogers": "C. Liang, C.A. Rogers, J. Intell. Mater. Syst. Struct. 1 (1990) 207; L.C. Brinson, J. Intell. "
                    "Mater. Syst. Struct. 4 (1993) 229; S. Toki, T. Fujimaki, M. Okuyama, Polymer 41 (2000) 5423",
    "jkr-adhesion": "K.L. Johnson, K. Kendall, A.D. Roberts, Proc. R. Soc. Lond. A 324 (1971) 301; D. Maugis, "
                    "J. Colloid Interface Sci. 150 (1992) 243",
    "burridge-knopoff": "R. Burridge, L. Knopoff, Bull. Seismol. Soc. Am. 57 (1967) 341; Z. Olami, H.J.S. Feder, "
                        "K. Christensen, Phys. Rev. Lett. 68 (1992) 1244",
}

FAULT_SOURCES = {
    "load-cell-creep": "the load cell's creep under load, first order (the creep test of OIML R 60)",
    "load-cell-hysteresis": "the load cell's own hysteresis (reversibility) error: it reads higher on a falling "
                            "than on a rising force (cf. OIML R 60, ISO 376)",
    "operator-pause": "the operator pauses the test mid-stroke (the crosshead holds), then resumes it",
    "results-block": "the export appends the software's per-cycle results table after the series: a second block",
    "fixture-expansion": "the fixture and frame warming during the test: linear thermal expansion alpha L dT(t) "
                         "between the crosshead and the plates",
    "speed-misset": "the speed set at the console differs from the method's, which the export's header states",
    "regulator-hysteresis": "the regulator's outlet pressure depends on the flow's direction (the hysteresis of its "
                            "flow characteristic, cf. ISO 6953-1)",
}


# ---------------------------------------------------------------------------------------------
# cases
# ---------------------------------------------------------------------------------------------
class Case11(gen8.Case8):
    """A hold-out-6 case (same attributes) whose ``loop`` names one of this module's laws and whose
    ``faults`` name this module's instrument and lab faults, sized by ``fault_params`` (hold-out 8's case,
    whose builder it shares)."""


def _c(*args, **kw) -> Case11:
    return gen8._c(*args, cls=Case11, **kw)


CASES: dict[str, Case11] = {c.name: c for c in [
    _c("h11-giesekus-creep", "be-pam", "energy", (100, 125, 150, 175, 200), "giesekus", 0.064, 0.010, 0.0,
       "zwick-de", 4, 25.0, 0.47, 1101, 0.6, 1.01, "trapvel", 40.0, 40.0, 20.0, 0.2, "white",
       {"lam": 0.5, "gamma": 4.0, "alpha": 0.4}, faults=("load-cell-creep",),
       fault_params={"creep": 0.003, "tau_s": 120.0}),
    _c("h11-schallamach-hyst", "bc-pam", "force_balance", (50, 70, 90, 110, 130), "schallamach-bonds", 0.05, 0.012,
       0.6, "bluehill", 5, 20.0, 0.54, 1102, 0.7, 0.97, "haversine", 45.0, 45.0, 20.0, 0.25, "ar1",
       {"k_on": 30.0, "k0": 2.0, "s_b": 0.03}, faults=("load-cell-hysteresis",),
       fault_params={"error_fraction": 0.002, "band_fraction": 0.1}, log_detection=False),
    _c("h11-lk-pause", "be-pam", "force_balance", (95, 135, 175, 215), "landau-khalatnikov", 0.058, 0.008, 0.0,
       "csv", 4, 50.0, 0.56, 1103, 0.45, 1.04, "tri-asym", 40.0, 55.0, 20.0, 0.25, "pink",
       {"n": 8, "spread": 0.25, "H": 0.8, "eta": 0.05}, faults=("operator-pause",),
       fault_params={"pause_cycle": 2, "at_fraction": 0.55, "pause_s": 25.0}, log_detection=False, L0_mm=150.0),
    _c("h11-huntcrossley-results", "bc-pam", "energy", (45, 65, 85, 105, 125, 145), "hunt-crossley", 0.058, 0.015,
       0.0, "mts-ts", 3, 20.0, 0.43, 1104, 0.8, 1.0, "trapvel", 50.0, 50.0, 25.0, 0.2, "white",
       {"d0": 0.3, "n": 1.5}, faults=("results-block",), log_detection=False),
    _c("h11-liangrogers-thermal", "be-pam", "energy", (100, 150, 200), "liang-rogers", 0.062, 0.020, 0.5,
       "trapezium", 5, 10.0, 0.59, 1105, 0.65, 0.98, "tri-dwell", 40.0, 40.0, 20.0, 0.3, "ar1",
       {"s_cs": 0.3, "s_cf": 0.95, "s_ms": 0.7, "s_mf": 0.05}, faults=("fixture-expansion",),
       fault_params={"alpha_per_k": 20e-6, "length_mm": 300.0, "dT_k": 8.0, "tau_s": 600.0}, dwell_s=2.0),
    _c("h11-jkr-adhesion", "bc-pam", "force_balance", (50, 75, 100, 125), "jkr-adhesion", 0.037, 0.006, 0.0,
       "mts-basic", 4, 25.0, 0.5, 1106, 0.5, 1.05, "haversine", 50.0, 50.0, 25.0, 0.2, "white",
       {"n": 40, "u_min": 0.1, "u_max": 1.0, "scale": 0.25}, log_detection=False),
    _c("h11-bk-regulator", "be-pam", "force_balance", (105, 135, 165, 195), "burridge-knopoff", 0.036, 0.030, 0.0,
       "zwick-en", 3, 20.0, 0.52, 1107, 0.75, 0.95, "trap-hold-free", 45.0, 45.0, 20.0, 0.2, "pink",
       {"n": 32, "spread": 0.15, "residual": 0.5, "k_drive": 25.0, "alpha": 0.8}, faults=("regulator-hysteresis",),
       fault_params={"band": 0.006, "flow_eps": 0.05}, log_detection=False, dwell_s=3.0, L0_mm=140.0),
    _c("h11-grosch-speed", "bc-pam", "energy", (55, 80, 105, 130), "grosch-friction", 0.033, 0.005, 0.0,
       "instron-console", 4, 25.0, 0.45, 1108, 0.6, 1.02, "haversine", 40.0, 40.0, 20.0, 0.1, "white",
       {"v_peak": 1.5, "width": 0.8, "mu_min": 0.15, "v_eps": 0.02}, faults=("speed-misset",),
       fault_params={"stated_speed_mm_min": 50.0}),
]}


#: The preset with the case's geometry changes (not the truth's constants), and the truth: hold-out 8's.
start_actuator, truth_actuator = gen8.start_actuator, gen8.truth_actuator


# ---------------------------------------------------------------------------------------------
# instrument and lab faults (hold-out 6's machine, patched for the call)
# ---------------------------------------------------------------------------------------------
_blocked_force = gen8._blocked_force
_PHYS0 = h6._physics
_WRITE0 = h6._write
_CYCLES0 = h6._cycles


def _expansion_mm(fp, t):
    """The fixture's thermal growth (mm) at machine time ``t``: ``alpha L dT (1 - exp(-t/tau))``."""
    return fp["alpha_per_k"] * fp["length_mm"] * fp["dT_k"] * (1.0 - np.exp(-np.asarray(t) / fp["tau_s"]))


def _creep(F, dt, fp):
    """The load cell's reading with its creep: ``F + C`` x ``F`` low-passed with ``tau`` (from the machine's start,
    where the cell was zeroed unloaded)."""
    a = math.exp(-dt / fp["tau_s"])
    return F + fp["creep"] * signal.lfilter([1.0 - a], [1.0, -a], F)


def _cell_hysteresis(F, F_ref, fp):
    """The reading with the cell's hysteresis: a play of half-width ``band`` on the force; the error runs from
    ``-E`` (rising force) to ``+E`` (falling), ``E = error_fraction x F_ref``, ``band = band_fraction x F_ref``."""
    r = fp["band_fraction"] * F_ref
    y, out = float(F[0]), np.empty(F.size)
    for i, f in enumerate(F.tolist()):
        y = min(max(y, f - r), f + r)
        out[i] = y
    return F + fp["error_fraction"] * F_ref * (out - F) / r


def _regulator(tr, ctx, k, fp):
    """The pressure with the regulator's hysteresis band: ``P (1 - band w)``, ``w = tanh(q/flow_eps)`` the
    direction of the air's flow, ``q`` the volume's rate (``dM/dP dk'/dt``, paper eq 13) over its value at the
    reference stroke (``dM/dP`` at k' = 0, ``k'_free`` per ``t_half``)."""
    P = ctx["P"]
    q = tr.dm_dp(P, k) * np.gradient(k, ctx["dt"]) / (float(tr.dm_dp(P, 0.0)) * ctx["k_free"] / ctx["t_half"])
    return P * (1.0 - fp["band"] * np.tanh(q / fp["flow_eps"]))


def _paused_cycles(case, rec):
    """Hold-out 6's cycles (``tri-asym``) with the operator's pause: in logged cycle ``pause_cycle`` the release
    stops at ``at_fraction`` of the stroke for ``pause_s``."""
    fp = case.fault_sizes

    def cycles(prog, c, s_amp, n):
        if n != c.cycles:  # the pre-cycle and the one-cycle plan: no pause
            return _CYCLES0(prog, c, s_amp, n)
        for i in range(n):
            if i + 1 == int(fp["pause_cycle"]):
                s_p = fp["at_fraction"] * s_amp
                prog.move(0.0, s_p, c.speed_mm_min, "linear")
                rec.update(pause_start_s=prog.t, pause_stroke_mm=s_p)
                prog.hold(s_p, fp["pause_s"])
                prog.move(s_p, s_amp, c.speed_mm_min, "linear")
                prog.move(s_amp, 0.0, c.return_speed_mm_min, "linear")
            else:
                _CYCLES0(prog, c, s_amp, 1)
        return None

    return cycles


def _results_block(x, F, cycles):
    """The per-cycle results table: for each stay above half the largest stroke (a cycle), its largest stroke and
    the force there; at most ``cycles`` rows."""
    top = x > 0.5 * float(np.max(x))
    edges = np.flatnonzero(np.diff(top.astype(np.int8))) + 1
    rows = []
    for r in np.split(np.arange(x.size), edges):
        if top[r[0]]:
            i = int(r[np.argmax(x[r])])
            rows.append((float(x[i]), float(F[i])))
    return rows[:cycles]


def _append_results(path: Path, rows) -> None:
    """Append the results table to an MTS TestSuite export (force in kN)."""
    lines = ["", "Results", '"Cycle","Max. Crosshead","Force at Max. Crosshead"', '"","mm","kN"']
    lines += [f"{i + 1},{x:.4f},{F / 1000.0:.8f}" for i, (x, F) in enumerate(rows)]
    with path.open("a", encoding="utf-8") as fh:
        fh.write("\n".join(lines) + "\n")


def _patched(case, seed, log):
    last: dict = {}

    def physics(c, ctx, t, x_act, noise, kappa):  # the plates' path, the pressure and the load cell's reading
        fp, tr = c.fault_sizes, ctx["truth"]
        if "fixture-expansion" in c.faults:  # the plates sit delta further bent than the crosshead says
            x_act = x_act + _expansion_mm(fp, t)
        F, k = _PHYS0(c, ctx, t, x_act, noise, kappa)
        if "regulator-hysteresis" in c.faults:
            Pe = _regulator(tr, ctx, k, fp)
            F = F + (tr.m(Pe, k) - tr.m(ctx["P"], k)) / h6.lever_mm(0.5 * k * tr.L0)
            last["pressure_range_kpa"] = [float(np.min(Pe)), float(np.max(Pe))]
        if "load-cell-creep" in c.faults:  # the reading: the controller sees it too
            F = _creep(F, ctx["dt"], fp)
        if "load-cell-hysteresis" in c.faults:
            F = _cell_hysteresis(F, _blocked_force(tr, float(np.median(c.pressures_kpa))), fp)
        return F, k

    def write(c, P_nom, sim, folder, rep):  # the export's faults
        rec = dict(last)
        last.clear()
        t, x, F = sim["time_s"], sim["stroke_mm"], sim["force_n"]
        rec.update(t_first=float(t[0]), t_last=float(t[-1]), rows=int(t.size))
        if "speed-misset" in c.faults:
            c = dataclasses.replace(c, speed_mm_min=c.fault_sizes["stated_speed_mm_min"])
        name = _WRITE0(c, P_nom, sim, folder, rep)
        if "results-block" in c.faults:
            rows = _results_block(x, F, c.cycles)
            _append_results(Path(folder) / name, rows)
            rec["results_rows"] = len(rows)
        if "operator-pause" in c.faults:
            rec.update(pauses.pop() if pauses else {})
        log.append(rec)
        return name

    pauses: list = []
    patches = gen8.machine_patches(case, _LAWS, physics, write)
    if "operator-pause" in case.faults:
        rec: dict = {}

        def note(prog, c, s_amp, n):  # the last programme built before a test is written is the test's
            out = cycles(prog, c, s_amp, n)
            if n == c.cycles and "pause_start_s" in rec:
                pauses[:] = [dict(rec)]
            return out

        cycles = _paused_cycles(case, rec)
        patches.append(mock.patch.object(h6, "_cycles", note))
    return patches


def _run(case, fn, *args, seed=0, log=None):
    return gen8.call_patched(_patched(case, seed, [] if log is None else log), fn, *args)


def _fault_record(case, tr, test, rec) -> dict:
    """What the case's fault did to one test (for the truth)."""
    fp, P = case.fault_sizes, test["pressure_kpa"]
    out: dict = {}
    if "load-cell-creep" in case.faults:
        out = {"creep_fraction": fp["creep"], "creep_tau_s": fp["tau_s"],
               "creep_share_at_last_row": 1.0 - math.exp(-rec["t_last"] / fp["tau_s"])}
    if "load-cell-hysteresis" in case.faults:
        F_ref = _blocked_force(tr, float(np.median(case.pressures_kpa)))
        out = {"hysteresis_error_n": fp["error_fraction"] * F_ref, "hysteresis_band_n": fp["band_fraction"] * F_ref,
               "hysteresis_error_fraction_of_blocked": fp["error_fraction"] * F_ref / _blocked_force(tr, P)}
    if "operator-pause" in case.faults:
        out = {"pause_start_s": rec["pause_start_s"], "pause_s": fp["pause_s"],
               "pause_stroke_mm": rec["pause_stroke_mm"], "pause_in_logged_cycle": int(fp["pause_cycle"])}
    if "results-block" in case.faults:
        out = {"results_rows": rec["results_rows"]}
    if "fixture-expansion" in case.faults:
        e0, e1 = _expansion_mm(fp, [rec["t_first"], rec["t_last"]])
        out = {"expansion_at_first_row_mm": float(e0), "expansion_at_last_row_mm": float(e1),
               "expansion_tau_s": fp["tau_s"]}
    if "speed-misset" in case.faults:
        out = {"stated_speed_mm_min": fp["stated_speed_mm_min"], "real_speed_mm_min": case.speed_mm_min}
    if "regulator-hysteresis" in case.faults:
        out = {"regulator_band": fp["band"], "pressure_range_kpa": rec["pressure_range_kpa"]}
    out["samples"] = rec["rows"]
    return out


def generate_set(case: Case11, seed: int, folder) -> dict:
    """Write one raw machine file per pressure into ``folder``; returns the truth and the file names.

    Runs hold-out 6's machine with this module's laws, faults and shut-off filter, for the call only
    (:func:`holdout8_generator.generate_logged`).
    """
    return gen8.generate_logged(case, seed, folder, _run, _fault_record, SOURCES, FAULT_SOURCES)


# ---------------------------------------------------------------------------------------------
# checks
# ---------------------------------------------------------------------------------------------
#: The band of the loop's half-width on the reference triangle (fraction of the blocked moment): hold-out 10's.
HALF_WIDTH_BAND = (0.028, 0.040)


def check_laws(n_cycles: int = 4, points: int = 2000) -> dict:
    """Hold-out 8's check of each case's law alone (:func:`holdout8_generator.check_laws`: loop areas, whether
    it dissipates on every cycle, the change between cycles, the half-width), run with this module's cases and
    laws; ``half_width_ok`` is whether the mean half-width is in :data:`HALF_WIDTH_BAND` (2.8-4.0 %)."""
    res = gen8.check_laws(n_cycles, points, CASES, _LAWS)
    for r in res.values():
        r["half_width_ok"] = HALF_WIDTH_BAND[0] <= r["half_width_mean"] <= HALF_WIDTH_BAND[1]
    return res


def check_machine(case: Case11, seed: int = 0) -> dict:
    """Hold-out 8's check of the clean machine's loops (:func:`holdout8_generator.check_machine`), run with this
    module's laws."""
    return gen8.check_machine(case, seed, run=_run)


def _print_checks() -> None:
    gen8.print_checks(check_laws(), CASES, check_machine, 19)


def main(argv=None) -> int:
    """``OUT [SEED]`` writes one seed of every case; ``--check`` prints the laws' and the clean machine's checks."""
    return gen8.command(argv, CASES, generate_set, "holdout11_generator.py", _print_checks)


if __name__ == "__main__":
    raise SystemExit(main())
