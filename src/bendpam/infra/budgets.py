"""Budgets: the limits of size, count, memory and time bendpam holds to, all in this module.

What would pass a budget is refused before any work, in one line that names the input, the
estimate and the limit (docs/budgets.md lists them all):

* **input files** (:func:`check_input_file`, :func:`read_input_bytes`): a regular file only (not
  a named pipe, a device, a socket or a folder: those can hang a reader or never end), and no
  larger than the limit of its kind, :data:`FILE_SIZE_LIMITS`;
* **structured text** (:func:`loads_toml`): tables nested no deeper than the format needs,
  :data:`TOML_MAX_DEPTH` (deeper nesting is never a bendpam file, and it can exhaust the parser);
* **values per option** (a range ``start:stop:count`` included): :data:`VALUE_LIMITS` per
  command, at most :data:`MAX_OPTION_VALUES` anywhere (:func:`value_limit`);
* **memory**: :data:`MEMORY_BUDGET_GIB` for what a computation holds at once (a sweep's result,
  the arrays of :func:`bendpam.internal_stresses`), :func:`memory_problem`; work done in chunks
  holds at most :data:`CHUNK_BYTES` of intermediate arrays per chunk;
* **time**: :data:`TIME_BUDGET_MIN` for a sweep's estimated run time;
* **a Dask scheduler** must answer within :data:`SCHEDULER_TIMEOUT_S` (:mod:`bendpam.infra.scheduler`).

This module imports only the standard library and :mod:`bendpam.errors`.
"""

from __future__ import annotations

import os
import stat
from typing import Any

from bendpam.errors import FileFormatError

__all__ = [
    "CHUNK_BYTES", "DEFAULT_VALUE_LIMIT", "FILE_SIZE_LIMITS", "GIB", "MAX_OPTION_VALUES", "MEMORY_BUDGET_GIB",
    "MIB", "SCHEDULER_TIMEOUT_S", "TIME_BUDGET_MIN", "TOML_MAX_DEPTH", "VALUE_LIMITS", "check_input_file",
    "format_bytes", "input_file_problem", "loads_toml", "memory_problem", "nesting_depth", "physical_memory_bytes",
    "read_input_bytes", "read_toml_file", "value_limit",
]

MIB = 1 << 20
GIB = 1 << 30

#: The largest size of an input file, by kind (bytes).  Each is far above any real file of its kind.
FILE_SIZE_LIMITS: dict[str, int] = {
    "actuator file": 1 * MIB,           # an [actuator] table (and [hysteresis]): under 2 KiB in practice
    "raw test file": 2 * GIB,           # a testing machine's export: a long test at 1 kHz is about 100 MiB
    "processed curves file": 1 * GIB,   # curves.nc of `bendpam process`: a few MiB
    "fit file": 64 * MIB,               # fit.json of `bendpam fit`: tens of KiB
    "scheduler file": 1 * MIB,          # the JSON file of `dask scheduler --scheduler-file`
    "manifest": 64 * MIB,               # manifest.json of an output set
    "format declaration": 1 * MIB,      # the TOML --format-file of a raw test file: under 2 KiB in practice
    "hand file": 1 * MIB,               # the TOML description of the soft hand (bendpam hand --hand): about 1 KiB
}

#: The deepest nesting of tables and arrays a bendpam TOML file may have: ``[actuator]`` and
#: ``[hysteresis]`` are tables of values (depth 2); one level more is left for an array value.
TOML_MAX_DEPTH = 3

#: The most values any one option may expand to (the parser's own ceiling, before a command's limit).
MAX_OPTION_VALUES = 1_000_000
#: The most values one option may give each command: what the command evaluates in about a minute
#: or less (a command evaluates each value; a sweep is further bounded by its memory and time).
VALUE_LIMITS: dict[str, int] = {
    "predict": 100_000,       # about 30 us per pressure: 3 s
    "curve": 1_000,           # one curve per pressure; a figure of 1000 curves takes about 7 s
    "sweep": 100_000,         # per option; the grid is bounded by memory and time
    "simulate-test": 1_000,   # one raw file per pressure, about 50 ms each
    "finger": 10_000,         # the design commands: about 10 ms per equilibrium
    "grasp": 10_000,
    "wrist": 10_000,
    "process": 10_000,        # one pressure per file
    "report": 10_000,
}
#: The limit of a command not in :data:`VALUE_LIMITS`.
DEFAULT_VALUE_LIMIT = 100_000

#: The memory (GiB) a computation may hold at once unless its caller raises the budget.
MEMORY_BUDGET_GIB = 2.0
#: The intermediate arrays of one chunk of chunked work (bytes).
CHUNK_BYTES = 64 * MIB
#: The longest estimated run time (minutes) of a sweep unless its caller raises the budget.
TIME_BUDGET_MIN = 5.0
#: How long (seconds) a Dask scheduler has to answer before it is refused.
SCHEDULER_TIMEOUT_S = 10.0

_KINDS = {stat.S_ISFIFO: "a named pipe", stat.S_ISCHR: "a character device", stat.S_ISBLK: "a block device",
          stat.S_ISSOCK: "a socket", stat.S_ISDIR: "a folder"}


def format_bytes(n: float) -> str:
    """A size in bytes for a message, in binary units (B, KiB, MiB, GiB, TiB), three significant digits or more.

    >>> format_bytes(512), format_bytes(1 << 20), format_bytes(3.7e9)
    ('512 B', '1 MiB', '3.45 GiB')
    """
    n, units = float(n), ("B", "KiB", "MiB", "GiB", "TiB")
    i = 0
    while abs(n) >= 1024 and i < len(units) - 1:
        n, i = n / 1024, i + 1
    return f"{n:.0f} {units[i]}" if abs(n) >= 100 else f"{n:.3g} {units[i]}"


def _article(kind: str) -> str:
    return ("an " if kind[:1].lower() in "aeiou" else "a ") + kind


def _limit(kind: str) -> int:
    try:
        return FILE_SIZE_LIMITS[kind]
    except KeyError:
        raise ValueError(f"unknown kind of input file {kind!r}; known: {', '.join(FILE_SIZE_LIMITS)}") from None


def _stat_problem(st: os.stat_result, kind: str) -> str | None:
    if not stat.S_ISREG(st.st_mode):
        what = next((name for test, name in _KINDS.items() if test(st.st_mode)), "a special file")
        return f"is {what}, not a regular file; expected {_article(kind)}"
    limit = _limit(kind)
    if st.st_size > limit:
        return (f"{format_bytes(st.st_size)} is larger than the {format_bytes(limit)} limit for "
                f"{_article(kind)}")
    return None


def input_file_problem(path: str | os.PathLike, kind: str) -> str | None:
    """Why ``path`` cannot be read as an input of ``kind`` (a key of :data:`FILE_SIZE_LIMITS`), or None.

    Looks only at ``os.stat`` (which never blocks, whatever the file is): a missing file, one
    that is not a regular file, or one larger than the kind's limit.  The reason does not name
    the file (the caller does, in its own error).

    >>> input_file_problem("no-such-file.toml", "actuator file")
    'actuator file not found'
    >>> input_file_problem(".", "actuator file")
    'is a folder, not a regular file; expected an actuator file'
    """
    try:
        st = os.stat(path)
    except FileNotFoundError:
        return f"{kind} not found"
    except OSError as exc:
        return f"cannot read the {kind} ({exc.strerror or exc})"
    return _stat_problem(st, kind)


def check_input_file(path: str | os.PathLike, kind: str) -> int:
    """Refuse, in one line, an input that is not a regular file or is too large for its kind; its size in bytes.

    Raises :class:`~bendpam.errors.FileFormatError` ``"PATH: reason"`` (see :func:`input_file_problem`).

    >>> import tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = pathlib.Path(d) / "a.toml"
    ...     _ = p.write_text("[actuator]\\n")
    ...     check_input_file(p, "actuator file")
    11
    >>> check_input_file("missing.toml", "actuator file")
    Traceback (most recent call last):
    ...
    bendpam.errors.FileFormatError: missing.toml: actuator file not found
    """
    problem = input_file_problem(path, kind)
    if problem is not None:
        raise FileFormatError(f"{path}: {problem}")
    return os.stat(path).st_size


def read_input_bytes(path: str | os.PathLike, kind: str) -> bytes:
    """The bytes of a small input file, after the checks of :func:`check_input_file`, safely.

    The file is opened without blocking (a named pipe put in its place after the check cannot
    hang the read), checked again on the open file, and read up to the kind's limit only (a file
    that grows past it, or a special file that reports no size, is refused).

    >>> import tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = pathlib.Path(d) / "a.toml"
    ...     _ = p.write_text("[actuator]\\n")
    ...     read_input_bytes(p, "actuator file")
    b'[actuator]\\n'
    """
    check_input_file(path, kind)
    limit = _limit(kind)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0))
    except FileNotFoundError:
        raise FileFormatError(f"{path}: {kind} not found") from None
    except OSError as exc:
        raise FileFormatError(f"{path}: cannot read the {kind} ({exc.strerror or exc})") from None
    with os.fdopen(fd, "rb") as fh:
        problem = _stat_problem(os.fstat(fh.fileno()), kind)
        if problem is not None:
            raise FileFormatError(f"{path}: {problem}")
        try:
            data = fh.read(limit + 1)
        except OSError as exc:
            raise FileFormatError(f"{path}: cannot read the {kind} ({exc.strerror or exc})") from None
    if len(data) > limit:
        raise FileFormatError(f"{path}: larger than the {format_bytes(limit)} limit for {_article(kind)}")
    return data


def nesting_depth(value: Any) -> int:
    """How deeply tables (dicts) and arrays (lists) nest in ``value``, counted without recursion.

    >>> nesting_depth(1), nesting_depth({"a": 1}), nesting_depth({"actuator": {"R0_mm": 9.0, "x": [1, 2]}})
    (0, 1, 3)
    """
    deepest = 0
    stack = [(value, 0)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict):
            children = list(item.values())
        elif isinstance(item, list | tuple):
            children = list(item)
        else:
            continue
        deepest = max(deepest, depth + 1)
        stack.extend((c, depth + 1) for c in children)
    return deepest


def loads_toml(text: str, source: str, *, kind: str = "actuator file", max_depth: int = TOML_MAX_DEPTH) -> dict:
    """Parse TOML, refusing in one line a document nested deeper than ``max_depth`` tables and arrays.

    Raises :class:`~bendpam.errors.FileFormatError` ``"SOURCE: ..."`` for invalid TOML and for
    nesting too deep (also when it is too deep for the parser itself).

    >>> loads_toml("[actuator]\\nR0_mm = 9.0\\n", "a.toml")
    {'actuator': {'R0_mm': 9.0}}
    >>> loads_toml("x = " + "[" * 5000 + "]" * 5000, "deep.toml")
    Traceback (most recent call last):
    ...
    bendpam.errors.FileFormatError: deep.toml: tables or arrays nested too deeply to read; an actuator file ...
    """
    import tomllib

    too_deep = f"{source}: tables or arrays nested too deeply to read; {_article(kind)} nests at most {max_depth} deep"
    try:
        data = tomllib.loads(text)
    except RecursionError:
        raise FileFormatError(too_deep) from None
    except tomllib.TOMLDecodeError as exc:
        raise FileFormatError(f"{source}: invalid TOML: {exc}") from None
    depth = nesting_depth(data)
    if depth > max_depth:
        raise FileFormatError(f"{source}: tables or arrays nested {depth} deep; {_article(kind)} nests at most "
                              f"{max_depth} deep")
    return data


def read_toml_file(path: str | os.PathLike, kind: str) -> dict:
    """A small TOML input file of ``kind`` (a key of :data:`FILE_SIZE_LIMITS`) read safely and parsed.

    :func:`read_input_bytes`, UTF-8 and :func:`loads_toml`: every refusal is one
    :class:`~bendpam.errors.FileFormatError` line naming the file.

    >>> import tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = pathlib.Path(d) / "a.toml"
    ...     _ = p.write_text("[actuator]\\nR0_mm = 9.0\\n")
    ...     read_toml_file(p, "actuator file")
    {'actuator': {'R0_mm': 9.0}}
    """
    raw = read_input_bytes(path, kind)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise FileFormatError(f"{path}: not UTF-8 text (byte {exc.start})") from None
    return loads_toml(text, str(path), kind=kind)


def physical_memory_bytes() -> int | None:
    """This machine's physical memory in bytes (None where the system does not say).

    >>> n = physical_memory_bytes()
    >>> n is None or n > 0
    True
    """
    try:
        n = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        return None
    return int(n) if n > 0 else None


def memory_problem(need_bytes: float, budget_gib: float | None = MEMORY_BUDGET_GIB) -> str | None:
    """Why holding ``need_bytes`` at once is refused (past the budget or this machine's memory), or None.

    ``budget_gib`` None means no budget (the machine's memory still applies).  The reason reads
    as the end of a sentence: ``"about 10.4 GiB, more than the memory budget of 2 GiB"``.

    >>> memory_problem(1e6) is None
    True
    >>> memory_problem(10e9)
    'about 9.31 GiB, more than the memory budget of 2 GiB'
    """
    if budget_gib is not None and need_bytes > budget_gib * GIB:
        return f"about {format_bytes(need_bytes)}, more than the memory budget of {budget_gib:g} GiB"
    machine = physical_memory_bytes()
    if machine is not None and need_bytes > machine:
        return f"about {format_bytes(need_bytes)}, more than this machine's memory ({format_bytes(machine)})"
    return None


def value_limit(command: str | None) -> int:
    """The most values one option of ``command`` may give (:data:`VALUE_LIMITS`, else the default).

    >>> value_limit("predict"), value_limit("curve"), value_limit(None)
    (100000, 1000, 100000)
    """
    return min(VALUE_LIMITS.get(command or "", DEFAULT_VALUE_LIMIT), MAX_OPTION_VALUES)

