"""Progress reporting for long work: a rich bar in a terminal, one-line reports otherwise.

:class:`Progress` is a context manager that counts units of work (cases, blocks, files).

* When the stream (standard error by default) is a terminal, it draws a :mod:`rich` progress
  bar (rich is imported only then, so ``import bendpam.infra.progress`` stays light).
* Otherwise (a pipe, a log file, CI) it writes one line every ``interval_s`` seconds while the
  work runs, e.g. ``bendpam: sweep: 1200/4000 (30 %), 12 s elapsed, ~28 s left`` (from a
  background timer, so also while a single long step runs), and then one line at the end.  Work
  that ends within the first ``interval_s`` writes nothing: short commands stay silent, and a
  command that fails early still writes just its one-line error.  The default interval is 5 s;
  the environment variable ``BENDPAM_PROGRESS_INTERVAL_S`` changes it (``0``: a line at every
  step, from the first; ``inf``: no line at all, however long the work takes, which is how a
  harness that checks a command's exact output on stderr keeps it independent of the time).
* With ``quiet=True`` it writes nothing at all.

:meth:`Progress.advance` is thread-safe, so it can be handed as a callback to code that reports
completion from worker threads (Dask block callbacks, thread pools).  On Ctrl-C (or any other
exception) the bar is stopped cleanly and the exception propagates unchanged.  Nested bars (a
report that runs a sweep) share one rich display: the inner bar is shown as a second line.
"""

from __future__ import annotations

import math
import os
import sys
import threading
import time
from collections.abc import Callable
from types import TracebackType
from typing import Any

from bendpam.infra.signals import raise_pending

__all__ = ["DEFAULT_INTERVAL_S", "INTERVAL_ENV", "Progress", "format_duration"]

#: Seconds between two plain progress lines unless the environment variable below says otherwise.
DEFAULT_INTERVAL_S = 5.0
#: Environment variable with the default interval between plain progress lines (s).
INTERVAL_ENV = "BENDPAM_PROGRESS_INTERVAL_S"

# one rich display per process (rich allows only one live display at a time); nested
# Progress objects add a task to it.  Guarded by _LIVE_LOCK.
_LIVE_LOCK = threading.Lock()
_LIVE: dict[str, Any] = {"progress": None, "users": 0}


def format_duration(seconds: float) -> str:
    """A short human-readable duration: ``'12 s'``, ``'3 min 05 s'``, ``'2 h 07 min'``.

    Parameters
    ----------
    seconds : float
        Duration in s (negative values count as 0; a non-finite value gives ``'?'``).

    Examples
    --------
    >>> format_duration(12.4), format_duration(185), format_duration(7625)
    ('12 s', '3 min 05 s', '2 h 07 min')
    """
    if not math.isfinite(seconds):
        return "?"
    s = max(round(seconds), 0)
    if s < 60:
        return f"{s} s"
    if s < 3600:
        return f"{s // 60} min {s % 60:02d} s"
    return f"{s // 3600} h {(s % 3600) // 60:02d} min"


def _interval(interval_s: float | None) -> float:
    """The interval between plain lines: the argument, else the environment variable, else 5 s.

    ``inf`` (never a line) is kept; NaN, a negative number or a word gives the default.
    """
    if interval_s is None:
        text = os.environ.get(INTERVAL_ENV, "").strip()
        try:
            interval_s = float(text) if text else DEFAULT_INTERVAL_S
        except ValueError:
            interval_s = DEFAULT_INTERVAL_S
    value = float(interval_s)
    return value if value >= 0 else DEFAULT_INTERVAL_S  # NaN >= 0 is False too


class Progress:
    """Report the progress of long work on standard error.

    Parameters
    ----------
    total : int or None
        Number of units of work expected; ``None`` if unknown (the report then shows the count
        and the elapsed time only).
    description : str
        What is being done, shown before the count (``'sweep'``, ``'fit'``).
    quiet : bool, optional
        Write nothing (default False).
    stream : text stream or rich.console.Console, optional
        Where to report; default :data:`sys.stderr`.  A rich bar is drawn when the stream is a
        terminal (``isatty()``), plain lines otherwise.  A :class:`rich.console.Console` is drawn
        on as a terminal if the console says it is one (``Console(force_terminal=True)``).
    interval_s : float, optional
        Time between two plain progress lines, in s; the first comes ``interval_s`` after the
        start, the last at the end if any came before.  Default: the environment variable
        ``BENDPAM_PROGRESS_INTERVAL_S``, else 5.  ``0``: a line at every :meth:`advance`;
        ``math.inf``: no plain line at all.
    clock : callable, optional
        Returns the time in s (default :func:`time.monotonic`); for tests.

    Examples
    --------
    >>> import io
    >>> out = io.StringIO()
    >>> with Progress(4, "demo", stream=out, interval_s=0) as bar:
    ...     for _ in range(4):
    ...         bar.advance()
    >>> print(out.getvalue().splitlines()[0].split(",")[0])
    bendpam: demo: 1/4 (25 %)
    """

    def __init__(
        self,
        total: int | None,
        description: str,
        *,
        quiet: bool = False,
        stream: Any = None,
        interval_s: float | None = None,
        clock: Callable[[], float] | None = None,
    ) -> None:
        if total is not None and total < 0:
            raise ValueError(f"total must be >= 0 or None, got {total}")
        self.total = None if total is None else int(total)
        self.description = str(description)
        self.quiet = bool(quiet)
        self.interval_s = _interval(interval_s)
        self.completed = 0
        self.lines_written = 0
        self._timer: threading.Thread | None = None
        self._stop_timer = threading.Event()
        self._stream = stream
        self._clock = clock or time.monotonic
        self._lock = threading.Lock()
        self._start = 0.0
        self._last_line = 0.0
        self._rich: Any = None  # the shared rich progress while this bar draws on it
        self._task: Any = None
        self._mode = "off"  # "off" | "rich" | "lines"
        self._active = False

    # -- mode ---------------------------------------------------------------------------------
    def _target(self) -> Any:
        return sys.stderr if self._stream is None else self._stream

    def _is_terminal(self) -> bool:
        target = self._target()
        if target is None:
            return False
        if hasattr(target, "is_terminal") and hasattr(target, "print"):  # a rich Console
            return bool(target.is_terminal)
        try:
            return bool(target.isatty())
        except (AttributeError, ValueError, OSError):
            return False

    # -- context manager ----------------------------------------------------------------------
    def __enter__(self) -> Progress:
        self.start()
        return self

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.stop(interrupted=exc_type is not None and issubclass(exc_type, KeyboardInterrupt), failed=exc is not None)

    def start(self) -> None:
        """Start reporting (called by ``with``)."""
        with self._lock:
            if self._active:
                return
            self._active = True
            self._start = self._last_line = self._clock()
            if self.quiet or self._target() is None:
                self._mode = "off"
            elif self._is_terminal():
                self._mode = "rich"
                self._start_rich()
            else:
                self._mode = "lines"
                if 0 < self.interval_s < threading.TIMEOUT_MAX:  # longer: never a line, no timer
                    self._stop_timer.clear()
                    self._timer = threading.Thread(target=self._tick, name="bendpam-progress", daemon=True)
                    self._timer.start()

    def stop(self, *, interrupted: bool = False, failed: bool = False) -> None:
        """Stop reporting (called by ``with``): remove the bar, or write the last line if any came before."""
        with self._lock:
            if not self._active:
                return
            self._active = False
            timer, self._timer = self._timer, None
            self._stop_timer.set()
            if self._mode == "rich":
                self._stop_rich()
            elif self._mode == "lines" and self.lines_written:
                if interrupted:
                    self._write(self._line(interrupted=True))
                elif not failed:
                    self._write(self._line(finished=True))
        if timer is not None and timer is not threading.current_thread():
            timer.join()

    def _tick(self) -> None:
        """Background timer (plain lines only): a line every ``interval_s`` even without :meth:`advance`."""
        while not self._stop_timer.wait(self.interval_s):
            with self._lock:
                if not self._active:
                    return
                self._maybe_line()

    # -- counting -----------------------------------------------------------------------------
    def advance(self, n: int = 1, description: str | None = None) -> None:
        """Count ``n`` more units as done (thread-safe); optionally change the description."""
        if threading.current_thread() is threading.main_thread():
            raise_pending()  # a signal that came inside a finalizer stops the run here
        with self._lock:
            self.completed += int(n)
            if description is not None:
                self.description = str(description)
            if not self._active:
                return
            if self._mode == "rich":
                if description is not None:
                    self._rich.update(self._task, advance=int(n), description=self.description)
                else:
                    self._rich.advance(self._task, int(n))
            elif self._mode == "lines":
                self._maybe_line()

    def _maybe_line(self) -> None:
        """Write a progress line if ``interval_s`` has passed since the last (or the start); lock held."""
        now = self._clock()
        unfinished = self.total is None or self.completed < self.total
        if unfinished and now - self._last_line >= self.interval_s:
            self._last_line = now
            self._write(self._line())

    # -- plain lines --------------------------------------------------------------------------
    def _line(self, *, finished: bool = False, interrupted: bool = False) -> str:
        elapsed = self._clock() - self._start
        done, total = self.completed, self.total
        if total:
            count = f"{done}/{total} ({min(100, math.floor(100 * done / total))} %)"
        elif total == 0:
            count = "0/0 (100 %)"
        else:
            count = f"{done} done" if done else ""  # unknown total and no count: the time only
        head = f"bendpam: {self.description}: "
        if interrupted:
            return head + (f"interrupted at {count} after " if count else "interrupted after ") \
                + format_duration(elapsed)
        if finished:
            return head + (f"{count}, " if count else "") + f"finished in {format_duration(elapsed)}"
        line = head + (f"{count}, " if count else "") + f"{format_duration(elapsed)} elapsed"
        if total and 0 < done < total:
            line += f", ~{format_duration(elapsed * (total - done) / done)} left"
        return line

    def _write(self, line: str) -> None:
        self.lines_written += 1
        target = self._target()
        try:
            if hasattr(target, "is_terminal") and hasattr(target, "print"):  # a rich Console
                target.print(line, markup=False, highlight=False, soft_wrap=True)
            else:
                target.write(line + "\n")
                target.flush()
        except (OSError, ValueError):  # a closed pipe must not stop the work
            pass

    # -- rich bar -----------------------------------------------------------------------------
    def _start_rich(self) -> None:
        from rich.console import Console
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            TaskProgressColumn,
            TextColumn,
            TimeElapsedColumn,
            TimeRemainingColumn,
        )
        from rich.progress import Progress as RichProgress

        with _LIVE_LOCK:
            shared = _LIVE["progress"]
            if shared is None:
                target = self._target()
                console = target if isinstance(target, Console) else Console(file=target)
                shared = RichProgress(
                    TextColumn("[progress.description]{task.description}"),
                    BarColumn(),
                    MofNCompleteColumn(),
                    TaskProgressColumn(),
                    TimeElapsedColumn(),
                    TextColumn("eta"),
                    TimeRemainingColumn(),
                    console=console,
                    transient=False,
                    redirect_stdout=False,
                    redirect_stderr=False,
                )
                shared.start()
                _LIVE["progress"] = shared
            _LIVE["users"] += 1
        self._rich = shared
        self._task = shared.add_task(self.description, total=self.total, completed=self.completed)

    def _stop_rich(self) -> None:
        shared, task = self._rich, self._task
        self._rich = self._task = None
        with _LIVE_LOCK:
            _LIVE["users"] -= 1
            last = _LIVE["users"] <= 0
            if last:
                _LIVE["progress"] = None
                _LIVE["users"] = 0
        try:
            if last:
                shared.refresh()
                shared.stop()
            else:
                shared.remove_task(task)
        except Exception:  # pragma: no cover - a broken terminal must not hide the real error
            pass

    def __repr__(self) -> str:
        return f"Progress({self.total!r}, {self.description!r}, completed={self.completed}, mode={self._mode!r})"
