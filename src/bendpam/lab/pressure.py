"""Inflation pressures of raw tests: from a value with its unit, a metadata line or a file name.

A raw test carries its pressure in one of three places: the ``pressure_kpa`` option of
:func:`~bendpam.lab.readers.read_test`, a metadata line (``Pressure: 200 kPa``, ``Druck;2;bar``)
or a token in the file name (``be_200kPa.csv``).  :func:`parse_pressure` reads a value with its
unit, :func:`is_pressure_key` recognises a metadata name (in several languages),
:func:`pressure_from_filename` finds a token; every pressure is converted to kPa and checked
against :data:`PRESSURE_RANGE_KPA`.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

import numpy as np

from bendpam.lab.read_error import ReadError, show

__all__ = [
    "PRESSURE_KEYS",
    "PRESSURE_RANGE_KPA",
    "PRESSURE_RANGE_TEXT",
    "PRESSURE_UNITS",
    "is_pressure_key",
    "parse_pressure",
    "pressure_from_filename",
    "pressure_out_of_range",
]

#: Pressure unit (lower case) -> factor to kPa.
PRESSURE_UNITS: dict[str, float] = {
    "kpa": 1.0, "mpa": 1000.0, "hpa": 0.1, "pa": 1e-3,
    "bar": 100.0, "mbar": 0.1, "psi": 6.894757293168361,
    "n/mm2": 1000.0, "n/mm²": 1000.0,
}  # fmt: skip
#: Metadata names (lower case) that carry the inflation pressure.
PRESSURE_KEYS: frozenset[str] = frozenset(
    {
        "pressure", "druck", "inflation pressure", "supply pressure", "test pressure",
        "fülldruck", "versorgungsdruck", "prüfdruck", "luftdruck", "pression", "pressione",
        "presión", "ciśnienie", "压力", "気圧", "空気圧",
    }
)  # fmt: skip
#: Allowed inflation pressures (kPa), inclusive.
PRESSURE_RANGE_KPA: tuple[float, float] = (0.0, 10_000.0)

_FILE_PRESSURE = re.compile(
    r"(?<![\d.,])((?:(?:^|(?<=[\s_=(\[]))-)?\d+(?:[.,]\d+)?)\s?"
    r"(kpa|mpa|hpa|mbar|bar|psi|pa)(?![a-z])",
    re.IGNORECASE,
)
_PRESSURE_VALUE = re.compile(
    r"\s*([+-]?(?:\d+(?:[.,]\d*)?|[.,]\d+)(?:[eE][+-]?\d+)?)\s*([^\d\s].*?)?\s*"
)
_BRACKET_UNIT = re.compile(r"(.*?)\s*[(\[]\s*(.*?)\s*[)\]]")
_SUFFIX_UNIT = re.compile(r"(.+?)_([^\W\d_]+)")


def _pressure_factor(unit: str) -> float | None:
    return PRESSURE_UNITS.get(unit.strip().strip("()[]").strip().lower())


def parse_pressure(value: str | float, unit: str | None = None) -> float:
    """Parse a pressure such as ``'200 kPa'``, ``'0,2 MPa'``, ``'2 bar'`` or ``'29 psi'``.

    Parameters
    ----------
    value : str or float
        A number, optionally followed by its unit.  A decimal comma is accepted.
    unit : str, optional
        Unit of ``value`` when ``value`` carries none (kPa, MPa, bar, mbar, hPa, Pa, psi).

    Returns
    -------
    float
        The pressure in kPa (not range-checked; see :data:`PRESSURE_RANGE_KPA`).

    Raises
    ------
    ReadError
        (a ``ValueError``) if the value is not a finite number, has no unit, or the unit is
        unknown, or ``value`` and ``unit`` name different units.

    Examples
    --------
    >>> parse_pressure("0,2 MPa"), parse_pressure("2 bar"), round(parse_pressure(29, "psi"), 2)
    (200.0, 200.0, 199.95)
    """
    if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool):
        number, text_unit, shown = float(value), "", repr(value)
    else:
        shown = show(str(value))
        m = _PRESSURE_VALUE.fullmatch(str(value))
        if m is None:
            raise ReadError(
                f"pressure {shown} is not a number with a unit; expected e.g. '200 kPa', "
                "'0,2 MPa' or '2 bar'"
            )
        number = float(m.group(1).replace(",", "."))
        text_unit = (m.group(2) or "").strip()
    given = (unit or "").strip()
    if text_unit and given and _pressure_factor(text_unit) != _pressure_factor(given):
        raise ReadError(f"pressure {shown} contradicts its unit {given!r}")
    u = text_unit or given
    if not u:
        raise ReadError(
            f"pressure {shown} has no unit; expected one of kPa, MPa, bar, Pa or psi"
        )
    factor = _pressure_factor(u)
    if factor is None:
        raise ReadError(
            f"unknown pressure unit {show(u)} in {shown}; expected kPa, MPa, bar, mbar, Pa or psi"
        )
    kpa = number * factor
    if not math.isfinite(kpa):
        raise ReadError(f"pressure {shown} is not finite; expected a finite number")
    return kpa


def pressure_out_of_range(kpa: float) -> bool:
    """Is ``kpa`` outside the allowed inflation pressures :data:`PRESSURE_RANGE_KPA`?

    >>> pressure_out_of_range(200.0), pressure_out_of_range(-5.0), pressure_out_of_range(2e4)
    (False, True, True)
    """
    lo, hi = PRESSURE_RANGE_KPA
    return not (lo <= kpa <= hi)


#: What a pressure out of range is refused with (the end of a message).
PRESSURE_RANGE_TEXT = "expected 0 to 10 000 kPa (an inflation pressure)"


def pressure_from_filename(name: str | os.PathLike) -> float | None:
    """Pressure in kPa encoded as a token in a file name, or None.

    Recognises ``200kPa``, ``0.2MPa``, ``2bar``, ``2,5bar``, ``200000Pa``, ``29psi`` (any
    case), also inside other text (``x200kPa_y``); the number must not be glued to a preceding
    digit or decimal mark and the unit must not run on into further letters (``2bars`` is not a
    token).  A minus sign counts only after ``_``, a blank, ``=`` or at the start
    (``be_-50kPa``); ``BE-200kPa`` is 200 kPa.  Only the last path component is looked at; the
    first token wins.  The value is not range-checked (:func:`~bendpam.lab.readers.read_test` refuses a pressure
    outside :data:`PRESSURE_RANGE_KPA`).

    Parameters
    ----------
    name : str or os.PathLike
        File name or path.

    Returns
    -------
    float or None
        Pressure in kPa.

    Examples
    --------
    >>> pressure_from_filename("be-pam_200kPa.csv"), pressure_from_filename("run_2,5bar.txt")
    (200.0, 250.0)
    >>> pressure_from_filename("run.csv") is None
    True
    """
    base = Path(os.fspath(name)).name if str(name) else ""
    for m in _FILE_PRESSURE.finditer(base):
        kpa = float(m.group(1).replace(",", ".")) * PRESSURE_UNITS[m.group(2).lower()]
        if math.isfinite(kpa):
            return kpa
    return None


def is_pressure_key(key: str) -> tuple[bool, str | None]:
    """Is ``key`` a metadata name of the inflation pressure?  Also return its unit.

    Parameters
    ----------
    key : str
        A metadata name as written (``'Pressure (kPa)'``, ``'Druck:'``, ``'pressure_bar'``).

    Returns
    -------
    (bool, str or None)
        Whether the name is one of :data:`PRESSURE_KEYS` (case and blanks ignored), and the
        unit the name carries, if any.

    Examples
    --------
    >>> is_pressure_key("Pressure (kPa)"), is_pressure_key("Druck"), is_pressure_key("Max pressure")
    ((True, 'kPa'), (True, None), (False, None))
    """
    k = key.strip().rstrip(":").strip()
    unit = None
    m = _BRACKET_UNIT.fullmatch(k)
    if m and m.group(2):
        k, unit = m.group(1), m.group(2)
    else:
        m = _SUFFIX_UNIT.fullmatch(k)
        if m and m.group(2).lower() in PRESSURE_UNITS:
            k, unit = m.group(1), m.group(2)
    k = " ".join(k.replace("_", " ").split()).lower()
    return k in PRESSURE_KEYS, unit
