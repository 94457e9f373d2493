"""Raw four-point-bending tests: read and write testing-machine exports.

A raw test at one pressure is a time series of time (s), crosshead stroke (mm) and force (N).
:func:`read_test` reads plain CSV, Zwick testXpert, Instron Bluehill and MTS TestSuite exports
(detected from the content) into a :class:`RawTest`; :func:`write_test` writes them.
"""

from __future__ import annotations

from .readers import (
    COLUMNS,
    DIALECTS,
    RawTest,
    ReadError,
    detect_dialect,
    parse_pressure,
    pressure_from_filename,
    read_test,
)
from .writers import write_test

__all__ = [
    "COLUMNS",
    "DIALECTS",
    "RawTest",
    "ReadError",
    "detect_dialect",
    "parse_pressure",
    "pressure_from_filename",
    "read_test",
    "write_test",
]
