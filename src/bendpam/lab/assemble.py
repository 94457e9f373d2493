"""From the numbers of a parsed export to a :class:`~bendpam.lab.rawtest.RawTest`.

:func:`assemble` takes what :func:`bendpam.lab.parser.parse_source` read and makes the test, in
steps, each a function here:

1. join the chunks of each column (:func:`_join`);
2. convert the units to s, mm and N (:func:`_convert_units`), or make the time from a sampling
   rate when the block has no time column (:func:`_time_from_rate`);
3. check the values (:mod:`bendpam.lab.checks`): isolated spikes and absurd magnitudes
   (:func:`_drop_spikes`), padding rows at the end (:func:`_drop_padding`), samples out of
   order in time, restarts, repeated stamps and gaps (:func:`_check_time`: the segments), the
   machine's cycle counter (:func:`_check_counter`); a wrong number is refused or, with
   ``repair=True``, removed and reported; what labs write (gaps, restarts, padding) is read and
   reported;
4. the metadata and the pressure: option, metadata line or file name (:func:`_metadata`,
   :func:`_choose_pressure`);
5. what else the file holds (:func:`_file_warnings`): other blocks, text after the data,
   undecodable bytes.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from bendpam.lab.channels import (
    DEFAULT_UNIT,
    ROLES,
    UNIT_HINT,
    ChannelChoice,
    canonical_unit,
    classify_column,
    unit_factor,
)
from bendpam.lab.checks import find_spikes, padding_rows, resent_rows, spread_repeats, time_structure
from bendpam.lab.parser import Block, ColumnData, Parsed, Parser
from bendpam.lab.pressure import (
    PRESSURE_RANGE_TEXT,
    is_pressure_key,
    parse_pressure,
    pressure_from_filename,
    pressure_out_of_range,
)
from bendpam.lab.rates import MAX_END_RECORDS, counted_samples, fill_empty_cells
from bendpam.lab.rawtest import COLUMNS, RawTest
from bendpam.lab.read_error import ReadError, show

__all__ = ["assemble", "check_values"]

_ROLE_COLUMN = dict(zip(ROLES, COLUMNS, strict=True))
_MAX_WARN_LINES = 5  # line numbers quoted in a message
_MAX_TIME_S = 1e9  # absurd beyond (about 30 years)
_MAX_STROKE_MM = 1e6
_MAX_FORCE_N = 1e9

Channels = dict[str, dict[str, str | None]]


def _lines_text(lines: Iterable[int]) -> str:
    ls = list(lines)
    shown = ", ".join(str(v) for v in ls[:_MAX_WARN_LINES])
    return shown + (f" (and {len(ls) - _MAX_WARN_LINES} more)" if len(ls) > _MAX_WARN_LINES else "")


def _fmt(v: float) -> str:
    return f"{v:.6g}"


@dataclass
class _Samples:
    """The columns in library units, the line of each sample and the cycle counter, as checked so far."""

    values: dict[str, np.ndarray]
    lines: np.ndarray
    counter: np.ndarray | None

    def keep(self, mask: np.ndarray) -> None:
        """Keep the samples where ``mask`` is True (every column, the lines and the counter)."""
        for role in self.values:
            self.values[role] = self.values[role][mask]
        self.lines = self.lines[mask]
        if self.counter is not None:
            self.counter = self.counter[mask]


def _column(data: ColumnData, role: str) -> np.ndarray:
    parts = data.cols.pop(role)
    arr = np.concatenate(parts) if len(parts) != 1 else parts[0]
    parts.clear()
    return arr


def _join(data: ColumnData, warnings: list[str]) -> np.ndarray:
    """The line of every sample, in one array (and a warning for the rows dropped while reading)."""
    lines = np.concatenate(data.lines) if len(data.lines) != 1 else data.lines[0]
    data.lines.clear()
    if data.dropped_nonfinite:
        warnings.append(
            f"dropped {len(data.dropped_nonfinite)} row(s) with a non-finite or empty value at "
            f"line(s) {_lines_text(data.dropped_nonfinite)}"
        )
    return lines


def _convert_units(data: ColumnData, ch: ChannelChoice, blk: Block, label: Path | str, warnings: list[str]
                   ) -> tuple[dict[str, np.ndarray], dict[str, str], Channels]:  # fmt: skip
    """Each chosen column in s, mm or N: ``(values, source_units, channels)``."""
    source_units: dict[str, str] = {}
    channels: Channels = {}
    values: dict[str, np.ndarray] = {}
    for role in ROLES:
        if role not in ch.chosen:
            continue
        col = ch.chosen[role]
        unit = col.unit
        if not unit:
            unit = DEFAULT_UNIT[role]
            warnings.append(f"no unit for the {role} column {col.source!r}; assumed {unit}")
        f = unit_factor(role, unit)
        if f is None:
            raise ReadError(
                f"unknown {role} unit {show(unit)} for column {col.source!r}; expected "
                f"{UNIT_HINT[role]}",
                label,
                col.unit_line or blk.header_line,
                col.source,
            )
        arr = _column(data, role)
        if f != 1.0:
            arr *= f
        values[role] = arr
        source_units[_ROLE_COLUMN[role]] = canonical_unit(role, unit)
        channels[role] = {"source": col.source, "unit": canonical_unit(role, unit),
                          "why": ch.why.get(role, "")}  # fmt: skip
    return values, source_units, channels


def _time_from_rate(values: dict[str, np.ndarray], source_units: dict[str, str], channels: Channels, p: Parser,
                    blk: Block, rate_hz: float | None, warnings: list[str]) -> float | None:  # fmt: skip
    """Make the time from the sampling rate when the block has none; the rate used (Hz) or None."""
    sample_rate: float | None = None
    if "time" not in values:
        got = p.rate_from_metadata(blk.header_line) if rate_hz is None else (float(rate_hz), "the rate_hz option")
        n = values["stroke"].size
        if got is None:  # no time and no rate: the sample number stands for the time, and says so
            values["time"] = np.arange(n, dtype=np.float64)
            source_units["time_s"] = "sample"
            channels["time"] = {"source": None, "unit": "sample",
                                "why": "no time column and no sampling rate: the sample number (0, 1, 2, ...)"}
            warnings.append("no time column and no sampling rate known: time_s is the sample number (one per "
                            "second as if sampled at 1 Hz); give the sampling rate for real times. Curvature and "
                            "moment do not depend on it")
            return None
        sample_rate, rate_src = got
        values["time"] = np.arange(n, dtype=np.float64) / sample_rate
        source_units["time_s"] = "s"
        channels["time"] = {
            "source": None,
            "unit": "s",
            "why": f"no time column; made from the sampling rate {sample_rate:g} Hz ({rate_src})",
        }
        warnings.append(f"no time column: time made from {sample_rate:g} Hz ({rate_src})")
    elif rate_hz is not None:
        warnings.append(f"rate_hz={rate_hz:g} ignored: the file has a time column")
    return sample_rate


def _drop_spikes(samples: _Samples, channels: Channels, label: Path | str, repair: bool,
                 warnings: list[str]) -> None:  # fmt: skip
    """Refuse (or drop, with ``repair``) isolated spikes and absurd magnitudes in the columns read from the file."""
    keep = np.ones(samples.lines.size, dtype=bool)
    limits = {"time": _MAX_TIME_S, "stroke": _MAX_STROKE_MM, "force": _MAX_FORCE_N}
    units_shown = {"time": "s", "stroke": "mm", "force": "N"}
    lines = samples.lines
    scratch = np.empty(lines.size)  # one temporary for the three columns
    for role in ("time", "stroke", "force"):
        if channels[role]["source"] is None:
            continue
        x = samples.values[role]
        name = channels[role]["source"]
        spikes = find_spikes(x, scratch)
        lim = limits[role]
        absurd = (np.flatnonzero((x > lim) | (x < -lim)) if (x.max() > lim or x.min() < -lim)
                  else np.empty(0, dtype=np.int64))  # |x| > limit, without a copy of x
        bad = np.union1d(spikes, absurd)
        if bad.size:
            i = int(bad[0])
            nb = [x[j] for j in (i - 1, i + 1) if 0 <= j < x.size and j not in set(bad[:20].tolist())]
            around = f" where the neighbours read {', '.join(_fmt(v) for v in nb)} {units_shown[role]}" if nb else ""
            where = _lines_text(lines[bad].tolist())
            if not repair:
                raise ReadError(
                    f"isolated spike in column {name!r}: {_fmt(x[i])} {units_shown[role]}{around} "
                    f"({bad.size} such sample(s), at line(s) {where}); expected values in the "
                    "column's range (read with repair=True to drop them)",
                    label,
                    int(lines[i]),
                    name,
                )
            keep[bad] = False
            warnings.append(
                f"dropped {bad.size} spike sample(s) in column {name!r} at line(s) {where}"
            )
    if not keep.all():
        samples.keep(keep)


def _fill_empty(samples: _Samples, data: ColumnData, channels: Channels, label: Path | str, repair: bool,
                warnings: list[str]) -> None:  # fmt: skip
    """Empty cells of time, stroke or force: interpolated, dropped or refused by their pattern.

    The patterns are those of :mod:`bendpam.lab.rates` (a channel sampled at another rate, a column that ends first).
    """
    clocks = {}
    for name, col in data.clocks.items():
        arr = _column(data, name)
        clocks[name] = (arr * (unit_factor("time", col.unit or "s") or 1.0), col.source)
    sources = {role: str(ch["source"] or role) for role, ch in channels.items()}
    keep = fill_empty_cells(samples.values, samples.lines, sources, clocks, data.empty_first, label, repair,
                            warnings)  # fmt: skip
    if not keep.all():
        samples.keep(keep)


def _drop_uncounted(samples: _Samples, counted: tuple[int, str] | None, warnings: list[str]) -> None:
    """Drop the last rows past the number of samples the metadata declare (end records), when a few."""
    if counted is None:
        return
    k = samples.lines.size - counted[0]
    if 1 <= k <= MAX_END_RECORDS and counted[0] >= 2:
        warnings.append(f"the metadata count {counted[0]} samples ({counted[1]}): the last {k} row(s) at "
                        f"line(s) {_lines_text(samples.lines[-k:].tolist())} are end records, not samples; dropped")
        keep = np.ones(samples.lines.size, dtype=bool)
        keep[-k:] = False
        samples.keep(keep)


def _drop_padding(samples: _Samples, channels: Channels, warnings: list[str]) -> None:
    """Drop padding rows at the end (rows of zeros, an end record whose time goes back to the start)."""
    v = samples.values
    if channels["time"]["source"] is None and channels["stroke"]["source"] is None:
        return
    k = padding_rows(v["time"], v["stroke"], v["force"]) if channels["time"]["source"] is not None else \
        padding_rows(np.zeros_like(v["force"]), v["stroke"], v["force"])
    if k:
        lines = samples.lines[-k:].tolist()
        warnings.append(f"dropped {k} padding row(s) at the end (zeros, or time back to the start) "
                        f"at line(s) {_lines_text(lines)}")  # fmt: skip
        keep = np.ones(samples.lines.size, dtype=bool)
        keep[-k:] = False
        samples.keep(keep)


def _check_time(samples: _Samples, channels: Channels, label: Path | str, repair: bool,
                warnings: list[str]) -> list[tuple[int, int]]:  # fmt: skip
    """Refuse (or drop, with ``repair``) samples out of order; report resets, repeats and gaps; the segments."""
    t = samples.values["time"]
    if channels["time"]["source"] is None:
        return [(0, t.size)]
    ts = time_structure(t)
    tname = channels["time"]["source"]
    if math.isnan(ts.median_step_s):
        raise ReadError(
            f"time does not advance in column {tname!r}: all {t.size} samples at {_fmt(t[0])} s or going back "
            f"(lines {int(samples.lines[0])}-{int(samples.lines[-1])}); expected a time series",
            label, int(samples.lines[0]), tname)  # fmt: skip
    if ts.glitches.size:
        lines = samples.lines
        i = int(ts.glitches[0])
        where = f"({ts.glitches.size} sample(s), at line(s) {_lines_text(lines[ts.glitches].tolist())})"
        if not repair:
            raise ReadError(
                f"time does not increase in column {tname!r}: {_fmt(t[i - 1])} s then {_fmt(t[i])} s, "
                f"then {_fmt(t[min(i + 1, t.size - 1)])} s: a sample out of order {where}; expected "
                "increasing time (read with repair=True to drop such samples)",
                label,
                int(lines[i]),
                tname,
            )
        warnings.append(f"dropped the sample(s) out of order in time {where}")
        k2 = np.ones(t.size, dtype=bool)
        k2[ts.glitches] = False
        samples.keep(k2)
        t = samples.values["time"]
        ts = time_structure(t)
    if ts.resets.size:
        t, ts = _drop_resent(samples, ts, warnings)
    if ts.repeats.size:
        t, ts = _spread_time(samples, ts, tname, warnings)
    lines = samples.lines
    if ts.resets.size:
        i = int(ts.resets[0])
        warnings.append(
            f"time {tname!r} restarts {ts.resets.size} time(s), at line(s) "
            f"{_lines_text(lines[ts.resets].tolist())} (first: {_fmt(t[i - 1])} s then {_fmt(t[i])} s); "
            "each run is a segment of the series"
        )
    if ts.gaps.size:
        i = int(ts.gaps[0])
        warnings.append(
            f"gap in the sampling: {_fmt(t[i] - t[i - 1])} s between line {int(lines[i - 1])} and line "
            f"{int(lines[i])} against a median step of {_fmt(ts.median_step_s)} s ({ts.gaps.size} gap(s), "
            f"at line(s) {_lines_text(lines[ts.gaps].tolist())}); the series is split there"
        )
    return ts.segments(t.size)


def _drop_resent(samples: _Samples, ts, warnings: list[str]):
    """Rows sent twice (:func:`~bendpam.lab.checks.resent_rows`) dropped, with a warning naming their lines; returns
    the times and their :func:`~bendpam.lab.checks.time_structure`."""
    t = samples.values["time"]
    drop = resent_rows(t, samples.values.values(), ts.resets)
    if drop.any():
        warnings.append(f"dropped {int(drop.sum())} row(s) sent twice (time goes back and the rows repeat the ones "
                        f"before exactly), at line(s) {_lines_text(samples.lines[drop].tolist())}")
        samples.keep(~drop)
        t = samples.values["time"]
    return t, time_structure(t)


def _spread_time(samples: _Samples, ts, tname: str, warnings: list[str]):
    """Repeated time stamps, spread evenly over each run of equal stamps (:func:`~bendpam.lab.checks.spread_repeats`)
    with a warning; returns the new times and their :func:`~bendpam.lab.checks.time_structure`.  A row equal to the
    one before in every column is kept too: a coarse clock during a hold, with a quantised force, writes such rows,
    and leaving them out would space the run's other samples wrongly."""
    t, longest = spread_repeats(samples.values["time"])
    warnings.append(
        f"time {tname!r} repeats the previous sample's value at {ts.repeats.size} sample(s), line(s) "
        f"{_lines_text(samples.lines[ts.repeats].tolist())}: a clock coarser than the sampling, or samples sent in "
        f"packets; the samples of each run of equal stamps (up to {longest}) are spread evenly between the runs, so "
        "the times move by at most half a run")
    samples.values["time"] = t
    return t, time_structure(t)


def _check_counter(samples: _Samples, ch: ChannelChoice, data: ColumnData, warnings: list[str]) -> str | None:
    """Leave out a cycle counter with non-numeric cells; the counter's column name, or None."""
    counter = samples.counter
    if counter is not None and not np.isfinite(counter).all():
        bad_line = data.counter_bad_line
        source = ch.counter.source if ch.counter is not None else None
        warnings.append(
            f"cycle counter {source!r} has non-numeric cells"
            + (f" (line {bad_line})" if bad_line else "")
            + "; not used"
        )
        samples.counter = counter = None
    return ch.counter.source if (counter is not None and ch.counter) else None


def _metadata(p: Parser, blk: Block, label: Path | str, pressure_kpa: float | None
              ) -> tuple[dict[str, str], float | None]:  # fmt: skip
    """The metadata before the block read, and the pressure (kPa) of its first pressure line (unless given)."""
    metadata: dict[str, str] = {}
    meta_pressure: float | None = None
    for ln, item in p.meta_items(blk.header_line):
        shown_value = item.shown
        metadata.setdefault(item.key, shown_value)
        if pressure_kpa is None and meta_pressure is None and shown_value:
            is_p, key_unit = is_pressure_key(item.key)
            if is_p:
                try:
                    meta_pressure = parse_pressure(shown_value, key_unit)
                except ReadError as exc:
                    raise ReadError(
                        f"metadata {item.key!r}: {exc.message}", label, ln, item.key
                    ) from None
                if pressure_out_of_range(meta_pressure):
                    raise ReadError(
                        f"metadata {item.key!r}: pressure {_fmt(meta_pressure)} kPa is out of "
                        f"range; {PRESSURE_RANGE_TEXT}",
                        label,
                        ln,
                        item.key,
                    )
    return metadata, meta_pressure


def _choose_pressure(pressure_kpa: float | None, meta_pressure: float | None, path: Path, label: Path | str
                     ) -> tuple[float | None, str | None]:  # fmt: skip
    """The test's pressure (kPa) and where it came from: the option, the metadata, the file name, or none."""
    pressure: float | None
    psource: str | None
    if pressure_kpa is not None:
        pressure, psource = pressure_kpa, "option"
    elif meta_pressure is not None:
        pressure, psource = meta_pressure, "metadata"
    else:
        pressure = pressure_from_filename(path.name)
        psource = "filename" if pressure is not None else None
        if pressure is not None and pressure_out_of_range(pressure):
            raise ReadError(
                f"pressure {_fmt(pressure)} kPa in the file name is out of range; {PRESSURE_RANGE_TEXT}",
                label,
            )
    return pressure, psource


def _file_warnings(parsed: Parsed, warnings: list[str]) -> None:
    """What else the file holds: other data blocks, text after the data, undecodable bytes."""
    p, blk = parsed.parser, parsed.block
    others = [b for b in p.blocks if b is not blk and b not in p.joined]
    if p.joined:
        warnings.append(
            f"the file holds {len(p.joined) + 1} data blocks with the same columns, read one after the other: "
            f"{'; '.join(b.describe() for b in [blk, *p.joined])}"
        )
    if others:
        warnings.append(
            f"the file holds {len(p.blocks)} data blocks; read {blk.describe()}"
            f"{' and the blocks that repeat its header' if p.joined else ''}; "
            f"not read: {'; '.join(b.describe() for b in others)}"
        )
    if p.trailing:
        ln, line = p.trailing[0]
        warnings.append(
            f"{len(p.trailing)} text line(s) after the data were not read (line {ln}: "
            f"{show(line.strip())})"
        )
    if any("\ufffd" in line for _ln, line in p.text[:200]) or any("\ufffd" in n for n in blk.names):
        warnings.append(
            f"undecodable bytes in the text (decoded as {parsed.source.encoding}, shown as "
            "U+FFFD); names were matched without them"
        )


def _channel_candidates(blk: Block) -> dict[str, list[dict[str, Any]]]:
    """Every column that could play each role, with its score (name rank, unit) and reasons."""
    out: dict[str, list[dict[str, Any]]] = {r: [] for r in ROLES}
    chosen = blk.choice.chosen if blk.choice is not None else {}
    for col in blk.columns:
        for c in classify_column(col):
            if c.role not in out:
                continue
            is_chosen = c.role in chosen and chosen[c.role].index == col.index
            reasons = [f"named as {c.kind} (rank {c.rank})",
                       f"unit {col.unit!r} fits" if col.unit and c.unit_ok else
                       ("no unit" if not col.unit else f"unit {col.unit!r} does not fit")]  # fmt: skip
            if is_chosen and blk.choice is not None:
                reasons.append("chosen: " + blk.choice.why.get(c.role, ""))
            score = c.rank + (10 if is_chosen else 0) - (0 if c.unit_ok else 5)
            out[c.role].append({"column": col.source, "score": score, "reasons": "; ".join(reasons)})
    for role in out:
        out[role].sort(key=lambda d: -d["score"])
    return out


def _blocks(parsed: Parsed, t: np.ndarray, lines: np.ndarray) -> list[dict[str, Any]]:
    """Every data block: line, columns, rows, read; for the blocks read, the first sample and whether time continues."""
    p, blk = parsed.parser, parsed.block
    out: list[dict[str, Any]] = []
    for b in p.blocks:
        d: dict[str, Any] = {"line": b.header_line, "columns": [n for n in b.names if n], "rows": b.n_rows,
                             "read": b is blk or b in p.joined}  # fmt: skip
        if d["read"]:
            i = int(np.searchsorted(lines, b.first_line))
            d["start"] = i
            d["lines"] = (b.first_line, b.last_line)
            d["continues"] = bool(b is blk or (0 < i < t.size and t[i] > t[i - 1]))
        if b is blk:
            d["header_candidates"] = list(b.header_candidates)
            d["channel_candidates"] = _channel_candidates(b)
        if b.groups > 1:
            d["specimens"] = list(b.group_labels)
            d["specimen"] = b.group
        out.append(d)
    return out


def _other_columns(blk: Block, ch: ChannelChoice) -> list[str]:
    """The block's columns not used, as written."""
    used = {id(c) for c in ch.chosen.values()}
    # a bare number without a unit as a column name is a specimen index (Bluehill Universal)
    return [c.source for c in blk.columns if c.source and id(c) not in used
            and not (c.source.isdigit() and not c.unit)]  # fmt: skip


def _samples(parsed: Parsed, rate_hz: float | None, repair: bool, warnings: list[str]) -> tuple[
        pd.DataFrame, Channels, dict[str, str], str | None, np.ndarray | None, float | None, np.ndarray,
        list[tuple[int, int]]]:
    """Steps 1-3: the checked samples as a frame, with their channels, units, counter, rate and lines."""
    p, blk = parsed.parser, parsed.block
    label = p.label
    data = p.data
    assert data is not None and blk.choice is not None
    ch = blk.choice
    if blk.n_rows < 2:
        raise ReadError(
            f"header row is followed by {blk.n_rows} data row(s); expected at least 2",
            label,
            blk.header_line,
        )
    lines = _join(data, warnings)
    values, source_units, channels = _convert_units(data, ch, blk, label, warnings)
    counter = _column(data, "counter") if ch.counter is not None else None
    sample_rate = _time_from_rate(values, source_units, channels, p, blk, rate_hz, warnings)
    samples = _Samples(values, lines, counter)
    if data.empty_first:
        _fill_empty(samples, data, channels, label, repair, warnings)
    _drop_padding(samples, channels, warnings)
    if not parsed.parser.joined and blk.groups == 1:
        _drop_uncounted(samples, counted_samples(p.meta_items(blk.header_line)), warnings)
    _drop_spikes(samples, channels, label, repair, warnings)
    segments = _check_time(samples, channels, label, repair, warnings)
    if values["time"].size < 2:
        raise ReadError(
            f"only {values['time'].size} sample(s) left after the checks; expected at least 2",
            label,
            blk.header_line,
        )
    counter_source = _check_counter(samples, ch, data, warnings)
    frame = pd.DataFrame(
        {"time_s": values.pop("time"), "stroke_mm": values.pop("stroke"),
         "force_n": values.pop("force")},
        copy=False,
    )  # fmt: skip
    return frame, channels, source_units, counter_source, samples.counter, sample_rate, samples.lines, segments


def assemble(parsed: Parsed, *, fmt: str, pressure_kpa: float | None, rate_hz: float | None,
             repair: bool) -> RawTest:  # fmt: skip
    """The :class:`~bendpam.lab.rawtest.RawTest` of a parsed export: units converted, values checked.

    Parameters
    ----------
    parsed : Parsed
        What :func:`bendpam.lab.parser.parse_source` read (its numbers are consumed).
    fmt : str
        The format to report (one of :data:`bendpam.lab.rawtest.FORMATS`).
    pressure_kpa : float or None
        Pressure given by the caller (kPa), checked; it overrides the metadata and the file name.
    rate_hz : float or None
        Sampling rate (Hz) for a block without a time column.
    repair : bool
        Drop spikes and samples out of order in time (reported in :attr:`RawTest.warnings`)
        instead of refusing them.  Gaps, restarts and padding are read and reported either way.

    Returns
    -------
    RawTest

    Raises
    ------
    ReadError
        For an unknown unit, a spike or a sample out of order in time (without ``repair``),
        time that never advances, fewer than 2 samples, or a pressure that cannot be read or is out of range.

    Examples
    --------
    >>> from bendpam.lab.parser import parse_source
    >>> from bendpam.lab.source import text_source
    >>> text = "# Pressure: 1,5 bar\\ntime_s,stroke_mm,force_kN\\n0,0,0.0118\\n0.05,0.027,0.01171\\n"
    >>> (source,), _ = text_source(text)
    >>> parsed = parse_source(source, dialect=None, overrides={}, rate_hz=None, repair=False)
    >>> raw = assemble(parsed, fmt="csv", pressure_kpa=None, rate_hz=None, repair=False)
    >>> raw.data["force_n"].tolist(), raw.source_units["force_n"]      # N, from kN
    ([11.8, 11.71], 'kN')
    >>> raw.pressure_kpa, raw.pressure_source, raw.metadata
    (150.0, 'metadata', {'Pressure': '1,5 bar'})
    """
    p, blk = parsed.parser, parsed.block
    label = p.label
    path = Path(label) if isinstance(label, (str, Path)) else Path(str(label))
    assert blk.choice is not None
    warnings = list(p.warnings)
    frame, channels, source_units, counter_source, counter, sample_rate, lines, segments = _samples(
        parsed, rate_hz, repair, warnings)
    data_lines = (int(lines[0]), int(lines[-1]))
    metadata, meta_pressure = _metadata(p, blk, label, pressure_kpa)
    pressure, psource = _choose_pressure(pressure_kpa, meta_pressure, path, label)
    _file_warnings(parsed, warnings)
    blocks = _blocks(parsed, frame["time_s"].to_numpy(), lines)
    if parsed.source.is_excel:
        metadata.setdefault("sheet", parsed.source.sheet or "")
    return RawTest(
        data=frame,
        path=path,
        dialect=fmt,
        metadata=metadata,
        pressure_kpa=pressure,
        pressure_source=psource,
        source_units=source_units,
        encoding=parsed.source.encoding,
        delimiter=blk.sep,
        decimal=blk.decimal,
        header_line=blk.header_line,
        channels={r: channels[r] for r in ROLES},
        other_columns=_other_columns(blk, blk.choice),
        warnings=warnings,
        cycle_counter=counter,
        cycle_counter_source=counter_source,
        blocks=blocks,
        sample_rate_hz=sample_rate,
        data_lines=data_lines,
        segments=segments,
    )


def check_values(values: dict[str, np.ndarray], lines: np.ndarray, channels: Channels, label: Path | str,
                 repair: bool, warnings: list[str]) -> tuple[dict[str, np.ndarray], np.ndarray]:  # fmt: skip
    """Step 3 for columns read some other way (a format declaration): spikes, time order and gaps.

    Parameters
    ----------
    values : dict of str to numpy.ndarray
        role -> column in s, mm or N (the time made from a rate when its channel has no ``source``).
    lines : numpy.ndarray
        1-based line of each sample.
    channels : dict
        role -> ``{"source": column name or None, ...}``.
    label : pathlib.Path or str
        The file, as named in messages.
    repair : bool
        Drop spikes and samples where time does not increase, accept gaps, instead of refusing.
    warnings : list of str
        Warnings so far (appended to).

    Returns
    -------
    (dict, numpy.ndarray)
        The values and lines kept.

    Examples
    --------
    >>> import numpy as np
    >>> values = {"time": np.array([0.0, 0.1, 0.2]), "stroke": np.zeros(3), "force": np.ones(3)}
    >>> channels = {r: {"source": r} for r in values}
    >>> kept, lines = check_values(values, np.array([2, 3, 4]), channels, "be.csv", False, [])
    >>> lines.tolist()
    [2, 3, 4]
    """
    samples = _Samples(values, lines, None)
    _drop_spikes(samples, channels, label, repair, warnings)
    _check_time(samples, channels, label, repair, warnings)
    return samples.values, samples.lines
