"""The ``bendpam`` console script: signal handlers first, then the package.

Importing the command line (Typer, the commands; NumPy and the models once a command runs) takes
a tenth of a second or more.  A Ctrl-C or SIGTERM in
that window would otherwise end in a ``KeyboardInterrupt`` traceback or a silent kill.  The first
statements of this tiny module (outside the package, so that importing it imports nothing else)
install handlers that end the process with one line and the exit status of an interrupted command
(130 / 143); they run when the console script imports this module, before :func:`main` is called.
:func:`bendpam.cli.app.main` then installs its own handlers while the command runs, and puts
these back when it returns, so a signal that arrives while the process exits still gets one line
-- ``interrupted after writing DIR`` once an output was committed
(:func:`bendpam.infra.signals.interrupted_line`).

In a worker process that a command starts with :mod:`multiprocessing` (the Dask workers of
``sweep --workers``: a spawned child imports the parent's main module again, as ``__mp_main__``),
SIGINT is ignored instead and logging is off: a Ctrl-C at the terminal reaches every process of the
group, and the parent alone answers it, shutting its workers down quietly (their errors reach the
parent through Dask all the same).

``bendpam --version`` alone is answered here, without building the command line (the same line as
``bendpam.cli.app``'s ``--version``: :func:`bendpam.infra.manifest.bendpam_version`).

What remains outside Python's reach is the interpreter's own start-up (before any line of the
console script runs): a signal there gets the system's default action.
"""

import os
import signal
import sys

_NOTHING_WRITTEN = "bendpam: interrupted; no outputs were changed"


def _early(signum, frame):  # pragma: no cover - exercised by the fault-injection tests
    line = _NOTHING_WRITTEN
    state = sys.modules.get("bendpam.infra.signals")
    if state is not None:
        try:
            line = state.interrupted_line()
        except Exception:
            line = _NOTHING_WRITTEN
    try:
        os.write(2, (line + "\n").encode("utf-8", "replace"))
    finally:
        os._exit(128 + signum)


def _in_worker() -> bool:
    """True in a multiprocessing child (it runs the parent's main module as ``__mp_main__``)."""
    return __name__ == "__mp_main__" or "__mp_main__" in sys.modules


def install() -> None:
    """Install the handlers (SIGINT and SIGTERM; a signal ignored by the parent stays ignored)."""
    if _in_worker():
        import logging

        signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent answers Ctrl-C and stops its workers
        logging.disable(logging.CRITICAL)  # the workers' shutdown warnings are noise on the terminal
        return
    for sig in (signal.SIGINT, signal.SIGTERM):
        if signal.getsignal(sig) is not signal.SIG_IGN:
            signal.signal(sig, _early)


install()


def main() -> int:
    """Run the ``bendpam`` command line; returns its exit status."""
    install()  # (again: a caller may have changed them after importing this module)
    if sys.argv[1:] == ["--version"]:  # the one answer that needs neither Typer nor the commands (start-up)
        from bendpam.infra.manifest import bendpam_version

        try:
            sys.stdout.write(f"bendpam {bendpam_version()}\n")
            sys.stdout.flush()
        except AttributeError:  # no stdout (closed): nothing to print to, as Typer's echo
            pass
        except OSError as exc:  # a full disk, a closed pipe: one line, as bendpam.cli.app.main says it
            os.write(2, f"bendpam: error: {exc.strerror or exc}\n".encode("utf-8", "replace"))
            return 2
        return 0
    from bendpam.cli.app import main as run

    return run()


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
