"""A virtual testing machine: raw four-point-bending cyclic tests from a model (section 2.2).

At each pressure the virtual machine

1. finds the free position as the real one does: it releases the actuator from the blocked state
   until the force falls to the detection load (0.2 N), on the *unloading* branch of the loop;
2. runs ``cycles`` triangular cycles blocked -> free -> blocked at ``speed_mm_min``, sampled at
   ``rate_hz``, with an optional dwell at each end;
3. computes the moment from the quasi-static model plus a smooth hysteresis loop
   (:mod:`bendpam.physics.hysteresis`: the Prandtl-Ishlinskii law by default, or Dahl's with
   ``hysteresis_law="dahl"``): ``M = M_model(P, k') - A z``, with the amplitude
   ``A = hysteresis * |M_model(P, 0)| + hysteresis_offset_nmm``; the loop's energy-loss ratio is
   about ``4 A / |M_blocked|`` for a nearly linear curve, so ``hysteresis = 0.06`` gives the
   paper's ~24 % (Table 2);
4. converts the moment to the machine force and the curvature to the stroke with eq 6-8, and
   adds Gaussian force noise (``noise_n``) and stroke noise (``noise_stroke_mm``).

The record starts at the blocked state just after a loading (``z = -1``).  The returned *truth*
holds the values that processing should recover, computed from the noiseless loop with the same
definitions (per-cycle maximum moment, curvature at the free turning point, loop area / area
under the cycle's mean curve) and the model's own values (blocked moment, free curvature, P_start).
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.optimize import brentq

from bendpam.errors import InputError, NoEquilibrium
from bendpam.infra.atomic import atomic_write_text, json_safe
from bendpam.physics.braid import curvature_limits
from bendpam.physics.fixture import PAPER_FIXTURE, Fixture
from bendpam.physics.hysteresis import LAWS, make_law
from bendpam.physics.models import resolve_model
from bendpam.predict import blocked_moment, free_curvature, moment
from bendpam.validate import number

__all__ = ["DIALECT_SUFFIX", "SimulationSettings", "simulate_test", "simulate_tests"]

#: The fixture's plates cannot pitch beyond this (deg); the free state must be found before it.
MAX_BETA_DEG = 80.0

DIALECT_SUFFIX = {"csv": ".csv", "testxpert": ".txt", "bluehill": ".csv", "mts": ".txt"}

#: The most samples one simulated test may record (rate x duration); a larger test is refused before any
#: allocation (10^7 samples are a few hundred MB of working arrays).
MAX_SAMPLES = 10_000_000
#: The most samples one call of :func:`simulate_tests` may record over all its pressures: about five
#: minutes of simulation at roughly 10^5 samples/s (and 0.6 GB of text files); larger requests are
#: refused before the first test is simulated (see docs/budgets.md).
MAX_TOTAL_SAMPLES = 30_000_000


@dataclass(frozen=True)
class SimulationSettings:
    """Settings of the virtual testing machine (units in the names).

    cycles : triangular cycles blocked -> free -> blocked per pressure.
    speed_mm_min : crosshead speed (mm/min).  rate_hz : sampling rate (Hz).
    noise_n, noise_stroke_mm : standard deviations of the Gaussian force (N) and stroke (mm) noise.
    hysteresis : pressure part of the loop amplitude, a fraction of the blocked moment.
    hysteresis_offset_nmm : constant part of the loop amplitude (N*mm).
    hysteresis_angle_deg, hysteresis_law : the loop law (``"pi"`` Prandtl-Ishlinskii or ``"dahl"``)
    and its angle (deg).  detection_load_n : force at which the machine finds the free state (N).
    dwell_s : dwell at each end of a stroke (s).  stroke_offset_mm : machine stroke at the blocked
    state (mm).  seed : random seed of the noise (None: fresh noise each time).

    Examples
    --------
    >>> SimulationSettings(cycles=2, rate_hz=5.0).speed_mm_min        # mm/min
    30.0
    >>> SimulationSettings(rate_hz=0.0)
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: rate_hz = 0.0 is outside the allowed range [0.001, 1e+06]
    """

    cycles: int = 3
    speed_mm_min: float = 30.0
    rate_hz: float = 20.0
    noise_n: float = 0.05
    noise_stroke_mm: float = 0.002
    hysteresis: float = 0.06
    hysteresis_offset_nmm: float = 0.0
    hysteresis_angle_deg: float = 5.0
    hysteresis_law: str = "pi"
    detection_load_n: float = 0.2
    dwell_s: float = 0.0
    stroke_offset_mm: float = 0.0
    seed: int | None = None

    def __post_init__(self) -> None:
        checks = [
            ("cycles", self.cycles, 1, 1000),
            ("speed_mm_min", self.speed_mm_min, 1e-6, 1e6),
            ("rate_hz", self.rate_hz, 1e-3, 1e6),
            ("noise_n", self.noise_n, 0.0, 1e6),
            ("noise_stroke_mm", self.noise_stroke_mm, 0.0, 1e3),
            ("hysteresis", self.hysteresis, 0.0, 10.0),
            ("hysteresis_offset_nmm", self.hysteresis_offset_nmm, 0.0, 1e9),
            ("hysteresis_angle_deg", self.hysteresis_angle_deg, 1e-6, 360.0),
            ("detection_load_n", self.detection_load_n, 0.0, 1e6),
            ("dwell_s", self.dwell_s, 0.0, 1e6),
            ("stroke_offset_mm", self.stroke_offset_mm, -1e6, 1e6),
        ]
        for name, v, lo, hi in checks:
            try:
                fv = float(v)
            except (TypeError, ValueError):
                raise InputError(f"{name} = {v!r} is not a number") from None
            if not (math.isfinite(fv) and lo <= fv <= hi):
                raise InputError(f"{name} = {v!r} is outside the allowed range [{lo:g}, {hi:g}]")
        if self.seed is not None and (isinstance(self.seed, bool) or not isinstance(self.seed, int | np.integer)
                                      or not 0 <= int(self.seed) < 2**128):
            raise InputError(f"seed = {self.seed!r} must be an integer in [0, 2^128)")
        if self.hysteresis_law not in LAWS:
            raise InputError(f"hysteresis_law = {self.hysteresis_law!r}; choose one of {', '.join(LAWS)}")


def _signed(actuator):
    return actuator.bend_sign or 1


def simulate_test(actuator, pressure_kpa: float, model: str | None = None, *, fixture: Fixture = PAPER_FIXTURE,
                  settings: SimulationSettings | None = None, rng: np.random.Generator | None = None):
    """Simulate one cyclic test.  Returns ``(data, truth)``.

    ``data`` is a DataFrame with ``time_s``, ``stroke_mm``, ``force_n`` as a machine records them;
    ``truth`` is a dict of the values processing should recover (magnitudes).

    Examples
    --------
    >>> import bendpam
    >>> data, truth = simulate_test(bendpam.physics.presets.be_pam(), 150.0, settings=SimulationSettings(seed=1))
    >>> data.columns.tolist(), len(data)
    (['time_s', 'stroke_mm', 'force_n'], 5250)
    >>> round(truth["blocked_moment_nmm"], 1), round(truth["free_curvature_per_mm"], 5)   # N*mm, 1/mm
    (204.3, 0.00729)
    """
    st = settings or SimulationSettings()
    model = resolve_model(actuator, model)
    rng = rng if rng is not None else np.random.default_rng(st.seed)
    P, Mb, A, law, m_qs = _setup(actuator, pressure_kpa, model, st)
    k_f, s_f = _free_state(actuator, P, pressure_kpa, model, fixture, law, A, st, m_qs)
    t, s, T = _stroke_path(s_f, st, pressure_kpa)
    force, _M, _k = _machine(actuator, P, model, fixture, law, A, s, m_qs)
    truth_cycles = _truth(actuator, P, model, fixture, law, A, s_f, st.cycles, m_qs)
    data = pd.DataFrame({
        "time_s": t,
        "stroke_mm": s + st.stroke_offset_mm + rng.normal(0.0, st.noise_stroke_mm, t.size),
        "force_n": force + rng.normal(0.0, st.noise_n, t.size),
    })
    fb = free_curvature(actuator, P, model)
    truth = {
        "pressure_kpa": float(pressure_kpa),
        "free_stroke_mm": s_f,
        "free_curvature_per_mm": k_f,
        "blocked_moment_nmm": truth_cycles["blocked_moment_nmm"],
        "energy_loss_ratio": truth_cycles["energy_loss_ratio"],
        "hysteresis_amplitude_nmm": A,
        "loop": {"law": st.hysteresis_law, "a0_nmm": st.hysteresis_offset_nmm,
                 "a1_nmm_per_kpa": st.hysteresis * Mb / max(P - actuator.P_start_kpa, 1e-300),
                 "theta_h_deg": st.hysteresis_angle_deg, "amplitude": "linear"},
        "model_blocked_moment_nmm": Mb,
        "model_free_curvature_per_mm": abs(float(fb.curvature_per_mm)) if fb.status.item() == "ok" else None,
        "samples": int(t.size),
        "duration_s": float(T),
    }
    return data, truth


def _setup(actuator, pressure_kpa: float, model: str, st: SimulationSettings):
    """The pressure, blocked moment, loop amplitude, loop law and quasi-static moment of one test."""
    P = float(number("pressure_kpa", pressure_kpa, 0.0, unit="kPa"))
    sgn = _signed(actuator)
    Mb = abs(float(blocked_moment(actuator, P, model)))
    if Mb <= 0.0:
        raise InputError(
            f"pressure {pressure_kpa:g} kPa is at or below P_start = {actuator.P_start_kpa:g} kPa: "
            "the actuator produces no moment to test"
        )
    A = st.hysteresis * Mb + st.hysteresis_offset_nmm
    law = make_law(st.hysteresis_law, st.hysteresis_angle_deg)

    def m_qs(k):  # model moment magnitude at curvature magnitude k
        return sgn * moment(actuator, P, sgn * np.asarray(k, dtype=float), model)

    return P, Mb, A, law, m_qs


def _free_state(actuator, P: float, pressure_kpa: float, model: str, fixture: Fixture, law, A: float,
                st: SimulationSettings, m_qs) -> tuple[float, float]:
    """Step 1: the free position, found as the machine finds it: ``(curvature 1/mm, stroke mm)``.

    The actuator is released from the blocked state (z0 = -1) on the unloading branch until the
    force falls to the detection load, before the lock-up limit and the fixture's plate pitch limit.
    """
    sgn = _signed(actuator)
    L0 = fixture.L0_mm
    lim = curvature_limits(actuator)
    k_lim = 0.999 * (lim.k_max if sgn > 0 else -lim.k_min)

    def force_unloading(k):  # vectorised over k
        # z on the unloading branch from the saturated state after a loading (an unbounded span)
        z, _ = law.steady_branches(np.asarray(k, dtype=float) * L0, np.inf)
        beta = fixture.curvature_to_beta(k)
        return (m_qs(k) - A * z) / fixture.lever(beta) - st.detection_load_n

    k_hi = min(k_lim, float(fixture.beta_to_curvature(math.radians(MAX_BETA_DEG))))
    grid = np.linspace(0.0, k_hi, 400)
    fvals = force_unloading(grid)
    cross = np.flatnonzero(fvals <= 0.0)
    if fvals[0] <= 0.0 or cross.size == 0:
        fb = free_curvature(actuator, P, model)
        why = fb.reason.item() if fb.status.item() == "no-equilibrium" else "the unloading force never falls that low"
        raise NoEquilibrium(
            f"at {pressure_kpa:g} kPa there is no free state: the force does not fall to "
            f"{st.detection_load_n:g} N before the lock-up limit or the fixture's {MAX_BETA_DEG:g} deg plate "
            f"pitch ({why})"
        )
    j = cross[0]
    k_f = brentq(lambda x: float(force_unloading(x)), grid[j - 1], grid[j], xtol=1e-14)
    return k_f, float(fixture.curvature_to_stroke(k_f))


def _stroke_path(s_f: float, st: SimulationSettings, pressure_kpa: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Step 2: the triangular stroke path, sampled at ``rate_hz``: ``(time s, stroke mm, duration s)``.

    The sample count is checked against :data:`MAX_SAMPLES` before any array is made.
    """
    knots_t, knots_s = _stroke_knots(s_f, st)
    T = knots_t[-1]
    n_samples = math.floor(T * st.rate_hz + 0.5) + 1
    if n_samples > MAX_SAMPLES:
        raise InputError(
            f"at {pressure_kpa:g} kPa the test would record {n_samples:,} samples ({st.rate_hz:g} Hz x {T:.4g} s), "
            f"more than the limit of {MAX_SAMPLES:,} per test; use a lower rate_hz, fewer cycles, a shorter "
            "dwell_s or a higher speed_mm_min"
        )
    t = np.arange(0.0, T + 0.5 / st.rate_hz, 1.0 / st.rate_hz)
    return t, np.interp(t, knots_t, knots_s), T


def _stroke_knots(s_f: float, st: SimulationSettings) -> tuple[list[float], list[float]]:
    """The corners ``(time s, stroke mm)`` of the triangular stroke path with its dwells."""
    t_ramp = s_f / (st.speed_mm_min / 60.0)
    legs = []
    for _ in range(st.cycles):
        legs += [("ramp", 0.0, s_f), ("dwell", s_f, s_f), ("ramp", s_f, 0.0), ("dwell", 0.0, 0.0)]
    knots_t, knots_s = [0.0], [0.0]
    for kind, _a, b in legs:
        dur = t_ramp if kind == "ramp" else st.dwell_s
        if dur <= 0:
            continue
        knots_t.append(knots_t[-1] + dur)
        knots_s.append(b)
    return knots_t, knots_s


def _check_total_samples(actuator, pressures_kpa: list[float], model: str, fixture: Fixture,
                         st: SimulationSettings) -> None:
    """Refuse, before any test is simulated, a run that would record more than :data:`MAX_TOTAL_SAMPLES`.

    The count is estimated from the free strokes at the lowest, middle and highest pressure (three
    free-state solutions, a few tens of milliseconds); :func:`simulate_tests` stops a run whose
    real count passes twice the limit.
    """
    ordered = sorted(pressures_kpa)
    picks = sorted({ordered[0], ordered[len(ordered) // 2], ordered[-1]})
    counts = []
    for p in picks:
        P, _Mb, A, law, m_qs = _setup(actuator, p, model, st)
        _k, s_f = _free_state(actuator, P, p, model, fixture, law, A, st, m_qs)
        counts.append(math.floor(_stroke_knots(s_f, st)[0][-1] * st.rate_hz + 0.5) + 1)
    expected = int(len(ordered) * float(np.mean(counts)))
    if expected > MAX_TOTAL_SAMPLES:
        raise InputError(
            f"{len(ordered)} tests of {st.cycles} cycles at {st.rate_hz:g} Hz would record about {expected:,} "
            f"samples, more than the limit of {MAX_TOTAL_SAMPLES:,} for one run (about five minutes); use fewer "
            "pressures, fewer cycles or a lower rate_hz"
        )


def _machine(actuator, P, model, fixture, law, A, stroke, m_qs):
    beta = fixture.stroke_to_beta(stroke)
    k = fixture.beta_to_curvature(beta)
    z = law.z_path(k * fixture.L0_mm, z0=-1.0)
    M = m_qs(k) - A * z
    return fixture.moment_to_force(M, beta), M, k


def _truth(actuator, P, model, fixture, law, A, s_f, cycles, m_qs):
    """Per-cycle blocked moment and energy-loss ratio of the noiseless loop (dense path)."""
    n = 1500
    s_up = np.linspace(0.0, s_f, n)
    one = np.concatenate([s_up, s_up[::-1]])  # the repeated turning sample is a zero step: z unchanged
    _, M, k = _machine(actuator, P, model, fixture, law, A, np.tile(one, cycles), m_qs)
    bms, ratios = [], []
    for c in range(cycles):
        seg_M, seg_k = M[2 * n * c: 2 * n * (c + 1)], k[2 * n * c: 2 * n * (c + 1)]
        up_k, up_M = seg_k[:n], seg_M[:n]  # unloading (lower branch), k increasing
        dn_k, dn_M = seg_k[n:][::-1], seg_M[n:][::-1]  # loading (upper branch), re-ordered by k
        th = up_k * fixture.L0_mm
        upper = np.interp(up_k, dn_k, dn_M)
        loss = np.trapezoid(upper - up_M, th)
        stored = np.trapezoid(0.5 * (upper + up_M), th)
        bms.append(float(seg_M.max()))
        ratios.append(float(loss / stored))
    return {"blocked_moment_nmm": float(np.mean(bms)), "energy_loss_ratio": float(np.mean(ratios)),
            "cycles_blocked_moment_nmm": bms, "cycles_energy_loss_ratio": ratios}


def simulate_tests(actuator, pressures_kpa, out_dir, model: str | None = None, *, dialect: str = "csv",
                   fixture: Fixture = PAPER_FIXTURE, settings: SimulationSettings | None = None,
                   prefix: str | None = None) -> dict:
    """Simulate tests at several pressures and write one raw file each plus ``truth.json``.

    Files are named ``{prefix}_{P}kPa{suffix}`` with the dialect's usual suffix and carry a
    ``Pressure`` metadata line.  Returns the truth dictionary that is also written to
    ``truth.json`` (atomically).

    Examples
    --------
    >>> import tempfile
    >>> import bendpam
    >>> from pathlib import Path
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     truth = simulate_tests(bendpam.physics.presets.be_pam(), [150.0], folder, dialect="testxpert",
    ...                            settings=SimulationSettings(cycles=2, rate_hz=5.0, seed=1))
    ...     written = sorted(path.name for path in Path(folder).iterdir())
    >>> written
    ['be-pam_150kPa.txt', 'truth.json']
    >>> round(truth["pressures"][0]["blocked_moment_nmm"], 1)            # N*mm
    204.3
    """
    from bendpam.lab.writers import write_test

    st = settings or SimulationSettings()
    model = resolve_model(actuator, model)
    if dialect not in DIALECT_SUFFIX:
        raise InputError(f"format {dialect!r} is not known; choose one of: {', '.join(DIALECT_SUFFIX)}")
    pressures_kpa = [float(p) for p in pressures_kpa]
    if pressures_kpa:
        _check_total_samples(actuator, pressures_kpa, model, fixture, st)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(st.seed)
    prefix = prefix or (actuator.kind.lower())
    truths = []
    files = []
    recorded = 0
    for p in pressures_kpa:
        data, truth = simulate_test(actuator, p, model, fixture=fixture, settings=st, rng=rng)
        name = f"{prefix}_{p:g}kPa{DIALECT_SUFFIX[dialect]}"
        meta = {"Actuator": actuator.name or actuator.kind, "Test speed": f"{st.speed_mm_min:g} mm/min",
                "Generator": "bendpam simulate-test"}
        write_test(out / name, data, dialect, metadata=meta, pressure_kpa=float(p),
                   force_unit="kN" if dialect == "mts" else "N")
        truth["file"] = name
        truths.append(truth)
        recorded += truth["samples"]
        if recorded > 2 * MAX_TOTAL_SAMPLES:
            raise InputError(
                f"the tests recorded {recorded:,} samples by {p:g} kPa, more than twice the limit of "
                f"{MAX_TOTAL_SAMPLES:,} for one run that the estimate allowed; use fewer pressures, fewer "
                "cycles or a lower rate_hz"
            )
        files.append(name)
    result = {
        "model": model,
        "actuator": actuator.to_dict(),
        "format": dialect,
        "fixture": asdict(fixture),
        "settings": asdict(st),
        "deadband_kpa": actuator.P_start_kpa,
        "pressures": truths,
        "files": files,
        "units": {"moment": "N*mm", "curvature": "1/mm", "pressure": "kPa", "sign": "magnitudes"},
    }
    atomic_write_text(out / "truth.json", json.dumps(json_safe(result), indent=2, allow_nan=False))
    return result
