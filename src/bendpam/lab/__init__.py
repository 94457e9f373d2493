"""Raw four-point-bending tests: read and write testing-machine exports.

A raw test at one pressure is a time series of time (s), crosshead stroke (mm) and force (N).
:func:`read_test` (one test) and :func:`read_tests` (every test of a file) read the exports
of real testing machines (Zwick testXpert, Instron
Bluehill/WaveMatrix/console, MTS 793 and TestSuite, Shimadzu Trapezium, plain CSV, ``.xlsx``/
``.xls`` workbooks; the layout, encoding and channels are found from the content) into a
:class:`RawTest`; :func:`inspect_file` reports how a file reads; :func:`write_test` writes
synthetic exports; :func:`check_cycle_count` compares a segmentation with the machine's cycle
counter.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from bendpam.lab.declaration import load_declaration
    from bendpam.lab.declared import read_declared
    from bendpam.lab.pressure import PRESSURE_RANGE_KPA, parse_pressure, pressure_from_filename
    from bendpam.lab.rawtest import COLUMNS, DIALECTS, FORMATS, RawTest, check_cycle_count
    from bendpam.lab.read_error import ReadError
    from bendpam.lab.readers import (
        detect_dialect,
        format_inspection,
        inspect_file,
        parse_columns,
        read_test,
        read_tests,
    )
    from bendpam.lab.suggest import suggest_declaration
    from bendpam.lab.writers import write_test

__all__ = [
    "COLUMNS",
    "DIALECTS",
    "FORMATS",
    "PRESSURE_RANGE_KPA",
    "RawTest",
    "ReadError",
    "check_cycle_count",
    "detect_dialect",
    "format_inspection",
    "inspect_file",
    "load_declaration",
    "parse_columns",
    "parse_pressure",
    "pressure_from_filename",
    "read_declared",
    "read_test",
    "read_tests",
    "suggest_declaration",
    "write_test",
]

#: Where each name lives (the readers module loads pandas; ``bendpam fit`` needs neither).
_FROM = {
    "COLUMNS": "rawtest", "DIALECTS": "rawtest", "FORMATS": "rawtest", "RawTest": "rawtest",
    "check_cycle_count": "rawtest", "PRESSURE_RANGE_KPA": "pressure", "parse_pressure": "pressure",
    "pressure_from_filename": "pressure", "ReadError": "read_error", "detect_dialect": "readers",
    "format_inspection": "readers", "inspect_file": "readers", "parse_columns": "readers", "read_test": "readers",
    "read_tests": "readers",
    "write_test": "writers", "load_declaration": "declaration", "read_declared": "declared",
    "suggest_declaration": "suggest",
}  # fmt: skip


def __getattr__(name: str):
    """Import the readers (and pandas) only when one of their names is used: ``bendpam fit`` needs neither."""
    if name in _FROM:
        import importlib

        value = getattr(importlib.import_module(f".{_FROM[name]}", __name__), name)
        globals()[name] = value
        return value
    import importlib
    import importlib.util

    if importlib.util.find_spec(f"{__name__}.{name}") is not None:  # a submodule, as an import gives it
        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
