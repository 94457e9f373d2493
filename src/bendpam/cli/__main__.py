"""``python -m bendpam.cli``: the same as the ``bendpam`` command (and ``python -m bendpam``).

It goes through the console script's module (:mod:`bendpam_entry`), so that its signal handlers
and its handling of Dask workers apply here too.
"""

import sys

try:
    from bendpam_entry import main
except ImportError:  # pragma: no cover - an installation without the console script's module
    from bendpam.cli.app import main

sys.exit(main())
