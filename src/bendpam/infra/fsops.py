"""File-system steps of the output sets: names of temporaries, flushing, hashing, the folder swap.

Temporaries beside a target ``NAME`` are named ``.NAME.bendpam-<kind>-<pid>-<random>[suffix]``
with ``kind`` one of ``tmp`` (a staging folder or temporary file), ``old`` (an old version kept
until the run ends) and ``del`` (an old set being removed).  A writer that itself writes through a
temporary beside the path it was given (:func:`bendpam.infra.atomic.atomic_path`) adds one more
leading dot, so :func:`stale_temporaries` finds those too.  A resumable set keeps its staging
folder under the fixed name ``.NAME.bendpam-part`` (:func:`part_name`): it is not stale, the next run
on the target either resumes it or removes it.

The swap of a folder into place (:func:`swap_in`):

* Linux: ``renameat2(RENAME_EXCHANGE)`` swaps the staging folder and the target in one step;
  readers see the old set or the new set.
* elsewhere (macOS, Windows, BSD, old kernels, file systems that refuse the flag): two renames,
  ``target -> .NAME.bendpam-old-...`` then ``staging -> target``.  Between them (microseconds) the
  target does not exist; a run killed right there leaves the complete old set under the ``old``
  name, and the next run on the target puts it back (:func:`restore_or_remove_stale`).  A reader
  therefore sees the complete old set, the complete new set, or (for microseconds) no set -- never
  a mixture.

Nothing here imports a POSIX-only module; ``ctypes`` looks ``renameat2`` up only on Linux.
"""

from __future__ import annotations

import contextlib
import ctypes
import hashlib
import os
import re
import secrets
import shutil
import sys
from pathlib import Path
from typing import Any

__all__ = [
    "ANY_TEMP",
    "TEMP_KINDS",
    "exchange",
    "fsync_dir",
    "fsync_file",
    "hash_file",
    "part_name",
    "remove_path",
    "restore_or_remove_stale",
    "stale_temporaries",
    "swap_back",
    "swap_in",
    "temp_name",
]

#: The kinds of temporaries (see the module docstring).
TEMP_KINDS = ("tmp", "old", "del")
#: Any bendpam temporary or lock file, of any target (skipped when hashing inputs).
ANY_TEMP = re.compile(r"\..+\.bendpam-(lock|part|(" + "|".join(TEMP_KINDS) + r")-\d+-.*)")

_AT_FDCWD = -100
_RENAME_EXCHANGE = 2


def fsync_dir(path: Path) -> None:
    """Flush a folder's entries to disk where the system allows it (not on Windows).

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     fsync_dir(Path(d))
    """
    with contextlib.suppress(OSError):
        fd = os.open(path, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def fsync_file(path: Path) -> None:
    """Flush a file to disk (Windows needs a handle open for writing for that).

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = Path(d) / "a.txt"; _ = p.write_text("a")
    ...     fsync_file(p)
    """
    flags = os.O_RDWR if os.name == "nt" else os.O_RDONLY
    fd = os.open(path, flags | getattr(os, "O_BINARY", 0))
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def hash_file(path: Path, *, fsync: bool = False) -> tuple[int, str]:
    """``(size in bytes, sha256 hex)`` of a file; optionally flush it to disk first.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = Path(d) / "a.txt"; _ = p.write_bytes(b"abc")
    ...     size, digest = hash_file(p)
    >>> size, digest[:12]
    (3, 'ba7816bf8f01')
    """
    if fsync:
        fsync_file(path)
    with open(path, "rb") as f:
        digest = hashlib.file_digest(f, "sha256").hexdigest()
        size = os.fstat(f.fileno()).st_size
    return size, digest


def remove_path(path: Path) -> None:
    """Remove a file, link or folder tree, whatever is there; missing is fine.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     (Path(d) / "x" / "y").mkdir(parents=True)
    ...     remove_path(Path(d) / "x"); remove_path(Path(d) / "missing")
    ...     print(list(Path(d).iterdir()))
    []
    """
    try:
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path, ignore_errors=True)
        else:
            path.unlink()
    except FileNotFoundError:
        pass


def _libc_renameat2() -> Any:
    if not sys.platform.startswith("linux"):
        return None
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        fn = libc.renameat2
    except (OSError, AttributeError, TypeError):  # no such symbol: glibc < 2.28, some other libcs
        return None
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    fn.restype = ctypes.c_int
    return fn


RENAMEAT2: Any = _libc_renameat2()


def exchange(a: Path, b: Path) -> bool:
    """Swap ``a`` and ``b`` atomically (Linux ``renameat2(RENAME_EXCHANGE)``).

    Returns ``False`` when the exchange is not available here (other OS, no libc symbol,
    kernel without the system call, file system that refuses the flag); both paths are
    then untouched.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     a, b = Path(d) / "a", Path(d) / "b"
    ...     a.mkdir(); b.mkdir(); _ = (a / "x").write_text("x")
    ...     swapped = exchange(a, b)
    ...     print(not swapped or (b / "x").exists())
    True
    """
    if RENAMEAT2 is None:
        return False
    return RENAMEAT2(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE) == 0


def temp_name(name: str, kind: str, suffix: str = "") -> str:
    """The name of a temporary of target ``name`` (``kind``: tmp, old or del).

    Examples
    --------
    >>> temp_name("proc", "tmp").startswith(".proc.bendpam-tmp-")
    True
    """
    return f".{name}.bendpam-{kind}-{os.getpid()}-{secrets.token_hex(4)}{suffix}"


def part_name(name: str) -> str:
    """The name of the kept staging folder of a resumable set of target ``name`` (no pid: any later run may resume it).

    Unlike the other temporaries it is not stale when its run died: the next run with the same
    resume key continues it, any other run on the target removes it (both under the target's lock).

    Examples
    --------
    >>> part_name("sweep.zarr")
    '.sweep.zarr.bendpam-part'
    """
    return f".{name}.bendpam-part"


def _temp_pattern(name: str) -> re.Pattern[str]:
    kinds = "|".join(TEMP_KINDS)
    return re.compile(r"\.+" + re.escape(f"{name}.bendpam-") + rf"({kinds})-(\d+)-[a-z0-9_]+(\..*)?")


def stale_temporaries(parent: Path, name: str) -> list[tuple[str, Path]]:
    """``(kind, path)`` of target ``name``'s temporaries in ``parent``, oldest first.

    Includes the temporaries that a writer made beside one of ours (one more leading dot).
    Only a holder of the target's lock may call them stale (see :mod:`bendpam.infra.locks`).

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = (Path(d) / ".fig.png.bendpam-tmp-99-ab12cd34.png").write_text("half")
    ...     _ = (Path(d) / "..fig.png.bendpam-tmp-99-ab12cd34.png.bendpam-tmp-99-0f0f0f0f.png").write_text("")
    ...     print(sorted(kind for kind, _ in stale_temporaries(Path(d), "fig.png")))
    ['tmp', 'tmp']
    """
    pattern = _temp_pattern(name)
    found: list[tuple[float, str, Path]] = []
    try:
        entries = list(os.scandir(parent))
    except (FileNotFoundError, NotADirectoryError):
        return []
    for entry in entries:
        m = pattern.fullmatch(entry.name)
        if m is None:
            continue
        try:
            mtime = entry.stat(follow_symlinks=False).st_mtime
        except FileNotFoundError:
            continue
        found.append((mtime, m.group(1), Path(entry.path)))
    found.sort(key=lambda t: t[0])
    return [(kind, path) for _, kind, path in found]


def restore_or_remove_stale(target: Path) -> None:
    """Clean the temporaries that killed runs left beside ``target`` (call it under the lock).

    An ``old`` folder while the target is missing is a fallback swap that died between its
    two renames: it is the complete old set and is put back.  Everything else is removed.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     old = Path(d) / ".out.bendpam-old-99-ab12cd34"; old.mkdir()
    ...     restore_or_remove_stale(Path(d) / "out")
    ...     print(sorted(p.name for p in Path(d).iterdir()))
    ['out']
    """
    for kind, path in stale_temporaries(target.parent, target.name):
        if kind == "old" and not os.path.lexists(target) and path.is_dir():
            os.rename(path, target)
        else:
            remove_path(path)


def swap_in(staging: Path, target: Path) -> Path | None:
    """Put the folder ``staging`` in place of ``target``; returns where the old target now is.

    ``None`` when there was no target.  The old version is kept (under a temporary name) so
    that :func:`swap_back` can undo the swap; the caller removes it or moves it aside.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     new, out = Path(d) / "new", Path(d) / "out"
    ...     new.mkdir(); out.mkdir(); _ = (new / "n.txt").write_text("n"); _ = (out / "o.txt").write_text("o")
    ...     old = swap_in(new, out)
    ...     print(sorted(p.name for p in out.iterdir()), sorted(p.name for p in old.iterdir()))
    ['n.txt'] ['o.txt']
    """
    parent = target.parent
    if not os.path.lexists(target):
        os.rename(staging, target)
        fsync_dir(parent)
        return None
    if exchange(staging, target):
        fsync_dir(parent)
        return staging  # it now holds the old set
    old = parent / temp_name(target.name, "old")
    os.rename(target, old)
    try:
        os.rename(staging, target)
    except BaseException:
        os.rename(old, target)
        raise
    fsync_dir(parent)
    return old


def swap_back(target: Path, old: Path | None, new_home: Path) -> None:
    """Undo :func:`swap_in`: the old version goes back to ``target``, the new one to ``new_home``.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     new, out = Path(d) / "new", Path(d) / "out"
    ...     new.mkdir(); out.mkdir(); _ = (out / "o.txt").write_text("o")
    ...     old = swap_in(new, out)
    ...     swap_back(out, old, new)
    ...     print(sorted(p.name for p in out.iterdir()))
    ['o.txt']
    """
    if old is None:
        os.rename(target, new_home)
    elif old == new_home and exchange(old, target):
        pass
    else:
        aside = target.parent / temp_name(target.name, "del")
        os.rename(target, aside)
        os.rename(old, target)
        if aside != new_home:
            os.rename(aside, new_home)
    fsync_dir(target.parent)
