"""All-or-nothing output sets: a command's outputs appear together or not at all.

Writing each output file atomically is not enough: a run killed between two files leaves
a new ``curves.nc`` beside an old ``summary.json``, two runs into one folder mix their
outputs, and ``process RAW --out RAW`` writes into its own input.  This module makes the
*set* the unit:

* :class:`OutputSet` -- a command that writes a folder.  Files go to a staging folder
  beside the target; on success a ``manifest.json`` (files, sizes, sha256, inputs,
  version, command line, times) is added and the staging folder replaces the target in
  one atomic step.
* :class:`OutputFile` -- a command whose output is one file (``--out curves.csv``): the
  same guarantees without a manifest.
* :func:`interrupts` -- for the command line's ``main``: SIGINT and SIGTERM raise
  :class:`Interrupted` (exit status 130 / 143) so that the cleanup above runs.

Both context managers take an exclusive ``fcntl.flock`` on ``.<name>.bendpam-lock``
beside the target, so a second run on the same target refuses at once
(:class:`OutputBusy`) or waits up to ``lock_timeout_s``.  Temporaries are named
``.<name>.bendpam-tmp-<pid>-<random>`` (staging folders and temporary files),
``.<name>.bendpam-old-...`` (an old set moved aside, fallback swap only) and
``.<name>.bendpam-del-...`` (an old set being removed).

Cleanup after ``SIGKILL`` (or a power cut) cannot run in the killed process, so every
run cleans the temporaries of its target when it starts, while it holds the lock:
because every writer holds that lock for as long as its temporaries exist, any temporary
found by a lock holder is stale (this holds even when the dead owner's pid has been
reused, which is why the pid in the name is informational only).  A lock file left by a
killed run is harmless (its ``flock`` died with the process); the next run takes it over
and removes it when it finishes.

Reading side: a reader that opens ``target/a`` and later ``target/b`` may still straddle
a replacement, as with any folder; a reader that wants one consistent set checks the
files against ``manifest.json`` (written last, it describes exactly the set it sits in).

POSIX only (``fcntl``); the atomic exchange is Linux-only and other systems use the
fallback described in :meth:`OutputSet.__exit__`.
"""

from __future__ import annotations

import contextlib
import ctypes
import datetime as _dt
import fcntl
import hashlib
import importlib.metadata
import json
import os
import re
import secrets
import shlex
import shutil
import signal
import sys
import tempfile
import threading
import time
from collections.abc import Iterable, Iterator, Sequence
from pathlib import Path, PurePath
from types import FrameType, TracebackType
from typing import Any, Literal

from bendpam.errors import InputError
from bendpam.infra.atomic import UMASK, json_safe

__all__ = [
    "MANIFEST_NAME",
    "Interrupted",
    "OutputBusy",
    "OutputFile",
    "OutputSet",
    "interrupts",
    "json_safe",
    "to_json",
]

#: Name of the manifest that :class:`OutputSet` adds to every set it writes.
MANIFEST_NAME = "manifest.json"
#: Format tag and version recorded in every manifest.
MANIFEST_FORMAT = "bendpam-output-set"
MANIFEST_VERSION = 1

_SIGNALS: tuple[int, ...] = (signal.SIGINT, signal.SIGTERM)
_EXIT_CODES: dict[int, int] = {signal.SIGINT: 130, signal.SIGTERM: 143}
_TEMP_KINDS = ("tmp", "old", "del")
_AT_FDCWD = -100
_RENAME_EXCHANGE = 2


# --------------------------------------------------------------------------------------
# exceptions, JSON
# --------------------------------------------------------------------------------------
class Interrupted(BaseException):
    """The run was stopped by SIGINT (exit status 130) or SIGTERM (143).

    A :class:`BaseException` like :class:`KeyboardInterrupt`, so that ``except
    Exception`` blocks in the library do not swallow it, while ``with`` blocks and
    ``finally`` clauses (the cleanup of :class:`OutputSet` and :class:`OutputFile`)
    still run.

    Parameters
    ----------
    exit_code : int
        The status the process should exit with (128 + signal number by shell
        convention).
    signum : int, optional
        The signal received.
    """

    def __init__(self, exit_code: int = 130, signum: int | None = None) -> None:
        super().__init__(exit_code, signum)
        self.exit_code = exit_code
        self.signum = signum

    def __str__(self) -> str:
        if self.signum is None:
            return "interrupted"
        try:
            name = signal.Signals(self.signum).name
        except ValueError:
            name = f"signal {self.signum}"
        return f"interrupted by {name}"


class OutputBusy(InputError):
    """Another bendpam run holds the lock on the output (one line naming its pid)."""


def to_json(obj: Any, *, indent: int | None = 2) -> str:
    """Strict JSON text of ``obj`` (after :func:`json_safe`), ending in a newline.

    Non-finite floats become ``null``; ``allow_nan=False`` guarantees that no ``NaN`` or
    ``Infinity`` token (which is not JSON) can reach a file.
    """
    return json.dumps(json_safe(obj), indent=indent, allow_nan=False) + "\n"


# --------------------------------------------------------------------------------------
# signals
# --------------------------------------------------------------------------------------
def _in_main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


@contextlib.contextmanager
def interrupts() -> Iterator[None]:
    """Turn SIGINT and SIGTERM into :class:`Interrupted` while the block runs.

    Meant for the command line's ``main``::

        with interrupts():
            try:
                run_command()
            except Interrupted as exc:
                print("bendpam: interrupted; no outputs were changed", file=sys.stderr)
                return exc.exit_code          # 130 for SIGINT (Ctrl-C), 143 for SIGTERM

    SIGTERM (``kill``, a batch scheduler's time limit) would otherwise end the process
    at once, without cleanup; SIGINT would raise :class:`KeyboardInterrupt`, which
    frameworks such as Click turn into exit status 1 (or 0).  With this handler both
    raise :class:`Interrupted` wherever the main thread is, the ``with OutputSet(...)``
    / ``with OutputFile(...)`` blocks remove their temporaries and leave their targets
    as they were, and ``main`` exits with ``exc.exit_code``.  "No outputs were changed"
    refers to the outputs being written when the signal came; sets that were already
    complete stay.  A signal arriving during the final swap of a set (a few system
    calls) is held until the swap is done, so in that case the new set is in place when
    :class:`Interrupted` is raised.

    A signal that is ignored when the block starts (``SIG_IGN``, e.g. SIGINT of a
    background job started by a non-interactive shell) stays ignored.  Only the main
    thread can install signal handlers; elsewhere this does nothing.  The previous
    handlers are restored on exit.
    """
    if not _in_main_thread():
        yield
        return

    def _raise(signum: int, frame: FrameType | None) -> None:
        raise Interrupted(_EXIT_CODES.get(signum, 128 + signum), signum)

    saved: dict[int, Any] = {}
    try:
        for sig in _SIGNALS:
            if signal.getsignal(sig) is not signal.SIG_IGN:
                saved[sig] = signal.signal(sig, _raise)
        yield
    finally:
        for sig, previous in saved.items():
            signal.signal(sig, previous if previous is not None else signal.SIG_DFL)


class _HeldSignals:
    """Hold SIGINT and SIGTERM while a short critical section runs.

    A signal arriving inside the block is recorded instead of handled.  On exit the
    previous handlers are restored and the first recorded signal is delivered to them
    (so an :class:`Interrupted` or :class:`KeyboardInterrupt` is raised, or a default
    SIGTERM ends the process, only once the section is complete) -- or, with
    ``drop=True`` (cleanup that runs because of a first signal), ignored.  Outside the
    main thread this does nothing.
    """

    def __init__(self, *, drop: bool = False) -> None:
        self.drop = drop
        self._saved: dict[int, Any] = {}
        self._pending: list[int] = []
        self._raised: BaseException | None = None

    def _record(self, signum: int, frame: FrameType | None) -> None:
        if signum not in self._pending:
            self._pending.append(signum)

    def __enter__(self) -> _HeldSignals:
        if not _in_main_thread():
            return self
        for sig in _SIGNALS:
            while True:
                try:
                    previous = signal.getsignal(sig)
                    if previous is signal.SIG_IGN:
                        break
                    # signal.signal first runs the handlers of signals that already
                    # arrived; if one of them raises, the new handler is not installed
                    # yet: keep that exception.
                    self._saved[sig] = signal.signal(sig, self._record)
                    break
                except BaseException as exc:
                    if self._raised is None:
                        self._raised = exc
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        late: BaseException | None = None
        for sig, previous in self._saved.items():
            while True:
                try:
                    signal.signal(
                        sig, previous if previous is not None else signal.SIG_DFL
                    )
                    break
                except BaseException as err:  # a signal after an earlier restore
                    late = late or err
        self._saved.clear()
        if self.drop:
            return
        first = self._raised or late
        if first is not None:
            raise first
        if self._pending:
            signal.raise_signal(self._pending[0])  # runs the restored handler now


def _is_interruption(exc: BaseException | None) -> bool:
    return isinstance(exc, Interrupted | KeyboardInterrupt)


# --------------------------------------------------------------------------------------
# file-system helpers
# --------------------------------------------------------------------------------------
def _fsync_dir(path: Path) -> None:
    with contextlib.suppress(OSError):
        fd = os.open(path, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def _fsync_file(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _hash_file(path: Path, *, fsync: bool = False) -> tuple[int, str]:
    """``(size, sha256 hex)`` of a file; optionally flush it to disk on the way."""
    with open(path, "rb") as f:
        digest = hashlib.file_digest(f, "sha256").hexdigest()
        size = os.fstat(f.fileno()).st_size
        if fsync:
            os.fsync(f.fileno())
    return size, digest


def _remove(path: Path) -> None:
    """Remove a file or folder tree, whatever is there; missing is fine."""
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
    except (OSError, AttributeError):  # no such symbol: glibc < 2.28, some other libcs
        return None
    fn.argtypes = [
        ctypes.c_int,
        ctypes.c_char_p,
        ctypes.c_int,
        ctypes.c_char_p,
        ctypes.c_uint,
    ]
    fn.restype = ctypes.c_int
    return fn


_RENAMEAT2: Any = _libc_renameat2()


def _exchange(a: Path, b: Path) -> bool:
    """Swap ``a`` and ``b`` atomically (Linux ``renameat2(RENAME_EXCHANGE)``).

    Returns ``False`` when the exchange is not available here (other OS, no libc symbol,
    kernel without the system call, file system that refuses the flag); both paths are
    then untouched.
    """
    if _RENAMEAT2 is None:
        return False
    src, dst = os.fsencode(a), os.fsencode(b)
    return _RENAMEAT2(_AT_FDCWD, src, _AT_FDCWD, dst, _RENAME_EXCHANGE) == 0


def _temp_name(name: str, kind: str, suffix: str = "") -> str:
    return f".{name}.bendpam-{kind}-{os.getpid()}-{secrets.token_hex(4)}{suffix}"


#: Any bendpam temporary or lock file, of any target (skipped when hashing inputs).
_ANY_TEMP = re.compile(r"\..+\.bendpam-(lock|(" + "|".join(_TEMP_KINDS) + r")-\d+-.*)")


def _temp_pattern(name: str) -> re.Pattern[str]:
    kinds = "|".join(_TEMP_KINDS)
    return re.compile(
        re.escape(f".{name}.bendpam-") + rf"({kinds})-(\d+)-[a-z0-9_]+(\..*)?"
    )


def _stale_temporaries(parent: Path, name: str) -> list[tuple[str, Path]]:
    """``(kind, path)`` of this target's temporaries in ``parent`` (oldest first)."""
    pattern = _temp_pattern(name)
    found: list[tuple[float, str, Path]] = []
    try:
        entries = list(os.scandir(parent))
    except FileNotFoundError:
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


def _as_path(p: str | os.PathLike[str]) -> Path:
    if isinstance(p, str | os.PathLike):
        return Path(p)
    raise TypeError(f"expected a path, got {type(p).__name__}")


def _resolved(p: str | os.PathLike[str]) -> Path:
    return _as_path(p).expanduser().resolve()


def _command_list(command: str | Sequence[str] | None) -> list[str]:
    if command is None:
        return [str(a) for a in sys.argv]
    if isinstance(command, str):
        return shlex.split(command)
    return [str(a) for a in command]


def _bendpam_version() -> str:
    try:
        return importlib.metadata.version("bendpam")
    except importlib.metadata.PackageNotFoundError:
        from bendpam.version import __version__

        return str(__version__)


def _now() -> str:
    return _dt.datetime.now(_dt.UTC).isoformat(timespec="milliseconds")


# --------------------------------------------------------------------------------------
# the lock
# --------------------------------------------------------------------------------------
class _Lock:
    """An exclusive ``flock`` on ``.<name>.bendpam-lock`` beside a target.

    The holder writes its pid into the file (for the refusal message) and removes the
    file when it releases the lock, while still holding it; a waiter that then gets the
    lock on the removed file notices (the path no longer names the file it holds) and
    starts again on a fresh one.
    """

    def __init__(self, target: Path) -> None:
        self.target = target
        self.path = target.parent / f".{target.name}.bendpam-lock"
        self.fd: int | None = None
        self.held = False

    def _holder_pid(self, fd: int) -> str:
        for _ in range(5):
            with contextlib.suppress(OSError):
                text = os.pread(fd, 32, 0).decode("ascii", "replace").strip()
                if text.isdigit():
                    return text
            time.sleep(0.01)
        return "unknown"

    def _busy(self, fd: int, timeout_s: float) -> OutputBusy:
        pid = self._holder_pid(fd)
        waited = f" and did not finish within {timeout_s:g} s" if timeout_s > 0 else ""
        return OutputBusy(
            f"another bendpam run is writing {self.target} (pid {pid}){waited}; "
            "wait for it or choose another folder"
        )

    def _is_current(self, fd: int) -> bool:
        try:
            st_path = os.stat(self.path)
        except FileNotFoundError:
            return False
        st_fd = os.fstat(fd)
        return (st_fd.st_dev, st_fd.st_ino) == (st_path.st_dev, st_path.st_ino)

    def acquire(self, timeout_s: float = 0.0) -> None:
        deadline = time.monotonic() + max(0.0, timeout_s)
        while True:
            with _HeldSignals():  # never lose track of an open lock file
                try:
                    self.fd = os.open(
                        self.path, os.O_RDWR | os.O_CREAT, 0o666 & ~UMASK
                    )
                except OSError as exc:
                    raise InputError(
                        f"cannot create the lock file {str(self.path)!r}: "
                        f"{exc.strerror or exc}"
                    ) from exc
            while True:
                try:
                    fcntl.flock(self.fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                    break
                except BlockingIOError:
                    remaining = deadline - time.monotonic()
                    if remaining <= 0:
                        busy = self._busy(self.fd, timeout_s)
                        self._close()
                        raise busy from None
                    time.sleep(min(0.05, remaining))
            self.held = True
            if self._is_current(self.fd):
                break
            # the previous holder removed this file: start again on a fresh one
            self._close()
        with contextlib.suppress(OSError):
            os.ftruncate(self.fd, 0)
            os.pwrite(self.fd, f"{os.getpid()}\n".encode(), 0)

    def _close(self) -> None:
        fd, self.fd, self.held = self.fd, None, False
        if fd is not None:
            os.close(fd)

    def release(self) -> None:
        """Remove the lock file (if still ours) and release the lock; idempotent."""
        if self.fd is None:
            return
        try:
            if not self.held:
                # we opened the file but never got the lock: take it only if nobody has
                # it, so that a lock file created by this run does not stay behind
                try:
                    fcntl.flock(self.fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                    self.held = True
                except OSError:
                    return
            if self._is_current(self.fd):
                with contextlib.suppress(OSError):
                    os.unlink(self.path)
        finally:
            self._close()


# --------------------------------------------------------------------------------------
# shared machinery
# --------------------------------------------------------------------------------------
class _Output:
    """What :class:`OutputSet` and :class:`OutputFile` share: inputs, lock, state."""

    _kind: Literal["folder", "file"]

    def __init__(
        self,
        target: str | os.PathLike[str],
        *,
        inputs: Iterable[str | os.PathLike[str]] = (),
        command: str | Sequence[str] | None = None,
        lock_timeout_s: float = 0.0,
    ) -> None:
        self._given = _as_path(target)
        self.target: Path = _resolved(target)
        """The absolute target path (symbolic links resolved)."""
        if isinstance(inputs, str | os.PathLike):
            inputs = [inputs]
        self.inputs: list[Path] = [_as_path(p) for p in inputs]
        """The inputs as given."""
        self.command: list[str] = _command_list(command)
        """The command line recorded for the run (``command`` or ``sys.argv``)."""
        self.lock_timeout_s = float(lock_timeout_s)
        self._lock = _Lock(self.target)
        self._state: Literal["new", "open", "done", "failed"] = "new"
        if self.target == Path(self.target.anchor):
            raise InputError(
                f"output {self._kind} {str(self._given)!r} is the file-system root"
            )

    def _prepare(self) -> None:
        """Checks before the lock (inputs, target)."""
        raise NotImplementedError

    def _open(self) -> None:
        """Setup under the lock (stale temporaries, the staging place)."""
        raise NotImplementedError

    def _abort(self, exc: BaseException | None) -> None:
        """Remove what was staged and release the lock."""
        raise NotImplementedError

    def _enter(self) -> Any:
        if self._state != "new":
            raise RuntimeError(f"an {type(self).__name__} can be entered only once")
        self._prepare()
        try:
            self._lock.acquire(self.lock_timeout_s)
            self._open()
        except BaseException as exc:
            self._abort(exc)
            raise
        self._state = "open"
        return self

    def _commit(self) -> None:
        """Move the written output into place."""
        raise NotImplementedError

    def _exit(self, exc: BaseException | None) -> Literal[False]:
        """Commit on success, else clean up; never swallows an exception."""
        if self._state != "open":
            return False
        if exc is not None:
            self._abort(exc)
            return False
        try:
            self._commit()
        except BaseException as err:
            self._abort(err)
            raise
        return False

    def _require_open(self) -> None:
        if self._state != "open":
            raise RuntimeError(
                f"output {self._kind} {str(self.target)!r} is not open for writing "
                "(use it in a with block)"
            )

    def _check_inputs(self) -> list[Path]:
        """The inputs resolved; refuse missing ones."""
        resolved = []
        for given in self.inputs:
            inp = _resolved(given)
            if not inp.exists():
                raise InputError(f"input {str(given)!r} does not exist")
            resolved.append(inp)
        return resolved


# --------------------------------------------------------------------------------------
# OutputSet
# --------------------------------------------------------------------------------------
class OutputSet(_Output):
    """Write a folder of outputs as one unit: the old set or the new set, never a mix.

    ::

        with OutputSet(out_dir, inputs=[raw_dir]) as out:
            out.write_json("summary.json", summary)
            ds.to_netcdf(out.path("curves.nc"))
        # here out_dir holds exactly the files written above plus manifest.json

    Files are written to a staging folder ``.<name>.bendpam-tmp-<pid>-<random>`` beside
    the target (same file system, so the final move is a rename).  On a normal exit
    ``manifest.json`` is added and the staging folder *replaces the target whole*: files
    of the old set that this run did not write are gone afterwards.  On an exception --
    including :class:`KeyboardInterrupt` and :class:`Interrupted` -- the staging folder
    is removed, the target is left exactly as it was and the exception propagates.  See
    the module docstring for the lock and the cleanup of temporaries left by killed
    runs.

    Parameters
    ----------
    target_dir : path
        The output folder.  Its parent folders are created if needed.
    inputs : iterable of paths, optional
        The files and folders the command reads.  The target may not be, or lie inside,
        an input folder, and no input may lie inside the target (it would be replaced);
        every input must exist.  They are listed, with size and sha256, in the manifest
        (folders expanded to their files, hashed when the set is committed).
    command : str or sequence of str, optional
        The command line to record (default ``sys.argv``).
    lock_timeout_s : float, optional
        How long to wait for another run writing the same target; 0 (default) refuses at
        once.
    force : bool, optional
        Replace an existing non-empty target that holds no ``manifest.json``.  Without
        it such a folder (most likely not bendpam's: ``--out ~/Documents``) is refused
        rather than deleted.  Empty folders and earlier bendpam sets are replaced
        without it.

    Raises
    ------
    InputError
        On entering, for the refusals above or a target that is an existing file (one
        line naming the paths).
    OutputBusy
        On entering, when another run holds the target's lock (an :class:`InputError`).

    Attributes
    ----------
    target : Path
        The absolute target folder.
    staging : Path
        The staging folder being written (valid inside the ``with`` block); hand it to
        writers that want a folder.  Every regular file in it at exit is part of the
        set.
    files : list of str
        The names given to :meth:`path` and the ``write_*`` methods, in order.
    manifest : dict or None
        The manifest written, once the set is in place.
    """

    _kind = "folder"

    def __init__(
        self,
        target_dir: str | os.PathLike[str],
        *,
        inputs: Iterable[str | os.PathLike[str]] = (),
        command: str | Sequence[str] | None = None,
        lock_timeout_s: float = 0.0,
        force: bool = False,
    ) -> None:
        super().__init__(
            target_dir, inputs=inputs, command=command, lock_timeout_s=lock_timeout_s
        )
        self.force = force
        self.files: list[str] = []
        self.manifest: dict[str, Any] | None = None
        self._staging: Path | None = None
        self._inputs_resolved: list[Path] = []
        self._started = ""

    # -- entering ----------------------------------------------------------------------
    def _check_target(self) -> None:
        t = self.target
        shown = str(self._given)
        for given, inp in zip(self.inputs, self._inputs_resolved, strict=True):
            if inp.is_dir() and (t == inp or t.is_relative_to(inp)):
                where = "is" if t == inp else "is inside"
                raise InputError(
                    f"output folder {shown!r} {where} the input folder "
                    f"{str(given)!r}; choose another folder"
                )
            if t == inp:
                raise InputError(
                    f"output folder {shown!r} is the input file {str(given)!r}"
                )
            if inp.is_relative_to(t):
                raise InputError(
                    f"input {str(given)!r} is inside the output folder {shown!r}, "
                    "which would be replaced; choose another folder"
                )
        if t.exists() and not t.is_dir():
            raise InputError(f"output folder {shown!r} exists and is not a folder")
        if t.is_dir():
            try:
                cwd = Path.cwd().resolve()
            except OSError:
                cwd = None
            if cwd is not None and (cwd == t or cwd.is_relative_to(t)):
                raise InputError(
                    f"output folder {shown!r} is (or contains) the current folder, "
                    "which would be replaced; run elsewhere or choose another folder"
                )

    def _check_replaceable(self) -> None:
        t = self.target
        if self.force or not t.is_dir() or (t / MANIFEST_NAME).is_file():
            return
        with os.scandir(t) as entries:
            empty = next(entries, None) is None
        if not empty:
            raise InputError(
                f"output folder {str(self._given)!r} exists, is not empty and holds "
                f"no {MANIFEST_NAME} (it was not written by bendpam) and would be "
                "replaced whole; empty it, remove it or choose another folder"
            )

    def _clean_stale(self) -> None:
        """Remove temporaries of killed runs (we hold the lock: none is live)."""
        t = self.target
        for kind, path in _stale_temporaries(t.parent, t.name):
            if kind == "old" and not os.path.lexists(t) and path.is_dir():
                # a fallback swap died between its two renames: restore the old set
                os.rename(path, t)
            else:
                _remove(path)

    def _prepare(self) -> None:
        self._started = _now()
        self._inputs_resolved = self._check_inputs()
        self._check_target()
        try:
            self.target.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise InputError(
                f"cannot create the folder {str(self.target.parent)!r}: "
                f"{exc.strerror or exc}"
            ) from exc

    def _open(self) -> None:
        self._clean_stale()
        self._check_target()  # again, under the lock
        self._check_replaceable()
        with _HeldSignals():
            self._staging = Path(
                tempfile.mkdtemp(
                    prefix=f".{self.target.name}.bendpam-tmp-{os.getpid()}-",
                    dir=self.target.parent,
                )
            )

    def __enter__(self) -> OutputSet:
        return self._enter()

    # -- writing -----------------------------------------------------------------------
    @property
    def staging(self) -> Path:
        """The staging folder (inside the ``with`` block only)."""
        self._require_open()
        assert self._staging is not None
        return self._staging

    def path(self, name: str | os.PathLike[str]) -> Path:
        """The staging path of output ``name`` (recorded; parent folders created).

        ``name`` is relative, may contain subfolders (``"figures/fig4.png"``) and may
        not contain ``..``; ``manifest.json`` is reserved.  Write the file there (any
        writer will do); it is moved into the target with the rest of the set.
        """
        self._require_open()
        rel = self._check_name(name)
        p = self.staging.joinpath(*rel.parts)
        p.parent.mkdir(parents=True, exist_ok=True)
        key = rel.as_posix()
        if key not in self.files:
            self.files.append(key)
        return p

    def _check_name(self, name: str | os.PathLike[str]) -> PurePath:
        text = os.fspath(name)
        if not isinstance(text, str):
            raise TypeError("output names are str or os.PathLike[str]")
        rel = PurePath(text)
        parts = [p for p in rel.parts if p != "."]
        if not text or "\0" in text or rel.is_absolute() or rel.anchor or not parts:
            raise InputError(
                f"output name {text!r} is not a relative file name inside the "
                "output folder"
            )
        if ".." in parts:
            raise InputError(
                f"output name {text!r} contains '..'; names must stay inside the "
                "output folder"
            )
        rel = PurePath(*parts)
        if rel.as_posix() == MANIFEST_NAME:
            raise InputError(
                f"output name {MANIFEST_NAME!r} is reserved for the manifest"
            )
        return rel

    def write_text(
        self, name: str | os.PathLike[str], text: str, *, encoding: str = "utf-8"
    ) -> Path:
        """Write ``text`` to output ``name``; returns the staging path."""
        p = self.path(name)
        p.write_text(text, encoding=encoding)
        return p

    def write_bytes(self, name: str | os.PathLike[str], data: bytes) -> Path:
        """Write ``data`` to output ``name``; returns the staging path."""
        p = self.path(name)
        p.write_bytes(data)
        return p

    def write_json(
        self, name: str | os.PathLike[str], obj: Any, *, indent: int | None = 2
    ) -> Path:
        """Write ``obj`` as strict JSON (see :func:`to_json`; NaN/inf become null)."""
        return self.write_text(name, to_json(obj, indent=indent))

    # -- leaving -----------------------------------------------------------------------
    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> Literal[False]:
        """Commit the set on success, else remove the staging folder; never swallows.

        The commit hashes every file (flushing it to disk), writes ``manifest.json`` and
        moves the set into place.  When the target exists, Linux swaps the two folders
        in one ``renameat2(RENAME_EXCHANGE)`` and then removes the old set.  Where that
        is not available (other systems, old kernels, file systems that refuse the flag)
        the fallback renames the target to ``.<name>.bendpam-old-...``, renames the
        staging folder to the target and removes the old set: between the two renames
        (microseconds) the target does not exist, and if the process is killed right
        there the next run restores the old set.  In neither case can a reader see a
        mixture.
        """
        return self._exit(exc)

    def _abort(self, exc: BaseException | None) -> None:
        with _HeldSignals(drop=_is_interruption(exc)):
            if self._state != "done":  # (a signal held during the swap comes after it)
                self._state = "failed"
            staging, self._staging = self._staging, None
            try:
                if staging is not None:
                    _remove(staging)
            finally:
                self._lock.release()

    def _collect_files(self, staging: Path) -> list[dict[str, Any]]:
        files = []
        for dirpath, dirnames, filenames in os.walk(staging):
            dirnames.sort()
            for fn in sorted(filenames):
                p = Path(dirpath) / fn
                rel = p.relative_to(staging).as_posix()
                if rel == MANIFEST_NAME or not p.is_file():
                    continue
                size, digest = _hash_file(p, fsync=True)
                files.append({"path": rel, "size": size, "sha256": digest})
        return files

    def _collect_inputs(self) -> list[dict[str, Any]]:
        entries: list[dict[str, Any]] = []
        seen: set[Path] = set()
        for inp in self._inputs_resolved:
            if inp.is_dir():
                members: list[Path] = []
                for dirpath, dirnames, filenames in os.walk(inp):
                    dirnames[:] = sorted(
                        d for d in dirnames if not _ANY_TEMP.fullmatch(d)
                    )
                    members.extend(
                        Path(dirpath) / fn
                        for fn in sorted(filenames)
                        if not _ANY_TEMP.fullmatch(fn)
                    )
            else:
                members = [inp]
            for p in members:
                if p in seen or not p.is_file():
                    continue
                seen.add(p)
                size, digest = _hash_file(p)
                entries.append({"path": str(p), "size": size, "sha256": digest})
        return entries

    def _commit(self) -> None:
        staging = self.staging
        manifest: dict[str, Any] = {
            "format": MANIFEST_FORMAT,
            "format_version": MANIFEST_VERSION,
            "bendpam_version": _bendpam_version(),
            "command": self.command,
            "cwd": os.getcwd(),
            "target": str(self.target),
            "started_utc": self._started,
            "finished_utc": "",
            "files": self._collect_files(staging),
            "inputs": self._collect_inputs(),
        }
        manifest["finished_utc"] = _now()
        (staging / MANIFEST_NAME).write_text(to_json(manifest), encoding="utf-8")
        _fsync_file(staging / MANIFEST_NAME)
        for dirpath, _, _ in os.walk(staging, topdown=False):
            _fsync_dir(Path(dirpath))
        try:
            mode = (
                self.target.stat().st_mode & 0o7777
                if self.target.is_dir()
                else 0o777 & ~UMASK
            )
        except OSError:
            mode = 0o777 & ~UMASK
        os.chmod(staging, mode)
        with _HeldSignals():
            self._swap(staging)
            self._state = "done"
            self._staging = None
            self.manifest = manifest
            self._lock.release()

    def _swap(self, staging: Path) -> None:
        target, parent = self.target, self.target.parent
        if not os.path.lexists(target):
            os.rename(staging, target)
        elif _exchange(staging, target):
            _fsync_dir(parent)
            _remove(staging)  # now holds the old set
        else:
            old = parent / _temp_name(target.name, "old")
            os.rename(target, old)
            try:
                os.rename(staging, target)
            except BaseException:
                os.rename(old, target)
                raise
            _fsync_dir(parent)
            trash = parent / _temp_name(target.name, "del")
            os.rename(old, trash)  # a half-removed old set must never be restored
            _remove(trash)
        _fsync_dir(parent)


# --------------------------------------------------------------------------------------
# OutputFile
# --------------------------------------------------------------------------------------
class OutputFile(_Output):
    """Write one output file all-or-nothing, under the same lock as :class:`OutputSet`.

    ::

        with OutputFile(out, inputs=[raw_dir]) as o:
            fig.savefig(o.path)        # a temporary file beside ``out``, same suffix
        # ``out`` is replaced in one os.replace

    The temporary file ``.<name>.bendpam-tmp-<pid>-<random><suffix>`` keeps the target's
    suffix so that writers choosing a format from the extension still work.  On success
    it is flushed and renamed onto the target (keeping the old file's permissions); on
    an exception it is removed, the target is untouched and the exception propagates.
    No manifest is written for a single file (there is no folder to put it in; a sidecar
    file would be a second output that could disagree with the first).

    Parameters
    ----------
    target_path : path
        The output file.  Its folder must exist.
    inputs : iterable of paths, optional
        Files and folders the command reads; the target may not be one of them.
    command : str or sequence of str, optional
        Kept as :attr:`command` for the caller's use (nothing is recorded on disk).
    lock_timeout_s : float, optional
        How long to wait for another run writing the same file; 0 refuses at once.

    Raises
    ------
    InputError
        On entering: the target is an input, an existing folder, or its folder does not
        exist.
    OutputBusy
        On entering, when another run holds the target's lock.
    """

    _kind = "file"

    def __init__(
        self,
        target_path: str | os.PathLike[str],
        *,
        inputs: Iterable[str | os.PathLike[str]] = (),
        command: str | Sequence[str] | None = None,
        lock_timeout_s: float = 0.0,
    ) -> None:
        super().__init__(
            target_path, inputs=inputs, command=command, lock_timeout_s=lock_timeout_s
        )
        self._tmp: Path | None = None

    def _check_target(self, inputs: list[Path]) -> None:
        t = self.target
        shown = str(self._given)
        for given, inp in zip(self.inputs, inputs, strict=True):
            same = t == inp
            if not same and t.exists():
                with contextlib.suppress(OSError):
                    same = os.path.samefile(t, inp)
            if same:
                raise InputError(
                    f"output file {shown!r} is the input {str(given)!r}; "
                    "choose another name"
                )
        if t.is_dir():
            raise InputError(f"output file {shown!r} is an existing folder")
        if not t.parent.is_dir():
            raise InputError(
                f"output folder {str(self._given.parent)!r} does not exist "
                f"(for {shown!r})"
            )

    def _prepare(self) -> None:
        self._check_target(self._check_inputs())

    def _open(self) -> None:
        for _, stale in _stale_temporaries(self.target.parent, self.target.name):
            _remove(stale)
        self._tmp = self.target.parent / _temp_name(self.target.name, "tmp", self.target.suffix)

    def __enter__(self) -> OutputFile:
        return self._enter()

    @property
    def path(self) -> Path:
        """The temporary path to write (it becomes the target on success)."""
        self._require_open()
        assert self._tmp is not None
        return self._tmp

    def write_text(self, text: str, *, encoding: str = "utf-8") -> Path:
        """Write ``text`` to the temporary file; returns its path."""
        self.path.write_text(text, encoding=encoding)
        return self.path

    def write_bytes(self, data: bytes) -> Path:
        """Write ``data`` to the temporary file; returns its path."""
        self.path.write_bytes(data)
        return self.path

    def write_json(self, obj: Any, *, indent: int | None = 2) -> Path:
        """Write ``obj`` as strict JSON (see :func:`to_json`)."""
        return self.write_text(to_json(obj, indent=indent))

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> Literal[False]:
        """Rename the temporary file onto the target on success; otherwise remove it."""
        return self._exit(exc)

    def _commit(self) -> None:
        tmp = self.path
        if not tmp.is_file():
            raise RuntimeError(
                f"nothing was written for {str(self.target)!r} "
                f"(expected a file at {str(tmp)!r})"
            )
        _fsync_file(tmp)
        try:
            mode = self.target.stat().st_mode & 0o7777
        except OSError:
            mode = 0o666 & ~UMASK
        os.chmod(tmp, mode)
        with _HeldSignals():
            os.replace(tmp, self.target)
            _fsync_dir(self.target.parent)
            self._state = "done"
            self._tmp = None
            self._lock.release()

    def _abort(self, exc: BaseException | None) -> None:
        with _HeldSignals(drop=_is_interruption(exc)):
            if self._state != "done":  # (a signal held during the swap comes after it)
                self._state = "failed"
            tmp, self._tmp = self._tmp, None
            try:
                if tmp is not None:
                    _remove(tmp)
            finally:
                self._lock.release()
