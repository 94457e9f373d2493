"""The error of the raw-test readers: one line ``FILE:LINE: what was wrong, what was expected``."""

from __future__ import annotations

import os
from pathlib import Path

from bendpam.errors import FileFormatError

__all__ = ["ReadError", "one_line", "show"]


def one_line(text: object) -> str:
    """``text`` as one line: every line break collapsed to a space.

    >>> one_line("unknown unit\\nin line 3")
    'unknown unit in line 3'
    """
    return " ".join(str(text).splitlines()) if text else ""


def show(value: object, limit: int = 40) -> str:
    """``repr`` of a cell value for a message, shortened to about ``limit`` characters.

    >>> show("11,80"), show("x" * 50, limit=10)
    ("'11,80'", "'xxxxxxxxxx...'")
    """
    s = str(value)
    if len(s) > limit:
        s = s[:limit] + "..."
    return repr(s)


class ReadError(FileFormatError):
    """A raw test file that cannot be read.

    ``str(err)`` is one line ``FILE:LINE: what was wrong, what was expected`` (``LINE`` is
    1-based and left out when it does not apply; ``FILE:`` is left out when there is no file).

    Parameters
    ----------
    message : str
        What was wrong and what was expected.
    path : str or os.PathLike, optional
        The file.
    line : int, optional
        1-based line number in the file (the row number for a spreadsheet).
    column : str, optional
        Name of the column (as written in the file) the error is about.

    Attributes
    ----------
    path : pathlib.Path or None
    line : int or None
    column : str or None
    message : str
        The message without the ``FILE:LINE:`` prefix.

    Examples
    --------
    >>> err = ReadError("no header row naming time, stroke and force columns", "x.csv", 3)
    >>> str(err)
    'x.csv:3: no header row naming time, stroke and force columns'
    >>> err.line, err.message
    (3, 'no header row naming time, stroke and force columns')
    """

    def __init__(
        self,
        message: str,
        path: str | os.PathLike | None = None,
        line: int | None = None,
        column: str | None = None,
    ) -> None:
        self.message = one_line(message)
        self.path = Path(path) if path is not None else None
        self.line = int(line) if line is not None else None
        self.column = column
        super().__init__(self._format())

    def _format(self) -> str:
        if self.path is None:
            prefix = f"line {self.line}: " if self.line is not None else ""
        else:
            loc = one_line(os.fspath(self.path))
            prefix = f"{loc}:{self.line}: " if self.line is not None else f"{loc}: "
        return prefix + self.message

    def __str__(self) -> str:
        return self._format()

    def __reduce__(self):  # type: ignore[override]
        return (type(self), (self.message, self.path, self.line, self.column))
