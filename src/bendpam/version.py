"""The package's version, in a module of its own so that any layer can read it without importing the facade.

>>> from bendpam.version import __version__
>>> __version__.count(".") >= 2
True
"""

__version__ = "0.4.0"

__all__ = ["__version__"]
