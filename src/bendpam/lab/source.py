"""The source of a raw test: a file's bytes (or a workbook's sheets, or text) as lines.

:func:`open_source` opens a file: refuses what is not a text export or a workbook (empty
files, what is not a regular file, files past the size limit, binary data), chooses the encoding
(:func:`bendpam.lab.encoding.detect_encoding`) and hands out the lines lazily; a workbook gives
one :class:`Source` per sheet (:mod:`bendpam.lab.excel`), a native Zwick ``.zs2``/``.zp2`` file one
per tested specimen (:mod:`bendpam.lab.zwick`, encoding ``"zs2"``).  :func:`text_source` does the same for
text already in memory.
"""

from __future__ import annotations

import io
import os
import re
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from bendpam.infra.budgets import input_file_problem
from bendpam.lab.encoding import container_kind, detect_encoding
from bendpam.lab.read_error import ReadError
from bendpam.lab.zwick import ZS2_SUFFIXES, zs2_sheets

__all__ = ["Source", "open_source", "text_source"]

_HEAD_BYTES = 1 << 20  # bytes used to choose the encoding


@dataclass
class Source:
    """Lines of one export (or one sheet of a workbook), ready for the parser.

    Attributes
    ----------
    label : pathlib.Path or str
        The file (``"<text>"`` for text in memory), as named in messages.
    encoding : str
        Codec the text is decoded with (``"xlsx"``/``"xls"`` for a workbook, ``"zs2"`` for a
        specimen of a native Zwick file, ``"str"`` for text).
    lines : iterable of str
        The lines, read lazily from the file.
    first_line : str
        The first non-blank line (an MTS 793 export announces itself there).
    is_excel : bool
        A workbook sheet (or a specimen of a native Zwick file, read the same way).
    sheet : str or None
        The sheet's (or the specimen's) name.
    close : callable or None
        Closes the file once the lines are read.

    Examples
    --------
    >>> import io
    >>> text = io.StringIO("time_s,stroke_mm,force_n\\n0,0,11.8\\n")
    >>> source = Source("<text>", "str", text, "time_s,stroke_mm,force_n")
    >>> next(iter(source.lines)).strip(), source.is_excel
    ('time_s,stroke_mm,force_n', False)
    """

    label: Path | str
    encoding: str
    lines: Iterable[str]
    first_line: str
    is_excel: bool = False
    sheet: str | None = None
    close: Any = None


def _read_head(path: Path) -> tuple[bytes, int]:
    problem = input_file_problem(path, "raw test file")  # a named pipe or a device would hang or never end
    if problem is not None and not problem.endswith("not found"):
        raise ReadError(problem, path)
    try:
        size = path.stat().st_size
        if path.is_dir():
            raise IsADirectoryError
        with open(path, "rb") as fh:
            head = fh.read(_HEAD_BYTES)
    except FileNotFoundError:
        raise ReadError("file not found; expected an existing raw test export", path) from None
    except IsADirectoryError:
        raise ReadError("is a directory; expected a raw test export file", path) from None
    except PermissionError:
        raise ReadError("permission denied; cannot read the file", path) from None
    except OSError as exc:
        raise ReadError(f"cannot read the file ({exc.strerror or exc})", path) from None
    return head, size


def _stray_nuls(head: bytes | str) -> bool:
    """A few NUL bytes, each just before a line end (Bose WinTest ends its first line with one): text, not binary."""
    nul = "\x00" if isinstance(head, str) else b"\x00"
    n = head.count(nul)  # type: ignore[arg-type]
    if n == 0 or n > 4:
        return False
    ends = ("\r", "\n") if isinstance(head, str) else (b"\r", b"\n")
    i = head.find(nul)  # type: ignore[arg-type]
    while i >= 0:
        nxt = head[i + 1:i + 2]
        if nxt not in ends:
            return False
        i = head.find(nul, i + 1)  # type: ignore[arg-type]
    return True


def _binary_error(path: Path, head: bytes) -> None:
    nul = head.find(b"\x00")
    if nul >= 0 and not _stray_nuls(head):
        raise ReadError(
            "binary data (NUL byte); expected a text export (CSV/TXT) or an .xlsx/.xls "
            "workbook, not a proprietary test file",
            path,
            head.count(b"\n", 0, nul) + 1,
        )


def _check_text_head(text: str, label: Path | str, whole: bool = True) -> None:
    if "\x00" in text and not _stray_nuls(text[:65536]):
        raise ReadError(
            "binary data (NUL character); expected a text export (CSV/TXT)",
            label,
            text.count("\n", 0, text.index("\x00")) + 1,
        )
    head = text[:65536]
    bad = re.findall(r"[\x01-\x08\x0e-\x19\x1b-\x1f\x7f]", head)
    if len(bad) > max(2, len(head) // 100):
        first = re.search(r"[\x00-\x08\x0e-\x19\x1b-\x1f\x7f]", head)
        assert first is not None
        raise ReadError(
            "binary data (control characters); expected a text export (CSV/TXT)",
            label,
            head.count("\n", 0, first.start()) + 1,
        )
    if not text.strip():
        n = max(1, len(text.splitlines()))
        where = "line 1" if n == 1 else f"lines 1-{n}"
        what = "the whole file" if whole else f"the first {len(text.encode())} bytes"
        raise ReadError(f"{where}: only whitespace in {what}; expected a header row and data rows", label)


def _open_excel(path: Path, kind: str) -> list[tuple[str, list[str]]]:
    from bendpam.lab.excel import EXCEL_EXTRA_HINT, ExcelUnavailable, workbook_sheets

    what = "an .xlsx workbook (ZIP container)" if kind == "zip" else "an .xls workbook (OLE2)"
    try:
        sheets = workbook_sheets(path)
    except ExcelUnavailable:
        raise ReadError(
            f"binary file, {what}: reading workbooks needs python-calamine; "
            f"{EXCEL_EXTRA_HINT}, or export CSV/TXT from the testing software",
            path,
            1,
        ) from None
    except ValueError as exc:
        raise ReadError(
            f"binary data that is not a readable workbook ({exc}); expected a text export "
            "(CSV/TXT) or an .xlsx/.xls workbook",
            path,
            1,
        ) from None
    return [(s.name, s.lines) for s in sheets]


def _open_zs2(path: Path) -> list[Source]:
    """One source per tested specimen of a native Zwick file (:mod:`bendpam.lab.zwick`), named like a sheet."""
    sources = []
    for name, lines in zs2_sheets(path):
        first = getattr(lines, "first", "")  # the 'Specimen' line, without writing the table
        sources.append(Source(path, "zs2", lines, first, is_excel=True, sheet=name))
    return sources


def open_source(path: Path) -> tuple[list[Source], int]:
    """Open an export: its sources (one, or one per workbook sheet) and its size in bytes.

    Parameters
    ----------
    path : pathlib.Path
        The file.

    Returns
    -------
    (list of Source, int)

    Raises
    ------
    ReadError
        For a file that is missing, empty, not a regular file (a directory, a named pipe, a
        device), larger than the limit of a raw test file (2 GiB, :mod:`bendpam.infra.budgets`),
        unreadable or binary, or a native Zwick file whose layout is not recognised.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "be_150kPa.csv"
    ...     _ = path.write_text("time_s,stroke_mm,force_n\\n0,0,11.8\\n", encoding="utf-8")
    ...     (source,), size = open_source(path)
    ...     lines = [line.rstrip() for line in source.lines]
    ...     source.close()
    >>> source.encoding, size, lines
    ('utf-8', 34, ['time_s,stroke_mm,force_n', '0,0,11.8'])
    """
    head, size = _read_head(path)
    if size == 0 or not head:
        raise ReadError("byte 0: the file is empty (0 bytes); expected a header row and data rows", path)
    kind = container_kind(head)
    if path.suffix.lower() in ZS2_SUFFIXES or kind == "gzip":
        return _open_zs2(path), size
    if kind in ("zip", "ole2"):
        sheets = _open_excel(path, kind)
        sources = []
        for name, lines in sheets:
            first = next((ln for ln in lines if ln.strip()), "")
            sources.append(Source(path, "xlsx" if kind == "zip" else "xls", lines, first,
                                   is_excel=True, sheet=name))  # fmt: skip
        if not sources:
            raise ReadError("workbook without sheets; expected a sheet of test data", path, 1)
        return sources, size
    encoding = detect_encoding(head, complete=size <= len(head))
    if not encoding.startswith(("utf-16", "utf-32")):
        _binary_error(path, head)
    try:
        head_text = head.decode(encoding, errors="replace")
    except LookupError:  # pragma: no cover - codecs are fixed
        head_text = head.decode("latin-1")
    _check_text_head(head_text, path, whole=len(head) >= size)
    fh = open(path, encoding=encoding, errors="replace", newline=None)
    first = head_text.lstrip("\ufeff").splitlines()[0] if head_text.strip() else ""
    return [Source(path, encoding, fh, first, close=fh.close)], size



def text_source(path_or_text_lines: Any) -> tuple[list[Source] | None, Path | None]:
    """A path, or text given as a string with line breaks or as lines: ``(sources, None)`` or ``(None, path)``.

    Examples
    --------
    >>> sources, path = text_source("be_150kPa.csv")
    >>> sources is None, path.name
    (True, 'be_150kPa.csv')
    >>> (source,), _ = text_source(["time_s,stroke_mm,force_n", "0,0,11.8"])
    >>> source.label, source.first_line
    ('<text>', 'time_s,stroke_mm,force_n')
    """
    if isinstance(path_or_text_lines, os.PathLike) or (
        isinstance(path_or_text_lines, str) and not re.search(r"[\r\n]", path_or_text_lines)
    ):
        return None, Path(path_or_text_lines)
    if isinstance(path_or_text_lines, str):
        text = path_or_text_lines
    elif isinstance(path_or_text_lines, Iterable):
        text = "\n".join(str(s).rstrip("\r\n") for s in path_or_text_lines)
    else:
        raise TypeError(
            f"expected a path or an iterable of text lines, got {type(path_or_text_lines).__name__}"
        )
    label = "<text>"
    if not text.strip():
        raise ReadError("no text; expected a header row and data rows", label)
    _check_text_head(text, label)
    lines = io.StringIO(text, newline=None)
    first = text.lstrip("\ufeff").splitlines()[0] if text.strip() else ""
    return [Source(label, "str", lines, first)], None
