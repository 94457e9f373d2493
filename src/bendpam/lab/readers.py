"""Readers of raw four-point-bending exports from testing machines.

A raw test at one pressure is a time series of time (s), crosshead stroke (mm) and force (N).
:func:`read_test` reads it from what a testing machine writes and returns a :class:`RawTest`;
:func:`inspect_file` says how a file was read, as a JSON-ready dict.

The reader is layered, not a list of dialects:

1. **Bytes to text** (:mod:`bendpam.lab.encoding`): BOM, strict UTF-8, then the legacy code
   pages of these machines (cp1252, cp1250, GB18030, Shift-JIS, latin-1), keeping the one under
   which the header makes sense.  Workbooks (``.xlsx``/``.xls``) are read with
   ``python-calamine`` (extra ``excel``); native Zwick ``.zs2``/``.zp2`` files with ``zs2decode``
   (extra ``zwick``), one test per specimen (:mod:`bendpam.lab.zwick`).
2. **Layout** (:mod:`bendpam.lab.layout`): delimiter (tab, ``;``, ``,``) and decimal mark
   inferred per data block and checked cell by cell; MTS 793's first line
   (``MTS793|MPT|DEU|1|2|,|.|...``) is honoured; quoted or unquoted cells, empty first fields,
   specimen-index columns, trailing empty columns, exponents like ``e-005``.
3. **Structure**: metadata lines in several grammars, a names row, an optional units row
   (``(s)``, ``[s]``, ``s``, ``in s``), found by scoring the rows above the data
   (:mod:`bendpam.lab.header`); several data blocks in one file (those that repeat the header
   of the one read are read with it: one test when time continues, one test per block when it
   restarts; the others are listed); several specimens side by side (:func:`read_tests`).
4. **Channels** (:mod:`bendpam.lab.channels`): names in English, German, French, Italian,
   Spanish, Polish, Chinese and Japanese; units s/ms/min, N/kN/lbf, mm/m/in converted.  Where
   several displacement channels exist, the relative crosshead travel is chosen (eq 6 wants the
   stroke from the blocked state); the choice and its reason are recorded, ``columns=``
   overrides it.  A file without time but with a sampling rate (metadata or ``rate_hz=``)
   reads.  A per-cycle summary or a results table is refused with the reason.
5. **Values** (:mod:`bendpam.lab.checks`): gaps, clock restarts, repeated stamps and padding
   rows are read and reported (:attr:`RawTest.segments`); non-finite cells, isolated spikes and
   samples out of order in time are refused (default) or, with ``repair=True``, removed and
   reported in :attr:`RawTest.warnings`; a dead stroke or force channel is replaced by a named
   one that moves.

The numeric block is read in blocks of text (about 2 MB, no string per line) by the C parser of
:func:`pandas.read_csv`, into buffers sized from the bytes left in the file, so a 450 MB export
is read in bounded memory and linear time, in about 2x the time of :func:`pandas.read_csv`; a block
the C parser cannot read is read in pieces of 2000 lines, and only the odd piece line by line,
which finds the offending line.  Every failure is a :class:`ReadError`
whose message is one line ``FILE:LINE: what was wrong, what was expected``.

The steps live in their own modules: :mod:`bendpam.lab.source` (file to lines),
:mod:`bendpam.lab.parser` (lines to blocks, metadata and numbers), :mod:`bendpam.lab.assemble`
(numbers to a :class:`~bendpam.lab.rawtest.RawTest`, units and values checked),
:mod:`bendpam.lab.pressure` (the pressure from a value, a metadata line or a file name).  This
module holds the entry points and the naming of the format.
"""

from __future__ import annotations

import dataclasses
import math
import os
import re
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from bendpam.infra.manifest import verify_input
from bendpam.lab.assemble import assemble
from bendpam.lab.channels import FORCE_UNITS, LENGTH_UNITS, ROLES, TIME_UNITS
from bendpam.lab.parser import Parsed, parse_path, parse_source
from bendpam.lab.pressure import (
    PRESSURE_KEYS,
    PRESSURE_RANGE_KPA,
    PRESSURE_RANGE_TEXT,
    PRESSURE_UNITS,
    is_pressure_key,
    parse_pressure,
    pressure_from_filename,
    pressure_out_of_range,
)
from bendpam.lab.rawtest import COLUMNS, DIALECTS, FORMATS, RawTest, check_cycle_count
from bendpam.lab.read_error import ReadError
from bendpam.lab.source import text_source
from bendpam.lab.zwick import ZS2_SUFFIXES

__all__ = [
    "COLUMNS",
    "DIALECTS",
    "FORCE_UNITS",
    "FORMATS",
    "LENGTH_UNITS",
    "PRESSURE_KEYS",
    "PRESSURE_RANGE_KPA",
    "PRESSURE_UNITS",
    "TIME_UNITS",
    "RawTest",
    "ReadError",
    "check_cycle_count",
    "detect_dialect",
    "format_inspection",
    "inspect_file",
    "is_pressure_key",
    "looks_dead",
    "parse_columns",
    "parse_pressure",
    "pressure_from_filename",
    "read_test",
    "read_tests",
    "with_declaration_hint",
]


# ------------------------------------------------------------------------------------------------
# columns option
# ------------------------------------------------------------------------------------------------
def parse_columns(columns: Mapping[str, str] | str | None) -> dict[str, str]:
    """Normalise the ``columns=`` option to ``{role: column name}``.

    Parameters
    ----------
    columns : mapping, str or None
        ``{"time": NAME, "stroke": NAME, "force": NAME}`` (any subset) or the string form
        ``"time=NAME,stroke=NAME,force=NAME"``.

    Returns
    -------
    dict of str to str

    Raises
    ------
    bendpam.errors.InputError
        For an unknown role, an empty name or a malformed string.

    Examples
    --------
    >>> parse_columns("time=Zeit,force=Kraft"), parse_columns({"Stroke": "Weg"})
    ({'time': 'Zeit', 'force': 'Kraft'}, {'stroke': 'Weg'})
    """
    from bendpam.errors import InputError

    if columns is None:
        return {}
    if isinstance(columns, str):
        out: dict[str, str] = {}
        for part in re.split(r",(?=\s*(?:time|stroke|force)\s*=)", columns.strip()):
            if not part.strip():
                continue
            if "=" not in part:
                raise InputError(
                    f"columns {columns!r}: {part.strip()!r} has no '='; expected "
                    "'time=NAME,stroke=NAME,force=NAME'"
                )
            role, name = part.split("=", 1)
            out[role.strip().lower()] = name.strip()
        columns = out
    if not isinstance(columns, Mapping):
        raise InputError(f"columns must be a mapping or a string, got {type(columns).__name__}")
    result: dict[str, str] = {}
    for role, name in columns.items():
        r = str(role).strip().lower()
        if r not in ROLES:
            raise InputError(f"columns: unknown role {role!r}; expected time, stroke or force")
        if not str(name).strip():
            raise InputError(f"columns: the {r} column name is empty")
        result[r] = str(name).strip()
    if len(set(result.values())) < len(result):
        raise InputError(f"columns: one column named for two roles ({result})")
    return result

# ------------------------------------------------------------------------------------------------
# format names
# ------------------------------------------------------------------------------------------------
_ZWICK = re.compile(r"prüfzeit|pruefzeit|standardweg|standardkraft|standard travel|standard force|"
                    r"traverse abs|testxpert|zwick")  # fmt: skip
_GERMAN = re.compile(r"zeit|kraft|weg\b")
_WAVEMATRIX = re.compile(r"total cycles|elapsed cycles|cycle elapsed time|digital position|"
                         r"wavematrix")  # fmt: skip
_TRAPEZIUM = re.compile(r"試験力|ストローク|trapezium|shimadzu")


def _classify_format(parsed: Parsed) -> str:
    p, blk, source = parsed.parser, parsed.block, parsed.source
    if source.encoding == "zs2":
        return "zs2"
    if source.is_excel:
        return "excel"
    if p.mts is not None:
        return "mts793"
    names = " ".join(c.casefold() for c in blk.names)
    meta = [(ln, line) for ln, line in p.text if ln < blk.header_line]
    meta_text = " ".join(line.casefold() for _ln, line in meta)
    other_meta = any(not line.lstrip().startswith(("#", "$")) for ln, line in meta
                     if ln not in p.block_lines)  # fmt: skip
    units_row = blk.units_line is not None
    paren_units = units_row and blk.units is not None and any(
        re.fullmatch(r"\(.*\)", u.strip()) for u in blk.units if u.strip()
    )
    if p.dollar or _ZWICK.search(names) or _ZWICK.search(meta_text):
        return "testxpert"
    if _TRAPEZIUM.search(names) or _TRAPEZIUM.search(meta_text):
        return "trapezium"
    if _WAVEMATRIX.search(names) or _WAVEMATRIX.search(meta_text):
        return "wavematrix"
    if blk.first_row.lstrip().startswith('"') or paren_units:
        return "bluehill"
    if re.search(r"text inputs :|general :|bluehill", meta_text):
        return "bluehill"
    german = _GERMAN.search(names) is not None
    if blk.sep == ";" and (german or blk.decimal == "," or other_meta or units_row):
        return "testxpert"
    if "instron" in meta_text:
        return "instron"
    if other_meta or units_row or re.search(r"(^|\s)_\w", names):
        return "mts"
    return "csv"


def _check_options(pressure_kpa: float | None, dialect: str | None, rate_hz: float | None
                   ) -> tuple[float | None, float | None]:  # fmt: skip
    from bendpam.errors import InputError

    if dialect is not None and dialect not in FORMATS:
        raise InputError(f"unknown dialect {dialect!r}; expected one of {', '.join(FORMATS)}")
    if pressure_kpa is not None:
        try:
            pressure_kpa = float(pressure_kpa)
        except (TypeError, ValueError):
            raise InputError(f"pressure_kpa must be a number in kPa, got {pressure_kpa!r}") from None
        if not math.isfinite(pressure_kpa):
            raise InputError(f"pressure_kpa must be finite, got {pressure_kpa!r}")
        if pressure_out_of_range(pressure_kpa):
            raise InputError(f"pressure_kpa = {pressure_kpa:g} is out of range; {PRESSURE_RANGE_TEXT}")
    if rate_hz is not None:
        try:
            rate_hz = float(rate_hz)
        except (TypeError, ValueError):
            raise InputError(f"rate_hz must be a number in Hz, got {rate_hz!r}") from None
        if not (math.isfinite(rate_hz) and 0 < rate_hz <= 1e7):
            raise InputError(f"rate_hz = {rate_hz!r} is out of range; expected 0 < rate <= 1e7 Hz")
    return pressure_kpa, rate_hz


#: Refusals about the file itself, where a format declaration does not help.
_NOT_LAYOUT = re.compile(r"^(file not found|is a directory|permission denied|cannot read|file is empty|"
                         r"binary|native Zwick|not a native Zwick|.*not found$|is a folder|larger than|byte 0|"
                         r"lines? [\d-]+: only)")


def with_declaration_hint(exc: ReadError) -> ReadError:
    """A detection refusal that also says how to read the file anyway: with a format declaration.

    Refusals about the file itself (missing, empty, binary, too large) are returned unchanged.

    >>> print(with_declaration_hint(ReadError("no header row naming time, stroke and force columns", "x.csv", 3)))
    x.csv:3: no header row naming time, stroke and force columns; or describe the file's layout in a format ...
    >>> print(with_declaration_hint(ReadError("byte 0: the file is empty (0 bytes); expected data rows", "x.csv")))
    x.csv: byte 0: the file is empty (0 bytes); expected data rows
    """
    from bendpam.lab.declaration import DECLARATION_HINT

    message = exc.message
    if _NOT_LAYOUT.match(message) or DECLARATION_HINT in message:
        return exc
    return ReadError(f"{message}; or {DECLARATION_HINT}", exc.path, exc.line, exc.column)


def _read_declared(path: str | os.PathLike, format_file: str | os.PathLike, dialect: str | None,
                   columns: Mapping[str, str] | str | None, pressure_kpa: float | None, rate_hz: float | None,
                   repair: bool) -> list[RawTest]:  # fmt: skip
    """Every test of a file read by its format declaration (no detection)."""
    from bendpam.errors import InputError
    from bendpam.lab.declared import read_declared

    if dialect is not None or parse_columns(columns):
        raise InputError("format_file: the declaration names the columns and the layout; expected no dialect "
                         "or columns with it")
    p = Path(path)
    verify_input(p)
    return read_declared(p, format_file, pressure_kpa=pressure_kpa, rate_hz=rate_hz, repair=repair)


def read_test(
    path: str | os.PathLike,
    *,
    pressure_kpa: float | None = None,
    dialect: str | None = None,
    columns: Mapping[str, str] | str | None = None,
    rate_hz: float | None = None,
    repair: bool = False,
    format_file: str | os.PathLike | None = None,
) -> RawTest:
    """Read one raw four-point-bending test export.

    Parameters
    ----------
    path : str or os.PathLike
        The export: text (CSV/TXT/DAT/TRA from Zwick testXpert, Instron Bluehill, WaveMatrix
        or console, MTS 793 or TestSuite, Shimadzu Trapezium, plain CSV) or an ``.xlsx``/
        ``.xls`` workbook (extra ``excel``).
    pressure_kpa : float, optional
        Inflation pressure in kPa (0 to 10 000).  Overrides a pressure in the metadata or the
        file name.
    dialect : str, optional
        Force the reported format (one of :data:`FORMATS`).  ``"testxpert"`` also makes the
        decimal comma the default when the data do not show the decimal mark.
    columns : mapping or str, optional
        Columns to use, overriding the automatic choice: ``{"time": NAME, "stroke": NAME,
        "force": NAME}`` (any subset) or ``"time=NAME,stroke=NAME,force=NAME"``.
    rate_hz : float, optional
        Sampling rate (Hz) for a file without a time column.
    repair : bool
        Drop spikes, samples out of order in time and rows with non-finite values, reporting
        each in :attr:`RawTest.warnings` (default: refuse them).  Gaps, clock restarts and
        padding rows are read and reported either way.
    format_file : str or os.PathLike, optional
        A format declaration (TOML, see ``docs/formats.md``): read the file as it says, with no
        detection (:func:`bendpam.lab.declared.read_declared`); ``dialect`` and ``columns`` are
        not allowed with it.  When detection fails, its error says so; a declaration reads
        the file, and :func:`bendpam.lab.suggest.suggest_declaration` drafts one.

    Returns
    -------
    RawTest
        Time in s, stroke in mm and force in N, with the metadata, the pressure in kPa and a
        record of how the file was read.

    Raises
    ------
    ReadError
        For anything that makes the file unreadable, with a one-line ``FILE:LINE: ...`` message.
    bendpam.errors.InputError
        (a ``ValueError``) for a bad option: unknown ``dialect``, a non-finite or out-of-range
        ``pressure_kpa`` or ``rate_hz``, a malformed ``columns``.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "be_150kPa.csv"
    ...     _ = path.write_text("time_s,stroke_mm,force_n\\n0,0.000,11.80\\n0.05,0.027,11.71\\n0.1,0.051,11.54\\n")
    ...     raw = read_test(path)
    >>> raw.dialect, len(raw), raw.pressure_kpa, raw.pressure_source
    ('csv', 3, 150.0, 'filename')
    >>> raw.data["force_n"].tolist()                     # N
    [11.8, 11.71, 11.54]
    """
    if format_file is not None:
        tests = _read_declared(path, format_file, dialect, columns, pressure_kpa, rate_hz, repair)
        if len(tests) != 1:
            what = "specimens" if tests[0].metadata.get("specimen") else "blocks"
            raise ReadError(f"holds {len(tests)} tests ({what}) as declared; read them with read_tests", path)
        return tests[0]
    raw = _read_one(path, pressure_kpa=pressure_kpa, dialect=dialect, columns=columns, rate_hz=rate_hz,
                    repair=repair)  # fmt: skip
    return _the_one(raw, pressure_kpa=pressure_kpa, dialect=dialect, columns=columns, rate_hz=rate_hz, repair=repair)


def _the_one(raw: RawTest, **kw: Any) -> RawTest:
    """read_test's one test: ``raw``, or its sheets joined when they continue one test; refused, naming them, when
    the file holds several tests (specimens, sheets or blocks)."""
    labels = _specimen_labels(raw)
    if len(labels) > 1:
        raise ReadError(f"holds {len(labels)} specimens side by side ({', '.join(labels[:4])}"
                        f"{', ...' if len(labels) > 4 else ''}); read them with read_tests",
                        raw.path, raw.header_line)  # fmt: skip
    sheets = _other_sheets(raw, **kw)
    joined = _join_sheets([raw, *sheets]) if sheets and raw.dialect != "zs2" else []
    if len(joined) == 1:
        return joined[0]
    if sheets:
        names = ", ".join(repr(s) for s in [raw.metadata.get("sheet"), *[t.metadata.get("sheet") for t in sheets]])
        where = "specimens of the series" if raw.dialect == "zs2" else "sheets"
        raise ReadError(f"holds {len(sheets) + 1} tests on the {where} {names}; read them with read_tests",
                        raw.path)  # fmt: skip
    parts = _split_blocks(raw)
    if len(parts) > 1:
        lines = ", ".join(str(t.header_line) for t in parts[1:4])
        raise ReadError(f"holds {len(parts)} tests in separate blocks (time restarts in the blocks at line(s) "
                        f"{lines}); read them with read_tests", raw.path, parts[1].header_line)  # fmt: skip
    return raw


def _read_one(path: str | os.PathLike, *, pressure_kpa: float | None, dialect: str | None,
              columns: Mapping[str, str] | str | None, rate_hz: float | None, repair: bool,
              specimen: int | None = None, sheet: str | None = None) -> RawTest:  # fmt: skip
    """One pass of the reader: the chosen block (and the blocks that repeat its header) of one specimen."""
    pressure_kpa, rate_hz = _check_options(pressure_kpa, dialect, rate_hz)
    overrides = parse_columns(columns)
    p = Path(path)
    verify_input(p)  # raw files of a bendpam set (simulate-test) are read only as bendpam wrote them
    kw: dict[str, Any] = {"pressure_kpa": pressure_kpa, "dialect": dialect, "overrides": overrides,
                          "rate_hz": rate_hz, "repair": repair, "specimen": specimen,
                          "sheet": sheet}  # fmt: skip
    try:
        parsed = parse_path(p, overrides=overrides, **{k: kw[k] for k in _PARSE_KEYS})
    except ReadError as exc:
        if exc.column is None:  # a declaration reads text exports and workbooks, not native Zwick files
            raise (exc if p.suffix.lower() in ZS2_SUFFIXES else with_declaration_hint(exc)) from None
        # a chosen column with cells that are not numbers (an extensometer removed mid-test): another one?
        found = parse_path(p, overrides=overrides, want_data=False, **{k: kw[k] for k in _PARSE_KEYS})
        return _other_column(exc, found, _alternates(found, overrides), p, dialect or _classify_format(found), **kw)
    fmt = dialect or _classify_format(parsed)
    alternates = _alternates(parsed, overrides)
    try:
        raw = assemble(parsed, fmt=fmt, pressure_kpa=pressure_kpa, rate_hz=rate_hz, repair=repair)
    except ReadError as exc:
        try:
            raw = _other_column(exc, parsed, alternates, p, fmt, **kw)
        except ReadError as final:  # a unit detection did not know: a declaration names it
            raise (with_declaration_hint(final) if final.message.startswith("unknown ") else final) from None
    for role, names in alternates.items():
        if role != "time":
            raw = _replace_dead(raw, role, names, path=path, **kw)
        elif len(raw.segments) > 1 and bool(np.any(np.diff(raw.data["time_s"].to_numpy()) < 0)):
            raw = _steadier_time(raw, names, p, fmt, **kw)  # the clock restarts: is another one steadier?
    return raw


def _steadier_time(raw: RawTest, names: list[str], path: Path, fmt: str, **kw: Any) -> RawTest:
    """A time column that restarts or pauses: another time column that runs through, if one does."""
    for name in names:
        try:
            parsed = parse_path(path, overrides={**kw["overrides"], "time": name},
                                **{k: kw[k] for k in _PARSE_KEYS})  # fmt: skip
            alt = assemble(parsed, fmt=fmt, pressure_kpa=kw["pressure_kpa"], rate_hz=kw["rate_hz"],
                           repair=kw["repair"])  # fmt: skip
        except ReadError:
            continue
        if len(alt) == len(raw) and len(alt.segments) < len(raw.segments):
            old = raw.channels["time"]["source"]
            alt.channels["time"]["why"] = (f"{old!r} restarts or pauses ({len(raw.segments)} segments); "
                                           f"{name!r} runs through ({len(alt.segments)})")  # fmt: skip
            alt.warnings.append(f"time column {old!r} restarts or pauses; read {name!r}, which runs through")
            return alt
    return raw


def _other_column(exc: ReadError, parsed: Parsed, alternates: dict[str, list[str]], path: Path, fmt: str,
                  **kw: Any) -> RawTest:  # fmt: skip
    """The refusal names a chosen column (time that goes back, a cell that is not a number): try the others
    named for its role; the first that reads is used, with a warning; else the refusal stands."""
    chosen = parsed.block.choice.chosen if parsed.block.choice is not None else {}
    role = next((r for r, col in chosen.items() if col.source == exc.column), None)
    if role is None or not alternates.get(role):
        raise exc
    for name in alternates[role]:
        try:
            alt = parse_path(path, overrides={**kw["overrides"], role: name}, **{k: kw[k] for k in _PARSE_KEYS})
            raw = assemble(alt, fmt=fmt, pressure_kpa=kw["pressure_kpa"], rate_hz=kw["rate_hz"],
                           repair=kw["repair"])  # fmt: skip
        except ReadError:
            continue
        raw.channels[role]["why"] = f"{exc.column!r} cannot be read ({exc.message}); {name!r} can"
        raw.warnings.append(f"{role} column {exc.column!r} not used (line {exc.line}: {exc.message}); read {name!r}")
        return raw
    raise exc


_ROLE_COL = {"stroke": "stroke_mm", "force": "force_n"}
_PARSE_KEYS = ("dialect", "rate_hz", "repair", "specimen", "sheet")  # what parse_path takes of _read_one's keywords
# below these ranges (mm, N) a channel is compared with the other channels named for its role
_SMALL_SPAN = {"stroke": 0.1, "force": 10.0}


def _alternates(parsed: Parsed, overrides: Mapping[str, str]) -> dict[str, list[str]]:
    """Other columns named for time, stroke and force (best rank first), for roles not given by the caller."""
    from bendpam.lab.channels import classify_column

    blk = parsed.block
    chosen = blk.choice.chosen if blk.choice is not None else {}
    out: dict[str, list[str]] = {}
    for role in ("time", "stroke", "force"):
        if role in overrides or role not in chosen:
            continue
        cands = [c for col in blk.columns for c in classify_column(col)
                 if c.role == role and c.unit_ok and c.rank > 0 and col.index != chosen[role].index]  # fmt: skip
        names = [c.column.source for c in sorted(cands, key=lambda c: -c.rank)]
        if names:
            out[role] = names[:3]
    return out


def looks_dead(x: np.ndarray) -> bool:
    """A channel whose whole range is within its sample-to-sample noise (a dead or unplugged sensor).

    Parameters
    ----------
    x : numpy.ndarray
        The channel's samples.

    Returns
    -------
    bool
        True when the range (max - min) is below 20 median steps, or zero.

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> looks_dead(0.2 * rng.standard_normal(500)), looks_dead(np.linspace(0.0, 373.0, 500))   # N
    (True, False)
    """
    v = np.asarray(x, dtype=np.float64)
    if not np.isfinite(v).all():
        v = v[np.isfinite(v)]
    if v.size < 10:
        return False
    span = float(v.max() - v.min())
    step = float(np.median(np.abs(np.diff(v[:200_001]))))  # the noise, from the first 200 000 samples
    return span == 0.0 or span < 20.0 * step


def _stuck_tail(x: np.ndarray) -> bool:
    """The last quarter of a moving channel holds one value (an extensometer saturated or taken off)."""
    n = x.size
    return n >= 40 and float(np.ptp(x)) > 0 and float(np.ptp(x[(3 * n) // 4:])) == 0.0


def _unstuck(raw: RawTest, names: list[str], *, path: str | os.PathLike, **kw: Any) -> RawTest:
    """A stroke stuck over the last quarter (an extensometer): a named displacement that still moves there."""
    overrides = dict(kw.pop("overrides"))
    for name in names:
        try:
            parsed = parse_path(Path(path), overrides={**overrides, "stroke": name}, **{k: kw[k] for k in _PARSE_KEYS})
            alt = assemble(parsed, fmt=raw.dialect, pressure_kpa=kw["pressure_kpa"], rate_hz=kw["rate_hz"],
                           repair=kw["repair"])  # fmt: skip
        except ReadError:
            continue
        y = alt.data["stroke_mm"].to_numpy()
        if len(alt) == len(raw) and not _stuck_tail(y) and not looks_dead(y):
            old = raw.channels["stroke"]["source"]
            alt.channels["stroke"]["why"] = f"{old!r} is stuck over the last quarter of the test; {name!r} moves"
            alt.warnings.append(f"the stroke column {old!r} is stuck over the last quarter of the test "
                                f"(saturated or taken off); read {name!r}, which moves")  # fmt: skip
            return alt
    return raw


def _replace_dead(raw: RawTest, role: str, names: list[str], *, path: str | os.PathLike, **kw: Any) -> RawTest:
    """Read an alternate column when the chosen one looks dead and the alternate moves (10x its range or more)."""
    col = _ROLE_COL[role]
    x = raw.data[col].to_numpy()
    span = float(np.ptp(x)) if x.size else 0.0
    dead = looks_dead(x)
    if role == "stroke" and not dead and _stuck_tail(x):
        return _unstuck(raw, names, path=path, **kw)
    if not dead and span >= _SMALL_SPAN[role]:
        return raw
    factor = 10.0 if dead else 100.0  # a quiet channel gives way only to one that moves 100 times more
    overrides = dict(kw.pop("overrides"))
    for name in names:
        try:
            parsed = parse_path(Path(path), overrides={**overrides, role: name}, **{k: kw[k] for k in _PARSE_KEYS})
            alt = assemble(parsed, fmt=raw.dialect, pressure_kpa=kw["pressure_kpa"], rate_hz=kw["rate_hz"],
                           repair=kw["repair"])  # fmt: skip
        except ReadError:
            continue
        y = alt.data[col].to_numpy()
        if len(alt) == len(raw) and not looks_dead(y) and float(np.ptp(y)) >= factor * span:
            old = raw.channels[role]["source"]
            what = "within its noise" if dead else f"against {float(np.ptp(y)):.3g} for {name!r}"
            alt.channels[role]["why"] = (f"{old!r} looks dead (range {span:.3g} {what}); "
                                         f"{name!r} moves over {float(np.ptp(y)):.3g}")  # fmt: skip
            alt.warnings.append(f"the {role} column {old!r} looks dead (range {span:.3g} {what}); "
                                f"read {name!r} instead")  # fmt: skip
            return alt
    return raw


def _other_sheets(raw: RawTest, **kw: Any) -> list[RawTest]:
    """The tests on the sheets of a workbook after the one read (testXpert writes a 'Values' sheet per specimen),
    or on the specimens of a native Zwick file after the first."""
    sheet = raw.metadata.get("sheet")
    if not sheet:
        return []
    from bendpam.lab.excel import workbook_sheets
    from bendpam.lab.zwick import read_zs2

    try:
        if raw.dialect == "zs2":
            names = [s.name for s in read_zs2(raw.path)]
        else:
            names = [s.name for s in workbook_sheets(raw.path)]
    except Exception:  # the workbook was read a moment ago; a failure now leaves the first test alone
        return []
    later = names[names.index(sheet) + 1:] if sheet in names else []
    out = []
    for name in later:
        try:
            out.append(_read_one(raw.path, sheet=name, **kw))
        except (ReadError, ValueError):
            continue
    return out


def _sheet_continues(a: RawTest, b: RawTest) -> bool:
    """Does sheet ``b`` continue the test of sheet ``a``: the same channels, and time running on from it (as blocks
    of a text file continue one test)?  A sheet per specimen (testXpert) starts its time again."""
    if any(a.channels.get(r, {}).get("source") != b.channels.get(r, {}).get("source") for r in ROLES):
        return False
    ta, tb = a.data["time_s"].to_numpy(), b.data["time_s"].to_numpy()
    return bool(a.channels["time"].get("source") is not None and ta.size and tb.size and tb[0] > ta[-1])


def _join_sheets(tests: list[RawTest]) -> list[RawTest]:
    """The tests of a workbook's sheets with the runs of sheets that continue one test (:func:`_sheet_continues`; a
    TA Instruments TRIOS export writes a sheet per step of the procedure) joined, each sheet a block of it."""
    import pandas as pd

    from bendpam.lab.checks import time_structure

    groups: list[list[RawTest]] = [[tests[0]]]
    for t in tests[1:]:
        if _sheet_continues(groups[-1][-1], t):
            groups[-1].append(t)
        else:
            groups.append([t])
    out = []
    for g in groups:
        if len(g) == 1:
            out.append(g[0])
            continue
        data = pd.concat([t.data for t in g], ignore_index=True)
        starts = np.cumsum([0] + [len(t) for t in g[:-1]])
        counters = [t.cycle_counter for t in g if t.cycle_counter is not None]
        names = [str(t.metadata.get("sheet")) for t in g]
        warns = list(dict.fromkeys(w for t in g for w in t.warnings))
        warns.append(f"the {len(g)} sheets {names[0]!r} to {names[-1]!r} continue one test (the same channels, "
                     f"time running on): read as one test of {len(data)} samples, each sheet a block")
        blocks = [{"line": t.header_line, "sheet": n, "columns": list(t.data.columns), "rows": len(t), "read": True,
                   "start": int(a), "continues": k > 0}
                  for k, (t, n, a) in enumerate(zip(g, names, starts, strict=True))]
        out.append(dataclasses.replace(
            g[0], data=data, warnings=warns, blocks=blocks,
            segments=time_structure(data["time_s"].to_numpy()).segments(len(data)),
            cycle_counter=np.concatenate(counters) if len(counters) == len(g) else None,
            metadata={**g[0].metadata, "sheets": "; ".join(names)}))
    return out


def _specimen_labels(raw: RawTest) -> list[str]:
    for b in raw.blocks:
        if b.get("read") and b.get("specimens"):
            return list(b["specimens"])
    return []


def _split_blocks(raw: RawTest) -> list[RawTest]:
    """The tests of a file whose blocks restart time: one per run of blocks that continue each other."""
    read = [b for b in raw.blocks if b.get("read")]
    cuts = [b for b in read[1:] if not b.get("continues", True)]
    if not cuts:
        return [raw]
    groups: list[list[dict[str, Any]]] = [[]]
    for b in read:
        if b in cuts:
            groups.append([])
        groups[-1].append(b)
    out = []
    n = len(raw)
    for k, group in enumerate(groups):
        a = int(group[0]["start"])
        z = int(groups[k + 1][0]["start"]) if k + 1 < len(groups) else n
        segs = [(max(s, a) - a, min(e, z) - a) for s, e in raw.segments if s < z and e > a]
        counter = raw.cycle_counter[a:z] if raw.cycle_counter is not None else None
        out.append(dataclasses.replace(
            raw, data=raw.data.iloc[a:z].reset_index(drop=True), block=k + 1, segments=segs,
            cycle_counter=counter, header_line=int(group[0]["line"]),
            data_lines=(int(group[0]["lines"][0]), int(group[-1]["lines"][1])), warnings=list(raw.warnings)))
    return out


def read_tests(
    path: str | os.PathLike,
    *,
    pressure_kpa: float | None = None,
    dialect: str | None = None,
    columns: Mapping[str, str] | str | None = None,
    rate_hz: float | None = None,
    repair: bool = False,
    format_file: str | os.PathLike | None = None,
) -> list[RawTest]:
    """Read every test of a raw export: one per specimen side by side, one per separate block.

    Parameters
    ----------
    path, pressure_kpa, dialect, columns, rate_hz, repair, format_file
        As for :func:`read_test`.

    Returns
    -------
    list of RawTest
        One test for a file of one test (the same as :func:`read_test`); for several specimens
        side by side one per specimen (:attr:`RawTest.specimen` names it); for several blocks
        that do not continue one test, one per block (:attr:`RawTest.block` numbers it).

    Raises
    ------
    ReadError, bendpam.errors.InputError
        As for :func:`read_test`.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "be_150kPa.csv"
    ...     _ = path.write_text("time_s,stroke_mm,force_n\\n0,0.000,11.80\\n0.05,0.027,11.71\\n")
    ...     tests = read_tests(path)
    >>> len(tests), len(tests[0]), tests[0].specimen, tests[0].block
    (1, 2, None, None)
    """
    if format_file is not None:
        return _read_declared(path, format_file, dialect, columns, pressure_kpa, rate_hz, repair)
    kw: dict[str, Any] = {"pressure_kpa": pressure_kpa, "dialect": dialect, "columns": columns,
                          "rate_hz": rate_hz, "repair": repair}  # fmt: skip
    raw = _read_one(path, **kw)
    labels = _specimen_labels(raw)
    if len(labels) <= 1:
        sheets = _other_sheets(raw, **kw)
        if sheets or raw.dialect == "zs2":  # a native Zwick file names its specimens, even a lone one
            tests = [raw, *sheets] if raw.dialect == "zs2" else _join_sheets([raw, *sheets])
            if len(tests) == 1 and raw.dialect != "zs2":  # every sheet continues one test: the workbook is that test
                return tests
            return [dataclasses.replace(t, specimen=t.metadata.get("sheet")) for t in tests]
        return _split_blocks(raw)
    out = [dataclasses.replace(raw, specimen=labels[0])]
    for k in range(1, len(labels)):
        other = _read_one(path, specimen=k, **kw)
        out.append(dataclasses.replace(other, specimen=labels[k]))
    return out


def detect_dialect(path_or_text_lines: str | os.PathLike | Iterable[str]) -> str:
    """Format of a raw test export, from its content (never from the extension).

    Parameters
    ----------
    path_or_text_lines : str, os.PathLike or iterable of str
        A file path, or the file's lines (a single string containing line breaks is taken as
        the text itself).

    Returns
    -------
    str
        One of :data:`FORMATS`.

    Raises
    ------
    ReadError
        If no data block with time (or a rate), stroke and force is found.

    Examples
    --------
    >>> detect_dialect("Test time;Standard travel;Standard force\\ns;mm;N\\n0;0,000;11,80\\n0,05;0,027;11,71\\n")
    'testxpert'
    """
    sources, path = text_source(path_or_text_lines)
    kw: dict[str, Any] = {"dialect": None, "overrides": {}, "rate_hz": None, "repair": False,
                          "want_data": False}  # fmt: skip
    if sources is None:
        assert path is not None
        parsed = parse_path(path, **kw)
    else:
        parsed = parse_source(sources[0], **kw)
    return _classify_format(parsed)



# ------------------------------------------------------------------------------------------------
# inspection
# ------------------------------------------------------------------------------------------------
def _finite_or_none(v: Any) -> float | None:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return None
    return f if math.isfinite(f) else None


def inspect_file(
    path: str | os.PathLike,
    *,
    pressure_kpa: float | None = None,
    columns: Mapping[str, str] | str | None = None,
    rate_hz: float | None = None,
    repair: bool = False,
    format_file: str | os.PathLike | None = None,
) -> dict[str, Any]:
    """How a raw test export reads, as a JSON-ready dict (never raises for a bad file).

    Parameters
    ----------
    path : str or os.PathLike
        The export.
    pressure_kpa, columns, rate_hz, repair, format_file
        As for :func:`read_test`.

    Returns
    -------
    dict
        ``{"file", "format", "encoding", "delimiter", "decimal", "header_line", "n_samples",
        "columns": {"time": {"source", "unit", "candidates"}, "stroke": {...}, "force": {...}},
        "other_columns", "first": {"time_s", "stroke_mm", "force_n"}, "last": {...},
        "metadata", "pressure_kpa", "cycle_counter": {"source", "max"} or None, "warnings",
        "header": {"line", "candidates"}, "specimen", "block", "segments"}``
        (and ``"tests"``, one summary per test, for a file of several specimens or blocks; the
        other keys describe the first); ``candidates`` list every column or row scored, each
        ``{"column" or "line", "score", "reasons"}``, best first.  For a file that cannot be read
        ``{"file", "error"}``.  No NaN or infinity anywhere
        (None instead).  Values are in s, mm, N and kPa.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "be_150kPa.csv"
    ...     _ = path.write_text("time_s,stroke_mm,force_n\\n0,0.000,11.80\\n0.05,0.027,11.71\\n")
    ...     info = inspect_file(path)
    ...     bad = inspect_file(Path(folder) / "missing.csv")
    >>> info["format"], info["n_samples"], info["columns"]["force"]["source"], info["pressure_kpa"]
    ('csv', 2, 'force_n', 150.0)
    >>> [c["column"] for c in info["columns"]["force"]["candidates"]], info["header"]["line"]
    (['force_n'], 1)
    >>> sorted(bad)
    ['error', 'file']
    """
    from bendpam.errors import BendpamError

    name = os.fspath(path)
    try:
        tests = read_tests(path, pressure_kpa=pressure_kpa, columns=columns, rate_hz=rate_hz,
                           repair=repair, format_file=format_file)  # fmt: skip
    except (BendpamError, ValueError, OSError) as exc:
        return {"file": name, "error": str(exc)}
    info = _inspect_one(name, tests[0])
    if len(tests) > 1:
        info["tests"] = [{"specimen": t.specimen, "block": t.block, "n_samples": len(t),
                          "first": _row(t, 0), "last": _row(t, len(t) - 1)} for t in tests]  # fmt: skip
    return info


def _row(raw: RawTest, i: int) -> dict[str, float | None]:
    return {c: _finite_or_none(raw.data[c].iat[i]) for c in COLUMNS}


def _inspect_one(name: str, raw: RawTest) -> dict[str, Any]:
    """The inspection dict of one test."""
    d = raw.data
    chosen = next((b for b in raw.blocks if b.get("header_candidates") is not None), {})
    cands = chosen.get("channel_candidates", {})

    def row(i: int) -> dict[str, float | None]:
        return {c: _finite_or_none(d[c].iat[i]) for c in COLUMNS}

    counter = None
    if raw.cycle_counter is not None:
        c = raw.cycle_counter[np.isfinite(raw.cycle_counter)]
        counter = {"source": raw.cycle_counter_source,
                   "max": _finite_or_none(c.max()) if c.size else None}  # fmt: skip
    return {
        "file": name,
        "format": raw.dialect,
        "encoding": raw.encoding,
        "delimiter": raw.delimiter,
        "decimal": raw.decimal,
        "header_line": raw.header_line,
        "n_samples": len(d),
        "columns": {
            r: {"source": raw.channels[r]["source"], "unit": raw.channels[r]["unit"],
                "candidates": list(cands.get(r, []))} for r in ROLES
        },
        "other_columns": list(raw.other_columns),
        "first": row(0),
        "last": row(len(d) - 1),
        "metadata": dict(raw.metadata),
        "pressure_kpa": _finite_or_none(raw.pressure_kpa) if raw.pressure_kpa is not None else None,
        "cycle_counter": counter,
        "warnings": list(raw.warnings),
        "header": {"line": raw.header_line, "candidates": list(chosen.get("header_candidates", []))},
        "specimen": raw.specimen,
        "block": raw.block,
        "segments": [list(s) for s in raw.segments],
    }


_DELIM_NAMES = {"\t": "tab", ";": "';'", ",": "','", " ": "space"}


def format_inspection(info: Mapping[str, Any]) -> str:
    """A short readable multi-line summary of one :func:`inspect_file` result.

    >>> info = {"file": "be_150kPa.csv", "format": "csv", "encoding": "utf-8", "delimiter": ",",
    ...         "decimal": ".", "header_line": 1, "n_samples": 2,
    ...         "columns": {r: {"source": f"{r}_col", "unit": u} for r, u in (("time", "s"), ("stroke", "mm"),
    ...                                                                       ("force", "N"))},
    ...         "first": {"time_s": 0.0, "stroke_mm": 0.0, "force_n": 11.8},
    ...         "last": {"time_s": 0.05, "stroke_mm": 0.027, "force_n": 11.71}, "pressure_kpa": 150.0}
    >>> print(format_inspection(info))
    be_150kPa.csv
      format csv, encoding utf-8, delimiter ',', decimal '.', header at line 1
      2 samples
      time   <- 'time_col' (s)
      stroke <- 'stroke_col' (mm)
      force  <- 'force_col' (N)
      first: 0 s, 0 mm, 11.8 N
      last:  0.05 s, 0.027 mm, 11.71 N
      pressure: 150 kPa
    """
    name = info.get("file", "?")
    if "error" in info:
        return f"{name}\n  error: {info['error']}"
    out = [str(name)]
    delim = _DELIM_NAMES.get(str(info.get("delimiter")), repr(info.get("delimiter")))
    if info.get("format") == "zs2":  # binary: no delimiter or header line of its own
        out.append(f"  format zs2 (native Zwick testXpert file), specimen {info.get('specimen')!r}")
    else:
        out.append(
            f"  format {info.get('format')}, encoding {info.get('encoding')}, delimiter {delim}, "
            f"decimal {info.get('decimal')!r}, header at line {info.get('header_line')}"
        )
    out.append(f"  {info.get('n_samples')} samples")
    tests = info.get("tests") or []
    if tests:
        names = [str(t.get("specimen") or f"block {t.get('block')}") for t in tests]
        shown = ", ".join(names[:6]) + (", ..." if len(names) > 6 else "")
        out.append(f"  {len(tests)} tests in the file ({shown}); the first is shown")
    cols = info.get("columns") or {}
    for role in ROLES:
        c = cols.get(role) or {}
        src = c.get("source")
        out.append(f"  {role:<6} <- {src!r} ({c.get('unit')})" if src is not None
                   else f"  {role:<6} <- made from a sampling rate")  # fmt: skip
    first, last = info.get("first") or {}, info.get("last") or {}

    def triple(r: Mapping[str, Any]) -> str:
        vals = []
        for key, unit in (("time_s", "s"), ("stroke_mm", "mm"), ("force_n", "N")):
            v = r.get(key)
            vals.append(f"{v:.6g} {unit}" if isinstance(v, (int, float)) else f"? {unit}")
        return ", ".join(vals)

    out.append(f"  first: {triple(first)}")
    out.append(f"  last:  {triple(last)}")
    others = info.get("other_columns") or []
    if others:
        shown = ", ".join(others[:8]) + (", ..." if len(others) > 8 else "")
        out.append(f"  other columns: {shown}")
    p = info.get("pressure_kpa")
    out.append(f"  pressure: {p:g} kPa" if isinstance(p, (int, float)) else "  pressure: unknown")
    cc = info.get("cycle_counter")
    if cc:
        out.append(f"  cycle counter: {cc.get('source')!r} (max {cc.get('max')})")
    for w in info.get("warnings") or []:
        out.append(f"  warning: {w}")
    return "\n".join(out)

