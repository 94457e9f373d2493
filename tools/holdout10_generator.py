"""Hold-out set 10: raw four-point-bending tests with the actuator's own loop physics and a lab's logging faults.

A fifth independent generator of raw testing-machine exports (time, stroke, force at one pressure
per file) for scoring, once, whether bendpam's standard errors hold on data it has never seen.
Like :mod:`holdout9_generator` it reuses :mod:`holdout6_generator` (an earlier independent
generator) for everything but the loop laws, the instrument faults and the cases: the truth
(``MomentLaw`` of the preset with alpha0 + 0.4-0.8 deg, ``S`` x 0.95-1.05, ``shape = C01/S`` in
0.4-0.6), the fixture (paper eq 6-8), the machine (pressurised hold, detection of the free state at
a detection load, the stroke waveforms, the clocks), the noise filters and the export writers
(dialects); and from :mod:`holdout8_generator` its case builder, its rate ``du/d(t/t_half)``, its
planned test length, its law and machine checks and its patching helper.  As in hold-outs 7-9 the
controller's force shut-off reads a causal 1 s moving average of the force.

Measured moment = quasi-static ``M(P, k')`` of the truth - ``kappa z`` + instrument effects, ``z``
the loop law of the case driven by ``u = k'/k'_ref`` (``k'_ref`` the free curvature at the median
pressure; ``ogden-roxburgh`` and ``stoner-wohlfarth`` use the test's own free curvature ``k'_free``,
so that their loops keep their shape relative to each test's span) and, for the rate-dependent laws,
by time in units of ``t_half`` (the time of a release stroke at the case's speed); ``z`` is positive
while releasing (``k'`` increasing), so each cycle dissipates.  ``kappa`` sets ``max|z| =
loop_fraction x M_blocked`` on a reference triangle 0 -> k'_free -> 0 (twice), per test, as in
hold-out 6.  The loop half-width (half the gap between the return and the release branch, averaged
over the middle 80 % of the stroke) is 2.8-4.0 % of the blocked moment for every law on the
reference triangle, and every law dissipates on every cycle (:func:`check_laws`); on the machine's
own strokes and speeds it is 1.6-4.1 % (:func:`check_machine`; 1.2 % on the Mullins case's first,
virgin cycle).

The laws and faults were chosen outside the families of the earlier sets (the list of main and
hold-outs 1-5 it was given, hold-outs 6-9 read here).  Already used, so not taken: Valanis'
endochronic law, Perzyna's overstress and Dupont's elastoplastic friction (hold-out 7),
Jiles-Atherton and Berg's friction (hold-out 6), Preisach (hold-out 8), Burgers' body (a two-term
Prony series, the family of hold-outs 7 and 8); aliased mains hum and per-sample time jitter
(hold-out 6), regulator ripple and a load-cell nonlinearity (hold-out 5).  Hold-out 5's Mullins-like
softening (Miehe's continuous damage of the moduli) is single-valued; ``ogden-roxburgh`` here is a
loop.

Loop laws (``z(t, k, ctx, params)``, one small function each)
-------------------------------------------------------------
Rate dependent (``v = du/d(t/t_half)``, ``tau = t/t_half``):

* ``braid-friction``: the dry friction between the braid and the bladder of a McKibben muscle,
  whose level follows the load pressing them together (B. Tondu, P. Lopez, "Modeling and control of
  McKibben artificial muscle robot actuators", IEEE Control Syst. Mag. 20(2), 15-38, 2000;
  C.-P. Chou, B. Hannaford, "Measurement and modeling of McKibben pneumatic artificial muscles",
  IEEE Trans. Robot. Autom. 12, 90-102, 1996), with rubber's sub-linear load dependence, friction
  ~ N^(2/3) (a Hertzian contact area; A. Schallamach, "The load dependence of rubber friction",
  Proc. Phys. Soc. B 65, 657-661, 1952): ``z = N^(2/3) tanh(v/v_eps)``, ``N = n0 + (1 - n0)
  max(M(P, k')/M(P, 0), 0)`` with the truth's quasi-static moment at the test's pressure (a part
  set by the pressure alone, n0 = 0.3, and a part carried with the moment), v_eps = 0.05 (the
  sign smoothed through zero velocity).  The loop is 2.2 x wider at the blocked end than at the
  free end.  Alone (:func:`check_laws`, no truth) ``M/M(P, 0)`` is ``1 - k'/k'_free``.
* ``quadratic-damping``: velocity-squared damping, ``z = v |v|``: the air pushed in and out of the
  bladder as its volume changes with the bend (``dV/dtheta``, paper eq 13) passes the supply
  fitting with a turbulent (orifice) pressure drop ~ Q|Q|, a drag of Morison's form
  (J.R. Morison, M.P. O'Brien, J.W. Johnson, S.A. Schaaf, "The force exerted by surface waves on
  piles", Petrol. Trans. AIME 189, 149-154, 1950; J.P. Den Hartog, Mechanical Vibrations, 4th ed.,
  McGraw-Hill, 1956, on its equivalent viscous damping).  The loop closes at every turn and dwell
  and follows the stroke's speed squared: lens-shaped on the haversine stroke of its case.
* ``moore-thixotropy``: the structural viscosity of a thixotropic grease between braid and
  bladder (F. Moore, "The rheology of ceramic slips and bodies", Trans. Br. Ceram. Soc. 58,
  470-494, 1959; H.A. Barnes, "Thixotropy - a review", J. Non-Newtonian Fluid Mech. 70, 1-33,
  1997): ``z = (e_inf + (1 - e_inf) lambda) v``, ``dlambda/dtau = (1 - lambda)/T_r - b |v|
  lambda``: the structure ``lambda`` (1 at rest) is broken by shearing and rebuilds at rest;
  T_r = 0.5, b = 3, e_inf = 0.3, rested at the start, each step exact at its constant rate.  A
  stroke at the reference speed takes ``lambda`` from 1 to 0.4 within 0.2 t_half (the viscosity
  falls to 0.58 of the rested one); its case's 3 s dwells (0.1-0.7 T_r) rebuild it in part.
* ``kraus-network``: the filler network of the bladder's rubber breaks with strain and reforms,
  Kraus' agglomeration kinetics behind the Payne effect (G. Kraus, "Mechanical losses in
  carbon-black-filled rubbers", J. Appl. Polym. Sci.: Appl. Polym. Symp. 39, 75-92, 1984;
  A.R. Payne, "The dynamic properties of carbon black-loaded natural rubber vulcanizates. Part I",
  J. Appl. Polym. Sci. 6, 57-63, 1962): ``dN/dtau = k_r (1 - N) - k_b N |u|^m``, ``z = (N -
  N_eq(u)) u`` with ``N_eq = k_r/(k_r + k_b |u|^m)``: the network's stiffness in excess of its
  equilibrium (the relaxed network is single-valued and belongs to the quasi-static moment);
  k_r = 3, k_b = 12 per t_half, m = 2, each step exact.  The network breaks faster than it
  reforms, so the loop is lopsided: its branches' mean is +0.056 max|z| (+0.37 % of the blocked
  moment) over the stroke, the one law here with a single-valued part left in.

Rate independent:

* ``bliman-sorine``: Bliman and Sorine's second-order dry friction, linear in the path length
  ``s`` since the last reversal (P.-A. Bliman, M. Sorine, "Easy-to-use realistic dry friction
  models for automatic control", Proc. 3rd Eur. Control Conf., Rome, 3788-3794, 1995; "Friction
  modelling by hysteresis operators. Application to Dahl, sticktion and Stribeck effects", in:
  A. Visintin (ed.), Models of Hysteresis, Longman, 10-19, 1993): ``dx1/ds = (sigma f1 - x1)/
  (eta eps)``, ``dx2/ds = (-sigma f2 - x2)/eps``, ``z = x1 + x2``, ``sigma`` the direction;
  f1 = 1.4, f2 = 0.4 (sliding level 1), eps = 0.08, eta = 0.15, from rest.  After every reversal
  the fast state overshoots: a stiction-like peak of 1.39 x the sliding level at s = 0.045, in
  travel, not time.  Closed form along each monotone stretch.
* ``ogden-roxburgh``: the Mullins effect of the bladder's rubber, pseudo-elastic damage set by the
  largest deformation so far (R.W. Ogden, D.G. Roxburgh, "A pseudo-elastic model for the Mullins
  effect in filled rubber", Proc. R. Soc. Lond. A 455, 2861-2877, 1999), with a reloading branch
  above the unloading one (L. Dorfmann, R.W. Ogden, "A pseudo-elastic model for loading, partial
  unloading and reloading of particle-reinforced rubber", Int. J. Solids Struct. 40, 2699-2714,
  2003, whose idea of a second damage variable for reloading this follows; the reloading function
  is this module's).  ``W = u^2/2``, ``u = k'/k'_free``, ``s = eta u``: ``eta = 1`` on the primary
  curve (``W`` >= its maximum ``W_m``), on unloading ``eta1 = 1 - erf((W_m - W)/(m + beta W_m))/r``,
  on reloading from the lower reversal ``W_lo``, ``eta2 = 1 - erf((W_m - W)/(m + beta W_m))/r (W_m
  - W)/(W_m - W_lo)``; a branch from a partial reversal adds the reversal's gap times a linear
  fade (continuous).  r = 2, m = 0.1, beta = 0.1.  ``z = s - (eta1 + eta2) u/2`` (the steady loop's
  mean at the current extremes removed, as hold-out 9 does for Takeda's law), so ``z = 0`` on the
  first loading: the first cycle dissipates half of what the later ones do.  Its case logs the
  detection run, the first loading.
* ``stoner-wohlfarth``: an assembly of single-domain particles rotating coherently
  (E.C. Stoner, E.P. Wohlfarth, "A mechanism of magnetic hysteresis in heterogeneous alloys",
  Phil. Trans. R. Soc. Lond. A 240, 599-642, 1948), used as an abstract loop (as hold-out 6 uses
  Jiles-Atherton's): a population of bistable elements, each with a reversible part and an abrupt
  switch (snap-through wrinkles of a bladder).  16 particles, easy axes at 10-80 deg (uniform) to
  the drive ``h = H (2 k'/k'_free - 1)``, H = 1.25, energy ``sin^2(theta - psi)/2 - h cos theta``;
  a particle stays in its minimum until it vanishes at the astroid field ``h_sw = (cos^(2/3) psi +
  sin^(2/3) psi)^(-3/2)`` (0.50-0.67), then jumps; each branch ``m = cos theta`` is closed form in
  theta (``h = -sin 2(theta - psi)/(2 sin theta)``), tabulated.  ``z`` = the major loop's centre -
  ``m``: closed at both ends, open over the middle with steps at u = 0.70-0.77 (releasing) and
  0.23-0.30 (returning).
* ``prandtl-tomlinson``: stick-slip of the braid's yarn crossings, each a contact dragged by a
  spring over a periodic potential (L. Prandtl, "Ein Gedankenmodell zur kinetischen Theorie der
  festen Körper", Z. Angew. Math. Mech. 8, 85-106, 1928; G.A. Tomlinson, "A molecular theory of
  friction", Phil. Mag. 7, 905-939, 1929): 12 contacts, equilibrium ``u = x + c sin(2 pi (x/a -
  phi_j))``, a = 0.08, ``c = eta a/(2 pi)`` with eta = 3 (> 1: unstable stretches, so each contact
  sticks and slips), phases ``phi_j`` the golden-ratio sequence; quasi-static with maximal delay (a
  contact keeps its well until the well vanishes, then jumps to the next: the first equilibrium in
  the direction of travel, found on a grid of the explicit ``u(x)`` by its running maximum or
  minimum); ``z = mean_j (u - x_j)/c``; at the start pushed down to the first sample (the actuator
  was mounted straight).  An elastic-plastic-like loop (presliding over ~0.03) with a stick-slip
  ripple of up to +-30 % of its half-width (13 % rms), period a/12 to a.

Instrument faults (each in one case; the rest of the lab is careful: pressure as declared, load
cell tared, no self-weight, no rig faults)
-----------------------------------------------------------------------------------------------
* ``gain-drift``: the load cell's span drifts as the cell and its amplifier warm up (cf. OIML R 60's
  temperature effect on the sensitivity), sized at the high end of what a lab sees, 0.4 % over a
  test (an uncompensated low-cost cell and amplifier, or a cell warmed unevenly by the valve
  manifold: a gradient across the cell errs far beyond its uniform-temperature coefficient): the
  reading is ``F (1 + G (1 - exp(-t/tau))/(1 - exp(-T/tau)))``, G = -0.4 % at the planned end ``T``
  of the logged test, tau = T/2, ``t`` from the machine's start (its case logs from there); the gain
  is 1 at the first row, -0.38 to -0.39 % at the last, -0.26 % on average (``gain_at_first_row``,
  ``gain_at_last_row`` in the returned tests).  The controller reads it.
* ``stroke-quantised``: the logged stroke is the crosshead encoder's, read to 0.01 mm, with no
  other stroke noise (the case's ``stroke_noise_mm`` is 0).
* ``packet-timestamps``: the PC stamps the rows of each 10-sample USB packet (0.2 s at 50 Hz) on its
  arrival: the last row with the acquisition of the packet's last sample + a latency of 1-6 ms
  (uniform, per packet), each earlier row one nominal period before, rounded to 1 ms: regular time
  within a packet, a blockwise jitter between packets (hold-out 6's PC clock jitters every sample).
  (Stamping every row of a packet with the arrival alone makes bendpam's processing refuse the file:
  its time does not increase.)
* ``dup-rows``: after a stall the logger's export buffer re-sends a block: three blocks of 12 rows
  per file, one in each third of the middle 90 % of the rows, each written twice in a row, so the
  time column steps back 12 samples three times (``resent_block_starts``; ``samples`` is the rows
  written, ``machine_samples`` the rows sampled).
* ``supply-step``: the compressor cuts in and the supply pressure jumps by ~2 bar; the regulator's
  outlet follows by its supply-pressure effect (its pressure regulation characteristic, cf. ISO
  6953-1; 0.01-0.05 bar per bar for general-purpose regulators, 2-10 kPa here): the actuator's
  pressure steps by +1.2 % (1.2-2.4 kPa) at a time drawn per test in 35-75 % of the
  planned logged test, always after the logged detection run (``supply_step_time_s``,
  ``step_in_logged_test_fraction``: 0.4-0.9 of the actual one).  The file states the set pressure.
* ``data-reduction``: the acquisition software logs a row only when the force changed by 1 % of the
  blocked force at the case's median pressure (a fixed 0.158 N for the series), or the travel by
  0.05 mm, or 1 s passed since the last row (testXpert's and Bluehill's data reduction); 30-60 % of
  the rows are kept (fewer at low pressure), at uneven times (``rows_kept_fraction``).

Force noise otherwise as hold-out 6 (white, AR(1), pink; 0.5-3 % of the blocked force), 2 um stroke
noise (none in the quantised case), 3-5 cycles, sampling at 10-50 Hz, eight export dialects (one per
case).  ``drift_fraction`` (hold-out 6's linear drift) is 0 in every case.

Cases (8; 35 files a seed, each case's seed in 0.05-0.35 s)
------------------------------------------------------------
===================== ====== ============= ================ ================= ================= ======= ==========
case                  preset model         pressures (kPa)  law               fault             noise   dialect
===================== ====== ============= ================ ================= ================= ======= ==========
h10-braid-gaindrift   BE     energy        100-200 (5)      braid-friction    gain-drift        1 % w   zwick-de
h10-quadratic-quant   BC     force_balance 50-130 (5)       quadratic-damping stroke-quantised  1.2 % a bluehill
h10-moore-packets     BE     force_balance 95-215 (4)       moore-thixotropy  packet-timestamps 0.8 % p csv
h10-bliman-dups       BC     energy        45-145 (6)       bliman-sorine     dup-rows          1.5 % w mts-ts
h10-mullins-supply    BE     energy        100-200 (3)      ogden-roxburgh    supply-step       2 % a   trapezium
h10-kraus-reduction   BC     force_balance 50-125 (4)       kraus-network     data-reduction    0.6 % w instron
h10-stoner-wohlfarth  BE     force_balance 105-195 (4)      stoner-wohlfarth  (none)            3 % p   zwick-en
h10-prandtl-tomlinson BC     energy        55-130 (4)       prandtl-tomlinson (none)            0.5 % w mts-basic
===================== ====== ============= ================ ================= ================= ======= ==========

(w white, a AR(1), p pink.)

``python tools/holdout10_generator.py OUT [SEED]`` writes one seed of every case into OUT/<case>/
with ``truth.json``; ``python tools/holdout10_generator.py --check`` prints the laws' dissipation,
periodicity and half-width table and the clean machine's loop table.
"""

from __future__ import annotations

import functools
import itertools
import math
import sys
from pathlib import Path

import numpy as np
from scipy import special

if str(Path(__file__).resolve().parent) not in sys.path:
    sys.path.insert(0, str(Path(__file__).resolve().parent))
import holdout8_generator as gen8
from holdout7_generator import h6

__all__ = ["CASES", "Case10", "check_laws", "check_machine", "generate_set", "start_actuator", "truth_actuator"]


# ---------------------------------------------------------------------------------------------
# rate-dependent loop laws: z(t, k, ctx, params), positive while k increases; scaled by the machine
# ---------------------------------------------------------------------------------------------
def _law_braid(t, k, ctx, p):
    v = gen8._rate(k / ctx["k_ref"], ctx)
    tr = ctx.get("truth")
    if tr is None:  # the law alone (check_laws): a moment falling linearly to zero at the free state
        load = 1.0 - k / ctx["k_free"]
    else:  # the truth's quasi-static moment over the blocked moment, at the test's pressure
        load = tr.m(ctx["P"], k) / float(tr.m(ctx["P"], 0.0))
    normal = p["n0"] + (1.0 - p["n0"]) * np.clip(load, 0.0, None)
    return normal ** p["exponent"] * np.tanh(v / p["v_eps"])


def _law_quadratic(t, k, ctx, p):
    v = gen8._rate(k / ctx["k_ref"], ctx)
    return np.sign(v) * np.abs(v) ** p["n"]


def _first_order(a, target, x0):
    """``x_i = target_i-1 + (x_i-1 - target_i-1) a_i-1`` from ``x_0 = x0``: each step's exact update of
    ``dx/dt = (target - x) rate`` with ``a = exp(-rate dt)`` (the rate and target held over the step)."""
    out = [x0]
    x = x0
    for ai, ti in zip(a.tolist(), target.tolist(), strict=True):
        x = ti + (x - ti) * ai
        out.append(x)
    return np.array(out)


def _law_moore(t, k, ctx, p):
    u = k / ctx["k_ref"]
    dtau = ctx["dt"] / ctx["t_half"]
    speed = np.abs(np.diff(u)) / dtau  # |du/dtau| over each step
    rebuild = 1.0 / p["T_r"]
    rate = rebuild + p["b"] * speed
    lam = _first_order(np.exp(-rate * dtau), rebuild / rate, 1.0)  # the structure: rested (1) at the start
    return (p["e_inf"] + (1.0 - p["e_inf"]) * lam) * gen8._rate(u, ctx)


def _kraus_eq(u, p):
    return p["kr"] / (p["kr"] + p["kb"] * np.abs(u) ** p["m"])


def _law_kraus(t, k, ctx, p):
    u = k / ctx["k_ref"]
    dtau = ctx["dt"] / ctx["t_half"]
    um = 0.5 * (u[1:] + u[:-1])
    rate = p["kr"] + p["kb"] * np.abs(um) ** p["m"]
    N = _first_order(np.exp(-rate * dtau), p["kr"] / rate, float(_kraus_eq(u[0], p)))
    return (N - _kraus_eq(u, p)) * u


# ---------------------------------------------------------------------------------------------
# rate-independent loop laws
# ---------------------------------------------------------------------------------------------
def _law_bliman_sorine(t, k, ctx, p):
    u = k / ctx["k_ref"]
    f1, f2, eps, eta = p["f1"], p["f2"], p["eps"], p["eta"]
    x1 = x2 = 0.0
    out = np.empty_like(u)
    for a, b, d in h6._segments(u):
        s = np.abs(u[a:b] - (u[a - 1] if a else u[0]))  # path length since the reversal
        y1 = d * f1 + (x1 - d * f1) * np.exp(-s / (eta * eps))
        y2 = -d * f2 + (x2 + d * f2) * np.exp(-s / eps)
        out[a:b] = y1 + y2
        x1, x2 = float(y1[-1]), float(y2[-1])
    return out


def _or_eta1(w, wm, p):
    """Ogden-Roxburgh's softening on unloading from the largest energy so far ``wm``."""
    return 1.0 - special.erf((wm - w) / (p["m"] + p["beta"] * wm)) / p["r"]


def _or_eta2(w, wm, wlo, p):
    """The reloading variable from the lower reversal ``wlo``: Ogden-Roxburgh's at ``wlo``, 1 at ``wm``."""
    d = wm - w
    return 1.0 - special.erf(d / (p["m"] + p["beta"] * wm)) / p["r"] * d / np.maximum(wm - wlo, 1e-300)


def _law_ogden_roxburgh(t, k, ctx, p):
    u = np.clip(k / ctx["k_free"], 0.0, None)
    W = 0.5 * u * u
    wm = wlo = float(W[0])
    er = 1.0
    eta, cen = np.empty_like(u), np.empty_like(u)
    for a, b, d in h6._segments(u):
        w = W[a:b]
        wr = float(W[a - 1]) if a else float(W[0])
        if d > 0:
            wlo = wr
            wmv = np.maximum.accumulate(np.maximum(w, wm))  # primary loading beyond the old maximum
            e2 = _or_eta2(w, wm, wr, p) + (er - _or_eta2(wr, wm, wr, p)) * (wm - w) / max(wm - wr, 1e-300)
            eta[a:b] = np.where(w >= wm, 1.0, e2)
            wm = float(wmv[-1])
        else:
            wmv = np.full_like(w, wm)
            corr = (er - float(_or_eta1(wr, wm, p))) * w / wr if wr > 0.0 else 0.0
            eta[a:b] = _or_eta1(w, wm, p) + corr
        cen[a:b] = 0.5 * (_or_eta1(w, wmv, p) + _or_eta2(w, wmv, wlo, p))
        er = float(eta[b - 1])
    return (eta - cen) * u


@functools.lru_cache(maxsize=8)
def _sw_table(n, psi_min_deg, psi_max_deg):
    """Stoner-Wohlfarth particles with easy axes spread over [psi_min, psi_max]: per particle the branch
    ``m_+(h) = cos theta`` (h increasing) from its fold ``-h_sw`` up, and ``h_sw``."""
    th = np.linspace(1e-4, math.pi - 1e-4, 20001)
    tabs, hsw = [], []
    for psi in np.radians(np.linspace(psi_min_deg, psi_max_deg, int(n))):
        h = -np.sin(2.0 * (th - psi)) / (2.0 * np.sin(th))  # dE/dtheta = 0
        stable = np.cos(2.0 * (th - psi)) + h * np.cos(th) > 0.0
        j = int(np.argmin(stable))  # the fold: the first unstable angle
        tabs.append((h[:j][::-1].copy(), np.cos(th[:j])[::-1].copy()))
        hsw.append((math.cos(psi) ** (2 / 3) + math.sin(psi) ** (2 / 3)) ** -1.5)
    return tuple(tabs), np.array(hsw)


def _law_stoner_wohlfarth(t, k, ctx, p):
    h = p["H"] * (2.0 * k / ctx["k_free"] - 1.0)
    tabs, hsw = _sw_table(p["n"], p["psi_min"], p["psi_max"])
    w = np.full(hsw.size, 1.0 / hsw.size)
    mp = np.stack([np.interp(h, hh, mm) for hh, mm in tabs], axis=1)  # on the + branch
    mn = -np.stack([np.interp(-h, hh, mm) for hh, mm in tabs], axis=1)  # on the - branch
    state = np.where(h[0] >= hsw, 1.0, -1.0)  # history: from negative saturation
    s = np.empty_like(mp)
    for a, b, d in h6._segments(h):
        if d > 0:
            y = np.where(np.maximum.accumulate(h[a:b])[:, None] >= hsw[None, :], 1.0, state[None, :])
        else:
            y = np.where(np.minimum.accumulate(h[a:b])[:, None] <= -hsw[None, :], -1.0, state[None, :])
        s[a:b] = y
        state = y[-1]
    m = np.where(s > 0.0, mp, mn) @ w
    up = np.where(h[:, None] >= hsw[None, :], mp, mn)  # the major loop's branches
    dn = np.where(h[:, None] > -hsw[None, :], mp, mn)
    return 0.5 * (up + dn) @ w - m


def _pt_move(xg, Xg, x0, X0, seg, d):
    """A Prandtl-Tomlinson contact at ``x0`` (in equilibrium with the drive ``X0``) dragged monotonically through
    ``seg`` (direction ``d``) with maximal delay: the first equilibrium reached from ``x0`` in that direction, found
    on the grid ``xg`` of ``X(x) = x + c sin(...)`` by its running maximum (minimum)."""
    if d > 0:
        i0 = int(np.searchsorted(xg, x0, side="right"))
        xs, Xs = np.r_[x0, xg[i0:]], np.r_[X0, Xg[i0:]]
        R = np.maximum.accumulate(Xs)
        j = np.clip(np.searchsorted(R, seg, side="left"), 1, Xs.size - 1)
    else:
        i1 = int(np.searchsorted(xg, x0, side="left"))
        xs, Xs = np.r_[x0, xg[:i1][::-1]], np.r_[X0, Xg[:i1][::-1]]
        R = np.minimum.accumulate(Xs)
        j = np.clip(np.searchsorted(-R, -seg, side="left"), 1, Xs.size - 1)
    f = (seg - Xs[j - 1]) / (Xs[j] - Xs[j - 1])
    return xs[j - 1] + np.clip(f, 0.0, 1.0) * (xs[j] - xs[j - 1])


def _law_prandtl_tomlinson(t, k, ctx, p):
    X = k / ctx["k_ref"]
    n = int(p["n"])
    a = p["a"]
    c = p["eta"] * a / (2.0 * math.pi)  # eta > 1: each contact sticks and slips
    xg = np.arange(float(np.min(X)) - 2.0 * a, float(np.max(X)) + 2.0 * a, a / 400.0)
    out = np.zeros_like(X)
    for j in range(n):  # the contacts' phases: the golden-ratio sequence over one period
        Xg = xg + c * np.sin(2.0 * math.pi * (xg / a - (j + 1) * 0.6180339887498949))
        x = float(_pt_move(xg, Xg, xg[-1], Xg[-1], X[:1], -1.0)[0])  # pushed down to X[0]: mounted straight
        xj = np.empty_like(X)
        for s0, s1, d in h6._segments(X):
            X0 = float(X[s0 - 1]) if s0 else float(X[0])
            xj[s0:s1] = _pt_move(xg, Xg, x, X0, X[s0:s1], d)
            x = float(xj[s1 - 1])
        out += (X - xj) / (c * n)
    return out


_LAWS = {"braid-friction": _law_braid, "quadratic-damping": _law_quadratic, "moore-thixotropy": _law_moore,
         "kraus-network": _law_kraus, "bliman-sorine": _law_bliman_sorine, "ogden-roxburgh": _law_ogden_roxburgh,
         "stoner-wohlfarth": _law_stoner_wohlfarth, "prandtl-tomlinson": _law_prandtl_tomlinson}

SOURCES = {
    "braid-friction": "B. Tondu, P. Lopez, IEEE Control Syst. Mag. 20(2) (2000) 15; C.-P. Chou, B. Hannaford, IEEE "
                      "Trans. Robot. Autom. 12 (1996) 90; A. Schallamach, Proc. Phys. Soc. B 65 (1952) 657",
    "quadratic-damping": "J.R. Morison, M.P. O'Brien, J.W. Johnson, S.A. Schaaf, Petrol. Trans. AIME 189 (1950) 149; "
                         "J.P. Den Hartog, Mechanical Vibrations, 4th ed. (1956)",
    "moore-thixotropy": "F. Moore, Trans. Br. Ceram. Soc. 58 (1959) 470; H.A. Barnes, J. Non-Newtonian Fluid Mech. 70 "
                        "(1997) 1",
    "kraus-network": "G. Kraus, J. Appl. Polym. Sci.: Appl. Polym. Symp. 39 (1984) 75; A.R. Payne, J. Appl. Polym. "
                     "Sci. 6 (1962) 57",
    "bliman-sorine": "P.-A. Bliman, M. Sorine, Proc. 3rd Eur. Control Conf., Rome (1995) 3788; in: A. Visintin (ed.), "
                     "Models of Hysteresis, Longman (1993) 10",
    "ogden-roxburgh": "R.W. Ogden, D.G. Roxburgh, Proc. R. Soc. Lond. A 455 (1999) 2861; L. Dorfmann, R.W. Ogden, "
                      "Int. J. Solids Struct. 40 (2003) 2699",
    "stoner-wohlfarth": "E.C. Stoner, E.P. Wohlfarth, Phil. Trans. R. Soc. Lond. A 240 (1948) 599",
    "prandtl-tomlinson": "L. Prandtl, Z. Angew. Math. Mech. 8 (1928) 85; G.A. Tomlinson, Phil. Mag. 7 (1929) 905",
}

FAULT_SOURCES = {
    "gain-drift": "load-cell span drifting with the bridge's and amplifier's warm-up (span temperature coefficient, "
                  "cf. OIML R 60)",
    "stroke-quantised": "crosshead encoder read to 10 um",
    "packet-timestamps": "rows stamped by the PC per 10-sample USB packet: its arrival (+ 1-6 ms latency), less the "
                         "nominal period per row",
    "dup-rows": "the logger's export buffer re-sends a few blocks of rows after a stall",
    "supply-step": "the regulator's supply-pressure effect when the compressor cuts in (cf. ISO 6953-1): a step",
    "data-reduction": "the software logs a row only when the force or the travel changed enough, or after 1 s",
}


# ---------------------------------------------------------------------------------------------
# cases
# ---------------------------------------------------------------------------------------------
class Case10(gen8.Case8):
    """A hold-out-6 case (same attributes) whose ``loop`` names one of this module's laws and whose
    ``faults`` name this module's instrument faults, sized by ``fault_params`` (hold-out 8's case, whose
    builder it shares)."""


def _c(*args, **kw) -> Case10:
    return gen8._c(*args, cls=Case10, **kw)


CASES: dict[str, Case10] = {c.name: c for c in [
    _c("h10-braid-gaindrift", "be-pam", "energy", (100, 125, 150, 175, 200), "braid-friction", 0.05, 0.010, 0.0,
       "zwick-de", 4, 25.0, 0.46, 1001, 0.55, 1.02, "trapvel", 45.0, 45.0, 20.0, 0.2, "white",
       {"n0": 0.3, "exponent": 2.0 / 3.0, "v_eps": 0.05}, faults=("gain-drift",),
       fault_params={"gain_change": -0.004, "tau_fraction": 0.5}),
    _c("h10-quadratic-quant", "bc-pam", "force_balance", (50, 70, 90, 110, 130), "quadratic-damping", 0.04, 0.012, 0.7,
       "bluehill", 5, 20.0, 0.53, 1002, 0.7, 0.97, "haversine", 40.0, 40.0, 20.0, 0.3, "ar1",
       {"n": 2.0}, faults=("stroke-quantised",), fault_params={"step_mm": 0.01}, log_detection=False,
       stroke_noise_mm=0.0),
    _c("h10-moore-packets", "be-pam", "force_balance", (95, 135, 175, 215), "moore-thixotropy", 0.05, 0.008, 0.0,
       "csv", 4, 50.0, 0.57, 1003, 0.45, 1.04, "tri-dwell", 40.0, 40.0, 20.0, 0.25, "pink",
       {"T_r": 0.5, "b": 3.0, "e_inf": 0.3}, faults=("packet-timestamps",),
       fault_params={"packet_rows": 10, "latency_min_s": 0.001, "latency_max_s": 0.006}, log_detection=False,
       dwell_s=3.0, L0_mm=150.0),
    _c("h10-bliman-dups", "bc-pam", "energy", (45, 65, 85, 105, 125, 145), "bliman-sorine", 0.05, 0.015, 0.0,
       "mts-ts", 3, 20.0, 0.42, 1004, 0.8, 1.0, "cycloid", 50.0, 50.0, 25.0, 0.2, "white",
       {"f1": 1.4, "f2": 0.4, "eps": 0.08, "eta": 0.15}, faults=("dup-rows",),
       fault_params={"blocks": 3, "block_rows": 12}, log_detection=False),
    _c("h10-mullins-supply", "be-pam", "energy", (100, 150, 200), "ogden-roxburgh", 0.075, 0.020, 0.5,
       "trapezium", 5, 10.0, 0.6, 1005, 0.65, 0.98, "tri-asym", 40.0, 55.0, 20.0, 0.3, "ar1",
       {"r": 2.0, "m": 0.1, "beta": 0.1}, faults=("supply-step",),
       fault_params={"step": 0.012, "at_min": 0.35, "at_max": 0.75}),
    _c("h10-kraus-reduction", "bc-pam", "force_balance", (50, 75, 100, 125), "kraus-network", 0.065, 0.006, 0.0,
       "instron-console", 4, 25.0, 0.49, 1006, 0.5, 1.05, "haversine", 50.0, 50.0, 25.0, 0.2, "white",
       {"kr": 3.0, "kb": 12.0, "m": 2.0}, faults=("data-reduction",),
       fault_params={"dF_fraction": 0.01, "ds_mm": 0.05, "dt_s": 1.0}),
    _c("h10-stoner-wohlfarth", "be-pam", "force_balance", (105, 135, 165, 195), "stoner-wohlfarth", 0.06, 0.030, 0.0,
       "zwick-en", 3, 20.0, 0.51, 1007, 0.75, 0.95, "trap-hold-free", 45.0, 45.0, 20.0, 0.2, "pink",
       {"n": 16, "psi_min": 10.0, "psi_max": 80.0, "H": 1.25}, log_detection=False, dwell_s=3.0, L0_mm=140.0),
    _c("h10-prandtl-tomlinson", "bc-pam", "energy", (55, 80, 105, 130), "prandtl-tomlinson", 0.05, 0.005, 0.0,
       "mts-basic", 5, 50.0, 0.44, 1008, 0.6, 1.01, "tri-dwell", 45.0, 45.0, 20.0, 0.1, "white",
       {"n": 12, "a": 0.08, "eta": 3.0}, log_detection=False, dwell_s=1.0),
]}


#: The preset with the case's geometry changes (not the truth's constants), and the truth: hold-out 8's.
start_actuator, truth_actuator = gen8.start_actuator, gen8.truth_actuator


# ---------------------------------------------------------------------------------------------
# instrument faults (hold-out 6's machine, patched for the call)
# ---------------------------------------------------------------------------------------------
_blocked_force = gen8._blocked_force
_PHYS0 = h6._physics
_WRITE0 = h6._write


def _gain(case, ctx, t):
    """The load cell's gain at machine time ``t``: ``1 + G (1 - exp(-t/tau)) / (1 - exp(-T/tau))``, ``T`` the
    planned logged test (the case logs from the machine's start), ``tau = tau_fraction T``."""
    fp = case.fault_sizes
    T = gen8._planned(case, ctx)[1]
    tau = fp["tau_fraction"] * T
    return 1.0 + fp["gain_change"] * (1.0 - np.exp(-np.asarray(t) / tau)) / (1.0 - math.exp(-T / tau))


def _step_time(case, ctx) -> float:
    """When the supply pressure steps (machine time, s): ``at_min .. at_max`` of the planned logged test, placed by
    the test's own random phase (hold-out 6 draws it for every test)."""
    fp = case.fault_sizes
    frac = fp["at_min"] + (fp["at_max"] - fp["at_min"]) * ctx["hum_phase"] / (2.0 * math.pi)
    return frac * gen8._planned(case, ctx)[1]


def _packet_times(t, fp, rng, rate_hz):
    """Rows stamped by the PC per packet of ``packet_rows``: the packet's arrival (its last sample + a latency) for
    its last row, one nominal period less for each row before it; rounded to 1 ms."""
    n = int(fp["packet_rows"])
    i = np.arange(t.size)
    last = np.minimum(i // n * n + n - 1, t.size - 1)
    lat = rng.uniform(fp["latency_min_s"], fp["latency_max_s"], t.size // n + 1)
    return np.round(t[last] + lat[i // n] - (last - i) / rate_hz, 3)


def _reduced(t, x, F, dF, ds, dt):
    """The rows a change-triggered logger keeps: the first, then each whose force or travel moved by ``dF`` or
    ``ds`` from the last kept row, or ``dt`` after it; and the last."""
    keep = [0]
    lt, lx, lF = float(t[0]), float(x[0]), float(F[0])
    for i, (a, b, c) in enumerate(zip(t.tolist(), x.tolist(), F.tolist(), strict=True)):
        if abs(c - lF) >= dF or abs(b - lx) >= ds or a - lt >= dt:
            keep.append(i)
            lt, lx, lF = a, b, c
    if keep[-1] != t.size - 1:
        keep.append(t.size - 1)
    return np.array(keep)


def _resent(n, fp, rng):
    """Row order with ``blocks`` blocks of ``block_rows`` rows sent twice (start rows spread over the middle 90 %,
    one block per equal share)."""
    m, B = int(fp["blocks"]), int(fp["block_rows"])
    edges = np.linspace(0.05 * n, 0.95 * n - B, m + 1)
    starts = [int(rng.integers(int(lo), int(hi))) for lo, hi in itertools.pairwise(edges)]
    order, at = [], 0
    for s in starts:
        order += [*range(at, s + B), *range(s, s + B)]
        at = s + B
    order += range(at, n)
    return np.array(order), starts


def _patched(case, seed, log):
    last = {}

    def physics(c, ctx, t, x_act, noise, kappa):  # the force with the pressure step and the drifting gain
        F, k = _PHYS0(c, ctx, t, x_act, noise, kappa)
        if "supply-step" in c.faults:
            tr, ts = ctx["truth"], _step_time(c, ctx)
            Pe = ctx["P"] * (1.0 + c.fault_sizes["step"] * (t >= ts))
            F = F + (tr.m(Pe, k) - tr.m(ctx["P"], k)) / h6.lever_mm(0.5 * k * tr.L0)
            last["supply_step_time_s"] = ts
        if "gain-drift" in c.faults:  # the reading: the controller sees it too
            F = F * _gain(c, ctx, t)
        return F, k

    def write(c, P_nom, sim, folder, rep):  # the logger's and the export's faults
        fp, rec = c.fault_sizes, dict(last)
        last.clear()
        rng = np.random.default_rng([int(seed), c.case_id, rep, 10])
        t, x, F = sim["time_s"], sim["stroke_mm"], sim["force_n"]
        rec.update(t_first=float(t[0]), t_last=float(t[-1]), machine_rows=int(t.size))
        if "stroke-quantised" in c.faults:
            x = fp["step_mm"] * np.round(x / fp["step_mm"])
        if "packet-timestamps" in c.faults:
            t = _packet_times(t, fp, rng, c.rate_hz)
        if "data-reduction" in c.faults:
            F_set = fp["dF_fraction"] * _blocked_force(h6._Truth(c), float(np.median(c.pressures_kpa)))
            keep = _reduced(t, x, F, F_set, fp["ds_mm"], fp["dt_s"])
            t, x, F = t[keep], x[keep], F[keep]
            rec["force_threshold_n"] = F_set
        if "dup-rows" in c.faults:
            order, rec["resent_block_starts"] = _resent(t.size, fp, rng)
            t, x, F = t[order], x[order], F[order]
        rec["rows"] = int(t.size)
        log.append(rec)
        return _WRITE0(c, P_nom, dict(sim, time_s=t, stroke_mm=x, force_n=F), folder, rep)

    return gen8.machine_patches(case, _LAWS, physics, write)


def _run(case, fn, *args, seed=0, log=None):
    return gen8.call_patched(_patched(case, seed, [] if log is None else log), fn, *args)


def _fault_record(case, tr, test, rec) -> dict:
    """What the case's fault did to one test (for the truth); ``samples`` becomes the rows written."""
    fp, P = case.fault_sizes, test["pressure_kpa"]
    out = {}
    if "gain-drift" in case.faults:
        ctx = {"truth": tr, "k_free": test["free_curvature_per_mm"]}
        g0, g1 = _gain(case, ctx, [rec["t_first"], rec["t_last"]])
        out = {"gain_change_at_planned_end": fp["gain_change"], "gain_tau_s": fp["tau_fraction"] *
               gen8._planned(case, ctx)[1], "gain_at_first_row": float(g0), "gain_at_last_row": float(g1)}
    if "stroke-quantised" in case.faults:
        out = {"stroke_step_mm": fp["step_mm"]}
    if "packet-timestamps" in case.faults:
        out = {"packet_rows": int(fp["packet_rows"]), "packet_period_s": fp["packet_rows"] / case.rate_hz,
               "latency_s": [fp["latency_min_s"], fp["latency_max_s"]]}
    if "dup-rows" in case.faults:
        out = {"resent_block_starts": rec["resent_block_starts"], "resent_block_rows": int(fp["block_rows"])}
    if "supply-step" in case.faults:
        out = {"supply_step_fraction": fp["step"], "supply_step_time_s": rec["supply_step_time_s"],
               "pressure_after_step_kpa": P * (1.0 + fp["step"]),
               "step_in_logged_test_fraction": (rec["supply_step_time_s"] - rec["t_first"]) /
               (rec["t_last"] - rec["t_first"])}
    if "data-reduction" in case.faults:
        out = {"force_threshold_n": rec["force_threshold_n"], "travel_threshold_mm": fp["ds_mm"],
               "time_threshold_s": fp["dt_s"], "rows_kept_fraction": rec["rows"] / rec["machine_rows"]}
    out["machine_samples"], out["samples"] = rec["machine_rows"], rec["rows"]
    return out


def generate_set(case: Case10, seed: int, folder) -> dict:
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


def check_machine(case: Case10, seed: int = 0) -> dict:
    """Hold-out 8's check of the clean machine's loops (:func:`holdout8_generator.check_machine`), run with this
    module's laws."""
    return gen8.check_machine(case, seed, run=_run)


def _print_checks() -> None:
    gen8.print_checks(check_laws(), CASES, check_machine, 18)


def main(argv=None) -> int:
    return gen8.command(argv, CASES, generate_set, "holdout10_generator.py", _print_checks)


if __name__ == "__main__":
    raise SystemExit(main())
