"""Aliases that keep the module paths of bendpam 0.3 importing for one release.

bendpam 0.4 regrouped the package into layers (``physics``, ``lab``, ``identify``, ``design``,
``present``, ``infra``).  Importing an old path (``import bendpam.law``) warns with a
:class:`DeprecationWarning` and binds the module at its new home, so that old code, pickles and
monkeypatches keep working until 0.5.
"""

from __future__ import annotations

import importlib
import sys
import warnings

__all__ = ["alias_module"]


def alias_module(old: str, new: str, submodules: tuple[str, ...] = ()) -> None:
    """Make the module ``old`` an alias of ``new`` (and ``old.sub`` of ``new.sub`` for each submodule).

    >>> import sys, warnings
    >>> with warnings.catch_warnings(record=True):
    ...     warnings.simplefilter("always")
    ...     import bendpam.law as old_law
    >>> import bendpam.physics.law as new_law
    >>> old_law is new_law and sys.modules["bendpam.law"] is new_law
    True
    """
    warnings.warn(f"{old} moved to {new} in bendpam 0.4; the old path is removed in 0.5",
                  DeprecationWarning, stacklevel=3)
    module = importlib.import_module(new)
    sys.modules[old] = module
    for sub in submodules:
        sys.modules[f"{old}.{sub}"] = importlib.import_module(f"{new}.{sub}")
