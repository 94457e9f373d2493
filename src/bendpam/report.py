"""A one-command, self-contained HTML report: raw cyclic tests -> processing -> fits -> figures.

:func:`build_report` reads raw four-point-bending exports (files, or folders of them), processes
them (:func:`bendpam.lab.processing.process_tests`), fits each model
(:func:`bendpam.identify.fit`), draws the figures and writes ONE HTML page atomically.  The page
needs nothing else: the figures are embedded as base64 PNG (``data:`` URIs), the style sheet is
inline, there is no JavaScript and no reference to any other file or address.  A
``Content-Security-Policy`` meta tag makes a browser refuse anything external.

The page holds

* Table 2 (``id="table2"``): per pressure the cycles, blocked moment ± SE, free-bending curvature
  ± SE and energy-loss ratio, and the deadband pressure ± SE (``id="deadband"``);
* the Figure 4 figure of the processed tests (``id="fig-figure4"``);
* Table 3 (``id="table3"``): per model alpha0, C10, C01 with standard errors and the NRMSE of the
  loading cycles, blocked moment and free-bending curvature (eq 53-55), then per model the fit's
  notes (``id="flags-MODEL"``), all parameters (``id="params-MODEL"``), the per-pressure metrics
  (``id="metrics-MODEL"``) and the Figure 7 figure (``id="fig-figure7-MODEL"``);
* the force-balance model's internal stresses (``id="fig-stresses"``) for the force-balance
  fitted actuator at the highest tested pressure and half the measured free curvature there
  (``k' = bend_sign * |k| / 2``);
* the actuator, nominal and fitted (``id="actuator"``), the input files with their detected
  dialect and pressure source (``id="inputs"``) and the bendpam version.

Every table cell with a number carries it unformatted in ``data-value`` (and its standard error
in ``data-se``), so a program can read the page back without parsing the formatted text.  The
formatting helpers :func:`fmt_num`, :func:`fmt_pm` and :func:`fmt_pct` are public so that the
same text can be produced elsewhere.

Progress: with ``progress=True`` a ``rich`` progress bar is drawn on stderr while the report is
built, only when stderr is a terminal (so logs, pipes and tests stay clean); ``progress=False``
never draws it.

Errors are the library's one-line errors: :class:`~bendpam.lab.ReadError` for an unreadable
file, :class:`~bendpam.lab.processing.ProcessingError` for a test that cannot be processed
(e.g. a file without a pressure) and :class:`ValueError` for bad arguments or a failed fit.  A
figure that cannot be drawn (for instance the internal stresses at a curvature beyond lock-up)
does not stop the report: the page shows a note in its place, and the note is returned too.
"""

from __future__ import annotations

import base64
import contextlib
import datetime as _dt
import html
import io
import math
import struct
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .actuator import Actuator
from .atomic import atomic_write_text
from .errors import InputError
from .fixture import PAPER_FIXTURE, Fixture
from .lab.files import RAW_SUFFIXES, collect_raw_files
from .presets import normalise_model

if TYPE_CHECKING:
    from rich.progress import Progress, TaskID

__all__ = [
    "RAW_SUFFIXES",
    "build_report",
    "collect_raw_files",
    "fmt_num",
    "fmt_pct",
    "fmt_pm",
    "fmt_se",
    "table2_rows",
    "table3_rows",
]


_DPI = 110
_MODEL_LABEL = {"energy": "energy", "force_balance": "force-balance"}


# ------------------------------------------------------------------------------------------------
# inputs
# ------------------------------------------------------------------------------------------------
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
            f"--pressure-kpa: got {len(out)} pressure(s) for {n_files} file(s); give one per file, in order"
        )
    return out


def _fixture(fixture, actuator: Actuator) -> Fixture:
    if fixture is None:
        return Fixture(PAPER_FIXTURE.d_mm, PAPER_FIXTURE.r_mm, PAPER_FIXTURE.t_mm, actuator.L0_mm)
    if isinstance(fixture, Fixture):
        return fixture
    if isinstance(fixture, str):
        return Fixture.from_string(fixture, L0_mm=actuator.L0_mm)
    raise InputError(f"fixture = {fixture!r}: give a bendpam.fixture.Fixture or a string 'd,r,t' in mm")


def _options(processing_options):
    from .lab.processing import ProcessingOptions

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


# ------------------------------------------------------------------------------------------------
# formatting (public, so that tests and other tools produce the page's exact text)
# ------------------------------------------------------------------------------------------------
def _finite(x) -> bool:
    try:
        return x is not None and math.isfinite(float(x))
    except (TypeError, ValueError):
        return False


def fmt_num(x, spec: str) -> str:
    """``format(x, spec)``, or an em dash for None/NaN/inf."""
    return format(float(x), spec) if _finite(x) else "—"


def fmt_se(x) -> str:
    """A standard error with two significant digits (whole numbers from 10 up, exponent below 0.001)."""
    if not _finite(x):
        return "n/a"
    x = float(x)
    if x == 0.0:
        return "0"
    if abs(x) >= 10.0:
        return format(x, ".0f")
    if abs(x) >= 1e-3:
        return format(x, ".2g")
    return format(x, ".1e")


def fmt_pm(value, se, spec: str, se_spec: str | None = None) -> str:
    """``"value ± se"``: ``se`` with ``se_spec``, or :func:`fmt_se` by default; ``n/a`` when missing."""
    if se_spec is None or not _finite(se):
        return f"{fmt_num(value, spec)} ± {fmt_se(se)}"
    return f"{fmt_num(value, spec)} ± {fmt_num(se, se_spec)}"


def fmt_pct(x, spec: str = ".2f") -> str:
    """A ratio as a percentage number (no % sign), or an em dash."""
    return fmt_num(100.0 * float(x), spec) if _finite(x) else "—"


#: Formats of the Table 3 parameter cells: short name -> (value format, heading).
_T3_PARAMS = (("alpha0", ".2f", "α0 (deg)"), ("C10", ".1f", "C10 (kPa)"), ("C01", ".1f", "C01 (kPa)"))


def _param_text(p, spec: str) -> str:
    if p is None:
        return "—"
    if not p.vary:
        return f"{fmt_num(p.value, spec)} (fixed)"
    return fmt_pm(p.value, p.stderr, spec)


def table2_rows(summary: dict) -> list[dict[str, str]]:
    """The text of Table 2's body cells, one dict per pressure, from ``ProcessedSet.summary()``."""
    rows = []
    for r in summary["pressures"]:
        rows.append({
            "pressure_kpa": fmt_num(r["pressure_kpa"], "g"),
            "cycles": str(int(r["cycles"])),
            "blocked_moment_nmm": fmt_pm(r["blocked_moment_nmm"], r["blocked_moment_se_nmm"], ".2f", ".2f"),
            "free_curvature_per_mm": fmt_pm(r["free_curvature_per_mm"], r["free_curvature_se_per_mm"], ".5g"),
            "energy_loss_percent": fmt_pct(r["energy_loss_ratio"]),
        })
    return rows


def table3_rows(fits: dict) -> list[dict[str, str]]:
    """The text of Table 3's body cells, one dict per model, from ``{model: FitResult}``."""
    rows = []
    for model, res in fits.items():
        m = res.metrics
        row = {"model": f"{_MODEL_LABEL.get(model, model)} model"}
        for name, spec, _ in _T3_PARAMS:
            row[name] = _param_text(res.parameters.get(name), spec)
        row["nrmse_cycles"] = fmt_pct(m.nrmse_cycles)
        row["nrmse_blocked_moment"] = fmt_pct(m.nrmse_blocked_moment)
        row["nrmse_free_curvature"] = fmt_pct(m.nrmse_free_curvature)
        rows.append(row)
    return rows


# ------------------------------------------------------------------------------------------------
# HTML helpers
# ------------------------------------------------------------------------------------------------
def _e(x) -> str:
    return html.escape(str(x), quote=True)


def _dv(x) -> str:
    """A ``data-value`` attribute value: the float's repr, or empty."""
    if isinstance(x, bool) or x is None:
        return ""
    if isinstance(x, int | np.integer):
        return str(int(x))
    return repr(float(x)) if _finite(x) else ""


def _td(text, value=None, se=None, cls: str = "num") -> str:
    attrs = f' class="{cls}"' if cls else ""
    if value is not None:
        attrs += f' data-value="{_e(_dv(value))}"'
    if se is not None or (value is not None and cls == "num pm"):
        attrs += f' data-se="{_e(_dv(se))}"'
    return f"<td{attrs}>{_e(text)}</td>"


def _table(tid: str, caption: str, head: Sequence[str], body: Iterable[str], foot: str = "") -> str:
    ths = "".join(f'<th scope="col">{_e(h)}</th>' for h in head)
    return (f'<table id="{_e(tid)}"><caption>{_e(caption)}</caption><thead><tr>{ths}</tr></thead>'
            f"<tbody>{''.join(body)}</tbody>{foot}</table>")


def _png_size(data: bytes) -> tuple[int, int]:
    if data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR":
        return struct.unpack(">II", data[16:24])
    return 0, 0


def _fig_png(fig) -> bytes:
    """Render a figure to PNG bytes in memory (``dpi=110``) and close it."""
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    try:
        fig.savefig(buf, format="png", dpi=_DPI)
    finally:
        plt.close(fig)
    return buf.getvalue()


def _img(fid: str, alt: str, caption: str, png: bytes) -> str:
    w, h = _png_size(png)
    b64 = base64.b64encode(png).decode("ascii")
    size = f' width="{w}" height="{h}"' if w and h else ""
    return (f'<figure><img id="{_e(fid)}" class="figure" alt="{_e(alt)}"{size} '
            f'src="data:image/png;base64,{b64}"><figcaption>{_e(caption)}</figcaption></figure>')


def _missing(fid: str, what: str, why: str) -> str:
    return f'<p class="warn" id="{_e(fid)}-missing">{_e(what)} could not be drawn: {_e(why)}</p>'


def _fmt_any(v) -> str:
    if v is None:
        return "—"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, int | np.integer):
        return str(int(v))
    if isinstance(v, float | np.floating):
        return fmt_num(v, ".6g")
    return str(v)


_CSS = """
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,Helvetica,Arial,sans-serif;margin:0 auto;
max-width:1280px;padding:1rem 1.5rem 3rem;color:#1a1a1a;line-height:1.45}
h1{font-size:1.6rem;margin-bottom:.2rem}h2{margin-top:2.2rem;border-bottom:1px solid #ccc;padding-bottom:.2rem}
h3{margin-top:1.6rem}.meta{color:#555;font-size:.9rem}
table{border-collapse:collapse;margin:.8rem 0;font-size:.9rem}
caption{text-align:left;font-weight:600;padding:.3rem 0}
th,td{border:1px solid #ccc;padding:.25rem .55rem;vertical-align:top}
th{background:#f2f4f7;text-align:left}td.num{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
tfoot td{background:#fafafa;font-style:italic}
figure{margin:1rem 0}img.figure{max-width:100%;height:auto;border:1px solid #e3e3e3}
figcaption{font-size:.85rem;color:#444;margin-top:.3rem}
.warn{color:#8a1c1c;background:#fdecec;padding:.4rem .6rem;border-left:3px solid #c62828}
ul.flags li{margin:.2rem 0}code{background:#f4f4f4;padding:0 .2rem}
nav ol{columns:2;font-size:.9rem}
"""


# ------------------------------------------------------------------------------------------------
# progress
# ------------------------------------------------------------------------------------------------
class _Steps:
    """A rich progress bar on stderr (only when enabled and stderr is a terminal)."""

    def __init__(self, total: int, enabled: bool):
        self.total = total
        self._progress: Progress | None = None
        self._task: TaskID | None = None
        if enabled:
            from rich.console import Console

            console = Console(stderr=True)
            if console.is_terminal:
                from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

                self._progress = Progress(
                    TextColumn("[bold]bendpam report[/]"), BarColumn(), MofNCompleteColumn(),
                    TextColumn("{task.description}"), TimeElapsedColumn(), console=console, transient=True,
                )

    def __enter__(self):
        if self._progress is not None:
            self._progress.start()
            self._task = self._progress.add_task("starting", total=self.total)
        return self

    def __exit__(self, *exc):
        if self._progress is not None:
            self._progress.stop()
        return False

    @property
    def shown(self) -> bool:
        return self._progress is not None

    @contextlib.contextmanager
    def step(self, description: str) -> Iterator[None]:
        if self._progress is not None and self._task is not None:
            self._progress.update(self._task, description=description)
        yield
        if self._progress is not None and self._task is not None:
            self._progress.advance(self._task)


# ------------------------------------------------------------------------------------------------
# the report
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Report:
    """What :func:`build_report` made: the page, and the values shown on it.

    Attributes
    ----------
    html : the report's path.  files : the raw files read.  inputs : what was read from each.
    processed : the :class:`~bendpam.lab.processing.ProcessedSet`.  summary : its summary (Table 2).
    fits : model name -> :class:`~bendpam.identify.FitResult`.
    table2, table3 : the tables' rows as shown (formatted strings).
    figures : ids of the figures embedded.  stresses : where the stress figure was drawn (or None).
    notes : warnings shown on the page.  version : bendpam's version.  bytes : the page's size.
    progress_shown : whether a progress display was drawn.
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


def build_report(
    inputs,
    actuator: Actuator,
    out_html,
    *,
    models: Sequence[str] = ("energy", "force_balance"),
    free=("alpha0", "C10", "C01"),
    pressure_kpa=None,
    fixture: Fixture | str | None = None,
    processing_options=None,
    progress: bool = True,
) -> Report:
    """Raw test files -> processing -> fits -> ONE self-contained HTML page at ``out_html``.

    Parameters
    ----------
    inputs : a path or a sequence of paths: raw test files, or folders of them (files with the
        suffixes in :data:`RAW_SUFFIXES`, sorted by name).
    actuator : the nominal :class:`~bendpam.actuator.Actuator` (geometry, start values, the values
        of the parameters held fixed).
    out_html : the page to write (atomically: a temporary file beside it, then a rename).
    models : model names to fit (``"energy"``, ``"force_balance"``/``"force-balance"``).
    free : parameters to identify (see :func:`bendpam.identify.fit`), a sequence or a comma string.
    pressure_kpa : None (each file's metadata or filename), one number (only with one file) or
        one pressure per file in order (kPa).
    fixture : a :class:`~bendpam.fixture.Fixture`, a string ``"d,r,t"`` (mm, L0 from the
        actuator) or None (the paper's fixture with the actuator's L0).
    processing_options : a :class:`~bendpam.lab.processing.ProcessingOptions`, a dict of its
        fields, or None for the defaults.
    progress : draw a rich progress bar on stderr while working, when stderr is a terminal.

    Returns
    -------
    a :class:`Report` with ``html`` (Path), ``files`` (input Paths), ``inputs`` (per file: path, dialect,
    pressure_kpa, pressure_source, samples), ``processed`` (the ProcessedSet), ``summary``
    (``processed.summary()``), ``fits`` ({model: FitResult}), ``table2``/``table3`` (the cell
    texts, see :func:`table2_rows`, :func:`table3_rows`), ``figures`` (ids of the embedded
    images), ``stresses`` (the pressure and curvature of the stress figure, or None),
    ``notes`` (figures that could not be drawn), ``version`` and ``bytes`` (size of the page).
    """
    import bendpam

    from .identify import fit as _fit
    from .identify import parse_free
    from .lab import read_test
    from .lab.processing import process_tests

    # ---- validate everything cheap before the work starts ------------------------------------
    if not isinstance(actuator, Actuator):
        raise TypeError(f"actuator must be a bendpam.Actuator, got {type(actuator).__name__}")
    out = Path(out_html)
    if out.is_dir():
        raise InputError(f"--out {str(out)!r} is a folder; give the HTML file to write, e.g. report.html")
    parent = out.parent if str(out.parent) else Path(".")
    if not parent.is_dir():
        raise InputError(f"--out {str(out)!r}: the folder {str(parent)!r} does not exist")
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
    fx = _fixture(fixture, actuator)
    opts = _options(processing_options)

    want_stress = "force_balance" in model_names
    total = len(files) + 1 + 2 * len(model_names) + 1 + (1 if want_stress else 0) + 1
    notes: list[str] = []
    figures: dict[str, str] = {}  # id -> HTML (figure or note)
    fits: dict = {}
    stresses = None
    with _Steps(total, progress) as steps:
        tests = []
        for f, p in zip(files, pressures, strict=True):
            with steps.step(f"reading {f.name}"):
                tests.append(read_test(f, pressure_kpa=p))
        with steps.step("processing the cycles"):
            processed = process_tests(tests, fixture=fx, options=opts)
        summary = processed.summary()
        for m in model_names:
            with steps.step(f"fitting the {_MODEL_LABEL[m]} model"):
                fits[m] = _fit(processed, actuator, m, free=free_names)

        def figure(fid: str, what: str, alt: str, caption: str, draw):
            with steps.step(f"drawing {what}"):
                try:
                    png = _fig_png(draw())
                except (ValueError, ArithmeticError) as exc:
                    msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
                    notes.append(f"{what}: {msg}")
                    figures[fid] = _missing(fid, what, msg)
                else:
                    figures[fid] = _img(fid, alt, caption, png)

        from . import plots

        who = actuator.name or actuator.kind
        figure("fig-figure4", "Figure 4",
               f"Figure 4: cyclic moment-curvature loops, blocked moment and free-bending curvature against "
               f"pressure for {who}",
               "Figure 4. (a) Filtered cyclic loops at each pressure (dashed: the mean of the branches); (b) blocked "
               "moment against pressure (mean ± SE) with the deadband line; (c) free-bending curvature against "
               "pressure (mean ± SE). Magnitudes.",
               lambda: plots.figure4(processed))
        for m in model_names:
            res = fits[m]
            figure(f"fig-figure7-{m}", f"Figure 7 ({_MODEL_LABEL[m]} model)",
                   f"Figure 7: {_MODEL_LABEL[m]} model fit against the measured moment-curvature curves, blocked "
                   f"moment and free-bending curvature",
                   f"Figure 7, {_MODEL_LABEL[m]} model. (a) Measured branches (thin), mean curve (markers) and the "
                   f"fitted model (lines); (b) blocked moment; (c) free-bending curvature. NRMSE of the cycles "
                   f"{fmt_pct(res.metrics.nrmse_cycles)} %.",
                   lambda res=res: plots.figure7(processed, res))
        if want_stress:
            fb_act = fits["force_balance"].actuator
            top = processed.results[-1]
            k_mag = 0.5 * float(top.free_curvature[0])
            k_signed = (fb_act.bend_sign or 1) * k_mag
            stresses = {"pressure_kpa": top.pressure_kpa, "curvature_per_mm": k_signed}
            figure("fig-stresses", "the internal stresses",
                   f"Force-balance internal stresses around the cross-section at {top.pressure_kpa:g} kPa and "
                   f"k' = {k_signed:.5g} 1/mm",
                   f"Force-balance model (fitted actuator): bladder and braid stresses around the cross-section "
                   f"at P = {top.pressure_kpa:g} kPa, the highest tested pressure, and k' = {k_signed:.5g} 1/mm, "
                   f"half the measured free-bending curvature there (k' = bend_sign · |k|/2).",
                   lambda: plots.plot_internal_stresses(fb_act, top.pressure_kpa, k_signed))

        with steps.step(f"writing {out.name}"):
            inputs_info = [
                {"path": str(t.path), "dialect": t.dialect, "pressure_kpa": t.pressure_kpa,
                 "pressure_source": t.pressure_source, "samples": len(t), "source_units": dict(t.source_units)}
                for t in tests
            ]
            page = _render(
                actuator=actuator, processed=processed, summary=summary, fits=fits, figures=figures,
                inputs_info=inputs_info, fixture=fx, options=opts, free=free_names, stresses=stresses,
                notes=notes, version=bendpam.__version__,
            )
            atomic_write_text(out, page)
    return Report(
        html=out, files=files, inputs=inputs_info, processed=processed, summary=summary, fits=fits,
        table2=table2_rows(summary), table3=table3_rows(fits),
        figures=[fid for fid, h in figures.items() if "<img " in h], stresses=stresses, notes=notes,
        version=bendpam.__version__, bytes=len(page.encode("utf-8")), progress_shown=steps.shown,
    )


def _render(*, actuator, processed, summary, fits, figures, inputs_info, fixture, options, free, stresses, notes,
            version) -> str:
    from .identify import PARAMETERS

    who = actuator.name or actuator.kind
    now = _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC")
    parts: list[str] = []
    a = parts.append
    a("<!DOCTYPE html>")
    a('<html lang="en"><head><meta charset="utf-8">')
    a('<meta name="viewport" content="width=device-width, initial-scale=1">')
    a("<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; img-src data:; "
      "style-src 'unsafe-inline'\">")
    a('<meta name="generator" content="' + _e(f"bendpam {version}") + '">')
    a('<link rel="icon" href="data:,">')
    a(f"<title>{_e(f'bendpam report: {who}')}</title><style>{_CSS}</style></head><body>")
    a(f'<header><h1>{_e(f"Bending PAM test report: {who}")}</h1>')
    a(f'<p class="meta" id="meta">{_e(f"bendpam {version}")} · {_e(now)} · {len(inputs_info)} test file(s) · '
      f'models: {_e(", ".join(_MODEL_LABEL[m] for m in fits))} · fitted: {_e(", ".join(free))}</p></header>')
    a('<nav><ol><li><a href="#tests">Processed cyclic tests (Table 2, Figure 4)</a></li>'
      '<li><a href="#fits">Model fits (Table 3, Figure 7)</a></li>'
      '<li><a href="#stresses">Internal stresses</a></li><li><a href="#actuator-section">Actuator</a></li>'
      '<li><a href="#inputs-section">Input files and settings</a></li></ol></nav>')
    if notes:
        a('<div class="warn" id="report-notes"><strong>Notes:</strong><ul>'
          + "".join(f"<li>{_e(n)}</li>" for n in notes) + "</ul></div>")

    # ---- 1. processed tests --------------------------------------------------------------------
    a('<section id="tests"><h2>1. Processed cyclic tests</h2>')
    a("<p>Values are magnitudes, as in the paper. Blocked moment: each cycle's maximum moment; free-bending "
      "curvature: each cycle's turning point toward the free state; both mean ± standard error over the cycles. "
      "Energy-loss ratio: loop area / area under the cycle's mean curve (M-θ), mean over the cycles.</p>")
    body = []
    t2 = table2_rows(summary)
    for r, txt in zip(summary["pressures"], t2, strict=True):
        body.append(
            "<tr>" + _td(txt["pressure_kpa"], r["pressure_kpa"]) + _td(txt["cycles"], r["cycles"])
            + _td(txt["blocked_moment_nmm"], r["blocked_moment_nmm"], r["blocked_moment_se_nmm"], "num pm")
            + _td(txt["free_curvature_per_mm"], r["free_curvature_per_mm"], r["free_curvature_se_per_mm"], "num pm")
            + _td(txt["energy_loss_percent"], r["energy_loss_ratio"]) + "</tr>"
        )
    ratios = [r["energy_loss_ratio"] for r in summary["pressures"] if _finite(r["energy_loss_ratio"])]
    mean_ratio = float(np.mean(ratios)) if ratios else math.nan
    foot = ('<tfoot><tr><td colspan="4">Average energy-loss ratio</td>'
            + _td(fmt_pct(mean_ratio), mean_ratio) + "</tr></tfoot>")
    a(_table("table2", "Table 2. Blocked moment, free-bending curvature and energy-loss ratio of the cyclic tests",
             ["Pressure (kPa)", "Cycles", "Blocked moment (N·mm)", "Free-bending curvature (1/mm)",
              "Energy-loss ratio (%)"], body, foot))
    db, db_se = summary["deadband_kpa"], summary["deadband_se_kpa"]
    a(f'<p id="deadband" data-value="{_e(_dv(db))}" data-se="{_e(_dv(db_se))}">Deadband pressure (x-intercept of '
      f"the blocked moment against pressure): <strong>{_e(fmt_pm(db, db_se, '.4g'))} kPa</strong></p>")
    pnotes = [(r["pressure_kpa"], n) for r in summary["pressures"] for n in r["notes"]]
    if pnotes:
        a('<ul id="processing-notes">' + "".join(f"<li>{_e(f'{p:g} kPa: {n}')}</li>" for p, n in pnotes) + "</ul>")
    a(figures.get("fig-figure4", ""))
    a("</section>")

    # ---- 2. fits --------------------------------------------------------------------------------
    a('<section id="fits"><h2>2. Model fits</h2>')
    a("<p>Parameters identified from the hysteresis-free mean curves of all pressures at once (section 3.4); "
      "± is the standard error. NRMSE of the loading cycles, blocked moment and free-bending curvature as in "
      "eq 53-55.</p>")
    body = []
    for (m, res), txt in zip(fits.items(), table3_rows(fits), strict=True):
        cells = [f'<th scope="row">{_e(txt["model"])}</th>']
        for name, _spec, _h in _T3_PARAMS:
            p = res.parameters.get(name)
            cells.append(_td(txt[name], p.value if p else None, (p.stderr if p and p.vary else None), "num pm"))
        mt = res.metrics
        cells += [_td(txt["nrmse_cycles"], mt.nrmse_cycles), _td(txt["nrmse_blocked_moment"], mt.nrmse_blocked_moment),
                  _td(txt["nrmse_free_curvature"], mt.nrmse_free_curvature)]
        body.append(f'<tr data-model="{_e(m)}">' + "".join(cells) + "</tr>")
    a(_table("table3", "Table 3. Fitted parameters and errors of the energy and force-balance models",
             ["Model"] + [h for _, _, h in _T3_PARAMS]
             + ["NRMSE loading cycles (%)", "NRMSE blocked moment (%)", "NRMSE free-bending curvature (%)"], body))
    for m, res in fits.items():
        label = _MODEL_LABEL[m]
        a(f'<h3 id="fit-{_e(m)}">{_e(f"{label.capitalize()} model")}</h3>')
        status = "converged" if res.converged else "NOT converged"
        info = (f"{status}: {res.message}; {res.nfev} evaluations, {res.time_s:.2f} s; lag-1 autocorrelation of "
                f"the residuals {res.autocorrelation:.3f}")
        a(f'<p class="meta">{_e(info)}</p>')
        if res.flags:
            a(f'<ul class="flags" id="flags-{_e(m)}">' + "".join(f"<li>{_e(f)}</li>" for f in res.flags) + "</ul>")
        else:
            a(f'<p id="flags-{_e(m)}">No notes from the fit.</p>')
        body = []
        for n, p in res.parameters.items():
            body.append(
                "<tr>" + f"<th scope=\"row\">{_e(PARAMETERS[n][0])}</th>" + _td(fmt_num(p.value, ".6g"), p.value)
                + _td(fmt_num(p.stderr, ".3g") if p.vary else "fixed", p.stderr if p.vary else None)
                + _td(f"[{p.min:g}, {p.max:g}]", None, None, "") + _td("yes" if p.vary else "no", None, None, "")
                + _td(fmt_num(p.initial, ".6g"), p.initial) + _td(p.unit, None, None, "") + "</tr>"
            )
        a(_table(f"params-{m}", f"Parameters of the {label} model fit",
                 ["Parameter", "Value", "Standard error", "Bounds", "Fitted", "Start (nominal)", "Unit"], body))
        if len(res.correlation_names) > 1:
            names = [PARAMETERS[n][0] for n in res.correlation_names]
            body = []
            for i, n in enumerate(names):
                body.append(f'<tr><th scope="row">{_e(n)}</th>'
                            + "".join(_td(fmt_num(res.correlation[i, j], "+.3f"), res.correlation[i, j])
                                      for j in range(len(names))) + "</tr>")
            a(_table(f"correlation-{m}", f"Correlation of the fitted parameters ({label} model)", ["", *names], body))
        mt = res.metrics
        body = []
        for r in mt.per_pressure:
            body.append(
                "<tr>" + _td(fmt_num(r["pressure_kpa"], "g"), r["pressure_kpa"])
                + _td(fmt_num(r["rmse_cycle_nmm"], ".3f"), r["rmse_cycle_nmm"])
                + _td(fmt_num(r["M_max_nmm"], ".2f"), r["M_max_nmm"])
                + _td(fmt_num(r["blocked_moment_model_nmm"], ".2f"), r["blocked_moment_model_nmm"])
                + _td(fmt_num(r["K_max_per_mm"], ".5f"), r["K_max_per_mm"])
                + _td(fmt_num(r["free_curvature_model_per_mm"], ".5f"), r["free_curvature_model_per_mm"]) + "</tr>"
            )
        a(_table(f"metrics-{m}",
                 f"Per-pressure errors of the {label} model (RMSE of the cycles {fmt_num(mt.rmse_cycles, '.3f')} N·mm, "
                 f"of the blocked moment {fmt_num(mt.rmse_blocked_moment, '.3f')} N·mm, of the free-bending curvature "
                 f"{fmt_num(mt.rmse_free_curvature, '.3g')} 1/mm)",
                 ["Pressure (kPa)", "RMSE of the cycle (N·mm)", "Blocked moment, data (N·mm)",
                  "Blocked moment, model (N·mm)", "Free-bending curvature, data (1/mm)",
                  "Free-bending curvature, model (1/mm)"], body))
        if mt.no_equilibrium_kpa:
            where = ", ".join(f"{p:g}" for p in mt.no_equilibrium_kpa)
            a(f'<p class="warn">{_e(f"No free-bending equilibrium in the fitted model at {where} kPa.")}</p>')
        a(figures.get(f"fig-figure7-{m}", ""))
    a("</section>")

    # ---- 3. stresses ----------------------------------------------------------------------------
    a('<section id="stresses"><h2>3. Internal stresses (force-balance model)</h2>')
    if stresses is None:
        a('<p id="stresses-none">The force-balance model was not fitted, so its internal stresses are not shown.</p>')
    else:
        ps, ks = stresses["pressure_kpa"], stresses["curvature_per_mm"]
        a(f"<p>{_e(f'Fitted force-balance actuator at P = {ps:g} kPa and k′ = {ks:.5g} 1/mm (eq 37-48).')}</p>")
        a(figures.get("fig-stresses", ""))
    a("</section>")

    # ---- 4. actuator ----------------------------------------------------------------------------
    a('<section id="actuator-section"><h2>4. Actuator</h2>')
    cols = [("nominal", actuator)] + [(f"fitted, {_MODEL_LABEL[m]}", r.actuator) for m, r in fits.items()]
    dicts = [(c, act.to_dict(), act.derived()) for c, act in cols]
    keys = list(dicts[0][1])
    dkeys = list(dicts[0][2])
    body = []
    for k in keys:
        body.append(f'<tr><th scope="row">{_e(k)}</th>'
                    + "".join(_td(_fmt_any(d[k]), d[k] if isinstance(d[k], int | float) else None,
                                  None, "num" if isinstance(d[k], int | float) else "") for _, d, _ in dicts) + "</tr>")
    for k in dkeys:
        body.append(f'<tr class="derived"><th scope="row">{_e(k)} (derived)</th>'
                    + "".join(_td(_fmt_any(dd[k]), dd[k]) for _, _, dd in dicts) + "</tr>")
    for label, fn in (("kind", lambda x: x.kind), ("bend_sign", lambda x: x.bend_sign)):
        body.append(f'<tr class="derived"><th scope="row">{_e(label)}</th>'
                    + "".join(_td(_fmt_any(fn(act)), None, None, "") for _, act in cols) + "</tr>")
    a(_table("actuator", "Actuator parameters (units in the names), nominal and fitted",
             ["Parameter"] + [c for c, _ in cols], body))
    a("</section>")

    # ---- 5. inputs ------------------------------------------------------------------------------
    a('<section id="inputs-section"><h2>5. Input files and settings</h2>')
    body = []
    for t in inputs_info:
        units = ", ".join(f"{k}: {v}" for k, v in t["source_units"].items())
        body.append(
            "<tr>" + _td(t["path"], None, None, "") + _td(t["dialect"], None, None, "")
            + _td(fmt_num(t["pressure_kpa"], "g"), t["pressure_kpa"]) + _td(t["pressure_source"] or "—", None, None, "")
            + _td(str(t["samples"]), t["samples"]) + _td(units, None, None, "") + "</tr>"
        )
    a(_table("inputs", "Input files", ["File", "Dialect", "Pressure (kPa)", "Pressure from", "Samples",
                                        "Units in the file"], body))
    fx = fixture
    settings = [
        ("fixture d, r, t (mm)", f"{fx.d_mm:g}, {fx.r_mm:g}, {fx.t_mm:g}"),
        ("L0 for k' = 2β/L0 (mm)", f"{fx.L0_mm:g}"),
        ("low-pass cutoff (Hz)",
         "1 Hz (max 40 % of Nyquist)" if options.cutoff_hz is None else f"{options.cutoff_hz:g}"),
        ("filter order", f"{options.filter_order}"),
        ("reversal threshold (fraction of the stroke range)", f"{options.reversal_fraction:g}"),
        ("curvature grid points", f"{options.grid_points}"),
        ("force tare (N)", f"{options.tare_n:g}"),
        ("parameters fitted", ", ".join(free)),
        ("bendpam version", version),
    ]
    a(_table("settings", "Settings", ["Setting", "Value"],
             [f'<tr><th scope="row">{_e(k)}</th><td>{_e(v)}</td></tr>' for k, v in settings]))
    a("</section>")
    a(f'<footer><p class="meta">Generated by {_e(f"bendpam {version}")} on {_e(now)}. '
      "This page is self-contained: no scripts, no external files.</p></footer>")
    a("</body></html>")
    return "\n".join(parts) + "\n"
