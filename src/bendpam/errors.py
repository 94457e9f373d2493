"""The exceptions bendpam raises for problems a user can fix.

Every message is one line that names the value, key, file or line at fault and what was
expected; none names a command-line flag (the library does not know how it was called).  The
command line turns these into ``bendpam: error: ...`` and exit status 2; anything else reaching
it is a bug and is reported as one.

* :class:`BendpamError`: the base class.
* :class:`InputError` (also a :class:`ValueError`): a value out of range, an unknown option or
  key, inconsistent arguments.
* :class:`FileFormatError` (an :class:`InputError`): a file that cannot be read or understood;
  the message starts with the file name and, where it applies, the line.
* :class:`ProcessingError` (an :class:`InputError`): a test that reads but cannot be processed
  (too few cycles, no reversal, ...).
* :class:`NoEquilibrium`: no physical answer exists (above a fold, beyond lock-up).
* :class:`FitError`: identification failed for a reason that lies in the data (curves that
  cannot separate two parameters, too few points), explained in terms of the data.
"""

from __future__ import annotations

__all__ = ["BendpamError", "FileFormatError", "FitError", "InputError", "NoEquilibrium", "ProcessingError"]


class BendpamError(Exception):
    """Base class of the errors that a user can act on (one-line messages)."""


class InputError(BendpamError, ValueError):
    """A bad argument or option value: out of range, unknown, of the wrong type or inconsistent."""


class FileFormatError(InputError):
    """A file that cannot be read or understood (message starts with the file name)."""


class ProcessingError(InputError):
    """A raw test that reads but cannot be processed (message starts with the file name)."""


class NoEquilibrium(BendpamError, ValueError):
    """No physical equilibrium exists for the request (e.g. above a fold or beyond lock-up)."""


class FitError(BendpamError, ValueError):
    """Identification failed for a reason that lies in the data."""
