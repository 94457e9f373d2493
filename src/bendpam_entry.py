"""The ``bendpam`` console script: signal handlers first, then the package.

Importing bendpam (NumPy and the models) takes a few tenths of a second.  A Ctrl-C or SIGTERM in
that window would otherwise end in a ``KeyboardInterrupt`` traceback or a silent kill.  This tiny
module, outside the package so that importing it imports nothing else, installs handlers that end
the process with the one line and the exit status of an interrupted command (130 / 143) before
the package is imported; :func:`bendpam.cli.app.main` then installs its own.
"""

from __future__ import annotations

import os
import signal
import sys


def _early(signum, frame):  # pragma: no cover - exercised by the fault-injection tests
    sys.stderr.write("bendpam: interrupted; no outputs were changed\n")
    sys.stderr.flush()
    os._exit(128 + signum)


def main() -> int:
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, _early)
    from bendpam.cli.app import main as run

    return run()


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
