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
  try, a poor fit (NRMSE of the loading cycles above :data:`NRMSE_CYCLES_LIMIT` = 10 %, or of the
  blocked moment or free-bending curvature above :data:`NRMSE_POINTS_LIMIT` = 20 %; the paper's
  fits reach 3-9 %), a parameter at (within :data:`BOUND_FRACTION` of the span of) a bound of its
  range, strongly correlated parameters (``|r| >`` :data:`CORRELATION_LIMIT`), a search that did
  not converge, no free-bending equilibrium of the fitted model at a tested pressure (a fold), a
  measured deadband far from the actuator's P_start (``|dP| > max(15 kPa, 30 % of P_start)`` and
  more than twice its standard error), data that bend the other way than the actuator's type, and
  a model that could not be fitted at all (see :func:`report_warnings`); without any, a short "no
  warnings" box.  A model that cannot be fitted does not stop the report: the page says why;
* Table 2 (``id="table2"``) with the deadband pressure (``id="deadband"``) and Figure 4
  (``id="fig-figure4"``);
* Table 3 (``id="table3"``): per model alpha0, C10, C01, the shear modulus mu = 2 (C10 + C01),
  and the NRMSEs of eq 53-55; per model a plain-language diagnosis of the search
  (``id="diagnosis-MODEL"``, never the optimiser's own text), the fit's notes
  (``id="flags-MODEL"``), the parameters (``id="params-MODEL"``), their correlations, the
  per-pressure errors (``id="metrics-MODEL"``), the alpha0 profile (``id="fig-alpha0-MODEL"``)
  and a prediction band when the fit carries them, and Figure 7 (``id="fig-figure7-MODEL"``);
* when the tests show hysteresis loops (:func:`bendpam.identify.fitting.has_loop`), a hysteresis section
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
"""

from __future__ import annotations

import base64
import datetime as _dt
import html
import io
import math
import re
import struct
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from decimal import ROUND_HALF_UP, Decimal
from pathlib import Path
from typing import Any

import numpy as np

from bendpam.errors import BendpamError, FitError, InputError
from bendpam.infra.atomic import atomic_write_text
from bendpam.lab.files import RAW_SUFFIXES, collect_raw_files
from bendpam.physics.actuator import NEUTRAL_ANGLE_DEG, Actuator
from bendpam.physics.fixture import PAPER_FIXTURE, Fixture
from bendpam.physics.presets import normalise_model

__all__ = [
    "BOUND_FRACTION",
    "CORRELATION_LIMIT",
    "DEADBAND_LIMIT_FRACTION",
    "DEADBAND_LIMIT_KPA",
    "LOOP_THRESHOLD",
    "NRMSE_CYCLES_LIMIT",
    "NRMSE_POINTS_LIMIT",
    "RAW_SUFFIXES",
    "SYMBOLS",
    "Report",
    "ReportWarning",
    "Symbol",
    "alpha0_profile",
    "build_report",
    "collect_raw_files",
    "describe_status",
    "fmt_pct",
    "fmt_value",
    "prediction_band",
    "report_warnings",
    "symbol",
    "table2_rows",
    "table3_rows",
    "type_comparison",
]

#: NRMSE of the loading cycles (eq 53) above which a fit is called poor (the paper's: 3.3-5.5 %).
NRMSE_CYCLES_LIMIT = 0.10
#: NRMSE of the blocked moment or free-bending curvature (eq 54-55) above which a fit is poor (paper: 2-9 %).
NRMSE_POINTS_LIMIT = 0.20
#: A parameter within this fraction of its range's span from a bound is "at the bound".
BOUND_FRACTION = 1e-3
#: Pairs of fitted parameters with a larger |correlation| are flagged.
CORRELATION_LIMIT = 0.95
#: The measured deadband is "far" from P_start beyond max(this, DEADBAND_LIMIT_FRACTION * P_start) kPa.
DEADBAND_LIMIT_KPA = 15.0
DEADBAND_LIMIT_FRACTION = 0.30
#: Energy-loss ratio above which the tests "show loops" and get a hysteresis section (the median ratio, by
#: :func:`bendpam.identify.fitting.has_loop`, whose threshold is the same 1 %; this one only serves without it).
LOOP_THRESHOLD = 0.01
#: The other actuator type "fits better" when its NRMSE of the cycles is below the chosen one's / this.
DIRECTION_RATIO = 1.5

_DPI = 140
_MODEL_LABEL = {"energy": "energy", "force_balance": "force-balance"}
_LAW_LABEL = {"pi": "Prandtl-Ishlinskii", "dahl": "Dahl"}


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


# ------------------------------------------------------------------------------------------------
# numbers (one formatting function; public, so that tests and other tools produce the page's text)
# ------------------------------------------------------------------------------------------------
def _finite(x) -> bool:
    try:
        return x is not None and not isinstance(x, bool) and math.isfinite(float(x))
    except (TypeError, ValueError):
        return False


_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
_MINUS = "−"  # U+2212, the typographic minus sign


def _exp10(x: float) -> int:
    return math.floor(math.log10(abs(x)))


def _decimal(x: float, q: int) -> Decimal:
    """``x`` (as written: its shortest repr) rounded half up to a multiple of ``10**q``."""
    return Decimal(repr(float(x))).quantize(Decimal(1).scaleb(q), rounding=ROUND_HALF_UP)


def _round_sig(x: float, digits: int) -> float:
    return float(_decimal(x, _exp10(x) - digits + 1))


_GROUP = "\u202f"  # narrow no-break space between digit groups


def _group(digits: str, from_left: bool) -> str:
    """Digits in groups of three (ISO 80000-1), only when there are more than four."""
    if len(digits) <= 4:
        return digits
    if from_left:
        return _GROUP.join(digits[i:i + 3] for i in range(0, len(digits), 3))
    head = len(digits) % 3
    groups = ([digits[:head]] if head else []) + [digits[i:i + 3] for i in range(head, len(digits), 3)]
    return _GROUP.join(groups)


def _fixed(x: float, q: int) -> str:
    """``x`` rounded to a multiple of ``10**q``, as text: digits grouped, no negative zero, typographic minus."""
    t = format(_decimal(x, q), "f")
    if float(t) == 0.0:
        t = t.lstrip("-")
    sign = _MINUS if t.startswith("-") else ""
    whole, _, frac = t.lstrip("-").partition(".")
    return sign + _group(whole, False) + ("." + _group(frac, True) if frac else "")


def fmt_value(value, se=None, unit: str = "", *, sig: int = 4) -> str:
    """A number as a paper prints it: ``value ± se`` with matching digits, or ``sig`` significant digits.

    * With a standard error (finite and > 0): the error to two significant digits and the value
      rounded to the same decimal place, ``69.7345 ± 0.0119 -> "69.735 ± 0.012"``,
      ``4666.2 ± 1523 -> "4700 ± 1500"``.  A standard error of exactly 0 is shown as ``± 0``.
    * Without one: ``sig`` significant digits (default 4), ``69.7345 -> "69.73"``.
    * Magnitudes below 10^-3 or from 10^5 up share a power of ten:
      ``0.00026760 ± 3.8e-8 -> "(2.676 00 ± 0.000 38) × 10⁻⁴"``.
    * More than four digits on either side of the decimal point are grouped in threes with a
      narrow no-break space (U+202F, ISO 80000-1): ``0.002 676 87``.
    * ``unit`` is appended after a space (directly for ``"°"``), with parentheses around a ``±``
      pair: ``"(69.735 ± 0.012)°"``, ``"(4700 ± 1500) kPa"``.
    * Negative numbers use the minus sign U+2212; None, NaN and inf give an em dash.

    Parameters
    ----------
    value : float
        The number.
    se : float or None
        Its standard error (same unit); None, NaN or < 0 means none.
    unit : str
        Unit text to append (``"kPa"``, ``"°"``), or ``""``.
    sig : int
        Significant digits of a value without a standard error (>= 1).

    Returns
    -------
    str

    Examples
    --------
    >>> fmt_value(69.7345, 0.0119, "°"), fmt_value(4666.2, 1523, "kPa"), fmt_value(-318.94)
    ('(69.735 ± 0.012)°', '(4700 ± 1500) kPa', '−318.9')
    >>> fmt_value(0.0026760, 3.8e-7).replace("\u202f", " "), fmt_value(2.676e-4, 3.8e-8).replace("\u202f", " ")
    ('0.002 676 00 ± 0.000 000 38', '(2.676 00 ± 0.000 38) × 10⁻⁴')
    >>> fmt_value(1.5e6), fmt_value(float("nan")), fmt_value(329.28, 0.0, "N·mm")
    ('1.500 × 10⁶', '—', '(329.3 ± 0) N·mm')
    """
    if not _finite(value):
        return "—"
    if isinstance(sig, bool) or not isinstance(sig, int | np.integer) or sig < 1:
        raise InputError(f"sig = {sig!r}: give a whole number of significant digits >= 1")
    v = float(value)
    s = float(se) if _finite(se) and float(se) >= 0 else None
    if s is not None and s > 0:
        s = _round_sig(s, 2)
        q = _exp10(s) - 1  # decimal exponent of the last digit shown
        big = max(abs(v), s)
    elif v == 0.0:
        q, big = 0, 0.0
    else:
        v = _round_sig(v, int(sig))
        q = _exp10(v) - int(sig) + 1
        big = abs(v)
    n = _exp10(big) if big and (big < 1e-3 or big >= 1e5) else 0
    scale = 10.0**n
    text = _fixed(v / scale, q - n)
    if s is not None:
        text = f"{text} ± {_fixed(s / scale, q - n) if s > 0 else '0'}"
    if n:
        text = (f"({text})" if s is not None else text) + f" × 10{str(n).translate(_SUPERSCRIPT)}"
    if unit:
        if s is not None and not n:
            text = f"({text})"
        text += unit if unit == "°" else f" {unit}"
    return text


def fmt_pct(ratio, *, sig: int = 3) -> str:
    """A ratio as a percentage number without the % sign (``0.5684 -> "56.8"``), or an em dash.

    >>> fmt_pct(0.56843), fmt_pct(0.011497), fmt_pct(None)
    ('56.8', '1.15', '—')
    """
    return fmt_value(100.0 * float(ratio), sig=sig) if _finite(ratio) else "—"


def _corr_text(r) -> str:
    return f"{float(r):+.3f}".replace("-", _MINUS) if _finite(r) else "—"


# ------------------------------------------------------------------------------------------------
# symbols and units
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Symbol:
    """How a quantity is shown: its symbol (plain text and HTML), unit and meaning."""

    text: str
    html: str
    unit: str
    meaning: str

    def heading(self, html_: bool = True) -> str:
        """``"α₀ (°)"``: the symbol with its unit in parentheses (HTML or text)."""
        sym = self.html if html_ else self.text
        return f"{sym} ({_e(self.unit) if html_ else self.unit})" if self.unit else sym


#: Display of every parameter and actuator quantity, by the short names of :mod:`bendpam.identify.fitting`
#: and by the unit-suffixed field names of :class:`~bendpam.physics.actuator.Actuator`.
SYMBOLS: dict[str, Symbol] = {
    "alpha0": Symbol("α₀", "α<sub>0</sub>", "°", "braid angle at rest"),
    "R0": Symbol("R₀", "R<sub>0</sub>", "mm", "bladder outer radius at rest"),
    "t0": Symbol("t₀", "t<sub>0</sub>", "mm", "bladder wall thickness at rest"),
    "L0": Symbol("L₀", "L<sub>0</sub>", "mm", "active length"),
    "h_f": Symbol("h_f", "h<sub>f</sub>", "mm", "frame thickness"),
    "w_f": Symbol("w_f", "w<sub>f</sub>", "mm", "frame width"),
    "E_f": Symbol("E_f", "E<sub>f</sub>", "MPa", "frame Young's modulus"),
    "C10": Symbol("C₁₀", "C<sub>10</sub>", "kPa", "Mooney-Rivlin constant of the bladder"),
    "C01": Symbol("C₀₁", "C<sub>01</sub>", "kPa", "Mooney-Rivlin constant of the bladder"),
    "mu": Symbol("μ", "μ", "kPa", "initial shear modulus of the bladder, 2(C₁₀ + C₀₁)"),
    "P_start": Symbol("P_start", "P<sub>start</sub>", "kPa", "pressure at which the bladder starts to act "
                      "(the deadband)"),
    "R0_start": Symbol("R₀,start", "R<sub>0,start</sub>", "mm", "bladder outer radius at P_start (prestrain)"),
    "t_br": Symbol("t_br", "t<sub>br</sub>", "mm", "braid thickness"),
    "t0_start": Symbol("t₀,start", "t<sub>0,start</sub>", "mm", "bladder wall thickness at P_start (eq 52)"),
    "A_bl": Symbol("A_bl", "A<sub>bl</sub>", "mm²", "bladder wall cross-section area (eq 51)"),
    "I_f": Symbol("I_f", "I<sub>f</sub>", "mm⁴", "second moment of area of the frame"),
    "EI_f": Symbol("E_f·I_f", "E<sub>f</sub>I<sub>f</sub>", "N·mm²", "bending stiffness of the frame"),
    "theta_h": Symbol("θ_h", "θ<sub>h</sub>", "°", "bending angle over which the friction loop saturates"),
    "a0": Symbol("a₀", "a<sub>0</sub>", "N·mm", "loop amplitude without pressure (fabric tension)"),
    "a1": Symbol("a₁", "a<sub>1</sub>", "N·mm/kPa", "loop amplitude per kPa of active pressure"),
    "sigma_f": Symbol("σ_f,max", "σ<sub>f,max</sub>", "MPa", "strength of the frame material"),
    "lambda_max": Symbol("λ_max", "λ<sub>max</sub>", "", "largest allowed principal stretch of the bladder"),
}
_FIELD_KEY = {
    "alpha0_deg": "alpha0", "R0_mm": "R0", "t0_mm": "t0", "L0_mm": "L0", "frame_thickness_mm": "h_f",
    "frame_width_mm": "w_f", "frame_modulus_mpa": "E_f", "C10_kpa": "C10", "C01_kpa": "C01",
    "P_start_kpa": "P_start", "R0_start_mm": "R0_start", "braid_thickness_mm": "t_br", "t0_start_mm": "t0_start",
    "bladder_area_mm2": "A_bl", "frame_inertia_mm4": "I_f", "frame_stiffness_nmm2": "EI_f",
    "shear_modulus_kpa": "mu", "theta_h_deg": "theta_h", "a0_nmm": "a0", "a1_nmm_per_kpa": "a1",
    "frame_strength_mpa": "sigma_f", "bladder_stretch_limit": "lambda_max",
}
#: Unit suffixes of field names (longest first) -> the unit as shown.
_UNIT_SUFFIX = (("_nmm_per_kpa", "N·mm/kPa"), ("_per_mm", "1/mm"), ("_nmm2", "N·mm²"), ("_nmm", "N·mm"),
                ("_mm2", "mm²"), ("_mm4", "mm⁴"), ("_mm", "mm"), ("_kpa", "kPa"), ("_mpa", "MPa"), ("_deg", "°"),
                ("_n", "N"), ("_s", "s"), ("_hz", "Hz"))


def symbol(name: str) -> Symbol:
    """The :class:`Symbol` of a short name (``"C10"``) or an actuator field (``"C10_kpa"``).

    A field without a symbol of its own is shown in words, its unit taken from its name
    (``"tip_load_n"`` -> "tip load" (N)), so a new field never shows its code name.

    >>> symbol("C10_kpa").heading(False), symbol("alpha0").text, symbol("tip_load_n").heading(False)
    ('C₁₀ (kPa)', 'α₀', 'tip load (N)')
    """
    key = _FIELD_KEY.get(name, name)
    if key in SYMBOLS:
        return SYMBOLS[key]
    base, unit = str(name), ""
    for suffix, u in _UNIT_SUFFIX:
        if base.lower().endswith(suffix) and len(base) > len(suffix):
            base, unit = base[: -len(suffix)], u
            break
    words = base.replace("_", " ").strip()
    return Symbol(words, _e(words), unit, words)


# the code names that may appear in text from elsewhere (fit flags and notes) -> their symbols
_CODE_NAMES = sorted({*_FIELD_KEY, *(k for k in SYMBOLS if k not in ("mu", "h_f", "w_f", "t_br", "A_bl", "I_f",
                                                                    "EI_f", "R0", "t0", "L0"))},
                     key=len, reverse=True)
_CODE_NAMES.append("mu")
_CODE_RE = re.compile(r"\b(" + "|".join(re.escape(n) for n in _CODE_NAMES) + r")\b")
#: Units and operators as code writes them -> as a paper prints them.
_PRETTY = ((re.compile(r"(?<=\d) ?deg\b"), "°"), (re.compile(r"N\*mm"), "N·mm"), (re.compile(r">="), "≥"),
           (re.compile(r"<="), "≤"), (re.compile(r"\+-"), "±"), (re.compile(r"(?<![\w.])-(?=\d)"), _MINUS),
           (re.compile(r"\bpi vs dahl\b"), "Prandtl-Ishlinskii vs Dahl"),
           (re.compile(r"\bdahl vs pi\b"), "Dahl vs Prandtl-Ishlinskii"),
           (re.compile(r"(?<=\d)e([+-]?)0*(\d+)\b"), None))


def _pretty(text: str) -> str:
    for rx, rep in _PRETTY:
        if rep is None:  # 1.8e+02 -> 1.8 × 10²
            text = rx.sub(lambda m: " × 10" + (("-" if m.group(1) == "-" else "") + m.group(2)).translate(_SUPERSCRIPT),
                          text)
        else:
            text = rx.sub(rep, text)
    return text


def _plain_html(text: str) -> str:
    """Escape ``text`` for HTML and show code names (``C10_kpa``, ``alpha0``) by their symbols.

    Spans in backticks (command-line input such as ``--free alpha0,C10``) are shown as code,
    unchanged.
    """
    parts = str(text).split("`")
    return "".join(f"<code>{_e(p)}</code>" if i % 2 else _CODE_RE.sub(lambda m: symbol(m.group(1)).html,
                                                                      _e(_pretty(p)))
                   for i, p in enumerate(parts))


def _plain_text(text: str) -> str:
    """``text`` with code names replaced by the symbols' plain-text forms (for a terminal); backtick spans kept."""
    parts = str(text).split("`")
    return "".join(p if i % 2 else _CODE_RE.sub(lambda m: symbol(m.group(1)).text, _pretty(p))
                   for i, p in enumerate(parts))


# ------------------------------------------------------------------------------------------------
# plain-language diagnostics
# ------------------------------------------------------------------------------------------------
_LIMIT_WORDS = ("max", "limit", "iteration", "evaluation", "budget", "nfev")


def describe_status(converged: bool, message: str = "") -> str:
    """One plain sentence for the state a search ended in, from its ``converged`` flag and message.

    The optimiser's own text (``"`gtol` termination condition is satisfied."``) is read, never
    shown: it is mapped to what it means for the fit.

    >>> describe_status(True, "`xtol` termination condition is satisfied.")
    'The fit converged: the parameters stopped changing.'
    >>> describe_status(False, "The maximum number of function evaluations is exceeded.")
    'The search stopped at its evaluation limit before converging: the values may not be the best fit.'
    """
    msg = str(message or "").lower()
    if not converged:
        if any(w in msg for w in _LIMIT_WORDS):
            return "The search stopped at its evaluation limit before converging: the values may not be the best fit."
        return "The search did not converge: the values may not be the best fit."
    if "linear" in msg and "exact" in msg:
        return ("Every fitted parameter enters the model linearly, so they were solved exactly; no iterative "
                "search was needed.")
    if "gtol" in msg or "gradient" in msg:
        return "The fit converged: the error no longer changes with any parameter (a minimum was reached)."
    if "ftol" in msg:
        return "The fit converged: the error stopped decreasing."
    return "The fit converged: the parameters stopped changing."


def _param_stats(res):
    """The shear modulus mu = 2 (C10 + C01) and its standard error (kPa), or (None, None) without C10, C01.

    From the fit's own material identification where it has one, else from C10, C01 and their correlation.
    """
    mat = getattr(res, "material", None)
    if mat is not None and _finite(getattr(mat, "shear_modulus_kpa", None)):
        se = getattr(mat, "se_shear_modulus_kpa", None)
        return float(mat.shear_modulus_kpa), (float(se) if _finite(se) else None)
    params = res.parameters
    c10, c01 = params.get("C10"), params.get("C01")
    if c10 is None or c01 is None:
        return None, None
    mu = 2.0 * (c10.value + c01.value)
    s10 = c10.stderr if (c10.vary and _finite(c10.stderr)) else 0.0
    s01 = c01.stderr if (c01.vary and _finite(c01.stderr)) else 0.0
    if (c10.vary and not _finite(c10.stderr)) or (c01.vary and not _finite(c01.stderr)):
        return mu, None
    r = 0.0
    names = list(res.correlation_names)
    if "C10" in names and "C01" in names:
        rr = res.correlation[names.index("C10"), names.index("C01")]
        r = float(rr) if _finite(rr) else 0.0
    var = s10 * s10 + s01 * s01 + 2.0 * r * s10 * s01
    se = 2.0 * math.sqrt(max(var, 0.0)) if (c10.vary or c01.vary) else None
    return mu, se


def _diagnosis(res, warned: bool) -> list[str]:
    """Plain sentences about one fit: the search, its cost, the residuals, the size of the error."""
    out = [describe_status(bool(res.converged), str(getattr(res, "message", "")))]
    if warned and res.converged:
        out.append("Converging only means that the search found a minimum, not that the model matches the data: "
                   "see the warnings at the top.")
    out.append(f"The search evaluated the model {int(res.nfev)} times in {fmt_value(res.time_s, sig=2)} s.")
    rho = float(getattr(res, "autocorrelation", 0.0) or 0.0)
    if rho > 0.5:
        out.append(f"Neighbouring residuals are strongly correlated (lag-1 autocorrelation {rho:.2f}): the model "
                   "misses part of the curves' shape systematically, beyond the measurement noise; the standard "
                   "errors are widened to allow for this.")
    else:
        out.append(f"The residuals look like measurement noise (lag-1 autocorrelation {rho:.2f}).")
    m = res.metrics
    out.append(f"The model reproduces the loading cycles within {fmt_pct(m.nrmse_cycles)} % (NRMSE, eq 53), the "
               f"blocked moment within {fmt_pct(m.nrmse_blocked_moment)} % and the free-bending curvature within "
               f"{fmt_pct(m.nrmse_free_curvature)} %; the paper's fits reach 3.3-5.5 %, 2.6-4.9 % and 1.9-8.8 %.")
    return out


# ------------------------------------------------------------------------------------------------
# warnings
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ReportWarning:
    """A problem the report shows in its warning box.

    Attributes
    ----------
    kind : ``"fit-failed"``, ``"poor-fit"``, ``"not-converged"``, ``"at-bound"``, ``"correlated"``,
        ``"fold"``, ``"deadband"`` or ``"direction"``.
    title : one line (plain text with symbols such as α₀ and P_start).
    meaning : what it means for the results.
    action : what to try.
    models : the models it concerns (empty for a problem of the data).
    severity : ``"warning"`` (the results should not be used as they are) or ``"caution"``.
    """

    kind: str
    title: str
    meaning: str
    action: str
    models: tuple[str, ...] = ()
    severity: str = "warning"

    def text(self) -> str:
        """The warning as plain text on one line (for a terminal)."""
        return _plain_text(f"{self.title}. {self.meaning} {self.action}")


def _at_bound(p) -> str | None:
    """``"lower"``/``"upper"`` if a fitted parameter is within BOUND_FRACTION of its range's span of a bound."""
    if not p.vary or not (_finite(p.min) and _finite(p.max) and _finite(p.value)) or not p.max > p.min:
        return None
    tol = BOUND_FRACTION * (p.max - p.min)
    if p.value - p.min <= tol:
        return "lower"
    if p.max - p.value <= tol:
        return "upper"
    return None


@dataclass(frozen=True)
class _Finding:
    """One model's share of a warning; findings with the same (kind, key) are merged across models."""

    kind: str
    key: str
    head: str
    detail: str
    meaning: str
    action: str
    model: str
    severity: str = "warning"


def _findings(model: str, res) -> list[_Finding]:
    """What is wrong with one fit (see :func:`report_warnings`)."""
    out: list[_Finding] = []
    m = res.metrics
    bad = []
    if _finite(m.nrmse_cycles) and m.nrmse_cycles > NRMSE_CYCLES_LIMIT:
        bad.append(f"loading cycles {fmt_pct(m.nrmse_cycles)} %")
    for what, v in (("blocked moment", m.nrmse_blocked_moment), ("free-bending curvature", m.nrmse_free_curvature)):
        if _finite(v) and v > NRMSE_POINTS_LIMIT:
            bad.append(f"{what} {fmt_pct(v)} %")
    if bad:
        out.append(_Finding(
            "poor-fit", "", "Poor fit", "NRMSE of the " + ", of the ".join(bad),
            f"The fitted model misses the measured curves by far more than the paper's fits (3-9 %; the limits here "
            f"are {fmt_pct(NRMSE_CYCLES_LIMIT, sig=2)} % for the loading cycles and "
            f"{fmt_pct(NRMSE_POINTS_LIMIT, sig=2)} % for the blocked moment and free-bending curvature), so its "
            "parameters do not describe this actuator.",
            "Check that the preset or actuator file is the actuator that was tested (its type, geometry and "
            "P_start), look at Figure 7 for where the model leaves the data, and consider fitting P_start too "
            "(`--free alpha0,C10,C01,P_start`).", model))
    if not res.converged:
        out.append(_Finding(
            "not-converged", "", "The search did not converge", "",
            "The parameters are where the search stopped, not necessarily the best fit.",
            "Fit fewer parameters (a narrower `--free`), or check the data for outliers in Figure 4.", model))
    for name, p in res.parameters.items():
        side = _at_bound(p)
        if side is None:
            continue
        sym = symbol(name)
        out.append(_Finding(
            "at-bound", name, f"{sym.text} is at a bound of its allowed range",
            f"{fmt_value(p.value, unit=sym.unit)}, the {side} bound of {fmt_value(p.min, unit=sym.unit)} to "
            f"{fmt_value(p.max, unit=sym.unit)}",
            "The fit would move it further if it could, so the value is set by the bound, not by the data, and "
            "its standard error means nothing.",
            ("Check that the actuator's type and nominal α₀ are right (the range is ±10 % of the nominal value, "
             "on the actuator's side of 54.74°)." if name == "alpha0" else
             "Check the nominal values and units of the actuator, or hold this parameter fixed."), model))
    c10, c01 = res.parameters.get("C10"), res.parameters.get("C01")
    if c10 is not None and c01 is not None and c10.vary and c01.vary:
        total, lo = c10.value + c01.value, 1.0
        span = (c10.max + c01.max) - lo
        if _finite(total) and _finite(span) and span > 0 and total - lo <= BOUND_FRACTION * span:
            out.append(_Finding(
                "at-bound", "mu", "The shear modulus μ = 2(C₁₀ + C₀₁) is at its lower bound",
                f"μ = {fmt_value(2 * total, unit='kPa')}",
                "The fit wants a bladder without stiffness (or with a negative one), which is not physical.",
                "Check the actuator's geometry and P_start, or fix C₁₀ and C₀₁ from a tension test (`--tension`).",
                model))
    names = list(res.correlation_names)
    pairs = []
    for i in range(len(names)):
        for j in range(i + 1, len(names)):
            r = res.correlation[i, j]
            if _finite(r) and abs(float(r)) > CORRELATION_LIMIT:
                pairs.append((names[i], names[j], float(r)))
    if pairs:
        cc = any({a, b} == {"C10", "C01"} for a, b, _ in pairs)
        mu, mu_se = _param_stats(res)
        detail = ", ".join((f"{symbol(a).text}–{symbol(b).text} " if len(pairs) > 1 else "") + f"r = {_corr_text(r)}"
                           for a, b, r in pairs)
        if cc and mu is not None and _finite(mu):
            detail += f"; μ = {fmt_value(mu, mu_se, 'kPa')}"
        out.append(_Finding(
            "correlated", ",".join(f"{a}+{b}" for a, b, _ in pairs),
            "Strongly correlated parameters: " + "; ".join(f"{symbol(a).text} and {symbol(b).text}"
                                                          for a, b, _ in pairs),
            detail,
            "The data determine a combination of each pair, not each one: the values trade off against each other "
            "and their standard errors are large."
            + (" For C₁₀ and C₀₁ the combination that is determined is the shear modulus μ = 2(C₁₀ + C₀₁), given "
               "in the title and in Table 3." if cc else ""),
            "Report the combination, hold one parameter of the pair fixed (e.g. `--free alpha0,C10`), or measure "
            "C₁₀ and C₀₁ in a tension test (`--tension`).", model, "caution"))
    no_eq = list(getattr(m, "no_equilibrium_kpa", []) or [])
    if no_eq:
        out.append(_Finding(
            "fold", "", "No free-bending equilibrium inside the tested range",
            "at " + ", ".join(f"{p:g}" for p in no_eq) + " kPa",
            "The fitted moment law folds there (snap-through): the model has no free-bending state although "
            "the test found one, and those pressures are left out of the free-curvature error.",
            "Compare the model with the data in Figure 7 (c); a fold inside the tested range usually means that "
            "the parameters are wrong or that the actuator type does not match.", model))
    return out


def _merge(findings: Sequence[_Finding]) -> list[ReportWarning]:
    """One warning per (kind, key), naming each model with its own detail."""
    groups: dict[tuple[str, str], list[_Finding]] = {}
    for f in findings:
        groups.setdefault((f.kind, f.key), []).append(f)
    out = []
    for fs in groups.values():
        f0 = fs[0]
        parts = [f"{_MODEL_LABEL.get(f.model, f.model)} model" + (f" ({f.detail})" if f.detail else "") for f in fs]
        out.append(ReportWarning(f0.kind, f"{f0.head}: " + "; ".join(parts), f0.meaning, f0.action,
                                 tuple(f.model for f in fs), f0.severity))
    return out


_KIND_RE = re.compile(r"\b(B[EC])[\s-]?PAMs?\b", re.IGNORECASE)


def _metadata_kinds(metadata: Iterable[tuple[str, Mapping]]) -> dict[str, str]:
    """Actuator types named in the files' metadata: ``{"BE-PAM": "file: key: value", ...}``."""
    found: dict[str, str] = {}
    for name, meta in metadata:
        for k, v in (meta or {}).items():
            for m in _KIND_RE.finditer(f"{k}: {v}"):
                kind = m.group(1).upper() + "-PAM"
                found.setdefault(kind, f"{name}: “{k}: {v}”")
    return found


_SIDES = {1: (NEUTRAL_ANGLE_DEG + 0.05, 85.0), -1: (15.0, NEUTRAL_ANGLE_DEG - 0.05)}


def _side_fit(processed, actuator: Actuator, model: str, free, sign: int):
    """A quick fit with alpha0 anywhere on one side of 54.74 deg (``sign``) and P_start free, or None."""
    from bendpam.identify.fitting import fit

    rng = _SIDES[sign]
    names = list(dict.fromkeys(["alpha0", *free, "P_start"]))
    act = actuator.replace(alpha0_deg=0.5 * (rng[0] + rng[1]))
    try:
        try:
            return fit(processed, act, model, free=names, bounds={"alpha0": rng}, law_uncertainty=False,
                       profile_points=0)
        except TypeError:  # an identification without those options
            return fit(processed, act, model, free=names, bounds={"alpha0": rng})
    except (BendpamError, ValueError, ArithmeticError):
        return None


def type_comparison(processed, actuator: Actuator, model: str = "energy", free=("alpha0", "C10", "C01")):
    """Fit both actuator types with the same freedom: ``(same, other)`` FitResults (None where a fit fails).

    Both fits free α₀ across their whole side of 54.74° and P_start besides ``free``, so that neither
    a wrong nominal α₀ nor a wrong P_start decides which type describes the data better.  Used by
    :func:`report_warnings` as evidence of the bending direction.  Returns ``(None, None)`` for a
    neutral actuator.
    """
    sign = int(actuator.bend_sign)
    if sign == 0:
        return None, None
    return (_side_fit(processed, actuator, model, free, sign), _side_fit(processed, actuator, model, free, -sign))


def _nrmse(res) -> float:
    return float(res.metrics.nrmse_cycles) if res is not None and _finite(res.metrics.nrmse_cycles) else math.nan


def report_warnings(processed, actuator: Actuator, fits: Mapping, *, metadata: Iterable[tuple[str, Mapping]] = (),
                    comparison=None, failed: Mapping[str, str] | None = None) -> list[ReportWarning]:
    """Everything the report warns about, most serious first.

    Per model (see the module docstring for the limits): a fit that failed, a poor fit, a search
    that did not converge, parameters at a bound, strongly correlated pairs (a caution), no
    free-bending equilibrium at a tested pressure.  For the data:

    * ``deadband``: the measured deadband ``P0 ± se`` (x-intercept of the blocked moment against
      pressure) differs from the actuator's ``P_start`` by more than ``max(15 kPa, 30 % P_start)``
      and by more than two standard errors;
    * ``direction``: the data bend the other way than the actuator's type (a BE-PAM bends toward the
      frame, k' > 0; a BC-PAM away from it).  The tests record magnitudes, so the evidence is
      indirect; any of these raises the warning: the files' metadata name the other type; with the
      chosen type's fit poor or failed, an actuator of the other type fitted with the same freedom
      (``comparison``, see :func:`type_comparison`) reproduces the cycles within the NRMSE limit and
      at least 1.5 times better than the chosen type; or the chosen fit is poor with α₀ pinned at
      the bound next to 54.74°.

    Parameters
    ----------
    processed : :class:`~bendpam.lab.processing.ProcessedSet`
    actuator : the nominal :class:`~bendpam.physics.actuator.Actuator` the fits started from.
    fits : ``{model: FitResult}`` of the fits that succeeded.
    metadata : ``(file name, {key: value})`` pairs read from the raw files' headers.
    comparison : ``(same, other)`` from :func:`type_comparison`, or None to skip that evidence.
    failed : ``{model: reason}`` of the fits that failed.

    Returns
    -------
    list of :class:`ReportWarning`
    """
    out = _merge([f for model, res in fits.items() for f in _findings(model, res)])
    for model, why in (failed or {}).items():
        out.append(ReportWarning(
            "fit-failed", f"The {_MODEL_LABEL.get(model, model)} model could not be fitted: {why}",
            "No parameters of this model reproduce the tests, so it is left out of the tables and figures.",
            "Check that the actuator's type, geometry and P_start are those of the tested actuator (see the "
            "other warnings), or fit P_start too (`--free alpha0,C10,C01,P_start`).", (model,)))
    # ---- the deadband against P_start --------------------------------------------------------
    p0, p0_se = processed.deadband()
    ps = float(actuator.P_start_kpa)
    if _finite(p0):
        d = float(p0) - ps
        limit = max(DEADBAND_LIMIT_KPA, DEADBAND_LIMIT_FRACTION * ps)
        if abs(d) > limit and (not _finite(p0_se) or abs(d) > 2.0 * float(p0_se)):
            fitted = [f"{_MODEL_LABEL.get(m, m)} model {fmt_value(r.parameters['P_start'].value, unit='kPa')}"
                      for m, r in fits.items() if "P_start" in r.parameters and r.parameters["P_start"].vary]
            out.append(ReportWarning(
                "deadband", f"The measured deadband, {fmt_value(p0, p0_se, 'kPa')}, is far from the actuator's "
                f"P_start of {fmt_value(ps, unit='kPa')}",
                f"The blocked moment extrapolates to zero {fmt_value(abs(d), sig=2, unit='kPa')} "
                f"{'above' if d > 0 else 'below'} the pressure at which the model lets the bladder start to act "
                f"(more than {fmt_value(limit, sig=2, unit='kPa')} apart); with the wrong P_start the other "
                "parameters absorb the difference"
                + (f" (fitted P_start: {', '.join(fitted)})." if fitted else "."),
                "Use the actuator that was tested (its preset or an `--actuator` file with its P_start), or fit "
                "P_start too (`--free alpha0,C10,C01,P_start`)."))
    # ---- the bending direction ---------------------------------------------------------------
    kind = actuator.kind
    if kind in ("BE-PAM", "BC-PAM"):
        other = "BC-PAM" if kind == "BE-PAM" else "BE-PAM"
        evidence = []
        named = _metadata_kinds(metadata)
        if other in named and kind not in named:
            evidence.append(f"the files' metadata name a {other} ({named[other]})")
        first: Any = next(iter(fits.values()), None)
        chosen = _nrmse(first)
        poor = (first is None and bool(failed)) or (_finite(chosen) and chosen > NRMSE_CYCLES_LIMIT)
        if poor and comparison is not None:
            same, alt = comparison
            e_same, e_alt = _nrmse(same), _nrmse(alt)
            if _finite(e_alt) and e_alt <= NRMSE_CYCLES_LIMIT and (not _finite(e_same)
                                                                   or e_alt * DIRECTION_RATIO < e_same):
                evidence.append(
                    f"given the same freedom (α₀ anywhere on its side of 54.74°, P_start fitted), an actuator of "
                    f"the other type reproduces the cycles within {fmt_pct(e_alt)} % (α₀ = "
                    f"{fmt_value(alt.parameters['alpha0'].value, unit='°')}), the {kind} "
                    + (f"only within {fmt_pct(e_same)} %" if _finite(e_same) else "not at all"))
        if poor and first is not None and "alpha0" in first.parameters:
            side = _at_bound(first.parameters["alpha0"])
            if (side == "upper" and kind == "BC-PAM") or (side == "lower" and kind == "BE-PAM"):
                evidence.append("the fit pushes α₀ against the bound next to 54.74°, the angle that separates "
                                "the two types")
        if evidence:
            sense = "toward the frame (k′ > 0)" if other == "BE-PAM" else "away from the frame (k′ < 0)"
            out.append(ReportWarning(
                "direction", f"The data look like a {other}, which bends {sense}, but the actuator is a {kind}",
                "Evidence: " + "; ".join(evidence) + ". A model of the wrong type cannot describe the tests, "
                "whatever its parameters.",
                f"Check the preset or the actuator file (a {other} has α₀ "
                f"{'above' if other == 'BE-PAM' else 'below'} 54.74°; e.g. `--preset "
                f"{other.lower()}`), and how the actuator was mounted in the fixture."))
    order = {"direction": 0, "deadband": 1, "fit-failed": 2, "poor-fit": 3, "fold": 4, "not-converged": 5,
             "at-bound": 6, "correlated": 7}
    return sorted(out, key=lambda w: (w.severity != "warning", order.get(w.kind, 9)))


# ------------------------------------------------------------------------------------------------
# table rows (the text shown, public so that tests and the CLI print the same)
# ------------------------------------------------------------------------------------------------
#: Table 3's parameter columns: short names.
_T3_PARAMS = ("alpha0", "C10", "C01")


def _param_text(p) -> str:
    if p is None:
        return "—"
    if not p.vary:
        return f"{fmt_value(p.value)} (fixed)"
    text = fmt_value(p.value, p.stderr)
    if not _finite(p.stderr):
        text += " ± n/a"
    return text + (" *" if _at_bound(p) else "")


def table2_rows(summary: dict) -> list[dict[str, str]]:
    """The text of Table 2's body cells, one dict per pressure, from ``ProcessedSet.summary()``.

    >>> row = {"pressure_kpa": 100.0, "cycles": 3, "blocked_moment_nmm": 80.0626, "blocked_moment_se_nmm": 0.8145,
    ...        "free_curvature_per_mm": 0.0121, "free_curvature_se_per_mm": 0.0021, "energy_loss_ratio": 0.1876}
    >>> list(table2_rows({"pressures": [row]})[0].values())
    ['100', '3', '80.06 ± 0.81', '0.0121 ± 0.0021', '18.8']
    """
    rows = []
    for r in summary["pressures"]:
        rows.append({
            "pressure_kpa": f"{float(r['pressure_kpa']):g}",
            "cycles": str(int(r["cycles"])),
            "blocked_moment_nmm": fmt_value(r["blocked_moment_nmm"], r["blocked_moment_se_nmm"]),
            "free_curvature_per_mm": fmt_value(r["free_curvature_per_mm"], r["free_curvature_se_per_mm"]),
            "energy_loss_percent": fmt_pct(r["energy_loss_ratio"]),
        })
    return rows


def table3_rows(fits: dict) -> list[dict[str, str]]:
    """The text of Table 3's body cells, one dict per model, from ``{model: FitResult}``.

    Keys: ``model``, ``alpha0``, ``C10``, ``C01`` (value ± SE, `` *`` at a bound, ``(fixed)``),
    ``mu`` (the shear modulus 2 (C10 + C01) ± SE, kPa) and the NRMSEs in % ``nrmse_cycles``,
    ``nrmse_blocked_moment``, ``nrmse_free_curvature``.
    """
    rows = []
    for model, res in fits.items():
        m = res.metrics
        row = {"model": f"{_MODEL_LABEL.get(model, model)} model"}
        for name in _T3_PARAMS:
            row[name] = _param_text(res.parameters.get(name))
        mu, mu_se = _param_stats(res)
        row["mu"] = fmt_value(mu, mu_se) if mu is not None else "—"
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


def _td(text, value=None, se=None, cls: str = "num", *, raw: bool = False) -> str:
    attrs = f' class="{cls}"' if cls else ""
    if value is not None:
        attrs += f' data-value="{_e(_dv(value))}"'
    if se is not None or (value is not None and cls == "num pm"):
        attrs += f' data-se="{_e(_dv(se))}"'
    return f"<td{attrs}>{text if raw else _e(text)}</td>"


def _th_row(content_html: str) -> str:
    return f'<th scope="row">{content_html}</th>'


def _table(tid: str, caption_html: str, head_html: Sequence[str], body: Iterable[str], foot: str = "") -> str:
    ths = "".join(f'<th scope="col">{h}</th>' for h in head_html)
    return (f'<table id="{_e(tid)}"><caption>{caption_html}</caption><thead><tr>{ths}</tr></thead>'
            f"<tbody>{''.join(body)}</tbody>{foot}</table>")


def _png_size(data: bytes) -> tuple[int, int]:
    if data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR":
        return struct.unpack(">II", data[16:24])
    return 0, 0


def _fig_png(fig) -> bytes:
    """Render a figure to PNG bytes in memory (``dpi=140``) and close it."""
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    try:
        fig.savefig(buf, format="png", dpi=_DPI)
    finally:
        plt.close(fig)
    return buf.getvalue()


def _img(fid: str, alt: str, caption_html: str, png: bytes) -> str:
    w, h = _png_size(png)
    b64 = base64.b64encode(png).decode("ascii")
    size = f' width="{w}" height="{h}"' if w and h else ""
    return (f'<figure><img id="{_e(fid)}" class="figure" alt="{_e(alt)}"{size} '
            f'src="data:image/png;base64,{b64}"><figcaption>{caption_html}</figcaption></figure>')


def _missing(fid: str, what: str, why: str) -> str:
    return f'<p class="note-missing" id="{_e(fid)}-missing">{_e(what)} could not be drawn: {_plain_html(why)}</p>'


# ------------------------------------------------------------------------------------------------
# what a fit may carry (read with getattr: older fits do not have these)
# ------------------------------------------------------------------------------------------------
def _get(obj, *names):
    for n in names:
        v = obj.get(n) if isinstance(obj, Mapping) else getattr(obj, n, None)
        if v is not None:
            return v
    return None


def _vector(v) -> np.ndarray | None:
    try:
        a = np.asarray(v, dtype=float).ravel()
    except (TypeError, ValueError):
        return None
    return a if a.size >= 2 else None


def alpha0_profile(res) -> dict | None:
    """The fit's α₀ profile as ``{"alpha0_deg", "objective", "nrmse_percent", "interval_deg"}``, or None.

    Reads ``res.alpha0_profile`` (:class:`bendpam.identify.fitting.Profile`: the objective, on the scale of
    NRMSE², minimised over every other parameter at each α₀; and the reported interval), or a
    mapping with the same keys.  ``nrmse_percent`` is ``100 √objective`` (the NRMSE of the fitted
    curves) when the objective is on that scale, else None; ``interval_deg`` is None when absent.
    """
    p = getattr(res, "alpha0_profile", None)
    if p is None:
        return None
    x, y = _vector(_get(p, "alpha0_deg")), _vector(_get(p, "objective"))
    if x is None or y is None or x.size != y.size or not (np.isfinite(x) & np.isfinite(y)).any():
        return None
    iv = _vector(_get(p, "interval_deg"))
    nrmse = 100.0 * np.sqrt(np.clip(y, 0.0, None)) if np.nanmin(y) >= 0 else None
    return {"alpha0_deg": x, "objective": y, "nrmse_percent": nrmse,
            "interval_deg": tuple(float(v) for v in iv[:2]) if iv is not None and np.isfinite(iv[:2]).all() else None}


def _figure_style():
    from bendpam.present import figures as plots

    style = getattr(plots, "figure_style", None)
    return style() if style is not None else _nullcontext()


class _nullcontext:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def _width_in() -> float:
    from bendpam.present import figures as plots

    return float(getattr(plots, "DOUBLE_COLUMN_IN", 7.2))


def _alpha0_figure(prof: dict, res, label: str):
    import matplotlib.pyplot as plt

    with _figure_style():
        x = prof["alpha0_deg"]
        y = prof["nrmse_percent"] if prof["nrmse_percent"] is not None else prof["objective"]
        fig, ax = plt.subplots(figsize=(0.6 * _width_in(), 2.6))
        ok = np.isfinite(x) & np.isfinite(y)
        order = np.argsort(x[ok])
        ax.plot(x[ok][order], y[ok][order], "o-", ms=3, lw=1.2, color="C0", label="best fit at fixed α₀")
        if prof["interval_deg"] is not None:
            ax.axvspan(*prof["interval_deg"], color="C1", alpha=0.2, lw=0, label="reported interval (±2 SE)")
        p = res.parameters.get("alpha0")
        if p is not None:
            ax.axvline(p.value, color="C3", lw=1.2, label=f"fitted α₀ = {fmt_value(p.value, p.stderr, '°')}")
        ax.set_xlabel("α₀ (°)")
        ax.set_ylabel("NRMSE of the fitted curves (%)" if prof["nrmse_percent"] is not None else "objective")
        ax.set_title(f"Profile of α₀, {label} model")
        ax.legend()
        fig.tight_layout()
    return fig


def prediction_band(res, processed) -> dict | None:
    """Predictions with their uncertainty band inside and beyond the tested pressures, or None.

    Uses :meth:`bendpam.identify.fitting.FitResult.band` where the fit has it: the blocked moment and the
    free-bending curvature from P_start to 1.5 times the
    highest, with ±2 standard errors.  Returns ``{"pressure_kpa", "series": [(quantity, unit,
    value, lower, upper)], "extrapolated"}`` or None when the fit has no band.
    """
    band = getattr(res, "band", None)
    if not callable(band):
        return None
    P = np.asarray(processed.pressures_kpa, dtype=float)
    lo = max(float(res.actuator.P_start_kpa), 0.0) if _finite(res.actuator.P_start_kpa) else 0.0
    grid = np.linspace(lo, 1.5 * float(P.max()), 61)
    series, extrap = [], None
    import warnings as _warnings

    for quantity in ("blocked_moment", "free_curvature"):
        try:
            with _warnings.catch_warnings():
                _warnings.simplefilter("ignore")
                b = band(grid, quantity=quantity)
        except (BendpamError, ValueError, ArithmeticError, TypeError):
            continue
        v, lw, up = (np.asarray(getattr(b, k), dtype=float) for k in ("value", "lower", "upper"))
        if v.shape != grid.shape or not np.isfinite(v).any():
            continue
        series.append((quantity, str(getattr(b, "unit", "")), v, lw, up))
        extrap = np.asarray(getattr(b, "extrapolated", np.zeros(grid.size, bool)), dtype=bool)
    if not series:
        return None
    return {"pressure_kpa": grid, "series": series, "extrapolated": extrap}


_BAND_LABEL = {"blocked_moment": "blocked moment (N·mm)", "free_curvature": "free-bending curvature (1/mm)",
               "moment": "moment (N·mm)"}


def _band_figure(band: dict, processed, label: str):
    import matplotlib.pyplot as plt

    with _figure_style():
        series = band["series"]
        fig, axes = plt.subplots(1, len(series), figsize=(_width_in(), 2.6), squeeze=False)
        P = processed.pressures_kpa
        x = band["pressure_kpa"]
        for ax, (name, _unit, mid, lo, hi) in zip(axes[0], series, strict=True):
            ax.axvspan(P.min(), P.max(), color="0.88", lw=0, label="tested range")
            ok = np.isfinite(lo) & np.isfinite(hi)
            ax.fill_between(x, np.where(ok, lo, np.nan), np.where(ok, hi, np.nan), color="C0", alpha=0.3, lw=0,
                            label="±2 SE band")
            ax.plot(x, mid, "-", color="C0", lw=1.2, label="prediction")
            data = ([r.blocked_moment[0] for r in processed.results] if name == "blocked_moment"
                    else [r.free_curvature[0] for r in processed.results])
            ax.plot(P, data, "o", color="k", ms=3, label="data")
            ax.set_xlabel("pressure (kPa)")
            ax.set_ylabel(_BAND_LABEL.get(name, name.replace("_", " ")))
            ax.legend()
        fig.suptitle(f"{label.capitalize()} model: predictions with their uncertainty band")
        fig.tight_layout()
    return fig


def _loss_figure(processed, hyst: Mapping):
    import matplotlib.pyplot as plt

    with _figure_style():
        fig, ax = plt.subplots(figsize=(0.6 * _width_in(), 2.6))
        P = processed.pressures_kpa
        ax.plot(P, [100 * float(r.energy_loss_ratio) for r in processed.results], "o", color="k", ms=4,
                label="measured")
        for i, (m, res) in enumerate(hyst.items()):
            e = res.hysteresis.energy_loss_ratio
            ax.plot([x.pressure_kpa for x in e], [100 * x.predicted for x in e], "s-" if i == 0 else "^--",
                    ms=3, lw=1.1, color=f"C{i}", label=f"{_MODEL_LABEL.get(m, m)} model with its loop")
        ax.set_xlabel("pressure (kPa)")
        ax.set_ylabel("energy-loss ratio (%)")
        ax.set_ylim(bottom=0)
        ax.set_title("Energy lost per cycle, measured and predicted")
        ax.legend()
        fig.tight_layout()
    return fig


def _fit_notes(res) -> list[str]:
    """Plain-language notes a fit carries: its flags and any identifiability notes (as given)."""
    out: list[str] = []
    for attr in ("flags", "notes", "identifiability"):
        v = getattr(res, attr, None)
        if v is None:
            continue
        items = [v] if isinstance(v, str) else (list(v.values()) if isinstance(v, Mapping) else list(v))
        for it in items:
            s = str(it).strip()
            if s and s not in out:
                out.append(s)
    return out


# ------------------------------------------------------------------------------------------------
# style: screen and print
# ------------------------------------------------------------------------------------------------
_CSS = """
:root{--warn:#b71c1c;--warn-bg:#fdecea;--caution:#8a5a00;--caution-bg:#fff6e0;--ok:#1b5e20;--ok-bg:#edf7ee}
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,Helvetica,Arial,sans-serif;margin:0 auto;
max-width:1280px;padding:1rem 1.5rem 3rem;color:#1a1a1a;line-height:1.45}
h1{font-size:1.6rem;margin-bottom:.2rem}h2{margin-top:2.2rem;border-bottom:1px solid #ccc;padding-bottom:.2rem}
h3{margin-top:1.6rem}.meta{color:#555;font-size:.9rem}
table{border-collapse:collapse;margin:.8rem 0;font-size:.9rem}
caption{text-align:left;font-weight:600;padding:.3rem 0}
th,td{border:1px solid #ccc;padding:.25rem .55rem;vertical-align:top}
th{background:#f2f4f7;text-align:left;font-weight:600}
td.num{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
td.meaning{color:#444;font-size:.85rem}
tfoot td{background:#fafafa;font-style:italic}
figure{margin:1rem 0}img.figure{max-width:100%;height:auto;border:1px solid #e3e3e3}
figcaption{font-size:.85rem;color:#444;margin-top:.3rem}
.warnings{border:2px solid var(--warn);background:var(--warn-bg);border-radius:6px;padding:.6rem 1rem;margin:1rem 0}
.warnings.ok{border-color:var(--ok);background:var(--ok-bg)}
.warnings>h2{margin:.2rem 0 .4rem;border:0;font-size:1.15rem;color:var(--warn)}
.warnings.ok>h2{color:var(--ok)}
.warning{margin:.55rem 0;padding:.35rem .6rem;border-left:4px solid var(--warn);background:#fff}
.warning.caution{border-left-color:#e0a100}
.warning .title{font-weight:700;color:var(--warn)}.warning.caution .title{color:var(--caution)}
.warning p{margin:.15rem 0}
.note-missing{color:var(--warn);background:var(--warn-bg);padding:.4rem .6rem;border-left:3px solid var(--warn)}
ul.flags li,ul.diagnosis li{margin:.2rem 0}
nav ol{columns:2;font-size:.9rem}code{white-space:nowrap;font-size:.9em}
@page{margin:15mm 12mm 16mm}
@media print{
body{max-width:none;padding:0;color:#000;font-size:9.5pt;line-height:1.35}
nav,.screen-only{display:none!important}
a{color:#000;text-decoration:none}
h1{font-size:15pt}h2{font-size:12.5pt;margin-top:1.2rem;break-after:avoid;page-break-after:avoid}
h3{font-size:11pt;break-after:avoid;page-break-after:avoid}
.meta,figcaption,td.meaning{color:#000}
table{font-size:8.5pt;break-inside:avoid;page-break-inside:avoid}
th,td{padding:.12rem .35rem;border-color:#888}
th{background:#eee}
figure,.warning,ul.diagnosis,p.deadband{break-inside:avoid;page-break-inside:avoid}
img.figure{border:0;max-width:100%;max-height:90mm;width:auto;object-fit:contain}
.warnings,.warning,th{-webkit-print-color-adjust:exact;print-color-adjust:exact}
.warning .title{color:#000}
}
"""


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
    fits : model name -> :class:`~bendpam.identify.fitting.FitResult`.
    table2, table3 : the tables' rows as shown (formatted strings).
    figures : ids of the figures embedded.  stresses : where the stress figure was drawn (or None).
    notes : figures that could not be drawn.  version : bendpam's version.  bytes : the page's size.
    progress_shown : whether progress was reported on stderr.
    warnings : the :class:`ReportWarning` shown in the warning box.
    hysteresis : ``{model: FitResult}`` of the fits with a loop model shown in the hysteresis section
        (empty when the tests show no loop).
    failed : ``{model: reason}`` of the models that could not be fitted.
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
    """Raw test files -> processing -> fits -> checks -> ONE self-contained HTML page at ``out_html``.

    Parameters
    ----------
    inputs : a path or a sequence of paths: raw test files, or folders of them (files with the
        suffixes in :data:`RAW_SUFFIXES`, sorted by name).
    actuator : the nominal :class:`~bendpam.physics.actuator.Actuator` (geometry, start values, the values
        of the parameters held fixed).
    out_html : the page to write (atomically: a temporary file beside it, then a rename).
    models : model names to fit (``"energy"``, ``"force_balance"``/``"force-balance"``).
    free : parameters to identify (see :func:`bendpam.identify.fitting.fit`), a sequence or a comma string.
    pressure_kpa : None (each file's metadata or filename), one number (only with one file) or
        one pressure per file in order (kPa).
    fixture : a :class:`~bendpam.physics.fixture.Fixture`, a string ``"d,r,t"`` (mm, L0 from the
        actuator) or None (the paper's fixture with the actuator's L0).
    processing_options : a :class:`~bendpam.lab.processing.ProcessingOptions`, a dict of its
        fields, or None for the defaults.
    progress : report progress on stderr (:class:`bendpam.infra.progress.Progress`: a bar on a terminal,
        a line every few seconds otherwise); False writes nothing.

    Returns
    -------
    a :class:`Report` with ``html`` (Path), ``files`` (input Paths), ``inputs`` (per file: path, dialect,
    pressure_kpa, pressure_source, samples, metadata), ``processed`` (the ProcessedSet), ``summary``
    (``processed.summary()``), ``fits`` ({model: FitResult}), ``table2``/``table3`` (the cell
    texts, see :func:`table2_rows`, :func:`table3_rows`), ``figures`` (ids of the embedded
    images), ``stresses`` (the pressure and curvature of the stress figure, or None), ``notes``
    (figures that could not be drawn), ``warnings`` (see :func:`report_warnings`), ``hysteresis``
    (the loop fit, or None), ``version`` and ``bytes`` (size of the page).
    """
    import bendpam
    from bendpam.identify.fitting import fit as _fit
    from bendpam.identify.fitting import parse_free
    from bendpam.infra.progress import Progress
    from bendpam.lab import read_test
    from bendpam.lab.processing import process_tests

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

    # reading, processing, fits, the type check (2), the loop fit, figures (4, 7/profile/band per model,
    # loss ratios, loops, stresses), writing
    total = len(files) + 1 + len(model_names) + 2 + 1 + (1 + 3 * len(model_names) + 2 + 1) + 1
    notes: list[str] = []
    figures: dict[str, str] = {}  # id -> HTML (figure or note)
    fits: dict = {}
    failed: dict[str, str] = {}
    stresses = None
    with Progress(total, "report", quiet=not progress) as bar:

        def step(what: str) -> None:
            bar.advance(0, description=f"report: {what}")

        tests = []
        for f, p in zip(files, pressures, strict=True):
            step(f"reading {f.name}")
            tests.append(read_test(f, pressure_kpa=p))
            bar.advance()
        step("processing the cycles")
        processed = process_tests(tests, fixture=fx, options=opts)
        bar.advance()
        summary = processed.summary()
        for m in model_names:
            step(f"fitting the {_MODEL_LABEL[m]} model")
            try:
                fits[m] = _fit(processed, actuator, m, free=free_names)
            except (FitError, InputError) as exc:  # these tests cannot be fitted with this actuator
                failed[m] = _plain_text(str(exc).splitlines()[0] if str(exc) else type(exc).__name__)
            bar.advance()
        # the type check costs two quick fits: only when the chosen type does not describe the data
        step("checking the actuator type")
        first = next(iter(fits.values()), None)
        comparison = None
        if first is None or not (_finite(first.metrics.nrmse_cycles)
                                 and first.metrics.nrmse_cycles <= NRMSE_CYCLES_LIMIT):
            comparison = type_comparison(processed, actuator, model_names[0], free_names)
        bar.advance(2)
        metadata = [(t.path.name, dict(getattr(t, "metadata", {}) or {})) for t in tests]
        warnings = report_warnings(processed, actuator, fits, metadata=metadata, comparison=comparison,
                                   failed=failed)
        ratios = [r["energy_loss_ratio"] for r in summary["pressures"] if _finite(r["energy_loss_ratio"])]
        mean_ratio = float(np.mean(ratios)) if ratios else math.nan
        loops = _shows_loops(processed, mean_ratio)
        hyst = {m: r for m, r in fits.items() if getattr(r, "hysteresis", None) is not None}
        separate = None  # a loop fit of its own, when the fits above did not model the loop
        hyst_error = None
        step("fitting the hysteresis loop")
        if loops and not hyst and fits:
            m0 = next(iter(fits))
            try:
                separate = _fit(processed, actuator, m0, free=free_names, hysteresis="pi")
                hyst = {m0: separate}
            except (BendpamError, ValueError, ArithmeticError) as exc:
                hyst_error = _plain_text(str(exc).splitlines()[0] if str(exc) else type(exc).__name__)
        bar.advance()

        def figure(fid: str, what: str, alt: str, caption_html: str, draw):
            step(f"drawing {what}")
            try:
                png = _fig_png(draw())
            except (ValueError, ArithmeticError) as exc:
                msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
                notes.append(f"{what}: {_plain_text(msg)}")
                figures[fid] = _missing(fid, what, msg)
            else:
                figures[fid] = _img(fid, alt, caption_html, png)
            bar.advance()

        from bendpam.present import figures as plots

        who = actuator.name or actuator.kind
        figure("fig-figure4", "Figure 4",
               f"Figure 4: cyclic moment-curvature loops, blocked moment and free-bending curvature against "
               f"pressure for {who}",
               "Figure 4. (a) Filtered cyclic loops at each pressure (dashed: the mean of the branches); (b) blocked "
               "moment against pressure (mean ± SE) with the deadband line; (c) free-bending curvature against "
               "pressure (mean ± SE). Magnitudes.",
               lambda: plots.figure4(processed))
        for m in model_names:
            res = fits.get(m)
            label = _MODEL_LABEL[m]
            if res is None:
                bar.advance(3)
                continue
            loop_txt = " with its friction loop" if getattr(res, "hysteresis", None) is not None else ""
            figure(f"fig-figure7-{m}", f"Figure 7 ({label} model)",
                   f"Figure 7: {label} model fit against the measured moment-curvature curves, blocked "
                   f"moment and free-bending curvature",
                   f"Figure 7, {label} model{loop_txt}. (a) Measured branches (thin), mean curve (markers) and "
                   f"the fitted model (lines); (b) blocked moment; (c) free-bending curvature. NRMSE of the cycles "
                   f"{fmt_pct(res.metrics.nrmse_cycles)} %.",
                   lambda res=res: plots.figure7(processed, res))
            prof = alpha0_profile(res)
            if prof is not None:
                figure(f"fig-alpha0-{m}", f"the α₀ profile ({label} model)",
                       f"Profile of the fit error against the braid angle α₀, {label} model",
                       f"Profile of α₀, {label} model: at each fixed α₀ every other parameter is fitted again. "
                       "A sharp minimum means that the data determine α₀; the shaded band is the reported "
                       "interval (±2 standard errors).",
                       lambda prof=prof, res=res, label=label: _alpha0_figure(prof, res, label))
            else:
                bar.advance()
            band = prediction_band(res, processed)
            if band is not None:
                figure(f"fig-band-{m}", f"the prediction band ({label} model)",
                       f"Predictions of the {label} model with their uncertainty band, inside and beyond the "
                       "tested pressures",
                       f"Predictions of the {label} model with a band of ±2 standard errors from the parameters' "
                       "covariance; the grey span is the tested pressure range: beyond it the predictions are "
                       "extrapolations and the band widens.",
                       lambda band=band, label=label: _band_figure(band, processed, label))
            else:
                bar.advance()
        if hyst:
            figure("fig-hysteresis", "the energy-loss ratios",
                   "Energy-loss ratio per pressure, measured and predicted by the fitted loop model",
                   "Energy-loss ratio (loop area / stored energy) per pressure: measured (markers, mean over the "
                   "cycles) and predicted by the fitted loop model of each model (lines). The fitted loops "
                   "themselves are drawn against the measured branches in Figure 7 (a)"
                   + (" and below." if separate is not None else "."),
                   lambda: _loss_figure(processed, hyst))
        else:
            bar.advance()
        if separate is not None and separate.hysteresis is not None:
            hl = _MODEL_LABEL[separate.model]
            figure("fig-hysteresis-loops", "the hysteresis loops",
                   f"Measured hysteresis loops against the fitted loop model ({hl} model)",
                   f"Hysteresis: (a) measured branches and the fitted loops ({hl} model with a "
                   f"{_LAW_LABEL.get(separate.hysteresis.law, separate.hysteresis.law)} loop); (b) blocked moment; "
                   "(c) free-bending curvature.",
                   lambda: plots.figure7(processed, separate))
        else:
            bar.advance()
        if "force_balance" in fits:
            fb_act = fits["force_balance"].actuator
            top = processed.results[-1]
            k_mag = 0.5 * float(top.free_curvature[0])
            k_signed = (fb_act.bend_sign or 1) * k_mag
            stresses = {"pressure_kpa": top.pressure_kpa, "curvature_per_mm": k_signed}
            kt = fmt_value(k_signed)
            figure("fig-stresses", "the internal stresses",
                   f"Force-balance internal stresses around the cross-section at {top.pressure_kpa:g} kPa and "
                   f"k′ = {kt} 1/mm",
                   f"Force-balance model (fitted actuator): bladder and braid stresses around the cross-section "
                   f"at P = {top.pressure_kpa:g} kPa, the highest tested pressure, and k′ = {kt} 1/mm, "
                   f"half the measured free-bending curvature there (k′ = ±|k|/2, signed by the actuator type).",
                   lambda: plots.plot_internal_stresses(fb_act, top.pressure_kpa, k_signed))
        else:
            bar.advance()

        step(f"writing {out.name}")
        inputs_info = [
            {"path": str(t.path), "dialect": t.dialect, "pressure_kpa": t.pressure_kpa,
             "pressure_source": t.pressure_source, "samples": len(t), "source_units": dict(t.source_units),
             "metadata": dict(getattr(t, "metadata", {}) or {})}
            for t in tests
        ]
        page = _render(
            actuator=actuator, processed=processed, summary=summary, fits=fits, figures=figures,
            inputs_info=inputs_info, fixture=fx, options=opts, free=free_names, stresses=stresses,
            notes=notes, version=bendpam.__version__, warnings=warnings, hyst=hyst, hyst_error=hyst_error,
            separate=separate, loops=loops, mean_ratio=mean_ratio, failed=failed, models=model_names,
        )
        atomic_write_text(out, page)
        bar.advance()
    return Report(
        html=out, files=files, inputs=inputs_info, processed=processed, summary=summary, fits=fits,
        table2=table2_rows(summary), table3=table3_rows(fits),
        figures=[fid for fid, h in figures.items() if "<img " in h], stresses=stresses, notes=notes,
        version=bendpam.__version__, bytes=len(page.encode("utf-8")), progress_shown=bool(progress),
        warnings=warnings, hysteresis=hyst, failed=failed,
    )


def _shows_loops(processed, mean_ratio: float) -> bool:
    """Whether the tests show hysteresis loops: :func:`bendpam.identify.fitting.has_loop` where it exists."""
    try:
        from bendpam.identify.fitting import has_loop
    except ImportError:  # an identification without it
        return _finite(mean_ratio) and mean_ratio > LOOP_THRESHOLD
    return bool(has_loop(processed))


# ------------------------------------------------------------------------------------------------
# the page
# ------------------------------------------------------------------------------------------------
def _warnings_html(warnings: Sequence[ReportWarning]) -> str:
    if not warnings:
        return ('<section class="warnings ok" id="warnings"><h2>No warnings</h2><p>The fits reproduce the tests within '
                f"the limits (NRMSE of the cycles below {fmt_pct(NRMSE_CYCLES_LIMIT)} %), no parameter is at a bound, "
                "no pair is strongly correlated, and the data match the actuator's type and P<sub>start</sub>.</p>"
                "</section>")
    n_w = sum(w.severity == "warning" for w in warnings)
    n_c = len(warnings) - n_w
    head = ", ".join(x for x in (f"{n_w} warning{'s' * (n_w != 1)}" if n_w else "",
                                 f"{n_c} caution{'s' * (n_c != 1)}" if n_c else "") if x)
    items = []
    for w in warnings:
        items.append(
            f'<div class="warning {_e(w.severity)}" data-kind="{_e(w.kind)}"'
            + (f' data-models="{_e(" ".join(w.models))}"' if w.models else "") + ">"
            f'<p class="title">{_plain_html(w.title)}</p><p class="meaning">{_plain_html(w.meaning)}</p>'
            f'<p class="try"><strong>What to try:</strong> {_plain_html(w.action)}</p></div>')
    return f'<section class="warnings" id="warnings"><h2>Check before use: {_e(head)}</h2>{"".join(items)}</section>'


def _render(*, actuator, processed, summary, fits, figures, inputs_info, fixture, options, free, stresses, notes,
            version, warnings, hyst, hyst_error, separate, loops, mean_ratio, failed, models) -> str:
    who = actuator.name or actuator.kind
    now = _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC")
    free_html = ", ".join(symbol(n).html for n in free)
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
      f'models: {_e(", ".join(_MODEL_LABEL[m] for m in models))} · fitted: {free_html}</p></header>')
    a(_warnings_html(warnings))
    nav = [("tests", "Processed cyclic tests (Table 2, Figure 4)"), ("fits", "Model fits (Table 3, Figure 7)")]
    if loops:
        nav.append(("hysteresis", "Hysteresis"))
    nav += [("stresses", "Internal stresses"), ("actuator-section", "Actuator"),
            ("inputs-section", "Input files and settings")]
    a('<nav class="screen-only"><ol>' + "".join(f'<li><a href="#{i}">{_e(t)}</a></li>' for i, t in nav)
      + "</ol></nav>")
    if notes:
        a('<div class="note-missing" id="report-notes"><strong>Figures not drawn:</strong><ul>'
          + "".join(f"<li>{_plain_html(n)}</li>" for n in notes) + "</ul></div>")
    n = 1
    a(_section_tests(n, actuator, summary, figures, mean_ratio))
    n += 1
    a(_section_fits(n, fits, figures, failed))
    if loops:
        n += 1
        a(_section_hysteresis(n, hyst, hyst_error, separate, figures, mean_ratio))
    n += 1
    a(f'<section id="stresses"><h2>{n}. Internal stresses (force-balance model)</h2>')
    if stresses is None:
        a('<p id="stresses-none">The force-balance model was not fitted (or could not be), so its internal stresses '
          "are not shown.</p>")
    else:
        ps, ks = stresses["pressure_kpa"], stresses["curvature_per_mm"]
        a(f"<p>Fitted force-balance actuator at P = {ps:g} kPa and k′ = {_e(fmt_value(ks))} 1/mm (eq 37-48).</p>")
        a(figures.get("fig-stresses", ""))
    a("</section>")
    n += 1
    a(_section_actuator(n, actuator, fits))
    n += 1
    a(_section_inputs(n, inputs_info, fixture, options, free, version))
    a(f'<footer><p class="meta">Generated by {_e(f"bendpam {version}")} on {_e(now)}. '
      "This page is self-contained: no scripts, no external files.</p></footer>")
    a("</body></html>")
    return "\n".join(parts) + "\n"


def _section_tests(n, actuator, summary, figures, mean_ratio) -> str:
    parts = [f'<section id="tests"><h2>{n}. Processed cyclic tests</h2>',
             "<p>Values are magnitudes, as in the paper. Blocked moment: each cycle's maximum moment; free-bending "
             "curvature: each cycle's turning point toward the free state; both mean ± standard error over the "
             "cycles. Energy-loss ratio: loop area / area under the cycle's mean curve (M-θ), mean over the "
             "cycles.</p>"]
    body = []
    for r, txt in zip(summary["pressures"], table2_rows(summary), strict=True):
        body.append(
            "<tr>" + _td(txt["pressure_kpa"], r["pressure_kpa"]) + _td(txt["cycles"], r["cycles"])
            + _td(txt["blocked_moment_nmm"], r["blocked_moment_nmm"], r["blocked_moment_se_nmm"], "num pm")
            + _td(txt["free_curvature_per_mm"], r["free_curvature_per_mm"], r["free_curvature_se_per_mm"], "num pm")
            + _td(txt["energy_loss_percent"], r["energy_loss_ratio"]) + "</tr>"
        )
    foot = ('<tfoot><tr><td colspan="4">Average energy-loss ratio</td>'
            + _td(fmt_pct(mean_ratio), mean_ratio) + "</tr></tfoot>")
    parts.append(_table(
        "table2", "Table 2. Blocked moment, free-bending curvature and energy-loss ratio of the cyclic tests",
        ["P (kPa)", "Cycles", "Blocked moment M<sub>b</sub> (N·mm)", "Free-bending curvature k′ (1/mm)",
         "Energy-loss ratio (%)"], body, foot))
    db, db_se = summary["deadband_kpa"], summary["deadband_se_kpa"]
    parts.append(
        f'<p class="deadband" id="deadband" data-value="{_e(_dv(db))}" data-se="{_e(_dv(db_se))}">Deadband pressure '
        f"(x-intercept of the blocked moment against pressure): <strong>{_e(fmt_value(db, db_se, 'kPa'))}</strong>; "
        f"the actuator's P<sub>start</sub> is {_e(fmt_value(actuator.P_start_kpa, unit='kPa'))}.</p>")
    pnotes = [(r["pressure_kpa"], note) for r in summary["pressures"] for note in r["notes"]]
    if pnotes:
        parts.append('<ul id="processing-notes">'
                     + "".join(f"<li>{_plain_html(f'{p:g} kPa: {t}')}</li>" for p, t in pnotes) + "</ul>")
    parts.append(figures.get("fig-figure4", ""))
    parts.append("</section>")
    return "".join(parts)


def _section_fits(n, fits, figures, failed) -> str:
    parts = [f'<section id="fits"><h2>{n}. Model fits</h2>',
             "<p>Parameters identified from the hysteresis-free mean curves of all pressures at once (section 3.4); "
             "± is the standard error, with the value given to the error's last digit. μ = 2(C<sub>10</sub> + "
             "C<sub>01</sub>) is the bladder's initial shear modulus, usually far better determined than "
             "C<sub>10</sub> and C<sub>01</sub> apart. NRMSE of the loading cycles, blocked moment and "
             "free-bending curvature as in eq 53-55.</p>"]
    body = []
    marked = False
    for (m, res), txt in zip(fits.items(), table3_rows(fits), strict=True):
        cells = [_th_row(_e(txt["model"]))]
        for name in _T3_PARAMS:
            p = res.parameters.get(name)
            marked = marked or (p is not None and _at_bound(p) is not None)
            cells.append(_td(txt[name], p.value if p else None, (p.stderr if p and p.vary else None), "num pm"))
        mu, mu_se = _param_stats(res)
        cells.append(_td(txt["mu"], mu, mu_se, "num pm"))
        mt = res.metrics
        cells += [_td(txt["nrmse_cycles"], mt.nrmse_cycles), _td(txt["nrmse_blocked_moment"], mt.nrmse_blocked_moment),
                  _td(txt["nrmse_free_curvature"], mt.nrmse_free_curvature)]
        body.append(f'<tr data-model="{_e(m)}">' + "".join(cells) + "</tr>")
    foot = ('<tfoot><tr><td colspan="8">* at a bound of its allowed range: the value is set by the bound, not by the '
            "data (see the warnings).</td></tr></tfoot>") if marked else ""
    for m, why in failed.items():
        body.append(f'<tr data-model="{_e(m)}" class="failed">' + _th_row(_e(f"{_MODEL_LABEL.get(m, m)} model"))
                    + f'<td colspan="7">could not be fitted: {_plain_html(why)}</td></tr>')
    parts.append(_table(
        "table3", "Table 3. Fitted parameters and errors of the models",
        ["Model"] + [symbol(x).heading() for x in _T3_PARAMS] + [symbol("mu").heading()]
        + ["NRMSE loading cycles (%)", "NRMSE blocked moment (%)", "NRMSE free-bending curvature (%)"], body, foot))
    for m, res in fits.items():
        parts.append(_fit_detail(m, res, figures))
    parts.append("</section>")
    return "".join(parts)


def _params_table(tid: str, caption: str, params: Mapping) -> str:
    body = []
    for name, p in params.items():
        sym = symbol(name)
        side = _at_bound(p)
        status = "fixed" if not p.vary else (f"fitted, at the {side} bound" if side else "fitted")
        rng = f"{fmt_value(p.min)} to {fmt_value(p.max)}" if _finite(p.min) and _finite(p.max) else "—"
        body.append(
            "<tr>" + _th_row(sym.html) + _td(_plain_html(sym.meaning), None, None, "meaning", raw=True)
            + _td(fmt_value(p.value, p.stderr if p.vary else None) + ("" if not p.vary or _finite(p.stderr)
                                                                         else " ± n/a"),
                  p.value, p.stderr if p.vary else None, "num pm")
            + _td(_e(sym.unit), None, None, "", raw=True) + _td(rng, None, None, "num")
            + _td(fmt_value(p.initial), p.initial) + _td(status, None, None, "") + "</tr>")
    return _table(tid, _e(caption), ["Symbol", "Meaning", "Value", "Unit", "Allowed range", "Start", "Status"], body)


def _fit_detail(m, res, figures) -> str:
    label = _MODEL_LABEL.get(m, m)
    parts = [f'<h3 id="fit-{_e(m)}">{_e(f"{label.capitalize()} model")}</h3>']
    warned = any(f.severity == "warning" for f in _findings(m, res))
    parts.append(f'<ul class="diagnosis" id="diagnosis-{_e(m)}">'
                 + "".join(f"<li>{_plain_html(s)}</li>" for s in _diagnosis(res, warned)) + "</ul>")
    fnotes = _fit_notes(res)
    if fnotes:
        parts.append(f'<p>Notes from the fit:</p><ul class="flags" id="flags-{_e(m)}">'
                     + "".join(f"<li>{_plain_html(f)}</li>" for f in fnotes) + "</ul>")
    else:
        parts.append(f'<p id="flags-{_e(m)}">No notes from the fit.</p>')
    parts.append(_params_table(f"params-{m}", f"Parameters of the {label} model fit", res.parameters))
    if len(res.correlation_names) > 1:
        names = [symbol(x).html for x in res.correlation_names]
        body = []
        for i, nm in enumerate(names):
            body.append("<tr>" + _th_row(nm) + "".join(_td(_corr_text(res.correlation[i, j]), res.correlation[i, j])
                                                       for j in range(len(names))) + "</tr>")
        parts.append(_table(f"correlation-{m}", f"Correlation of the fitted parameters ({_e(label)} model)",
                            ["", *names], body))
    mt = res.metrics
    body = []
    for r in mt.per_pressure:
        body.append(
            "<tr>" + _td(f"{float(r['pressure_kpa']):g}", r["pressure_kpa"])
            + _td(fmt_value(r["rmse_cycle_nmm"]), r["rmse_cycle_nmm"])
            + _td(fmt_value(r["M_max_nmm"]), r["M_max_nmm"])
            + _td(fmt_value(r["blocked_moment_model_nmm"]), r["blocked_moment_model_nmm"])
            + _td(fmt_value(r["K_max_per_mm"]), r["K_max_per_mm"])
            + _td(fmt_value(r["free_curvature_model_per_mm"]) if r["free_curvature_model_per_mm"] is not None
                  else "no equilibrium", r["free_curvature_model_per_mm"]) + "</tr>"
        )
    parts.append(_table(
        f"metrics-{m}",
        _e(f"Per-pressure errors of the {label} model (RMSE of the cycles {fmt_value(mt.rmse_cycles)} N·mm, of the "
           f"blocked moment {fmt_value(mt.rmse_blocked_moment)} N·mm, of the free-bending curvature "
           f"{fmt_value(mt.rmse_free_curvature)} 1/mm)"),
        ["P (kPa)", "RMSE of the cycle (N·mm)", "M<sub>b</sub>, data (N·mm)", "M<sub>b</sub>, model (N·mm)",
         "k′<sub>free</sub>, data (1/mm)", "k′<sub>free</sub>, model (1/mm)"], body))
    for key in (f"fig-alpha0-{m}", f"fig-band-{m}", f"fig-figure7-{m}"):
        parts.append(figures.get(key, ""))
    return "".join(parts)


def _section_hysteresis(n, hyst, hyst_error, separate, figures, mean_ratio) -> str:
    parts = [f'<section id="hysteresis"><h2>{n}. Hysteresis</h2>']
    lead = (f"The tests show hysteresis loops: on average {_e(fmt_pct(mean_ratio))} % of the stored energy is lost "
            "per cycle (friction in the braid and between sleeve and bladder). ")
    if not hyst:
        parts.append(f"<p>{lead}The loop model could not be fitted: "
                     f"{_plain_html(hyst_error or 'no model was fitted')}.</p></section>")
        return "".join(parts)
    laws = sorted({_LAW_LABEL.get(r.hysteresis.law, r.hysteresis.law) for r in hyst.values()})
    how = ("The fits of section 2 include the loop: both branches of every loop were fitted with" if separate is None
           else f"The fits of section 2 used the mean curves; the {_e(_MODEL_LABEL[separate.model])} model was "
           "fitted again to both branches of every loop with")
    parts.append(
        f"<p>{lead}{how} a friction moment M = M<sub>qs</sub> − (a<sub>0</sub> + a<sub>1</sub> P<sub>active</sub>) z, "
        f"where z follows a {_e(' or '.join(laws))} law that saturates over the bending angle θ<sub>h</sub>. "
        "The table compares the energy-loss ratio each fitted loop predicts with the measured one.</p>")
    body = []
    ms = list(hyst)
    for i, r in enumerate(hyst[ms[0]].hysteresis.energy_loss_ratio):
        row = "<tr>" + _td(f"{r.pressure_kpa:g}", r.pressure_kpa) + _td(fmt_pct(r.measured), r.measured)
        for m in ms:
            e = hyst[m].hysteresis.energy_loss_ratio
            pred = e[i].predicted if i < len(e) else math.nan
            row += _td(fmt_pct(pred), pred)
        body.append(row + "</tr>")
    parts.append(_table("hysteresis-loss", "Energy-loss ratio per pressure, measured and predicted by the loop model",
                        ["P (kPa)", "Measured (%)"] + [f"Predicted, {_e(_MODEL_LABEL.get(m, m))} model (%)"
                                                       for m in ms], body))
    for m, res in hyst.items():
        h = res.hysteresis
        label = _MODEL_LABEL.get(m, m)
        parts.append(_params_table(
            f"hysteresis-params-{m}", f"Loop parameters of the {label} model ({_LAW_LABEL.get(h.law, h.law)} law; "
            f"NRMSE of both branches {fmt_pct(h.nrmse_branches)} %)", h.parameters))
    parts.append(figures.get("fig-hysteresis", ""))
    parts.append(figures.get("fig-hysteresis-loops", ""))
    parts.append("</section>")
    return "".join(parts)


def _section_actuator(n, actuator, fits) -> str:
    cols = [("nominal", actuator)] + [(f"fitted, {_MODEL_LABEL[m]}", r.actuator) for m, r in fits.items()]
    dicts = [(c, act.to_dict(), act.derived()) for c, act in cols]
    body = []
    sense = {1: "bends toward the frame", -1: "bends away from the frame", 0: "does not bend"}
    body.append("<tr>" + _th_row("Type") + _td("", None, None, "meaning") + "".join(
        _td(f"{act.kind} ({sense[int(act.bend_sign)]})", None, None, "") for _, act in cols) + "<td></td></tr>")
    for c_key in dicts[0][1]:
        if c_key in ("name", "model"):
            continue
        sym = symbol(c_key)
        body.append("<tr>" + _th_row(sym.html) + _td(_plain_html(sym.meaning), None, None, "meaning", raw=True)
                    + "".join(_td(fmt_value(d[c_key]), d[c_key]) for _, d, _ in dicts)
                    + _td(_e(sym.unit), None, None, "", raw=True) + "</tr>")
    for c_key in dicts[0][2]:
        sym = symbol(c_key)
        body.append('<tr class="derived">' + _th_row(sym.html)
                    + _td(_plain_html(sym.meaning) + " (derived)", None, None, "meaning", raw=True)
                    + "".join(_td(fmt_value(dd[c_key]), dd[c_key]) for _, _, dd in dicts)
                    + _td(_e(sym.unit), None, None, "", raw=True) + "</tr>")
    names = "".join(f"<li>{_e(c)}: {_e(act.name or act.kind)}</li>" for c, act in cols)
    return (f'<section id="actuator-section"><h2>{n}. Actuator</h2><ul class="actuator-names">{names}</ul>'
            + _table("actuator", "Actuator parameters, nominal and fitted",
                     ["Symbol", "Meaning"] + [_e(c) for c, _ in cols] + ["Unit"], body) + "</section>")


def _section_inputs(n, inputs_info, fixture, options, free, version) -> str:
    body = []
    for t in inputs_info:
        units = ", ".join(f"{k}: {v}" for k, v in t["source_units"].items())
        body.append(
            "<tr>" + _td(t["path"], None, None, "") + _td(t["dialect"], None, None, "")
            + _td(f"{t['pressure_kpa']:g}" if _finite(t["pressure_kpa"]) else "—", t["pressure_kpa"])
            + _td(t["pressure_source"] or "—", None, None, "") + _td(str(t["samples"]), t["samples"])
            + _td(units, None, None, "") + "</tr>"
        )
    fx = fixture
    settings = [
        ("fixture d, r, t (mm)", _e(f"{fx.d_mm:g}, {fx.r_mm:g}, {fx.t_mm:g}")),
        ("L<sub>0</sub> for k′ = 2β/L<sub>0</sub> (mm)", _e(f"{fx.L0_mm:g}")),
        ("low-pass cutoff (Hz)",
         "1 Hz (max 40 % of Nyquist)" if options.cutoff_hz is None else _e(f"{options.cutoff_hz:g}")),
        ("filter order", _e(f"{options.filter_order}")),
        ("reversal threshold (fraction of the stroke range)", _e(f"{options.reversal_fraction:g}")),
        ("curvature grid points", _e(f"{options.grid_points}")),
        ("force tare (N)", _e(f"{options.tare_n:g}")),
        ("parameters fitted", ", ".join(symbol(x).html for x in free)),
        ("warning limits", _e(f"NRMSE of the cycles {fmt_pct(NRMSE_CYCLES_LIMIT)} %, of the blocked moment and "
                              f"free-bending curvature {fmt_pct(NRMSE_POINTS_LIMIT)} %; |r| > {CORRELATION_LIMIT:g}; "
                              f"deadband vs P_start: max({DEADBAND_LIMIT_KPA:g} kPa, "
                              f"{100 * DEADBAND_LIMIT_FRACTION:g} %)")),
        ("bendpam version", _e(version)),
    ]
    rows = [f"<tr>{_th_row(k)}<td>{_plain_html(html.unescape(v)) if 'P_start' in v else v}</td></tr>"
            for k, v in settings]
    return (f'<section id="inputs-section"><h2>{n}. Input files and settings</h2>'
            + _table("inputs", "Input files", ["File", "Format", "Pressure (kPa)", "Pressure from", "Samples",
                                               "Units in the file"], body)
            + _table("settings", "Settings", ["Setting", "Value"], rows) + "</section>")
