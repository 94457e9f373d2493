"""The report's words and numbers: one number format, symbols with units, code names in plain words.

Numbers are written by one function, :func:`fmt_value`: a value with a standard error shows the
error to two significant digits and the value to the same decimal place (``69.735 ± 0.012``); a
value without one has four significant digits; below 10^-3 and from 10^5 up a common power of ten
is factored out (``(2.676 00 ± 0.000 38) × 10⁻⁴``), and long digit runs are grouped in threes.
Parameters appear by their symbols with units (α₀ (°), C₁₀ (kPa), P_start (kPa) ...;
:data:`SYMBOLS`), never by their names in the code: :func:`plain_html` and :func:`plain_text`
replace the code names in text from elsewhere (the fit's notes, error messages).
"""

from __future__ import annotations

import html
import math
import re
from dataclasses import dataclass
from decimal import ROUND_HALF_UP, Decimal

import numpy as np

from bendpam.errors import InputError
from bendpam.identify.diagnose import search_state
from bendpam.identify.ensemble import OFFSET_PARAMETERS, OFFSETS

__all__ = [
    "LAW_LABEL",
    "MODEL_LABEL",
    "SYMBOLS",
    "Symbol",
    "corr_text",
    "describe_status",
    "escape",
    "finite",
    "fmt_pct",
    "fmt_value",
    "law_label",
    "plain_html",
    "plain_text",
    "symbol",
]

#: The models and loop laws by name, as the page writes them.
MODEL_LABEL = {"energy": "energy", "force_balance": "force-balance"}
LAW_LABEL = {"pi": "Prandtl-Ishlinskii", "dahl": "Dahl", "bouc_wen": "Bouc-Wen", "maxwell_slip": "Maxwell-slip",
             "stiction": "breakaway (stiction)",
             "viscous": "viscous (the test's time; else a constant crosshead speed)",
             "viscous_period": "viscous (constant cycle period)",
             "zener": "standard linear solid (a dashpot and a Maxwell branch)",
             "pi_play": "Prandtl-Ishlinskii after a fixture play (backlash)",
             "pi_maxwell": "Prandtl-Ishlinskii and a Maxwell branch",
             "pi_dashpot": "Prandtl-Ishlinskii and a dashpot (Coulomb and viscous damping)",
             "maxwell2": "two Maxwell branches (a two-term Prony series)",
             "dahl_span": "Dahl (angle in proportion to the span)",
             "bouc_wen_span": "Bouc-Wen (angle in proportion to the span)"}


def law_label(law: str) -> str:
    """A loop law's name in words (:data:`LAW_LABEL`), the ensemble's offset members' too
    (:data:`bendpam.identify.ensemble.OFFSETS`).

    >>> law_label("stiction+offset")
    'breakaway (stiction) with a load-cell zero offset'
    >>> law_label("dahl+pressure_offset")
    'Dahl with a force offset in proportion to the pressure'
    >>> law_label("dahl+both_offsets")
    'Dahl with a load-cell zero offset and a force offset in proportion to the pressure'
    """
    for suffix, names in OFFSETS.items():
        if law.endswith(suffix):
            base = law.removesuffix(suffix)
            return f"{LAW_LABEL.get(base, base)} with " + " and ".join(OFFSET_PARAMETERS[n][1] for n in names)
    return LAW_LABEL.get(law, law)


def escape(x) -> str:
    """``x`` as text escaped for HTML (quotes included).

    >>> escape('a < b & "c"')
    'a &lt; b &amp; &quot;c&quot;'
    """
    return html.escape(str(x), quote=True)


def finite(x) -> bool:
    """Whether ``x`` is a finite number (not None, not a bool, not NaN or inf).

    >>> finite(1.5), finite(float("nan")), finite(None), finite("2")
    (True, False, False, True)
    """
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
    if not finite(value):
        return "—"
    if isinstance(sig, bool) or not isinstance(sig, int | np.integer) or sig < 1:
        raise InputError(f"sig = {sig!r}: give a whole number of significant digits >= 1")
    v = float(value)
    s = float(se) if finite(se) and float(se) >= 0 else None
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
    return fmt_value(100.0 * float(ratio), sig=sig) if finite(ratio) else "—"


def corr_text(r) -> str:
    """A correlation with its sign and three decimals (typographic minus), or an em dash.

    >>> corr_text(-0.98765), corr_text(None)
    ('−0.988', '—')
    """
    return f"{float(r):+.3f}".replace("-", _MINUS) if finite(r) else "—"


# ------------------------------------------------------------------------------------------------
# symbols and units
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Symbol:
    """How a quantity is shown: its symbol (plain text and HTML), unit and meaning.

    >>> Symbol("α₀", "α<sub>0</sub>", "°", "braid angle at rest").heading()
    'α<sub>0</sub> (°)'
    """

    text: str
    html: str
    unit: str
    meaning: str

    def heading(self, html_: bool = True) -> str:
        """``"α₀ (°)"``: the symbol with its unit in parentheses (HTML or text)."""
        sym = self.html if html_ else self.text
        return f"{sym} ({escape(self.unit) if html_ else self.unit})" if self.unit else sym


#: Display of every parameter and actuator quantity, by the short names of :mod:`bendpam.identify.result`
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
    "P_max": Symbol("P_max", "P<sub>max</sub>", "kPa", "burst limit: the highest pressure the actuator is "
                    "evaluated at"),
    "P_tested": Symbol("P_tested", "P<sub>tested</sub>", "kPa", "pressures of the tests the actuator was fitted "
                       "on (lowest, highest)"),
    "fit": Symbol("fit", "fit", "", "the fit the actuator comes from (fit.json hash, processed set, date, version)"),
    "shape": Symbol("C₀₁/(C₁₀ + C₀₁)", "C<sub>01</sub>/(C<sub>10</sub> + C<sub>01</sub>)", "",
                    "shape of the bladder's strain energy"),
}
_FIELD_KEY = {
    "alpha0_deg": "alpha0", "R0_mm": "R0", "t0_mm": "t0", "L0_mm": "L0", "frame_thickness_mm": "h_f",
    "frame_width_mm": "w_f", "frame_modulus_mpa": "E_f", "C10_kpa": "C10", "C01_kpa": "C01",
    "P_start_kpa": "P_start", "R0_start_mm": "R0_start", "braid_thickness_mm": "t_br", "t0_start_mm": "t0_start",
    "bladder_area_mm2": "A_bl", "frame_inertia_mm4": "I_f", "frame_stiffness_nmm2": "EI_f",
    "shear_modulus_kpa": "mu", "theta_h_deg": "theta_h", "a0_nmm": "a0", "a1_nmm_per_kpa": "a1",
    "frame_strength_mpa": "sigma_f", "bladder_stretch_limit": "lambda_max", "max_pressure_kpa": "P_max",
    "tested_pressure_kpa": "P_tested", "fit_identity": "fit", "shape": "shape",
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
    return Symbol(words, escape(words), unit, words)


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


def plain_html(text: str) -> str:
    """Escape ``text`` for HTML and show code names (``C10_kpa``, ``alpha0``) by their symbols.

    Spans in backticks (command-line input such as ``--free alpha0,C10``) are shown as code,
    unchanged.

    >>> plain_html("alpha0 >= 54.7 deg; try `--free alpha0`")
    'α<sub>0</sub> ≥ 54.7°; try <code>--free alpha0</code>'
    """
    parts = str(text).split("`")
    return "".join(f"<code>{escape(p)}</code>" if i % 2 else _CODE_RE.sub(lambda m: symbol(m.group(1)).html,
                                                                      escape(_pretty(p)))
                   for i, p in enumerate(parts))


def plain_text(text: str) -> str:
    """``text`` with code names replaced by the symbols' plain-text forms (for a terminal); backtick spans kept
    as they are (without the backticks).

    >>> plain_text("C10_kpa is at a bound; try `--free C10`")
    'C₁₀ is at a bound; try --free C10'
    """
    parts = str(text).split("`")
    return "".join(p if i % 2 else _CODE_RE.sub(lambda m: symbol(m.group(1)).text, _pretty(p))
                   for i, p in enumerate(parts))


# ------------------------------------------------------------------------------------------------
# plain-language diagnostics
# ------------------------------------------------------------------------------------------------
#: What each way a search can end (:func:`bendpam.identify.diagnose.search_state`) means for the fit.
_STATUS = {
    "limit": "The search stopped at its evaluation limit before converging: the values may not be the best fit.",
    "not-converged": "The search did not converge: the values may not be the best fit.",
    "exact": ("Every fitted parameter enters the model linearly, so they were solved exactly; no iterative "
              "search was needed."),
    "gradient": "The fit converged: the error no longer changes with any parameter (a minimum was reached).",
    "ftol": "The fit converged: the error stopped decreasing.",
    "converged": "The fit converged: the parameters stopped changing.",
}


def describe_status(converged: bool, message: str = "") -> str:
    """One plain sentence for the state a search ended in, from its ``converged`` flag and message.

    The optimiser's own text (``"`gtol` termination condition is satisfied."``) is read, never
    shown: it is mapped to what it means for the fit.

    >>> describe_status(True, "`xtol` termination condition is satisfied.")
    'The fit converged: the parameters stopped changing.'
    >>> describe_status(False, "The maximum number of function evaluations is exceeded.")
    'The search stopped at its evaluation limit before converging: the values may not be the best fit.'
    """
    return _STATUS[search_state(converged, message)]
