"""Atomic output helpers: write to a temporary file in the target folder, then rename.

An interrupted run therefore never leaves a half-written output behind, and an existing file is
replaced in one step (``os.replace`` is atomic on POSIX and Windows for same-volume renames).  The
temporary is named like the temporaries of :mod:`bendpam.infra.outputs`
(``.NAME.bendpam-tmp-<pid>-<random><suffix>``), so that a run that writes the same target under
its lock removes one left by a killed process.
"""

from __future__ import annotations

import contextlib
import math
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

__all__ = ["UMASK", "atomic_path", "atomic_write_bytes", "atomic_write_text", "json_safe"]

#: The process's umask (mkstemp creates files readable by the owner only; outputs get the usual
#: permissions instead).
UMASK = os.umask(0)
os.umask(UMASK)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike, suffix: str | None = None) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success rename it onto ``path``.

    The temporary file keeps ``path``'s suffix (or ``suffix``) so that writers which choose a
    format from the extension (matplotlib, pandas, xarray) still work.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     with atomic_path(Path(d) / "a.csv") as tmp:
    ...         _ = tmp.write_text("x\\n")
    ...     print(sorted(p.name for p in Path(d).iterdir()))
    ['a.csv']
    """
    target = Path(path)
    parent = target.parent if str(target.parent) else Path(".")
    if not parent.is_dir():
        raise FileNotFoundError(f"output folder {str(parent)!r} does not exist (for {str(target)!r})")
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.bendpam-tmp-{os.getpid()}-",
                               suffix=suffix or target.suffix or ".tmp", dir=parent)
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        yield tmp_path
        if tmp_path.exists():
            os.chmod(tmp_path, 0o666 & ~UMASK)
        os.replace(tmp_path, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp_path.unlink()
        raise


def atomic_write_text(path: str | os.PathLike, text: str, encoding: str = "utf-8") -> None:
    """Write ``text`` to ``path`` atomically.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     atomic_write_text(Path(d) / "a.txt", "hello")
    ...     print((Path(d) / "a.txt").read_text())
    hello
    """
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding=encoding)


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     atomic_write_bytes(Path(d) / "a.bin", b"\\x00\\x01")
    ...     print((Path(d) / "a.bin").read_bytes())
    b'\\x00\\x01'
    """
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


def json_safe(obj: Any) -> Any:
    """``obj`` made fit for strict JSON (``json.dumps(..., allow_nan=False)``).

    NumPy scalars become plain Python numbers and NumPy arrays nested lists;
    NaN becomes ``None`` (JSON ``null``: missing) and +-inf the strings ``"inf"`` and ``"-inf"``
    (``float()`` reads them back; docs/formats.md, "JSON"); tuples become
    lists; paths become strings; NumPy mapping keys become plain, non-finite float
    keys strings.  Anything else is returned unchanged (``json.dumps`` decides).

    Examples
    --------
    >>> import numpy as np
    >>> json_safe({"x": np.float64("nan"), "a": np.arange(2), "t": (1, 2.5), "m": -np.inf})
    {'x': None, 'a': [0, 1], 't': [1, 2.5], 'm': '-inf'}
    """
    if isinstance(obj, dict):
        return {_json_key(k): json_safe(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [json_safe(v) for v in obj]
    if isinstance(obj, str | bytes):
        return obj
    if isinstance(obj, os.PathLike):
        return os.fspath(obj)
    if hasattr(obj, "tolist") and getattr(obj, "ndim", 0) > 0:  # arrays, not 0-d
        return json_safe(obj.tolist())
    if hasattr(obj, "item"):  # NumPy scalars and 0-d arrays
        obj = obj.item()
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None if math.isnan(obj) else "inf" if obj > 0 else "-inf"
    return obj


def _json_key(key: Any) -> Any:
    if hasattr(key, "item") and not isinstance(key, str | bytes):
        key = key.item()
    if isinstance(key, float) and not math.isfinite(key):
        return str(key)
    if isinstance(key, os.PathLike):
        return os.fspath(key)
    return key
