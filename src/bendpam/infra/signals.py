"""SIGINT and SIGTERM as an exception, short sections that hold them, and honest words about them.

* :func:`interrupts` turns SIGINT and SIGTERM into :class:`Interrupted` (exit status 130 / 143)
  while a block runs, so that ``with``/``finally`` cleanup runs instead of the process dying.
* :class:`HeldSignals` holds both signals while a few system calls run (the swap of an output set
  into place) and delivers them afterwards.
* :func:`record_written`, :func:`written` and :func:`interrupted_line` keep the list of outputs that
  this process has put in place, so that the line printed for an interruption tells the truth:
  ``interrupted; no outputs were changed`` before the first output was committed,
  ``interrupted after writing DIR`` after it.

Only the standard library is imported, and nothing POSIX-only: on Windows SIGINT (Ctrl-C) and
SIGTERM exist in :mod:`signal` and :func:`signal.raise_signal` works.
"""

from __future__ import annotations

import contextlib
import logging
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from types import FrameType, TracebackType
from typing import Any

__all__ = [
    "EXIT_CODES",
    "HeldSignals",
    "Interrupted",
    "forget_written",
    "interrupt_behind",
    "interrupted_line",
    "interrupts",
    "is_interruption",
    "quiet_logging",
    "raise_pending",
    "record_written",
    "written",
]

#: The signals handled: SIGINT (Ctrl-C) and SIGTERM (``kill``, a batch scheduler's time limit).
SIGNALS: tuple[int, ...] = (signal.SIGINT, signal.SIGTERM)
#: The exit status for each signal (128 + signal number, by shell convention).
EXIT_CODES: dict[int, int] = {int(signal.SIGINT): 130, int(signal.SIGTERM): 143}

_WRITTEN: list[Path] = []


class Interrupted(BaseException):
    """The run was stopped by SIGINT (exit status 130) or SIGTERM (143).

    A :class:`BaseException` like :class:`KeyboardInterrupt`, so that ``except
    Exception`` blocks in the library do not swallow it, while ``with`` blocks and
    ``finally`` clauses (the cleanup of output sets) still run.

    Parameters
    ----------
    exit_code : int
        The status the process should exit with (128 + signal number by shell
        convention).
    signum : int, optional
        The signal received.

    Examples
    --------
    >>> import signal
    >>> exc = Interrupted(143, signal.SIGTERM)
    >>> exc.exit_code, str(exc), isinstance(exc, Exception)
    (143, 'interrupted by SIGTERM', False)
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


def is_interruption(exc: BaseException | None) -> bool:
    """True for :class:`Interrupted` and :class:`KeyboardInterrupt`.

    Examples
    --------
    >>> is_interruption(KeyboardInterrupt()), is_interruption(ValueError("x")), is_interruption(None)
    (True, False, False)
    """
    return isinstance(exc, Interrupted | KeyboardInterrupt)


def interrupt_behind(exc: BaseException) -> BaseException | None:
    """The interrupt (Ctrl-C, SIGTERM) an error was raised from, if any.

    A signal that arrives while a module initialises reaches the caller wrapped: a compiled module's
    (pybind11's, say) as ``ImportError("initialization failed")`` raised *from* the interrupt, a dataclass's
    field being set up as ``RuntimeError("Error calling __set_name__ ...")``.  It is the interrupt still.

    >>> try:
    ...     try:
    ...         raise KeyboardInterrupt
    ...     except KeyboardInterrupt as k:
    ...         raise ImportError("initialization failed") from k
    ... except ImportError as e:
    ...     type(interrupt_behind(e)).__name__, interrupt_behind(ValueError("x"))
    ('KeyboardInterrupt', None)
    """
    seen: set[int] = set()
    e: BaseException | None = exc
    while e is not None and id(e) not in seen:
        if is_interruption(e):
            return e
        seen.add(id(e))
        e = e.__cause__ or e.__context__
    return None


def _in_main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


@contextlib.contextmanager
def interrupts(on_signal: Callable[[int], None] | None = None) -> Iterator[None]:
    """Turn SIGINT and SIGTERM into :class:`Interrupted` while the block runs.

    Meant for a command line's ``main``::

        with interrupts():
            try:
                run_command()
            except Interrupted as exc:
                print(interrupted_line(), file=sys.stderr)
                return exc.exit_code          # 130 for SIGINT (Ctrl-C), 143 for SIGTERM

    SIGTERM would otherwise end the process at once, without cleanup; SIGINT would raise
    :class:`KeyboardInterrupt`, which frameworks such as Click turn into exit status 1 (or
    0).  With this handler both raise :class:`Interrupted` wherever the main thread is,
    the output blocks remove their temporaries and leave their targets as they were.  A
    signal arriving during the final swap of a set is held until the swap is done
    (:class:`HeldSignals`).

    A signal that is ignored when the block starts (``SIG_IGN``, e.g. SIGINT of a
    background job started by a non-interactive shell) stays ignored.  Only the main
    thread can install signal handlers; elsewhere this does nothing.  The previous
    handlers are restored on exit.

    Parameters
    ----------
    on_signal : callable, optional
        Called with the signal number before :class:`Interrupted` is raised (e.g.
        :func:`quiet_logging`, so that the shutdown of worker pools is silent).

    Examples
    --------
    >>> import signal
    >>> try:
    ...     with interrupts():
    ...         signal.raise_signal(signal.SIGTERM)
    ... except Interrupted as exc:
    ...     print(exc.exit_code)
    143
    """
    if not _in_main_thread():
        yield
        return

    def _raise(signum: int, frame: FrameType | None) -> None:
        if on_signal is not None:
            on_signal(signum)
        raise Interrupted(EXIT_CODES.get(signum, 128 + signum), signum)

    saved: dict[int, Any] = {}
    previous_hook = sys.unraisablehook

    def _redeliver(unraisable: Any) -> None:
        # the signal came while a finalizer or weakref callback ran (during garbage collection),
        # where Python prints the exception instead of raising it: keep it, silently, for the next
        # checkpoint (raise_pending: each output's commit, each progress step)
        if isinstance(unraisable.exc_value, Interrupted):
            _PENDING.append(unraisable.exc_value)
            return
        previous_hook(unraisable)

    try:
        for sig in SIGNALS:
            if signal.getsignal(sig) is not signal.SIG_IGN:
                saved[sig] = signal.signal(sig, _raise)
        sys.unraisablehook = _redeliver
        yield
    finally:
        sys.unraisablehook = previous_hook
        for sig, previous in saved.items():
            signal.signal(sig, previous if previous is not None else signal.SIG_DFL)


#: Interruptions Python could not raise (they came inside a finalizer), for :func:`raise_pending`.
_PENDING: list[Interrupted] = []


def raise_pending() -> None:
    """Raise the :class:`Interrupted` of a signal that arrived inside a finalizer, if one did.

    A signal handled while garbage collection runs a finalizer or weakref callback cannot raise
    there (Python would print "Exception ignored" and go on); :func:`interrupts` keeps it and the
    output blocks and progress steps call this, so the run still stops with its one line.

    >>> raise_pending()   # nothing pending: nothing happens
    """
    if _PENDING:
        exc = _PENDING.pop(0)
        _PENDING.clear()
        raise exc


class HeldSignals:
    """Hold SIGINT and SIGTERM while a short critical section runs.

    A signal arriving inside the block is recorded instead of handled.  On exit the
    previous handlers are restored and the first recorded signal is delivered to them
    (so an :class:`Interrupted` or :class:`KeyboardInterrupt` is raised, or a default
    SIGTERM ends the process, only once the section is complete) -- or, with
    ``drop=True`` (cleanup that runs because of a first signal), ignored.  Outside the
    main thread this does nothing.

    Parameters
    ----------
    drop : bool, optional
        Forget the signals that arrive inside the block instead of delivering them.

    Examples
    --------
    >>> import signal
    >>> done = []
    >>> try:
    ...     with interrupts(), HeldSignals():
    ...         signal.raise_signal(signal.SIGINT)
    ...         done.append("the section ran to its end")
    ... except Interrupted as exc:
    ...     print(done, exc.exit_code)
    ['the section ran to its end'] 130
    """

    def __init__(self, *, drop: bool = False) -> None:
        self.drop = drop
        self._saved: dict[int, Any] = {}
        self._pending: list[int] = []
        self._raised: BaseException | None = None

    def _record(self, signum: int, frame: FrameType | None) -> None:
        if signum not in self._pending:
            self._pending.append(signum)

    def __enter__(self) -> HeldSignals:
        if not _in_main_thread():
            return self
        for sig in SIGNALS:
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
                    signal.signal(sig, previous if previous is not None else signal.SIG_DFL)
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


# ----------------------------------------------------------------------------------------------
# what this process has written: the words of the interruption line
# ----------------------------------------------------------------------------------------------
def record_written(path: str | os.PathLike[str]) -> None:
    """Note that the output ``path`` is now in place (called when an output is committed).

    Examples
    --------
    >>> forget_written()
    >>> record_written("results/proc")
    >>> [p.name for p in written()]
    ['proc']
    >>> forget_written()
    """
    p = Path(path)
    if p not in _WRITTEN:
        _WRITTEN.append(p)


def written() -> list[Path]:
    """The outputs committed by this process since the last :func:`forget_written`.

    Examples
    --------
    >>> forget_written()
    >>> written()
    []
    """
    return list(_WRITTEN)


def forget_written() -> None:
    """Start a new run: forget the outputs recorded so far.

    Examples
    --------
    >>> record_written("a.csv"); forget_written(); written()
    []
    """
    _WRITTEN.clear()


def interrupted_line(prog: str = "bendpam") -> str:
    """The one line to print for an interruption, true to what was written.

    ``"<prog>: interrupted; no outputs were changed"`` while nothing was committed,
    ``"<prog>: interrupted after writing A and B"`` once outputs are in place.

    Examples
    --------
    >>> forget_written()
    >>> interrupted_line()
    'bendpam: interrupted; no outputs were changed'
    >>> record_written("out/proc"); record_written("fig.png")
    >>> interrupted_line()
    'bendpam: interrupted after writing out/proc and fig.png'
    >>> forget_written()
    """
    done = [str(p) for p in _WRITTEN]
    if not done:
        return f"{prog}: interrupted; no outputs were changed"
    names = done[0] if len(done) == 1 else ", ".join(done[:-1]) + " and " + done[-1]
    return f"{prog}: interrupted after writing {names}"


def quiet_logging(signum: int | None = None) -> None:
    """Silence every logger of the process (for a shutdown after an interruption).

    Worker pools (a Dask cluster) log their shutdown at WARNING and ERROR level; after an
    interruption the one line that says so is enough.  Undo with
    ``logging.disable(logging.NOTSET)``.

    Examples
    --------
    >>> import logging
    >>> quiet_logging()
    >>> logging.getLogger("distributed").error("not shown")
    >>> logging.disable(logging.NOTSET)
    """
    logging.disable(logging.CRITICAL)
