"""Building the report: raw test files -> processing -> fits -> checks -> figures -> ONE HTML page.

:func:`build_report` goes through its steps in order, each a function of its own: the arguments
are checked before any work (:func:`_arguments`), the files read and processed, each model fitted
(a model that cannot be fitted is reported, not raised), the fits and the data judged
(:mod:`bendpam.identify.diagnose`, in words by :mod:`bendpam.present.report.findings`), the loop
fitted when the fits did not model it, the figures drawn (:mod:`bendpam.present.report.plots`),
and the page rendered (:mod:`bendpam.present.report.html`) and written atomically.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from bendpam.errors import BendpamError, FitError, InputError
from bendpam.identify.compare import type_comparison
from bendpam.identify.diagnose import has_loop, needs_type_check
from bendpam.identify.fitting import fit
from bendpam.identify.result import parse_free
from bendpam.infra.atomic import atomic_write_text
from bendpam.lab.files import collect_raw_files
from bendpam.physics.actuator import Actuator
from bendpam.physics.fixture import PAPER_FIXTURE, Fixture
from bendpam.physics.presets import normalise_model
from bendpam.present.report.findings import plausibility_warnings, report_warnings
from bendpam.present.report.html import render_page
from bendpam.present.report.plots import draw_figures
from bendpam.present.report.tables import table2_rows, table3_rows
from bendpam.present.report.text import MODEL_LABEL, finite, plain_text
from bendpam.version import __version__

__all__ = ["Report", "build_report"]


@dataclass(frozen=True)
class Report:
    """What :func:`build_report` made: the page, and the values shown on it.

    Attributes
    ----------
    html : the report's path.  files : the raw files read.  inputs : what was read from each.
    processed : the :class:`~bendpam.lab.processing.ProcessedSet`.  summary : its summary (Table 2).
    fits : model name -> :class:`~bendpam.identify.result.FitResult`.
    table2, table3 : the tables' rows as shown (formatted strings).
    figures : ids of the figures embedded.  stresses : where the stress figure was drawn (or None).
    notes : figures that could not be drawn.  version : bendpam's version.  bytes : the page's size.
    progress_shown : whether progress was reported on stderr.
    warnings : the :class:`~bendpam.present.report.findings.ReportWarning` shown in the warning box.
    hysteresis : ``{model: FitResult}`` of the fits with a loop model shown in the hysteresis section
        (empty when the tests show no loop).
    failed : ``{model: reason}`` of the models that could not be fitted.

    Examples
    --------
    :func:`build_report` makes one; by hand (no page behind it):

    >>> r = Report(Path("report.html"), [], [], None, {}, {}, [], [], [], None, [], "0.3.0", 0, False)
    >>> r.html.name, r.warnings, r.failed
    ('report.html', [], {})
    """

    html: Path
    files: list
    inputs: list
    processed: Any
    summary: dict
    fits: dict
    table2: list
    table3: list
    figures: list
    stresses: Any
    notes: list
    version: str
    bytes: int
    progress_shown: bool
    warnings: list = field(default_factory=list)
    hysteresis: dict = field(default_factory=dict)
    failed: dict = field(default_factory=dict)


def build_report(
    inputs, actuator: Actuator, out_html, *,
    models: Sequence[str] = ("energy", "force_balance"), free=("alpha0", "C10", "C01"), pressure_kpa=None,
    fixture: Fixture | str | None = None, processing_options=None, progress: bool = True,
    shown_as: str | None = None, instrument=None, read_options: dict | None = None,
) -> Report:
    """Raw test files -> processing -> fits -> checks -> ONE self-contained HTML page at ``out_html``.

    Parameters
    ----------
    inputs : a path or a sequence of paths: raw test files, or folders of them (files with the
        suffixes in :data:`bendpam.lab.files.RAW_SUFFIXES`, sorted by name).
    actuator : the nominal :class:`~bendpam.physics.actuator.Actuator` (geometry, start values, the values
        of the parameters held fixed).
    out_html : the page to write (atomically: a temporary file beside it, then a rename).
    models : model names to fit (``"energy"``, ``"force_balance"``/``"force-balance"``).
    free : parameters to identify (see :func:`bendpam.identify.fitting.fit`), a sequence or a comma string.
    pressure_kpa : None (each file's metadata or filename), one number (only with one file) or
        one pressure per file in order (kPa).
    fixture : a :class:`~bendpam.physics.fixture.Fixture`, a string ``"d,r,t"`` (mm, L0 from the
        actuator) or None (the paper's fixture with the actuator's L0).
    processing_options : a :class:`~bendpam.lab.processing.ProcessingOptions`, a dict of its fields, or None.
    progress : report progress on stderr (:class:`bendpam.infra.progress.Progress`); False writes nothing.
    shown_as : the page's name in the progress lines (default ``out_html``'s; a temporary file's caller: the target).
    instrument : a declared calibration of the rig for the fits (:class:`~bendpam.identify.uncertainty.Instrument`).
    read_options : :func:`bendpam.lab.read_tests`' ``columns``, ``rate_hz``, ``repair``, ``format_file`` (a dict).

    Returns
    -------
    a :class:`Report`: the page's path and the values shown on it (tables, figures, warnings).

    Examples
    --------
    Two virtual tests of the paper's BE-PAM (coarse, without a loop), reported with the energy model:

    >>> import tempfile
    >>> from pathlib import Path
    >>> import bendpam
    >>> from bendpam.lab.simulate import SimulationSettings, simulate_tests
    >>> be = bendpam.physics.presets.be_pam()
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     raw = simulate_tests(be, [100, 200], Path(folder) / "raw", settings=SimulationSettings(
    ...         cycles=1, rate_hz=2.0, hysteresis=0.0, seed=1))
    ...     report = build_report(Path(folder) / "raw", be, Path(folder) / "report.html", models=["energy"],
    ...                           processing_options={"grid_points": 21}, progress=False)
    >>> report.table3[0]["model"], report.figures[0], report.html.name
    ('energy model', 'fig-figure4', 'report.html')
    """
    from bendpam.infra.progress import Progress

    out, model_names, free_names, files, pressures, fx, opts = _arguments(
        inputs, actuator, out_html, models, free, pressure_kpa, fixture, processing_options)
    with Progress(_steps(len(files), len(model_names)), "report", quiet=not progress) as bar:
        tests, processed = _read_and_process(files, pressures, fx, opts, bar, _read_options(read_options))
        summary = processed.summary()
        fits, failed = _fit_models(processed, actuator, model_names, free_names, bar, instrument)
        warnings = plausibility_warnings(processed) + _judge(processed, actuator, fits, failed, tests, model_names[0],
                                                              free_names, bar)
        loops = has_loop(processed)
        hyst, separate, hyst_error = _loop_fit(processed, actuator, fits, free_names, loops, bar, instrument)
        figures, notes, stresses = draw_figures(processed, actuator, fits, model_names, hyst, separate, bar)
        bar.advance(0, description=f"report: writing {shown_as or out.name}")
        inputs_info = [_input_info(t) for t in tests]
        page = render_page(
            actuator=actuator, summary=summary, fits=fits, figures=figures, inputs_info=inputs_info, fixture=fx,
            options=opts, free=free_names, stresses=stresses, notes=notes, version=__version__, warnings=warnings,
            hyst=hyst, hyst_error=hyst_error, separate=separate, loops=loops, mean_ratio=_mean_ratio(summary),
            failed=failed, models=model_names)
        atomic_write_text(out, page)
        bar.advance()
    return Report(
        html=out, files=files, inputs=inputs_info, processed=processed, summary=summary, fits=fits,
        table2=table2_rows(summary), table3=table3_rows(fits),
        figures=[fid for fid, d in figures.items() if not d.missing], stresses=stresses, notes=notes,
        version=__version__, bytes=len(page.encode("utf-8")), progress_shown=bool(progress),
        warnings=warnings, hysteresis=hyst, failed=failed,
    )


def _steps(n_files: int, n_models: int) -> int:
    """The progress steps: reading, processing, fits, the type check (2), the loop fit, figures (4, 7/profile/band
    per model, loss ratios, loops, stresses), writing."""
    return n_files + 1 + n_models + 2 + 1 + (1 + 3 * n_models + 2 + 1) + 1


def _mean_ratio(summary: dict) -> float:
    """The mean energy-loss ratio of the tests (NaN without one)."""
    ratios = [r["energy_loss_ratio"] for r in summary["pressures"] if finite(r["energy_loss_ratio"])]
    return float(np.mean(ratios)) if ratios else math.nan


def _arguments(inputs, actuator, out_html, models, free, pressure_kpa, fixture, processing_options):
    """Everything cheap checked before the work starts: ``(out, models, free, files, pressures, fixture, options)``."""
    if not isinstance(actuator, Actuator):
        raise TypeError(f"actuator must be a bendpam.Actuator, got {type(actuator).__name__}")
    out = Path(out_html)
    if out.is_dir():
        raise InputError(f"the report's path {str(out)!r} is a folder; give the HTML file to write, e.g. report.html")
    parent = out.parent if str(out.parent) else Path(".")
    if not parent.is_dir():
        raise InputError(f"the report's path {str(out)!r}: the folder {str(parent)!r} does not exist")
    if isinstance(models, str):
        models = [m for m in models.replace(" ", ",").split(",") if m]
    model_names: list[str] = []
    for m in models:
        n = normalise_model(m)
        if n not in model_names:
            model_names.append(n)
    if not model_names:
        raise InputError("give at least one model to fit: energy, force-balance")
    free_names = parse_free(free)
    files = collect_raw_files(inputs)
    pressures = _pressures(pressure_kpa, len(files))
    return out, model_names, free_names, files, pressures, _fixture(fixture, actuator), _options(processing_options)


def _read_options(read_options) -> dict:
    """``build_report``'s ``read_options``, checked: the keywords of :func:`bendpam.lab.read_tests` it passes on."""
    allowed = ("columns", "rate_hz", "repair", "format_file")
    if read_options is None:
        return {}
    if not isinstance(read_options, dict) or any(k not in allowed for k in read_options):
        raise InputError(f"read_options = {read_options!r}: give a dict of {', '.join(allowed)}")
    return {k: v for k, v in read_options.items() if v is not None}


def _read_and_process(files, pressures, fx: Fixture, opts, bar, read: dict | None = None):
    """Read every file (one step each; ``read``: :func:`bendpam.lab.read_tests`' keywords) and process the cycles
    (one step): ``(tests, processed)``."""
    from bendpam.lab import read_tests
    from bendpam.lab.processing import process_tests

    tests = []
    for f, p in zip(files, pressures, strict=True):
        bar.advance(0, description=f"report: reading {f.name}")
        tests.extend(read_tests(f, pressure_kpa=p, **(read or {})))  # every specimen or block of the file
        bar.advance()
    bar.advance(0, description="report: processing the cycles")
    processed = process_tests(tests, fixture=fx, options=opts)
    bar.advance()
    return tests, processed


def _fit_models(processed, actuator: Actuator, model_names, free_names, bar, instrument=None):
    """Fit each model (one step each): ``(fits, failed)``; a model that cannot be fitted goes to ``failed``."""
    fits: dict = {}
    failed: dict[str, str] = {}
    for m in model_names:
        bar.advance(0, description=f"report: fitting the {MODEL_LABEL[m]} model")
        try:
            fits[m] = fit(processed, actuator, m, free=free_names, instrument=instrument)
        except (FitError, InputError) as exc:  # these tests cannot be fitted with this actuator
            failed[m] = plain_text(str(exc).splitlines()[0] if str(exc) else type(exc).__name__)
        bar.advance()
    return fits, failed


def _judge(processed, actuator: Actuator, fits, failed, tests, model: str, free_names, bar):
    """The warning box; the type check (two steps) costs two quick fits, made only when the chosen type is poor."""
    bar.advance(0, description="report: checking the actuator type")
    comparison = type_comparison(processed, actuator, model, free_names) if needs_type_check(fits) else None
    bar.advance(2)
    metadata = [(t.path.name, dict(getattr(t, "metadata", {}) or {})) for t in tests]
    return report_warnings(processed, actuator, fits, metadata=metadata, comparison=comparison, failed=failed)


def _loop_fit(processed, actuator: Actuator, fits, free_names, loops: bool, bar, instrument=None):
    """The loop fits shown in the hysteresis section (one step): ``(hyst, separate, error)``.

    The fits' own when they modelled the loop; otherwise, when the tests show loops, a loop fit of
    its own (``separate``) of the first model, with the same declared ``instrument`` as the main fits,
    or why it could not be made (``error``).
    """
    hyst = {m: r for m, r in fits.items() if getattr(r, "hysteresis", None) is not None}
    separate = None  # a loop fit of its own, when the fits above did not model the loop
    hyst_error = None
    bar.advance(0, description="report: fitting the hysteresis loop")
    if loops and not hyst and fits:
        m0 = next(iter(fits))
        try:
            separate = fit(processed, actuator, m0, free=free_names, hysteresis="pi", instrument=instrument)
            hyst = {m0: separate}
        except (BendpamError, ValueError, ArithmeticError) as exc:
            hyst_error = plain_text(str(exc).splitlines()[0] if str(exc) else type(exc).__name__)
    bar.advance()
    return hyst, separate, hyst_error


def _input_info(t) -> dict:
    """What was read from one file: path, dialect, pressure and its source, samples, units, metadata."""
    return {"path": str(t.path), "dialect": t.dialect, "pressure_kpa": t.pressure_kpa,
            "pressure_source": t.pressure_source, "samples": len(t), "source_units": dict(t.source_units),
            "metadata": dict(getattr(t, "metadata", {}) or {})}


def _pressures(pressure_kpa, n_files: int) -> list[float | None]:
    """One pressure (kPa) or None per file, from None, a number or a sequence (one per file)."""
    if pressure_kpa is None:
        return [None] * n_files
    values = [pressure_kpa] if isinstance(pressure_kpa, int | float | np.number) else list(pressure_kpa)
    if not values:
        return [None] * n_files
    out: list[float | None] = []
    for v in values:
        try:
            fv = float(v)
        except (TypeError, ValueError):
            raise InputError(f"pressure {v!r} is not a number in kPa") from None
        if not math.isfinite(fv) or fv < 0:
            raise InputError(f"pressure {v!r} kPa must be a finite gauge pressure >= 0 kPa")
        out.append(fv)
    if len(out) != n_files:
        raise InputError(
            f"pressure_kpa: got {len(out)} pressure(s) for {n_files} file(s); give one per file, in order"
        )
    return out


def _fixture(fixture, actuator: Actuator) -> Fixture:
    if fixture is None:
        return Fixture(PAPER_FIXTURE.d_mm, PAPER_FIXTURE.r_mm, PAPER_FIXTURE.t_mm, actuator.L0_mm)
    if isinstance(fixture, Fixture):
        return fixture
    if isinstance(fixture, str):
        return Fixture.from_string(fixture, L0_mm=actuator.L0_mm)
    raise InputError(f"fixture = {fixture!r}: give a bendpam.physics.fixture.Fixture or a string 'd,r,t' in mm")


def _options(processing_options):
    from bendpam.lab.processing import ProcessingOptions

    if processing_options is None:
        return ProcessingOptions()
    if isinstance(processing_options, ProcessingOptions):
        return processing_options
    if isinstance(processing_options, dict):
        try:
            return ProcessingOptions(**processing_options)
        except TypeError as exc:
            raise InputError(f"processing_options: {exc}") from None
    raise InputError(f"processing_options = {processing_options!r}: give a ProcessingOptions or a dict")
