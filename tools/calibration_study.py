"""The calibration study of bendpam's error bars (issue 23): do the fit's standard errors hold?

    python tools/calibration_study.py [--seeds 10] [--set main|holdout|...|holdout11] [--cases CASE ...] [--jobs 1]
                                      [--out FILE]

For every case of :data:`raw_generators.CASES` (or of :data:`raw_generators.HOLDOUT` with ``--set holdout``:
cases kept out of any tuning) and every seed, raw test files are made by the
independent generators (``tools/raw_generators.py``: loop laws and instrument faults bendpam does not
assume), then read, processed and fitted through bendpam's Python API with the defaults of
``bendpam process`` and ``bendpam fit`` (a drift case is processed twice: with the linear drift
correction and without it, to show what the flag is for).  Per case it reports, for alpha0, the
shear modulus mu = 2 (C10 + C01) and the shape C01 / (C10 + C01):

* bias: the mean of (fitted - true) over the seeds (mu in % of the truth);
* mean SE: the mean of the fit's standard errors (statistical and systematic, as the fit reports them);
* SD: the seed-to-seed standard deviation of the fitted values;
* SE/SD: well-calibrated error bars give about 1 (the issue's target: at most 3);
* coverage: the share of runs whose ``|fitted - true| <= 2 SE`` (target: at least 85 %);
* for the shape, how often the fit called it determined, and the coverage among those;
* the tests whose drift was flagged, and the runs that failed (read, process or fit refused).

It writes the numbers as JSON (``--out``, default ``benchmarks/results/calibration.json``) and the
tables into ``docs/calibration.md`` between its two markers (``--docs``; ``--no-docs`` leaves the page).
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import sys
import tempfile
import time
import traceback
import warnings
from concurrent.futures import ProcessPoolExecutor
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))

import holdout6_generator as gen6  # noqa: E402
import holdout7_generator as gen7  # noqa: E402
import holdout8_generator as gen8  # noqa: E402
import holdout9_generator as gen9  # noqa: E402
import holdout10_generator as gen10  # noqa: E402
import holdout11_generator as gen11  # noqa: E402
import raw_generators as gen  # noqa: E402

from bendpam.infra.atomic import atomic_write_text, json_safe  # noqa: E402
from bendpam.version import __version__  # noqa: E402

START, END = "<!-- calibration-table:start -->", "<!-- calibration-table:end -->"
#: The case sets: ``main`` (:data:`raw_generators.CASES`, what the error bars are tuned and judged on) and
#: ``holdout`` (:data:`raw_generators.HOLDOUT`, other parameters and combined faults, kept out of any tuning).
SETS = {"main": gen.CASES, "holdout": gen.HOLDOUT, "holdout2": gen.HOLDOUT2, "holdout3": gen.HOLDOUT3,
        "holdout4": gen.HOLDOUT4, "holdout5": gen.HOLDOUT5, "holdout6": gen6.CASES, "holdout7": gen7.CASES,
        "holdout8": gen8.CASES, "holdout9": gen9.CASES, "holdout10": gen10.CASES,
        "holdout11": gen11.CASES}
ALL_CASES = {**gen.CASES, **gen.HOLDOUT, **gen.HOLDOUT2, **gen.HOLDOUT3, **gen.HOLDOUT4, **gen.HOLDOUT5,
             **gen6.CASES, **gen7.CASES, **gen8.CASES, **gen9.CASES, **gen10.CASES, **gen11.CASES}


def generator(case):
    """The module that makes ``case``'s raw tests: :mod:`holdout11_generator`, :mod:`holdout10_generator`,
    :mod:`holdout9_generator`,
    :mod:`holdout8_generator`,
    :mod:`holdout7_generator` and
    :mod:`holdout6_generator` for
    theirs (a machine written independently), :mod:`raw_generators` for the others; each has ``generate_set``
    and ``start_actuator``."""
    if isinstance(case, gen11.Case11):
        return gen11
    if isinstance(case, gen10.Case10):
        return gen10
    if isinstance(case, gen9.Case9):
        return gen9
    if isinstance(case, gen8.Case8):
        return gen8
    if isinstance(case, gen7.Case7):
        return gen7
    return gen6 if isinstance(case, gen6.Case6) else gen


def markers(case_set: str) -> tuple[str, str]:
    """The docs page's markers of a case set's tables."""
    name = case_set.removeprefix("main-")  # "main-tared": the main set with --tared
    return (START, END) if case_set == "main" else (f"<!-- calibration-{name}:start -->",
                                                     f"<!-- calibration-{name}:end -->")
COVERAGE_TARGET, RATIO_TARGET = 0.85, 3.0
#: What ``--tared`` declares (:class:`~bendpam.identify.uncertainty.Instrument` ``(force %, pressure kPa, zero N,
#: pressure force N/kPa)``): a lab that tared its load cell with the fixture as tested, to 5 mN (0.1 % of the study's
#: smallest blocked force, about 4.4 N; the mean of a second of readings), and checked that no force in proportion
#: to the pressure reaches it.
TARED = (0.0, 0.0, 0.005, 0.0)


# ------------------------------------------------------------------------------------------------
# one run
# ------------------------------------------------------------------------------------------------
def _fit_record(result) -> dict:
    """The numbers of one fit: alpha0, mu, shape with their standard errors, and the loop law's shift."""
    a = result.parameters["alpha0"]
    m = result.material
    shift = (result.hysteresis.law_shift.get("alpha0_deg") if result.hysteresis is not None else None)
    return {"alpha0_deg": a.value, "se_alpha0_deg": a.stderr,
            "alpha0_law_shift_deg": shift,
            "mu_kpa": m.shear_modulus_kpa if m else None, "se_mu_kpa": m.se_shear_modulus_kpa if m else None,
            "shape": m.shape if m else None, "se_shape": m.se_shape if m else None,
            "shape_determined": bool(m.shape_identified) if m else False,
            "shape_narrow": bool(getattr(m, "shape_narrow", m.shape_identified)) if m else False,
            "converged": bool(result.converged), "loop": result.metrics.curves}


def run_one(case_name: str, seed: int, case: gen.Case | gen6.Case6 | None = None,
            fit_options: dict | None = None) -> list[dict]:
    """Generate, read, process and fit one case and seed: one record per processing variant.

    ``fit_options`` are keywords of :func:`bendpam.identify.fitting.fit` (default: those of ``bendpam fit``); an
    ``instrument`` given as ``(force %, pressure kPa)`` is the :class:`~bendpam.identify.uncertainty.Instrument`.
    """
    fit_kw = dict(fit_options or {})
    from bendpam.identify.fitting import fit
    from bendpam.identify.uncertainty import Instrument

    if isinstance(fit_kw.get("instrument"), tuple | list):
        fit_kw["instrument"] = Instrument(*fit_kw["instrument"])
    from bendpam.lab import read_test
    from bendpam.lab.processing import process_tests
    from bendpam.physics.fixture import Fixture

    case = case or ALL_CASES[case_name]
    variants = ["linear", "none"] if case.drift_fraction else ["none"]
    records = []
    with tempfile.TemporaryDirectory(prefix="bendpam-calib-") as folder, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t0 = time.perf_counter()
        try:
            truth = generator(case).generate_set(case, seed, folder)
            raws = [read_test(Path(folder) / name) for name in truth["files"]]
        except Exception as exc:  # a failed run is counted, with its reason
            return [{"case": case_name, "variant": v, "seed": seed, "case_info": _case_info(case),
                     "failed": f"generate/read: {_why(exc)}"} for v in variants]
        t_gen = time.perf_counter() - t0
        for drift in variants:
            t1 = time.perf_counter()
            rec = {"case": case_name, "variant": drift, "seed": seed, "case_info": _case_info(case), "truth": {
                k: truth[k] for k in ("alpha0_deg", "shear_modulus_kpa", "shape")}}
            try:
                ps = process_tests(raws, fixture=Fixture(L0_mm=truth["fixture_L0_mm"]), keep_series=False,
                                   drift=drift)
                rec["drift_flagged"] = sum(bool(r.drift is not None and r.drift.flagged) for r in ps.results)
                rec["tests"] = len(ps.results)
                rec.update(_fit_record(fit(ps, generator(case).start_actuator(case), **fit_kw)))
                if drift == "linear":
                    rec.update(_drift_propagation(raws, ps, Fixture(L0_mm=truth["fixture_L0_mm"]), case, fit_kw))
            except Exception as exc:
                rec["failed"] = f"process/fit: {_why(exc)}"
            rec["seconds"] = t_gen + time.perf_counter() - t1  # generating and reading, then this variant
            records.append(rec)
    return records


def _drift_propagation(raws, processed, fixture, case: gen.Case | gen6.Case6, fit_kw: dict) -> dict:
    """What the drift corrections' own uncertainty adds to alpha0's and mu's SE (a diagnostic the fit lacks).

    Each test's force is corrected by its fitted drift rate, once as estimated and once with one test's rate moved
    by its standard error (processed without a further correction, refitted): the shifts, added in quadrature over
    the tests (their drift estimates are independent), are the standard errors the correction contributes.
    """
    import dataclasses

    from bendpam.identify.fitting import fit
    from bendpam.lab.processing import process_tests

    est = {float(r.pressure_kpa): r.drift for r in processed.results}

    def refit(moved: int | None) -> tuple[float, float]:
        shifted = []
        for i, raw in enumerate(raws):
            e = est[float(raw.pressure_kpa)]
            rate = e.rate_n_per_s + (e.rate_se_n_per_s if i == moved else 0.0)
            d = raw.data
            force = d["force_n"] - rate * (d["time_s"] - e.t0_s)
            shifted.append(dataclasses.replace(raw, data=d.assign(force_n=force)))
        r = fit(process_tests(shifted, fixture=fixture, keep_series=False, drift="none"),
                generator(case).start_actuator(case), **fit_kw)
        return r.parameters["alpha0"].value, r.material.shear_modulus_kpa

    a0, m0 = refit(None)
    shifts = np.array([np.subtract(refit(i), (a0, m0)) for i in range(len(raws))])
    return {"se_alpha0_drift_deg": float(np.sqrt(np.sum(shifts[:, 0] ** 2))),
            "se_mu_drift_kpa": float(np.sqrt(np.sum(shifts[:, 1] ** 2)))}


def _case_info(case: gen.Case | gen6.Case6) -> dict:
    """What the table says of a case (its actuator, pressures, loop, noise, drift, truth of the shape)."""
    keys = ("loop", "loop_fraction", "preset", "model", "pressures_kpa", "noise_fraction", "noise_ar1",
            "drift_fraction", "dialect", "cycles", "rate_hz")
    info = {k: (list(v) if isinstance(v, tuple) else v) for k in keys for v in [getattr(case, k)]}
    return {**info, "true_shape": case.shape}


def _why(exc: BaseException) -> str:
    text = str(exc).splitlines()[0] if str(exc) else ""
    where = traceback.extract_tb(exc.__traceback__)[-1] if exc.__traceback__ else None
    return f"{type(exc).__name__}: {text}" + (f" ({Path(where.filename).name}:{where.lineno})" if where else "")


# ------------------------------------------------------------------------------------------------
# the summary
# ------------------------------------------------------------------------------------------------
def _stats(est, se, truth, scale: float = 1.0) -> dict:
    """Bias, mean SE, seed-to-seed SD, SE/SD, 2-SE coverage (``scale`` turns the numbers into the table's unit)."""
    est, se = np.asarray(est, float), np.asarray(se, float)
    ok = np.isfinite(est) & np.isfinite(se)
    if not ok.any():
        return {"n": 0}
    err = est[ok] - truth
    sd = float(np.std(est[ok], ddof=1)) if ok.sum() > 1 else math.nan
    mse = float(np.mean(se[ok]))
    return {"n": int(ok.sum()), "bias": float(np.mean(err)) * scale, "mean_se": mse * scale, "sd": sd * scale,
            "se_over_sd": mse / sd if sd > 0 else math.inf, "coverage": float(np.mean(np.abs(err) <= 2.0 * se[ok])),
            "bias_in_se": float(np.mean(err)) / mse if mse > 0 else math.inf,
            "rms_z": float(np.sqrt(np.mean((err / se[ok]) ** 2)))}


def summarise(records: list[dict]) -> list[dict]:
    """One row per case and processing variant, in the order of the records."""
    rows: dict[tuple[str, str], list[dict]] = {}
    for r in records:
        rows.setdefault((r["case"], r["variant"]), []).append(r)
    out = []
    for (name, variant), recs in rows.items():
        good = [r for r in recs if "failed" not in r]
        row = {"case": name, "variant": variant, "runs": len(recs), "failed": len(recs) - len(good),
               "failures": sorted({r["failed"] for r in recs if "failed" in r}), **recs[0]["case_info"]}
        if good:
            t = good[0]["truth"]

            def col(k, good=good):
                return [np.nan if r.get(k) is None else r[k] for r in good]

            row["alpha0"] = _stats(col("alpha0_deg"), col("se_alpha0_deg"), t["alpha0_deg"])
            row["mu"] = _stats(col("mu_kpa"), col("se_mu_kpa"), t["shear_modulus_kpa"],
                               100.0 / t["shear_modulus_kpa"])
            row["shape"] = _stats(col("shape"), col("se_shape"), t["shape"])
            if all(r.get("se_alpha0_drift_deg") is not None for r in good):
                se_a = np.hypot(col("se_alpha0_deg"), col("se_alpha0_drift_deg"))
                row["alpha0_drift_se"] = _stats(col("alpha0_deg"), se_a, t["alpha0_deg"])
                row["mu_drift_se"] = _stats(col("mu_kpa"), np.hypot(col("se_mu_kpa"), col("se_mu_drift_kpa")),
                                            t["shear_modulus_kpa"], 100.0 / t["shear_modulus_kpa"])
            nar = [r for r in good if r.get("shape_narrow", r["shape_determined"]) and r.get("se_shape") is not None]
            row["shape_narrow"] = len(nar)
            row["shape_narrow_covered"] = sum(abs(r["shape"] - t["shape"]) <= 2.0 * r["se_shape"] for r in nar)
            row["shape_determined"] = sum(bool(r["shape_determined"]) for r in good)
            row["drift_flagged"] = sum(r["drift_flagged"] for r in good)
            row["tests"] = sum(r["tests"] for r in good)
            row["seconds_per_run"] = float(np.mean([r["seconds"] for r in good]))
        out.append(row)
    return out


def _label(row: dict) -> str:
    if row["variant"] == "linear":
        return f"{row['case']} (corrected)"
    return f"{row['case']} (not corrected)" if row.get("drift_fraction") else row["case"]


def _f(x, fmt: str) -> str:
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, fmt)


def _pct(x) -> str:
    return "-" if x is None or not math.isfinite(x) else f"{100 * x:.0f} %"


def _mark(row: dict, key: str) -> str:
    s = row.get(key) or {}
    if not s.get("n"):
        return "-"
    ok = s["coverage"] >= COVERAGE_TARGET and s["se_over_sd"] <= RATIO_TARGET
    return "yes" if ok else "**no**"


def tables(rows: list[dict], meta: dict) -> str:
    """The markdown tables of the summary (alpha0, mu, shape and drift)."""
    lines = [f"{meta['seeds']} seeds per case; bendpam {meta['version']} (commit {meta['commit']}); "
             f"{meta['runs']} runs in {meta['wall_s']:.0f} s on {meta['jobs']} process(es)"
             + (f"; fit options {meta['fit_options']}" if meta.get("fit_options") else "") + ".", "",
             "| case | actuator, pressures (kPa) | noise (AR(1)) | runs (failed) | α0 bias (deg) | α0 mean SE "
             "| α0 SD | SE/SD | α0 coverage"
             " | μ bias (%) | μ mean SE (%) | μ SD (%) | SE/SD | μ coverage | target met |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        a, m = r.get("alpha0") or {}, r.get("mu") or {}
        met = "yes" if _mark(r, "alpha0") == "yes" and _mark(r, "mu") == "yes" else "**no**"
        lines.append(
            f"| {_label(r)} | {r.get('preset', '')} {r.get('model', '')}, "
            f"{', '.join(f'{p:g}' for p in r.get('pressures_kpa', []))} | "
            f"{100 * r.get('noise_fraction', 0):.1f} % ({r.get('noise_ar1', 0):g}) | {r['runs']} ({r['failed']}) | "
            f"{_f(a.get('bias'), '+.3f')} | {_f(a.get('mean_se'), '.3f')} | {_f(a.get('sd'), '.3f')} | "
            f"{_f(a.get('se_over_sd'), '.2g')} | {_pct(a.get('coverage'))} | {_f(m.get('bias'), '+.2f')} | "
            f"{_f(m.get('mean_se'), '.2f')} | {_f(m.get('sd'), '.2f')} | {_f(m.get('se_over_sd'), '.2g')} | "
            f"{_pct(m.get('coverage'))} | {met} |")
    lines += ["", "| case | shape truth | shape bias | shape mean SE | shape SD | shape coverage | "
              "interval narrow | truth within 2 SE when narrow | called determined | tests with drift flagged |",
              "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        s = r.get("shape") or {}
        nar, ok = r.get("shape_narrow", r.get("shape_determined", 0)), r.get("shape_narrow_covered",
                                                                          r.get("shape_determined_covered", 0))
        lines.append(
            f"| {_label(r)} | {_truth_shape(r)} | {_f(s.get('bias'), '+.3f')} | {_f(s.get('mean_se'), '.3f')} | "
            f"{_f(s.get('sd'), '.3f')} | {_pct(s.get('coverage'))} | {nar} of {r['runs'] - r['failed']} | "
            f"{ok} of {nar} | {r.get('shape_determined', 0)} | {r.get('drift_flagged', 0)} of {r.get('tests', 0)} |")
    lines += _drift_table(rows)
    fails = [f"{_label(r)}: {', '.join(r['failures'])}" for r in rows if r["failures"]]
    if fails:
        lines += ["", "Failed runs: " + "; ".join(fails) + "."]
    return "\n".join(lines)


def _drift_table(rows: list[dict]) -> list[str]:
    """The drift cases with the correction's own uncertainty added to the fit's SE (a diagnostic)."""
    drift = [r for r in rows if r.get("alpha0_drift_se")]
    if not drift:
        return []
    lines = ["", "| case | α0 mean SE, fit + drift correction | α0 coverage with it | SE/SD | "
             "μ mean SE (%), fit + drift correction | μ coverage with it | SE/SD |", "|---|---|---|---|---|---|---|"]
    for r in drift:
        a, m = r["alpha0_drift_se"], r["mu_drift_se"]
        lines.append(f"| {_label(r)} | {_f(a.get('mean_se'), '.3f')} | {_pct(a.get('coverage'))} | "
                     f"{_f(a.get('se_over_sd'), '.2g')} | {_f(m.get('mean_se'), '.2f')} | {_pct(m.get('coverage'))} | "
                     f"{_f(m.get('se_over_sd'), '.2g')} |")
    return lines


def _truth_shape(row: dict) -> str:
    return f"{row['true_shape']:g}" if "true_shape" in row else "-"


# ------------------------------------------------------------------------------------------------
# the command
# ------------------------------------------------------------------------------------------------
def run_study(case_names, seeds: int, jobs: int = 1, first_seed: int = 0, cases: dict | None = None,
              fit_options: dict | None = None) -> tuple:
    """``(records, rows, meta)`` of the study over ``case_names`` x ``seeds`` (``cases`` overrides the case set)."""
    cases = cases or ALL_CASES
    tasks = [(name, first_seed + s, cases[name], fit_options) for name in case_names for s in range(seeds)]
    t0 = time.perf_counter()
    if jobs > 1:
        with ProcessPoolExecutor(max_workers=jobs) as pool:
            parts = list(pool.map(run_one, *zip(*tasks, strict=True)))
    else:
        parts = [run_one(*task) for task in tasks]
    wall = time.perf_counter() - t0
    records = [r for p in parts for r in p]
    meta = {"fit_options": dict(fit_options or {}),
            "seeds": seeds, "first_seed": first_seed, "cases": list(case_names), "jobs": jobs, "wall_s": wall,
            "runs": len(records), "version": __version__, "commit": _commit(), "bendpam": _where(),
            "date": datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ"), "python": platform.python_version(),
            "machine": platform.machine()}
    return records, summarise(records), meta


def _commit() -> str:
    """The commit of the bendpam under test (the repository its package was imported from), ``+`` when modified."""
    import subprocess

    import bendpam

    where = str(Path(bendpam.__file__).resolve().parent)
    try:
        head = subprocess.run(["git", "-C", where, "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                              timeout=10, check=False).stdout.strip()
        dirty = subprocess.run(["git", "-C", where, "status", "--porcelain", "--", "."], capture_output=True,
                               text=True, timeout=10, check=False).stdout.strip()
        return (head + ("+" if dirty else "")) or "unknown"
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def _where() -> str:
    import bendpam

    return str(Path(bendpam.__file__).resolve().parent)


def write_docs(path: Path, text: str, case_set: str = "main") -> None:
    """Put ``text`` between the page's markers of ``case_set`` (the rest of the page is left as it is)."""
    start, end = markers(case_set)
    page = path.read_text(encoding="utf-8")
    i, j = page.find(start), page.find(end)
    if i < 0 or j < i:
        raise SystemExit(f"calibration_study: {path} has no {start} ... {end} markers")
    atomic_write_text(path, page[: i + len(start)] + "\n" + text + "\n" + page[j:])


def _fit_options(ap: argparse.ArgumentParser, items: list[str]) -> dict:
    import ast

    out = {}
    for item in items:
        key, sep, value = item.partition("=")
        try:
            out[key.strip()] = ast.literal_eval(value.strip())
        except (ValueError, SyntaxError):
            ap.error(f"--fit {item!r}: expected KEY=VALUE with a Python literal value")
        if not sep or not key.strip().isidentifier():
            ap.error(f"--fit {item!r}: expected KEY=VALUE")
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=10, help="seeds per case (default 10)")
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument("--set", dest="case_set", choices=list(SETS), default="main",
                    help="main (default): the cases the error bars are judged on; holdout: other parameters and "
                    "combined faults, kept out of any tuning; holdout2-4: further such sets, each scored once; "
                    "holdout5: loop laws and instrument faults chosen independently of the fit (a springpot, Iwan, "
                    "Coleman-Hodgdon, asymmetric stops, rate-and-state friction, softening; pressure leak and "
                    "ripple, load-cell error, frame compliance, filtered force, dropped rows, clipping), scored once; "
                    "holdout6: an independent machine (tools/holdout6_generator.py: its own fixture, waveforms, "
                    "loop laws, faults and export layouts), scored once; holdout7: eight more loop laws on that "
                    "machine with a careful lab's instrument (tools/holdout7_generator.py), scored once; holdout8: "
                    "common loop laws with a lab's instrument faults on that machine (a tare offset, a warm-up drift, "
                    "a wandering offset, a stroke zero error, a quantised force; tools/holdout8_generator.py); "
                    "holdout9: further loop laws and faults on that machine (a channel skew, pressure crosstalk, a "
                    "clock error, spikes, a slipping clamp, a pressure droop; tools/holdout9_generator.py); "
                    "holdout10: loop laws of the actuator's own physics (braid friction, orifice damping, a "
                    "thixotropic grease, a filler network, Bliman-Sorine, Mullins, Stoner-Wohlfarth, "
                    "Prandtl-Tomlinson) and logging faults on that machine (a gain drift, a quantised stroke, packet "
                    "time stamps, re-sent rows, a supply-pressure step, data reduction; tools/holdout10_generator.py); "
                    "holdout11: lubricant, adhesion, wrinkling, contact, crystallisation and stick-slip loops with a "
                    "lab's handling faults on that machine (load-cell creep and hysteresis, a pause, a results table, "
                    "thermal expansion, regulator hysteresis, a mis-set speed; tools/holdout11_generator.py)")
    ap.add_argument("--cases", nargs="+", choices=list(ALL_CASES), metavar="CASE",
                    help=f"cases to run (default: the whole set; main: {', '.join(gen.CASES)}; holdout: "
                    f"{', '.join(gen.HOLDOUT)}; holdout2: {', '.join(gen.HOLDOUT2)}; "
                    f"holdout3: {', '.join(gen.HOLDOUT3)}; holdout4: {', '.join(gen.HOLDOUT4)}; "
                    f"holdout5: {', '.join(gen.HOLDOUT5)}; holdout6: {', '.join(gen6.CASES)}; "
                    f"holdout7: {', '.join(gen7.CASES)}; holdout8: {', '.join(gen8.CASES)}; "
                    f"holdout9: {', '.join(gen9.CASES)}; holdout10: {', '.join(gen10.CASES)}; "
                    f"holdout11: {', '.join(gen11.CASES)})")
    ap.add_argument("--tared", action="store_true",
                    help="every fit declares the load cell tared to 5 mN and no force in proportion to the pressure "
                    f"(--fit instrument={TARED}); its own JSON and docs tables (calibration-tared)")
    ap.add_argument("--jobs", type=int, default=1, help="processes (default 1; the machine may be shared)")
    ap.add_argument("--fit", dest="fit_options", action="append", default=[], metavar="KEY=VALUE",
                    help="a keyword of bendpam.identify.fitting.fit, as a Python literal (law_uncertainty=False, "
                    "hysteresis_law='dahl'); repeatable; the default is the defaults of `bendpam fit`")
    ap.add_argument("--out", type=Path, help="JSON of every run and the summary (default "
                    "benchmarks/results/calibration.json, calibration-holdout.json for the holdout set)")
    ap.add_argument("--docs", type=Path, default=ROOT / "docs" / "calibration.md", help="page to put the tables in")
    ap.add_argument("--no-docs", action="store_true", help="leave the docs page as it is")
    args = ap.parse_args(argv)
    if args.seeds < 2 or args.jobs < 1:
        ap.error("--seeds must be at least 2 and --jobs at least 1")
    if args.tared and args.case_set != "main" and not args.no_docs:
        ap.error("--tared has docs tables for the main set only: add --no-docs (and --out) for another set")
    cases = args.cases or list(SETS[args.case_set])
    name = ("" if args.case_set == "main" else f"-{args.case_set}") + ("-tared" if args.tared else "")
    out = args.out or ROOT / "benchmarks" / "results" / f"calibration{name}.json"
    fit_options = _fit_options(ap, args.fit_options)
    if args.tared:
        fit_options.setdefault("instrument", TARED)
    records, rows, meta = run_study(cases, args.seeds, args.jobs, args.first_seed, fit_options=fit_options)
    meta["set"] = args.case_set
    text = tables(rows, meta)
    print(text)
    out.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out, json.dumps(json_safe({"meta": meta, "summary": rows, "runs": records}), indent=1,
                                      allow_nan=False))
    if not args.no_docs:
        write_docs(args.docs, text, args.case_set + ("-tared" if args.tared else ""))
    print(f"wrote {out}" + ("" if args.no_docs else f" and the tables in {args.docs}"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
