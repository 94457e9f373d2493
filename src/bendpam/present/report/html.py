"""The report as one HTML page, rendered from the Jinja2 templates in ``present/report/templates/``.

:func:`render_page` gathers what each section shows (tables as rows of cells, the fits' notes,
the figures drawn by :func:`bendpam.present.report.plots.draw_figures`) and renders
``page.html.j2``; the templates lay it out: ``warnings.html.j2`` (the box at the top),
``tests.html.j2`` (Table 2, Figure 4), ``fits.html.j2`` and ``fit_detail.html.j2`` (Table 3, each
model), ``hysteresis.html.j2``, ``actuator.html.j2``, ``inputs.html.j2``, with ``macros.html.j2``
for cells, tables and figures and ``report.css`` for the screen and print style.  Every value is
escaped by Jinja2 (``autoescape``) unless it is markup made here on purpose.  Every table cell with
a number carries it unformatted in ``data-value`` (and its standard error in ``data-se``).
"""

from __future__ import annotations

import base64
import datetime as _dt
import html
import math
import struct
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cache
from typing import Any

import numpy as np
from markupsafe import Markup

from bendpam.identify.diagnose import LIMITS, at_bound
from bendpam.present.report.findings import ReportWarning, diagnosis, fit_notes
from bendpam.present.report.tables import T3_PARAMS, shear_modulus, table2_rows, table3_rows
from bendpam.present.report.text import (
    LAW_LABEL,
    MODEL_LABEL,
    corr_text,
    escape,
    finite,
    fmt_pct,
    fmt_value,
    law_label,
    plain_html,
    symbol,
)

__all__ = ["fits_curves", "render_page"]


# ------------------------------------------------------------------------------------------------
# cells, rows and tables (laid out by macros.html.j2)
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class _Cell:
    text: Any  # str (escaped by the template) or Markup
    value: Any = None  # the number in data-value
    se: Any = None  # its standard error in data-se
    cls: str = "num"


@dataclass(frozen=True)
class _Row:
    cells: list[_Cell]
    head: Any = None  # the row's <th> (markup), or None
    attrs: dict[str, str] = field(default_factory=dict)
    tail: Any = ""  # markup after the cells


@dataclass(frozen=True)
class _Table:
    tid: str
    caption: Any
    head: list
    rows: list[_Row]


def _td(text, value=None, se=None, cls: str = "num", *, raw: bool = False) -> _Cell:
    return _Cell(Markup(text) if raw else text, value, se, cls)


def _dv(x) -> str:
    """A ``data-value`` attribute value: the float's repr, or empty."""
    if isinstance(x, bool) or x is None:
        return ""
    if isinstance(x, int | np.integer):
        return str(int(x))
    return repr(float(x)) if finite(x) else ""


def _png_size(data: bytes) -> tuple[int, int] | None:
    if data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR":
        w, h = struct.unpack(">II", data[16:24])
        return (w, h) if w and h else None
    return None


@cache
def _environment():
    from jinja2 import Environment, PackageLoader

    env = Environment(loader=PackageLoader("bendpam.present.report", "templates"), autoescape=True,
                      trim_blocks=True, lstrip_blocks=True, keep_trailing_newline=True)
    env.filters.update(dv=_dv, png_size=_png_size, b64=lambda b: base64.b64encode(b).decode("ascii"),
                       plain_html=lambda s: Markup(plain_html(s)), fmt_value=fmt_value)
    return env


# ------------------------------------------------------------------------------------------------
# the page
# ------------------------------------------------------------------------------------------------
def render_page(*, actuator, summary: dict, fits: Mapping, figures: Mapping, inputs_info: Sequence[dict], fixture,
                options, free: Sequence[str], stresses: dict | None, notes: Sequence[str], version: str,
                warnings: Sequence[ReportWarning], hyst: Mapping, hyst_error: str | None, separate, loops: bool,
                mean_ratio: float, failed: Mapping[str, str], models: Sequence[str]) -> str:
    """The report's HTML page (see :func:`bendpam.present.report.build.build_report` for what it shows).

    Parameters
    ----------
    actuator : the nominal actuator.  summary : ``ProcessedSet.summary()``.  fits : ``{model: FitResult}``.
    figures : ``{id: Drawn}`` (:func:`bendpam.present.report.plots.draw_figures`).
    inputs_info : per file its path, dialect, pressure, pressure source, samples and units.
    fixture, options : the fixture and processing options used.  free : the parameters fitted.
    stresses : the pressure and curvature of the stress figure, or None.  notes : figures not drawn.
    version : bendpam's.  warnings : the warning box (:func:`~bendpam.present.report.findings.report_warnings`).
    hyst : ``{model: FitResult}`` with a loop.  hyst_error : why no loop fit could be made, or None.
    separate : a loop fit of its own, or None.  loops : whether the tests show loops.
    mean_ratio : the mean energy-loss ratio.  failed : ``{model: reason}``.  models : the models asked for.

    Examples
    --------
    An empty page (no tests, no fits):

    >>> import bendpam
    >>> from bendpam.lab.processing import ProcessingOptions
    >>> from bendpam.physics.fixture import PAPER_FIXTURE
    >>> summary = {"pressures": [], "deadband_kpa": float("nan"), "deadband_se_kpa": float("nan")}
    >>> page = render_page(actuator=bendpam.physics.presets.be_pam(), summary=summary, fits={}, figures={},
    ...                    inputs_info=[], fixture=PAPER_FIXTURE, options=ProcessingOptions(), free=["alpha0"],
    ...                    stresses=None, notes=[], version="0.0", warnings=[], hyst={}, hyst_error=None,
    ...                    separate=None, loops=False, mean_ratio=float("nan"), failed={}, models=["energy"])
    >>> page.startswith("<!DOCTYPE html>"), '<section class="warnings ok" id="warnings">' in page
    (True, True)
    """
    who = actuator.name or actuator.kind
    numbers = {"tests": 1, "fits": 2}
    n = 2
    for key in (["hysteresis"] if loops else []) + ["stresses", "actuator", "inputs"]:
        n += 1
        numbers[key] = n
    nav = [("tests", "Processed cyclic tests (Table 2, Figure 4)"), ("fits", "Model fits (Table 3, Figure 7)")]
    if loops:
        nav.append(("hysteresis", "Hysteresis"))
    nav += [("stresses", "Internal stresses"), ("actuator-section", "Actuator"),
            ("inputs-section", "Input files and settings")]
    context = {
        "who": who, "version": version, "now": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "n_files": len(inputs_info), "model_labels": ", ".join(MODEL_LABEL[m] for m in models),
        "free_html": Markup(", ".join(symbol(x).html for x in free)), "nav": nav, "notes": notes,
        "numbers": numbers, "figures": figures, "loops": loops, "stresses": stresses,
        **_warnings_context(warnings), **_tests_context(actuator, summary, mean_ratio),
        **_fits_context(fits, failed), "hysteresis": _hysteresis_context(hyst, hyst_error, separate, mean_ratio),
        **_actuator_context(actuator, fits), **_inputs_context(inputs_info, fixture, options, free, version),
    }
    return _environment().get_template("page.html.j2").render(context)


def _warnings_context(warnings: Sequence[ReportWarning]) -> dict:
    n_w = sum(w.severity == "warning" for w in warnings)
    n_c = len(warnings) - n_w
    head = ", ".join(x for x in (f"{n_w} warning{'s' * (n_w != 1)}" if n_w else "",
                                 f"{n_c} caution{'s' * (n_c != 1)}" if n_c else "") if x)
    return {"warnings": warnings, "warning_head": head, "nrmse_limit": fmt_pct(LIMITS.nrmse_cycles)}


def _tests_context(actuator, summary: dict, mean_ratio: float) -> dict:
    """Section 1: Table 2, the deadband, the processing notes."""
    rows = []
    groups = {float(g["pressure_kpa"]): g for g in summary.get("replicates", [])}
    tests = summary["pressures"]
    for k, (r, txt) in enumerate(zip(tests, table2_rows(summary), strict=True)):
        group = groups.get(float(r["pressure_kpa"])) or {}
        several = int(group.get("n", 1)) > 1
        label = f"{txt['pressure_kpa']} (#{r.get('replicate', 1)})" if several else txt["pressure_kpa"]
        rows.append(_Row([
            _td(label, r["pressure_kpa"]), _td(txt["cycles"], r["cycles"]),
            _td(txt["blocked_moment_nmm"], r["blocked_moment_nmm"], r["blocked_moment_se_nmm"], "num pm"),
            _td(txt["free_curvature_per_mm"], r["free_curvature_per_mm"], r["free_curvature_se_per_mm"], "num pm"),
            _td(txt["energy_loss_percent"], r["energy_loss_ratio"])],
            attrs={"data-source": str(r.get("source", "")), "data-replicate": str(r.get("replicate", 1))}))
        if several and (k + 1 == len(tests) or float(tests[k + 1]["pressure_kpa"]) != float(r["pressure_kpa"])):
            rows.append(_replicate_row(group))
    table = _Table("table2",
                   "Table 2. Blocked moment, free-bending curvature and energy-loss ratio of the cyclic tests",
                   ["P (kPa)", "Cycles", Markup("Blocked moment M<sub>b</sub> (N·mm)"),
                    "Free-bending curvature k′ (1/mm)", "Energy-loss ratio (%)"], rows)
    db, db_se = summary["deadband_kpa"], summary["deadband_se_kpa"]
    return {"table2": table, "mean_ratio_cell": _td(fmt_pct(mean_ratio), mean_ratio),
            "deadband": {"value": db, "se": db_se, "text": fmt_value(db, db_se, "kPa"),
                         "p_start": fmt_value(actuator.P_start_kpa, unit="kPa")},
            "processing_notes": [f"{r['pressure_kpa']:g} kPa: {note}" for r in summary["pressures"]
                                 for note in r["notes"]],
            "skipped_files": [f"{f['file']}: {f.get('reason', '')}" for f in summary.get("files", [])
                              if f.get("status") == "skipped"]}


def _replicate_row(group: dict) -> _Row:
    """The mean of the replicates at one pressure, ± their standard deviation, with their number."""
    p = float(group["pressure_kpa"])
    return _Row([
        _td(f"{p:g} mean (n = {group['n']})", p), _td("", None, cls=""),
        _td(fmt_value(group["blocked_moment_nmm"], group["blocked_moment_std_nmm"]), group["blocked_moment_nmm"],
            group["blocked_moment_std_nmm"], "num pm"),
        _td(fmt_value(group["free_curvature_per_mm"], group["free_curvature_std_per_mm"]),
            group["free_curvature_per_mm"], group["free_curvature_std_per_mm"], "num pm"),
        _td(fmt_pct(group["energy_loss_ratio"]), group["energy_loss_ratio"])],
        attrs={"class": "replicate-mean", "data-n": str(group["n"])})


def _fits_context(fits: Mapping, failed: Mapping[str, str]) -> dict:
    """Section 2: Table 3 (a row per fit, then the models that failed) and each model in detail."""
    rows, marked = [], False
    for (m, res), txt in zip(fits.items(), table3_rows(fits), strict=True):
        cells = []
        for name in T3_PARAMS:
            p = res.parameters.get(name)
            marked = marked or (p is not None and at_bound(p) is not None)
            cells.append(_td(txt[name], p.value if p else None, (p.stderr if p and p.vary else None), "num pm"))
        mu, mu_se = shear_modulus(res)
        cells.append(_td(txt["mu"], mu, mu_se, "num pm"))
        mt = res.metrics
        cells += [_td(txt["nrmse_cycles"], mt.nrmse_cycles), _td(txt["nrmse_blocked_moment"], mt.nrmse_blocked_moment),
                  _td(txt["nrmse_free_curvature"], mt.nrmse_free_curvature)]
        rows.append(_Row(cells, txt["model"], {"data-model": m}))
    for m, why in failed.items():
        rows.append(_Row([], f"{MODEL_LABEL.get(m, m)} model", {"data-model": m, "class": "failed"},
                         Markup(f'<td colspan="7">could not be fitted: {plain_html(why)}</td>')))
    table = _Table("table3", "Table 3. Fitted parameters and errors of the models",
                   ["Model"] + [Markup(symbol(x).heading()) for x in T3_PARAMS] + [Markup(symbol("mu").heading())]
                   + ["NRMSE loading cycles (%)", "NRMSE blocked moment (%)", "NRMSE free-bending curvature (%)"],
                   rows)
    return {"table3": table, "table3_marked": marked, "fits_curves": fits_curves(fits),
            "fit_details": [_fit_detail(m, res) for m, res in fits.items()]}


def fits_curves(fits: Mapping) -> str:
    """What the fits of section 2 were fitted to, in words, from the FitResults (loop model or mean curves).

    >>> from types import SimpleNamespace as NS
    >>> fits_curves({"energy": NS(hysteresis=None)})
    'the mean curves (the average of the loading and unloading branches, hysteresis-free, as the paper)'
    >>> fits_curves({"energy": NS(hysteresis=NS(law="pi"))})[:40]
    'both branches of every loop with the loo'
    """
    with_loop = [m for m, r in fits.items() if getattr(r, "hysteresis", None) is not None]
    mean = ("the mean curves (the average of the loading and unloading branches, hysteresis-free, as the paper)")
    if not with_loop:
        return mean
    laws = sorted({LAW_LABEL.get(fits[m].hysteresis.law, fits[m].hysteresis.law) for m in with_loop})
    loop = f"both branches of every loop with the loop model ({' or '.join(laws)}; hysteresis-aware)"
    if len(with_loop) == len(fits):
        return loop
    return (f"{loop} for the {', '.join(MODEL_LABEL.get(m, m) for m in with_loop)} model, and {mean} for the "
            "others")


def _params_table(tid: str, caption: str, params: Mapping) -> _Table:
    rows = []
    for name, p in params.items():
        sym = symbol(name)
        side = at_bound(p)
        status = "fixed" if not p.vary else (f"fitted, at the {side} bound" if side else "fitted")
        rng = f"{fmt_value(p.min)} to {fmt_value(p.max)}" if finite(p.min) and finite(p.max) else "—"
        value = fmt_value(p.value, p.stderr if p.vary else None) + ("" if not p.vary or finite(p.stderr) else " ± n/a")
        rows.append(_Row([_td(plain_html(sym.meaning), None, None, "meaning", raw=True),
                          _td(value, p.value, p.stderr if p.vary else None, "num pm"),
                          _td(escape(sym.unit), None, None, "", raw=True), _td(rng, None, None, "num"),
                          _td(fmt_value(p.initial), p.initial), _td(status, None, None, "")], Markup(sym.html)))
    return _Table(tid, caption, ["Symbol", "Meaning", "Value", "Unit", "Allowed range", "Start", "Status"], rows)


def _fit_detail(m: str, res) -> dict:
    """One model's fit: the search in words, the fit's notes, parameters, correlations, per-pressure errors."""
    label = MODEL_LABEL.get(m, m)
    correlation = None
    if len(res.correlation_names) > 1:
        names = [Markup(symbol(x).html) for x in res.correlation_names]
        rows = [_Row([_td(corr_text(res.correlation[i, j]), res.correlation[i, j]) for j in range(len(names))], nm)
                for i, nm in enumerate(names)]
        correlation = _Table(f"correlation-{m}", f"Correlation of the fitted parameters ({label} model)",
                             ["", *names], rows)
    mt = res.metrics
    rows = []
    for r in mt.per_pressure:
        kf = r["free_curvature_model_per_mm"]
        rows.append(_Row([_td(f"{float(r['pressure_kpa']):g}", r["pressure_kpa"]),
                          _td(fmt_value(r["rmse_cycle_nmm"]), r["rmse_cycle_nmm"]),
                          _td(fmt_value(r["M_max_nmm"]), r["M_max_nmm"]),
                          _td(fmt_value(r["blocked_moment_model_nmm"]), r["blocked_moment_model_nmm"]),
                          _td(fmt_value(r["K_max_per_mm"]), r["K_max_per_mm"]),
                          _td(fmt_value(kf) if kf is not None else "no equilibrium", kf)]))
    metrics = _Table(
        f"metrics-{m}",
        f"Per-pressure errors of the {label} model (RMSE of the cycles {fmt_value(mt.rmse_cycles)} N·mm, of the "
        f"blocked moment {fmt_value(mt.rmse_blocked_moment)} N·mm, of the free-bending curvature "
        f"{fmt_value(mt.rmse_free_curvature)} 1/mm)",
        ["P (kPa)", "RMSE of the cycle (N·mm)", Markup("M<sub>b</sub>, data (N·mm)"),
         Markup("M<sub>b</sub>, model (N·mm)"), Markup("k′<sub>free</sub>, data (1/mm)"),
         Markup("k′<sub>free</sub>, model (1/mm)")], rows)
    return {"model": m, "title": f"{label.capitalize()} model", "diagnosis": diagnosis(m, res),
            "uncertainty": _uncertainty_tables(m, label, res),
            "notes": fit_notes(res), "params": _params_table(f"params-{m}", f"Parameters of the {label} model fit",
                                                              res.parameters),
            "correlation": correlation, "metrics": metrics,
            "figures": (f"fig-alpha0-{m}", f"fig-band-{m}", f"fig-figure7-{m}")}


def _uncertainty_tables(m: str, label: str, res) -> list[_Table]:
    """The standard errors in their statistical and systematic parts, and the loop laws behind the latter."""
    b = getattr(res, "uncertainty", None)
    if b is None:
        return []
    rows = []
    parts = [b.statistical, b.systematic, *([b.instrument] if b.instrument else [])]
    for f in b.statistical:
        cells = [part.get(f, 0.0) for part in parts] + [b.total[f]]
        rows.append(_Row([_td(fmt_value(v), v) for v in cells], Markup(symbol(f).heading())))
    inst = (f"; instrument, its declared calibration: {b.declared}" if b.instrument else
            "; the rig's calibration (load cell, pressure gauge) is not included: none was declared")
    out = [_Table(f"uncertainty-{m}", f"Standard errors of the {label} model fit: statistical ({b.resampling}) and "
                  f"systematic (the loop law){inst}", ["", "Statistical", "Systematic",
                                                *(["Instrument (declared)"] if b.instrument else []), "Total"], rows)]
    if b.ensemble:
        keys = list(b.ensemble[0].values)
        rows = [_Row([_td(fmt_value(e.weight), e.weight), _td(fmt_pct(e.nrmse), e.nrmse)]
                     + [_td(fmt_value(e.values.get(k)), e.values.get(k)) for k in keys],
                     law_label(e.law)) for e in b.ensemble]
        out.append(_Table(f"ensemble-{m}", f"The loop laws fitted to the same data ({b.weighting})",
                          ["Loop law", "Weight", "NRMSE of both branches (%)",
                           *(Markup(symbol(k).heading()) for k in keys)], rows))
    return out


def _hysteresis_context(hyst: Mapping, hyst_error: str | None, separate, mean_ratio: float) -> dict:
    """The hysteresis section: the energy-loss ratios, measured and predicted, and each loop's parameters."""
    out: dict[str, Any] = {"mean_ratio": fmt_pct(mean_ratio), "fits": bool(hyst),
                           "error": hyst_error or "no model was fitted"}
    if not hyst:
        return out
    laws = sorted({LAW_LABEL.get(r.hysteresis.law, r.hysteresis.law) for r in hyst.values()})
    out["laws"] = " or ".join(laws)
    out["how"] = ("The fits of section 2 include the loop: both branches of every loop were fitted with"
                  if separate is None else f"The fits of section 2 used the mean curves; the "
                  f"{MODEL_LABEL[separate.model]} model was fitted again to both branches of every loop with")
    ms = list(hyst)
    rows = []
    for i, r in enumerate(hyst[ms[0]].hysteresis.energy_loss_ratio):
        cells = [_td(f"{r.pressure_kpa:g}", r.pressure_kpa), _td(fmt_pct(r.measured), r.measured)]
        for m in ms:
            e = hyst[m].hysteresis.energy_loss_ratio
            pred = e[i].predicted if i < len(e) else math.nan
            cells.append(_td(fmt_pct(pred), pred))
        rows.append(_Row(cells))
    out["loss"] = _Table("hysteresis-loss", "Energy-loss ratio per pressure, measured and predicted by the loop model",
                         ["P (kPa)", "Measured (%)"] + [f"Predicted, {MODEL_LABEL.get(m, m)} model (%)" for m in ms],
                         rows)
    out["params"] = [
        _params_table(f"hysteresis-params-{m}", f"Loop parameters of the {MODEL_LABEL.get(m, m)} model "
                      f"({LAW_LABEL.get(res.hysteresis.law, res.hysteresis.law)} law; NRMSE of both branches "
                      f"{fmt_pct(res.hysteresis.nrmse_branches)} %)", res.hysteresis.parameters)
        for m, res in hyst.items()]
    return out


def _actuator_context(actuator, fits: Mapping) -> dict:
    """The actuator, nominal and fitted: a column each, its type, fields and derived quantities."""
    cols = [("nominal", actuator)] + [(f"fitted, {MODEL_LABEL[m]}", r.actuator) for m, r in fits.items()]
    dicts = [(c, act.to_dict(), act.derived()) for c, act in cols]
    sense = {1: "bends toward the frame", -1: "bends away from the frame", 0: "does not bend"}
    rows = [_Row([_td("", None, None, "meaning")]
                 + [_td(f"{act.kind} ({sense[int(act.bend_sign)]})", None, None, "") for _, act in cols],
                 "Type", tail=Markup("<td></td>"))]
    for c_key in dicts[0][1]:
        if c_key in ("name", "model", "tested_pressure_kpa", "fit_identity"):  # labels, not parameters
            continue
        sym = symbol(c_key)
        rows.append(_Row([_td(plain_html(sym.meaning), None, None, "meaning", raw=True)]
                         + [_td(fmt_value(d[c_key]), d[c_key]) for _, d, _ in dicts]
                         + [_td(escape(sym.unit), None, None, "", raw=True)], Markup(sym.html)))
    for c_key in dicts[0][2]:
        sym = symbol(c_key)
        rows.append(_Row([_td(plain_html(sym.meaning) + " (derived)", None, None, "meaning", raw=True)]
                         + [_td(fmt_value(dd[c_key]), dd[c_key]) for _, _, dd in dicts]
                         + [_td(escape(sym.unit), None, None, "", raw=True)], Markup(sym.html), {"class": "derived"}))
    table = _Table("actuator", "Actuator parameters, nominal and fitted", ["Symbol", "Meaning"] + [c for c, _ in cols]
                   + ["Unit"], rows)
    return {"actuator_names": [(c, act.name or act.kind) for c, act in cols], "actuator_table": table}


def _inputs_context(inputs_info: Sequence[dict], fixture, options, free: Sequence[str], version: str) -> dict:
    """The input files, and the settings of the processing, the fits and the warnings."""
    rows = []
    for t in inputs_info:
        units = ", ".join(f"{k}: {v}" for k, v in t["source_units"].items())
        rows.append(_Row([_td(t["path"], None, None, ""), _td(t["dialect"], None, None, ""),
                          _td(f"{t['pressure_kpa']:g}" if finite(t["pressure_kpa"]) else "—", t["pressure_kpa"]),
                          _td(t["pressure_source"] or "—", None, None, ""), _td(str(t["samples"]), t["samples"]),
                          _td(units, None, None, "")]))
    fx = fixture
    settings = [
        ("fixture d, r, t (mm)", escape(f"{fx.d_mm:g}, {fx.r_mm:g}, {fx.t_mm:g}")),
        ("L<sub>0</sub> for k′ = 2β/L<sub>0</sub> (mm)", escape(f"{fx.L0_mm:g}")),
        ("low-pass cutoff (Hz)",
         "1 Hz (max 40 % of Nyquist)" if options.cutoff_hz is None else escape(f"{options.cutoff_hz:g}")),
        ("filter order", escape(f"{options.filter_order}")),
        ("reversal threshold (fraction of the stroke range)", escape(f"{options.reversal_fraction:g}")),
        ("curvature grid points", escape(f"{options.grid_points}")),
        ("force tare (N)", escape(f"{options.tare_n:g}")),
        ("parameters fitted", ", ".join(symbol(x).html for x in free)),
        ("warning limits", escape(
            f"NRMSE of the cycles {fmt_pct(LIMITS.nrmse_cycles)} %, of the blocked moment and free-bending "
            f"curvature {fmt_pct(LIMITS.nrmse_points)} %; |r| > {LIMITS.correlation:g}; deadband vs P_start: "
            f"max({LIMITS.deadband_kpa:g} kPa, {100 * LIMITS.deadband_fraction:g} %)")),
        ("bendpam version", escape(version)),
    ]
    srows = [_Row([], Markup(k), tail=Markup(f"<td>{plain_html(html.unescape(v)) if 'P_start' in v else v}</td>"))
             for k, v in settings]
    return {"inputs_table": _Table("inputs", "Input files", ["File", "Format", "Pressure (kPa)", "Pressure from",
                                                            "Samples", "Units in the file"], rows),
            "settings_table": _Table("settings", "Settings", ["Setting", "Value"], srows)}
