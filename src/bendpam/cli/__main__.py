"""``python -m bendpam.cli``: the same as the ``bendpam`` command."""

import sys

from bendpam.cli.app import main

sys.exit(main())
