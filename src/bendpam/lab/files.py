"""Finding raw test files: folders expand to their exports (known suffixes, sorted)."""

from __future__ import annotations

import os
from pathlib import Path

from bendpam.errors import InputError
from bendpam.infra.budgets import check_input_file

__all__ = ["RAW_SUFFIXES", "collect_raw_files"]

#: File suffixes taken from a folder as raw testing-machine exports.
RAW_SUFFIXES = frozenset({".csv", ".txt", ".tsv", ".dat", ".asc", ".tra", ".xlsx", ".xls", ".zs2", ".zp2"})


def collect_raw_files(inputs) -> list[Path]:
    """Expand folders into their raw test files (known suffixes, sorted); check files exist.

    ``inputs`` is one path or a sequence of paths.  Raises ``ValueError`` (one line) for a missing
    path, a folder without raw files, a file that is not a regular file (a named pipe, a device) or
    is larger than the limit of a raw test file (:mod:`bendpam.infra.budgets`), or no input at all.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     for name in ("be_200kPa.csv", "be_100kPa.TXT", "notes.md"):
    ...         _ = (Path(folder) / name).write_text("")
    ...     found = [path.name for path in collect_raw_files(folder)]
    >>> found
    ['be_100kPa.TXT', 'be_200kPa.csv']
    """
    if isinstance(inputs, str | os.PathLike):
        inputs = [inputs]
    files: list[Path] = []
    for item in inputs or []:
        p = Path(item)
        if p.is_dir():
            found = sorted(q for q in p.iterdir() if q.is_file() and q.suffix.lower() in RAW_SUFFIXES)
            if not found:
                raise InputError(f"{p}: no raw test files here (looked for {', '.join(sorted(RAW_SUFFIXES))})")
            files.extend(found)
        elif p.exists():
            check_input_file(p, "raw test file")  # a named pipe, a device or a file past the size limit
            files.append(p)
        else:
            raise InputError(f"{p}: no such file or folder")
    if not files:
        raise InputError("give raw test files or a folder of them")
    return files
