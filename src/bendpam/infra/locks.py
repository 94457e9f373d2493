"""The lock of an output target: one bendpam run at a time writes a given folder or file.

:class:`TargetLock` takes an exclusive lock on ``.NAME.bendpam-lock`` beside the target ``NAME``.
The holder writes its pid into the file (for the refusal message) and removes the file when it
releases the lock, while still holding it; a waiter that then gets the lock on the removed file
notices (the path no longer names the file it holds) and starts again on a fresh one.

The lock itself is portable:

* through :func:`filelock.lock_descriptor` (``flock`` on POSIX, ``LockFileEx`` on Windows) when
  the ``filelock`` package provides it, else through ``fcntl`` or ``msvcrt``, each imported only
  when it is needed and only where it exists;
* where no native lock exists at all (a system without ``fcntl`` that is not Windows), a *soft*
  lock: the lock file is created exclusively, and a lock file whose pid is no longer running is
  taken over.

A lock file left by a killed run is harmless with a native lock (the lock died with the process)
and is taken over with a soft one; the next run removes it when it finishes.
"""

from __future__ import annotations

import contextlib
import errno
import os
import time
import warnings
from collections.abc import Callable
from pathlib import Path

from bendpam.errors import InputError
from bendpam.infra.atomic import UMASK
from bendpam.infra.signals import HeldSignals, interrupt_behind

__all__ = ["OutputBusy", "TargetLock", "native_locking"]

#: where the holder's pid is written in the lock file (Windows locks byte 0 of it)
_PID_OFFSET = 8
_LockFns = tuple[Callable[[int], bool], Callable[[int], None]]
_NATIVE: list[_LockFns | None] = []
#: lock files held by this process (a second output on the same target in one run)
_HELD: set[Path] = set()


class OutputBusy(InputError):
    """Another bendpam run holds the lock on the output (one line naming its pid).

    Examples
    --------
    >>> issubclass(OutputBusy, InputError)
    True
    """


def _filelock_fns() -> _LockFns | None:
    try:
        with warnings.catch_warnings():  # filelock warns when it has only soft locks
            warnings.simplefilter("ignore")
            from filelock import lock_descriptor, unlock_descriptor
    except Exception as exc:  # a signal during the import comes back wrapped (a dataclass's RuntimeError): raise it
        cause = interrupt_behind(exc)
        if cause is not None:
            raise cause from None
        if isinstance(exc, ImportError):
            return None
        raise

    def lock(fd: int) -> bool:
        return bool(lock_descriptor(fd, blocking=False))

    try:  # is a native lock there (not only filelock's soft fallback)?
        probe = os.open(os.devnull, os.O_RDWR)
        try:
            lock_descriptor(probe, blocking=False)
            unlock_descriptor(probe)
        finally:
            os.close(probe)
    except OSError as exc:
        if exc.errno == errno.ENOSYS:
            return None
    return lock, unlock_descriptor


def _platform_fns() -> _LockFns | None:
    try:
        import fcntl
    except ImportError:
        fcntl = None  # type: ignore[assignment]
    if fcntl is not None:
        def lock(fd: int) -> bool:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as exc:
                if exc.errno in (errno.EAGAIN, errno.EACCES, errno.EWOULDBLOCK):
                    return False
                raise
            return True

        return lock, lambda fd: fcntl.flock(fd, fcntl.LOCK_UN)
    if os.name == "nt":  # pragma: no cover - Windows
        import msvcrt

        def lock_nt(fd: int) -> bool:
            os.lseek(fd, 0, os.SEEK_SET)
            try:
                msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)  # type: ignore[attr-defined]
            except OSError:
                return False
            return True

        def unlock_nt(fd: int) -> None:
            os.lseek(fd, 0, os.SEEK_SET)
            msvcrt.locking(fd, msvcrt.LK_UNLCK, 1)  # type: ignore[attr-defined]

        return lock_nt, unlock_nt
    return None


def native_locking() -> _LockFns | None:
    """``(try_lock(fd) -> bool, unlock(fd))`` of this system, or None when it has none.

    Examples
    --------
    >>> fns = native_locking()
    >>> fns is None or len(fns) == 2
    True
    """
    if not _NATIVE:
        _NATIVE.append(_filelock_fns() or _platform_fns())
    return _NATIVE[0]


def _pid_alive(pid: int) -> bool:
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)  # only reached on POSIX systems (Windows always has a native lock)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True


class TargetLock:
    """An exclusive lock on ``.NAME.bendpam-lock`` beside a target (see the module docstring).

    Parameters
    ----------
    target : Path
        The output folder or file (absolute).

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     lock = TargetLock(Path(d) / "out")
    ...     lock.acquire()
    ...     held = lock.path.exists()
    ...     lock.release()
    ...     print(held, lock.path.exists())
    True False
    """

    def __init__(self, target: Path) -> None:
        self.target = target
        self.path = target.parent / f".{target.name}.bendpam-lock"
        self.fd: int | None = None
        self.held = False
        self.soft = False

    # -- messages ------------------------------------------------------------------------------
    def _read_pid(self, fd: int) -> str:
        with contextlib.suppress(OSError):
            os.lseek(fd, _PID_OFFSET, os.SEEK_SET)
            text = os.read(fd, 32).decode("ascii", "replace").strip()
            if text.isdigit():
                return text
        return "unknown"

    def _holder_pid(self, fd: int) -> str:
        for _ in range(5):
            pid = self._read_pid(fd)
            if pid != "unknown":
                return pid
            time.sleep(0.01)
        return "unknown"

    def _busy(self, pid: str, timeout_s: float) -> OutputBusy:
        if self.path in _HELD:
            return OutputBusy(f"{self.target} is written twice by this run (pid {os.getpid()}); "
                              "give each output its own name")
        waited = f" and did not finish within {timeout_s:g} s" if timeout_s > 0 else ""
        return OutputBusy(f"another bendpam run is writing {self.target} (pid {pid}){waited}; "
                          "wait for it or choose another folder")

    # -- taking and leaving --------------------------------------------------------------------
    def _is_current(self, fd: int) -> bool:
        try:
            st_path = os.stat(self.path)
        except FileNotFoundError:
            return False
        st_fd = os.fstat(fd)
        return (st_fd.st_dev, st_fd.st_ino) == (st_path.st_dev, st_path.st_ino)

    def _open(self, flags: int = 0) -> int:
        with HeldSignals():  # never lose track of an open lock file
            try:
                self.fd = os.open(self.path, os.O_RDWR | os.O_CREAT | flags | getattr(os, "O_BINARY", 0),
                                  0o666 & ~UMASK)
            except FileExistsError:
                raise
            except OSError as exc:
                raise InputError(f"cannot create the lock file {str(self.path)!r}: {exc.strerror or exc}") from exc
        return self.fd

    def _write_pid(self) -> None:
        assert self.fd is not None
        with contextlib.suppress(OSError):
            os.ftruncate(self.fd, 0)
            os.lseek(self.fd, _PID_OFFSET, os.SEEK_SET)
            os.write(self.fd, f"{os.getpid()}\n".encode())

    def acquire(self, timeout_s: float = 0.0) -> None:
        """Take the lock, waiting up to ``timeout_s`` seconds; :class:`OutputBusy` when it stays taken."""
        if self.path in _HELD:
            raise self._busy(str(os.getpid()), 0.0)
        deadline = time.monotonic() + max(0.0, timeout_s)
        fns = native_locking()
        if fns is None:
            self._acquire_soft(deadline, timeout_s)
        else:
            self._acquire_native(fns[0], deadline, timeout_s)
        self._write_pid()
        _HELD.add(self.path)

    def _acquire_native(self, try_lock: Callable[[int], bool], deadline: float, timeout_s: float) -> None:
        while True:
            fd = self._open()
            while not try_lock(fd):
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    busy = self._busy(self._holder_pid(fd), timeout_s)
                    self._close()
                    raise busy
                time.sleep(min(0.05, remaining))
            self.held = True
            if self._is_current(fd):
                return
            self._close()  # the previous holder removed this file: start again on a fresh one

    def _acquire_soft(self, deadline: float, timeout_s: float) -> None:
        self.soft = True
        while True:
            try:
                self._open(os.O_EXCL)
                self.held = True
                return
            except FileExistsError:
                pass
            pid = "unknown"
            with contextlib.suppress(OSError):
                fd = os.open(self.path, os.O_RDONLY)
                try:
                    pid = self._read_pid(fd)
                finally:
                    os.close(fd)
            if pid.isdigit() and not _pid_alive(int(pid)):
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(self.path)  # its holder is gone: take it over
                continue
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise self._busy(pid, timeout_s)
            time.sleep(min(0.05, remaining))

    def _close(self) -> None:
        fd, self.fd, self.held = self.fd, None, False
        _HELD.discard(self.path)
        if fd is not None:
            os.close(fd)

    def release(self) -> None:
        """Remove the lock file (if still ours) and release the lock; idempotent."""
        if self.fd is None:
            return
        try:
            if self.soft:
                if self.held and self._is_current(self.fd):
                    with contextlib.suppress(OSError):
                        os.unlink(self.path)
                return
            fns = native_locking()
            if not self.held and fns is not None:
                # we opened the file but never got the lock: take it only if nobody has it,
                # so that a lock file created by this run does not stay behind
                if not fns[0](self.fd):
                    return
                self.held = True
            if self._is_current(self.fd):
                with contextlib.suppress(OSError):
                    os.unlink(self.path)
        finally:
            self._close()
