"""Infrastructure beside the layers: atomic writes, output sets, progress lines.

These modules import only the standard library, :mod:`bendpam.errors`, :mod:`bendpam.validate` and
:mod:`bendpam.version`, so every layer may use them.
"""
