"""``python -m bendpam``: the ``bendpam`` command (the same as the console script).

The package itself is imported before this module runs; the signal handlers of the console
script (:mod:`bendpam_entry`) are installed as soon as this module starts.
"""

import sys

try:
    from bendpam_entry import main
except ImportError:  # pragma: no cover - an installation without the console script's module
    from bendpam.cli.app import main

sys.exit(main())
