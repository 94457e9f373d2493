"""Writers of raw four-point-bending exports in the dialects :func:`read_test` reads.

:func:`write_test` is the inverse of :func:`bendpam.lab.read_test`: reading back what it
wrote gives the same numbers to the printed precision (9 significant digits) and the same
metadata (plus a pressure line when ``pressure_kpa`` is given).  It is meant for fixtures,
converted data sets and tests of the processing code; the files look like real exports::

    csv        # Pressure: 200 kPa            testxpert  $testXpert II ASCII export
               time_s,stroke_mm,force_n                  Druck;200;kPa
               0,0,0.0123                                 Prüfzeit;Standardweg;Standardkraft
                                                          s;mm;N
                                                          0;0;0,0123

    bluehill   "Pressure : 200 kPa"           mts        Pressure,200,kPa
               "Time","Extension","Load"                  Time,Crosshead,Force
               "(s)","(mm)","(N)"                         sec,mm,N
               "0","0","0.0123"                           0,0,0.0123
"""

from __future__ import annotations

import csv
import io
import math
import os

import numpy as np
import pandas as pd

from bendpam.infra.atomic import atomic_write_bytes
from bendpam.lab.channels import FORCE_UNITS
from bendpam.lab.pressure import is_pressure_key
from bendpam.lab.rawtest import COLUMNS, DIALECTS

__all__ = ["write_test"]

_DIGITS = "%.9g"
_FORCE_SPELLING = {"n": "N", "kn": "kN", "mn": "mN", "lbf": "lbf", "dan": "daN", "kgf": "kgf"}
_NAMES = {
    ("csv", "en"): ("time_s", "stroke_mm", "force_{unit}"),
    ("testxpert", "en"): ("Test time", "Standard travel", "Standard force"),
    ("testxpert", "de"): ("Prüfzeit", "Standardweg", "Standardkraft"),
    ("bluehill", "en"): ("Time", "Extension", "Load"),
    ("mts", "en"): ("Time", "Crosshead", "Force"),
}


def _fmt(x: float, decimal: str = ".") -> str:
    s = _DIGITS % x
    return s.replace(".", ",") if decimal == "," else s


def _csv_line(cells: list[str], sep: str, quote_all: bool = False) -> str:
    buf = io.StringIO()
    csv.writer(
        buf,
        delimiter=sep,
        quotechar='"',
        lineterminator="",
        quoting=csv.QUOTE_ALL if quote_all else csv.QUOTE_MINIMAL,
    ).writerow(cells)
    return buf.getvalue()


def _check_metadata(metadata: dict[str, str] | None) -> list[tuple[str, str]]:
    items: list[tuple[str, str]] = []
    for key, value in (metadata or {}).items():
        key, value = str(key), str(value)
        if not key.strip():
            raise ValueError("metadata names must not be empty")
        for what, text in (("name", key), ("value", value)):
            if len(text.splitlines()) > 1 or "\n" in text or "\r" in text:
                raise ValueError(f"metadata {what} {text!r} must not contain a line break")
        if ":" in key or key.lstrip().startswith(("$", "#", '"')):
            raise ValueError(
                f"metadata name {key!r} must not contain ':' or start with '$', '#' or a quote"
            )
        items.append((key.strip(), value.strip()))
    return items


def write_test(
    path: str | os.PathLike,
    data: pd.DataFrame,
    dialect: str = "csv",
    *,
    metadata: dict[str, str] | None = None,
    pressure_kpa: float | None = None,
    language: str = "en",
    force_unit: str = "N",
) -> None:
    """Write a raw test as a testing-machine export, atomically.

    The file is written to a temporary file in the target folder and renamed onto ``path``
    (``os.replace``), so an interrupted write never leaves a partial file.

    Parameters
    ----------
    path : str or os.PathLike
        Output file; its folder must exist.
    data : pandas.DataFrame
        Columns ``time_s`` (s), ``stroke_mm`` (mm) and ``force_n`` (N), finite numbers; other
        columns are ignored.  A :class:`~bendpam.lab.RawTest` is accepted too.
    dialect : {"csv", "testxpert", "bluehill", "mts"}
        Export format to imitate.
    metadata : dict of str to str, optional
        Written as metadata lines in the dialect's style, in order.  Names must not contain
        ``:`` or line breaks.  Surrounding whitespace is not preserved.
    pressure_kpa : float, optional
        Inflation pressure in kPa, written as a metadata line (``Pressure``/``Druck``) that
        :func:`read_test` picks up; it replaces any pressure entry in ``metadata``.
    language : {"en", "de"}
        ``"de"`` writes German testXpert names (``Prüfzeit;Standardweg;Standardkraft``,
        ``Druck``); the other dialects have English names only and ignore it.
    force_unit : str
        Unit the force is written in: ``"N"`` (default), ``"kN"``, ``"mN"`` or ``"lbf"``.

    Raises
    ------
    ValueError
        For an unknown dialect, language or force unit, missing columns, non-finite values or
        unwritable metadata.

    Examples
    --------
    >>> import tempfile
    >>> import pandas as pd
    >>> from pathlib import Path
    >>> data = pd.DataFrame({"time_s": [0.0, 0.05], "stroke_mm": [0.0, 0.027], "force_n": [11.8, 11.71]})
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "be.txt"
    ...     write_test(path, data, "testxpert", pressure_kpa=150.0)
    ...     print(path.read_text(encoding="utf-8"))
    $testXpert II ASCII export
    $written by bendpam
    Pressure;150;kPa
    <BLANKLINE>
    Test time;Standard travel;Standard force
    s;mm;N
    0;0;11,8
    0,05;0,027;11,71
    <BLANKLINE>
    """
    if dialect not in DIALECTS:
        raise ValueError(f"unknown dialect {dialect!r}; expected one of {', '.join(DIALECTS)}")
    if language not in ("en", "de"):
        raise ValueError(f"unknown language {language!r}; expected 'en' or 'de'")
    fkey = str(force_unit).strip().lower()
    if fkey not in _FORCE_SPELLING:
        raise ValueError(f"unknown force unit {force_unit!r}; expected N, kN, mN or lbf")
    arr = _numbers(data, fkey)
    pressure_kpa, items = _metadata_items(metadata, pressure_kpa)
    lang = language if dialect == "testxpert" else "en"
    head, nl, sep, encoding = _header(dialect, lang, _FORCE_SPELLING[fkey], pressure_kpa, items)
    text = nl.join(head) + nl + _rows(arr, dialect, sep, nl)
    try:
        raw = text.encode(encoding)
    except UnicodeEncodeError:  # a metadata value outside cp1252: testXpert also reads UTF-8
        raw = text.encode("utf-8")
    atomic_write_bytes(path, raw)


def _metadata_items(metadata: dict[str, str] | None, pressure_kpa: float | None
                    ) -> tuple[float | None, list[tuple[str, str]]]:  # fmt: skip
    """The pressure (checked finite) and the metadata lines to write (a given pressure replaces theirs)."""
    if pressure_kpa is not None:
        pressure_kpa = float(pressure_kpa)
        if not math.isfinite(pressure_kpa):
            raise ValueError(f"pressure_kpa must be finite, got {pressure_kpa!r}")
    items = _check_metadata(metadata)
    if pressure_kpa is not None:
        items = [(k, v) for k, v in items if not is_pressure_key(k)[0]]
    return pressure_kpa, items


def _rows(arr: np.ndarray, dialect: str, sep: str, nl: str) -> str:
    """The data rows in the dialect's style (quoted cells for Bluehill, decimal comma for testXpert)."""
    decimal = "," if dialect == "testxpert" else "."
    cell = f'"{_DIGITS}"' if dialect == "bluehill" else _DIGITS
    row = sep.join([cell] * 3)
    body = nl.join(map(row.__mod__, map(tuple, arr.tolist())))
    if decimal == ",":
        body = body.replace(".", ",")
    if body:
        body += nl
    return body


def _numbers(data: pd.DataFrame, fkey: str) -> np.ndarray:
    """Time (s), stroke (mm) and force (in the unit ``fkey``) as an (n, 3) array, checked finite."""
    if hasattr(data, "data") and isinstance(data.data, pd.DataFrame):
        data = data.data  # a RawTest
    missing = [c for c in COLUMNS if c not in data.columns]
    if missing:
        raise ValueError(
            f"data has no column(s) {', '.join(missing)}; expected {', '.join(COLUMNS)}"
        )
    arr = data[list(COLUMNS)].to_numpy(dtype=np.float64, copy=True)
    if not np.isfinite(arr).all():
        bad_row = int(np.argwhere(~np.isfinite(arr))[0][0])
        raise ValueError(f"data row {bad_row} has a non-finite value; a readable export needs numbers")
    arr[:, 2] /= FORCE_UNITS[fkey]
    return arr


def _header(dialect: str, lang: str, funit: str, pressure_kpa: float | None, items: list[tuple[str, str]]
            ) -> tuple[list[str], str, str, str]:  # fmt: skip
    """The dialect's header lines (metadata, names, units) and its line end, delimiter and encoding."""
    names = [n.format(unit=funit) for n in _NAMES[(dialect, lang)]]
    units = ["s", "mm", funit]
    head: list[str] = []
    if dialect == "csv":
        nl, sep, encoding = "\n", ",", "utf-8"
        if pressure_kpa is not None:
            head.append(f"# Pressure: {_fmt(pressure_kpa)} kPa")
        head += [f"# {k}: {v}" for k, v in items]
        head.append(_csv_line(names, sep))
    elif dialect == "testxpert":
        nl, sep, encoding = "\r\n", ";", "cp1252"
        head += ["$testXpert II ASCII-Export" if lang == "de" else "$testXpert II ASCII export"]
        head += ["$geschrieben von bendpam" if lang == "de" else "$written by bendpam"]
        if pressure_kpa is not None:
            head.append(_csv_line(["Druck" if lang == "de" else "Pressure",
                                   _fmt(pressure_kpa, ","), "kPa"], sep))  # fmt: skip
        head += [_csv_line([k, v], sep) for k, v in items]
        head += ["", _csv_line(names, sep), _csv_line(units, sep)]
    elif dialect == "bluehill":
        nl, sep, encoding = "\r\n", ",", "utf-8"
        if pressure_kpa is not None:
            head.append(_csv_line([f"Pressure : {_fmt(pressure_kpa)} kPa"], sep, True))
        head += [_csv_line([f"{k} : {v}"], sep, True) for k, v in items]
        head += ["", _csv_line(names, sep, True), _csv_line([f"({u})" for u in units], sep, True)]
    else:  # mts
        nl, sep, encoding = "\r\n", ",", "utf-8"
        if pressure_kpa is not None:
            head.append(_csv_line(["Pressure", _fmt(pressure_kpa), "kPa"], sep))
        head += [_csv_line([k, v], sep) for k, v in items]
        head += ["", _csv_line(names, sep), _csv_line(["sec", "mm", funit], sep)]
    return head, nl, sep, encoding
