"""Spreadsheet exports (``.xlsx``, ``.xlsm``, ``.xls``, ``.ods``) as text lines.

Testing-machine software also saves native workbooks (Bluehill, Trapezium, testXpert's Excel
export).  :func:`workbook_sheets` reads every sheet with ``python-calamine`` (the optional extra
``excel``: ``pip install 'bendpam[excel]'``) and turns each row into one tab-separated line with
decimal points, so that the text reader handles workbooks exactly like text exports.  Line
numbers are the sheet's row numbers.
"""

from __future__ import annotations

import datetime as _dt
import math
import os
from dataclasses import dataclass

__all__ = ["EXCEL_EXTRA_HINT", "ExcelUnavailable", "Sheet", "workbook_sheets"]

#: How to install the reader of workbooks.
EXCEL_EXTRA_HINT = "install the optional extra 'excel' (pip install 'bendpam[excel]')"


class ExcelUnavailable(ImportError):
    """``python-calamine`` is not installed (an :class:`ImportError` whose message says how to install it).

    >>> print(ExcelUnavailable(EXCEL_EXTRA_HINT))
    install the optional extra 'excel' (pip install 'bendpam[excel]')
    """


@dataclass(frozen=True)
class Sheet:
    """One sheet of a workbook: its name and its rows as tab-separated lines.

    >>> sheet = Sheet("Probe 1", ["Time\\tLoad", "0.5\\t11.8"])
    >>> sheet.name, sheet.lines[1].split("\\t")
    ('Probe 1', ['0.5', '11.8'])
    """

    name: str
    lines: list[str]


def _cell_text(value: object) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return "TRUE" if value else "FALSE"
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if value.is_integer() and abs(value) < 1e15:
            return str(int(value))
        return repr(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, (_dt.datetime, _dt.date, _dt.time)):
        return value.isoformat()
    if isinstance(value, _dt.timedelta):
        return repr(value.total_seconds())
    text = str(value)
    return " ".join(text.replace("\t", " ").splitlines())


def workbook_sheets(path: str | os.PathLike) -> list[Sheet]:
    """Every sheet of a workbook, each row as one tab-separated text line.

    Parameters
    ----------
    path : str or os.PathLike
        The workbook.

    Returns
    -------
    list of Sheet

    Raises
    ------
    ExcelUnavailable
        If ``python-calamine`` is not installed.
    ValueError
        If the file is not a readable workbook (the message says why).

    Examples
    --------
    A file that is not a workbook is refused (and without ``python-calamine`` every file is,
    with :class:`ExcelUnavailable`):

    >>> import tempfile
    >>> from pathlib import Path
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "notes.xlsx"
    ...     _ = path.write_text("not a workbook")
    ...     try:
    ...         workbook_sheets(path)
    ...     except (ValueError, ExcelUnavailable) as exc:
    ...         refused = exc
    >>> isinstance(refused, (ValueError, ImportError))
    True
    """
    try:
        from python_calamine import CalamineWorkbook
    except ImportError as exc:
        raise ExcelUnavailable(EXCEL_EXTRA_HINT) from exc
    try:
        book = CalamineWorkbook.from_path(os.fspath(path))
        sheets = []
        for name in book.sheet_names:
            rows = book.get_sheet_by_name(name).to_python(skip_empty_area=False)
            lines = ["\t".join(_cell_text(v) for v in row).rstrip("\t") for row in rows]
            sheets.append(Sheet(str(name), lines))
    except Exception as exc:  # calamine raises its own types for broken files
        raise ValueError(" ".join(str(exc).split())[:200] or type(exc).__name__) from None
    return sheets
