"""A one-command, self-contained HTML report for papers: raw cyclic tests -> processing -> fits -> figures.

:func:`build_report` reads raw four-point-bending exports (files, or folders of them), processes
them (:func:`bendpam.lab.processing.process_tests`), fits each model
(:func:`bendpam.identify.fitting.fit`), checks the result, draws the figures and writes ONE HTML page
atomically.  The page needs nothing else: the figures are embedded as base64 PNG (``data:`` URIs),
the style sheet is inline, there is no JavaScript and no reference to any other file or address.
A ``Content-Security-Policy`` meta tag makes a browser refuse anything external.  It prints
cleanly (``@media print``: 15 mm margins that suit A4 and US letter, black text, no navigation,
no page break inside a table, a figure or a warning).

The page holds, from the top

* the warnings (``id="warnings"``): a styled box listing, each with what it means and what to
  try, a poor fit (NRMSE of the loading cycles above 10 %, or of the blocked moment or free-bending
  curvature above 20 %; the paper's fits reach 3-9 %), a parameter at (within 0.1 % of the span
  of) a bound of its range, strongly correlated parameters (``|r| > 0.95``), a search that did
  not converge, no free-bending equilibrium of the fitted model at a tested pressure (a fold), a
  measured deadband far from the actuator's P_start (``|dP| > max(15 kPa, 30 % of P_start)`` and
  more than twice its standard error), data that bend the other way than the actuator's type, and
  a model that could not be fitted at all (see :func:`report_warnings`); without any, a short "no
  warnings" box.  The report judges nothing itself: the findings and their limits are
  :mod:`bendpam.identify.diagnose`'s (one table, :data:`bendpam.identify.diagnose.LIMITS`), the
  report puts them into words (:mod:`bendpam.present.report.findings`).  A model that cannot be
  fitted does not stop the report: the page says why;
* Table 2 (``id="table2"``) with the deadband pressure (``id="deadband"``) and Figure 4
  (``id="fig-figure4"``);
* Table 3 (``id="table3"``): per model alpha0, C10, C01, the shear modulus mu = 2 (C10 + C01),
  and the NRMSEs of eq 53-55; per model a plain-language diagnosis of the search
  (``id="diagnosis-MODEL"``, never the optimiser's own text), the fit's notes
  (``id="flags-MODEL"``), the parameters (``id="params-MODEL"``), their correlations, the
  per-pressure errors (``id="metrics-MODEL"``), the alpha0 profile (``id="fig-alpha0-MODEL"``)
  and a prediction band when the fit carries them, and Figure 7 (``id="fig-figure7-MODEL"``);
* when the tests show hysteresis loops (:func:`bendpam.identify.diagnose.has_loop`), a hysteresis section
  (``id="hysteresis"``): the energy-loss ratio per pressure measured and predicted by each fitted
  loop (``id="hysteresis-loss"``, figure ``id="fig-hysteresis"``) and the loop parameters
  (``id="hysteresis-params-MODEL"``).  The fits model the loop themselves when the tests show one
  (Figure 7 then draws the fitted loops); otherwise a loop fit of its own is made and drawn
  (``id="fig-hysteresis-loops"``);
* the force-balance model's internal stresses (``id="fig-stresses"``);
* the actuator, nominal and fitted (``id="actuator"``), the input files (``id="inputs"``) and
  the settings (``id="settings"``).

Numbers are written by one function, :func:`fmt_value`: a value with a standard error shows the
error to two significant digits and the value to the same decimal place (``69.735 ± 0.012``);
a value without one has four significant digits; below 10^-3 and from 10^5 up a common power of
ten is factored out (``(2.676 00 ± 0.000 38) × 10⁻⁴``), and long digit runs are grouped in threes
(``0.002 676 87 ± 0.000 000 29``).  Parameters appear by their symbols with
units (α₀ (°), C₁₀ (kPa), P_start (kPa) ...; :data:`SYMBOLS`), never by their names in the code.
Every table cell with a number also carries it unformatted in ``data-value`` (and its standard
error in ``data-se``), so a program can read the page back without parsing the text.

Progress: :class:`bendpam.infra.progress.Progress` on stderr (a bar on a terminal, a line every few
seconds otherwise); ``progress=False`` writes nothing.

Errors are the library's one-line errors: :class:`~bendpam.lab.ReadError` for an unreadable
file, :class:`~bendpam.lab.processing.ProcessingError` for a test that cannot be processed
(e.g. a file without a pressure) and :class:`ValueError` for bad arguments.  A model that cannot
be fitted to these tests with this actuator (:class:`~bendpam.errors.FitError`, or a P_start above
the lowest tested pressure) does not stop the report: it is left out, and the warning box says
why.  Nor does a figure that cannot be drawn: the page shows a note in its place, and the note is
returned too.

The package, a module per job: :mod:`~bendpam.present.report.build` (:func:`build_report`, step by
step), :mod:`~bendpam.present.report.text` (numbers, symbols, words),
:mod:`~bendpam.present.report.tables` (the tables' text), :mod:`~bendpam.present.report.findings`
(the warnings and notes in words), :mod:`~bendpam.present.report.plots` (the figures) and
:mod:`~bendpam.present.report.html` (the page, from the Jinja2 templates in ``templates/``).
"""

from __future__ import annotations

from bendpam.present.report.build import Report, build_report
from bendpam.present.report.findings import ReportWarning, report_warnings
from bendpam.present.report.plots import alpha0_profile, prediction_band
from bendpam.present.report.tables import table2_rows, table3_rows
from bendpam.present.report.text import SYMBOLS, Symbol, describe_status, fmt_pct, fmt_value, symbol

__all__ = [
    "SYMBOLS",
    "Report",
    "ReportWarning",
    "Symbol",
    "alpha0_profile",
    "build_report",
    "describe_status",
    "fmt_pct",
    "fmt_value",
    "prediction_band",
    "report_warnings",
    "symbol",
    "table2_rows",
    "table3_rows",
]
