"""Why a text is refused when no table of time, stroke and force was found in it.

:func:`role_hits` counts the roles (time, stroke, force) that a row of cells names; the parser
(:mod:`bendpam.lab.parser`) uses it to find names rows, and :func:`no_header_error` to say, in one
line, what was found instead of a table.
"""

from __future__ import annotations

from typing import Any

from bendpam.lab.channels import ACCEPTED_NAMES, ROLES, UNIT_HINT, ColumnInfo, classify_column, split_name_unit
from bendpam.lab.layout import DELIMITERS, split_cells
from bendpam.lab.read_error import ReadError, show

__all__ = ["no_header_error", "role_hits"]


def role_hits(cells: list[str]) -> int:
    """How many of the roles time, stroke and force the cells name (cells over 80 characters are not names).

    Examples
    --------
    >>> role_hits(["Prüfzeit", "Standardweg", "Standardkraft"]), role_hits(["0.5", "1.2", "hello"])
    (3, 0)
    """
    roles = set()
    for i, cell in enumerate(cells):
        if not cell or len(cell) > 80:
            continue
        name, unit = split_name_unit(cell)
        for c in classify_column(ColumnInfo(i, cell, name, unit)):
            if c.role in ROLES:
                roles.add(c.role)
    return len(roles)


def no_header_error(p: Any) -> ReadError:
    """The one-line refusal of a text in which no block of time, stroke and force columns was found.

    ``p`` is the :class:`bendpam.lab.parser.Parser` that searched it.  In order: a column named in
    the columns option that is not there, a channel's unknown unit, a per-cycle summary, a header
    that names some roles only, a header without data rows, data rows without a header, nothing.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> p = SimpleNamespace(label="x.csv", blocks=[], overrides={}, text=[(1, "hello"), (2, "world")],
    ...                     first_orphan=None)
    >>> print(no_header_error(p))
    x.csv: lines 1-2: no header row naming time, stroke and force columns; expected e.g. 'time_s,stroke_mm,force_n' ...
    """
    label = p.label
    partial = [b for b in p.blocks if b.choice is not None and b.choice.n_roles >= 2]
    summaries = [b for b in p.blocks if b.summary and (b.choice is None or b.choice.n_roles < 2)]
    missing_override = [b for b in p.blocks if b.override_missing is not None]
    if missing_override and p.overrides:
        b = missing_override[0]
        wanted = b.override_missing
        cols = ", ".join(repr(n) for n in b.names if n)
        return ReadError(
            f"column {wanted!r} named in the columns option is not in the file; its columns "
            f"are {cols}",
            label,
            b.header_line,
        )
    for b in partial:
        assert b.choice is not None
        for role, col in b.choice.bad_unit.items():
            return ReadError(
                f"unknown {role} unit {show(col.unit or '')} for column {col.source!r}; expected "
                f"{UNIT_HINT[role]}",
                label,
                col.unit_line or b.header_line,
                col.source,
            )
    if summaries and not partial:
        b = summaries[0]
        cols = ", ".join(repr(c) for c in b.summary[:4])
        return ReadError(
            f"a per-cycle or per-specimen summary, not a time series: columns such as {cols} "
            "hold one value per cycle or specimen and no column is a time, stroke or force "
            "sample; expected the raw data export (time, stroke and force samples)",
            label,
            b.header_line,
        )
    if partial:
        b = partial[0]
        assert b.choice is not None
        ch = b.choice
        found = ", ".join(f"{r} {ch.chosen[r].source!r}" for r in ROLES if r in ch.chosen)
        missing = [r for r in ROLES if r not in ch.chosen]  # stroke or force (time alone is made up)
        return ReadError(
            f"header row has no {' or '.join(missing)} column (found {found}); expected a "
            f"column named after {' and '.join(missing)} (accepted names: {ACCEPTED_NAMES})",
            label,
            b.header_line,
        )
    return _no_table_error(p)


def _no_table_error(p: Any) -> ReadError:
    """No header naming two roles: a header without data rows, data rows without a header, or nothing."""
    label = p.label
    # a header without data rows?
    for ln, line in p.text:
        for sep in DELIMITERS:
            if sep in line and role_hits(split_cells(line, sep)) >= 3:
                return ReadError(
                    "header row is followed by no data rows; expected at least 2", label, ln
                )
    first_data = p.blocks[0].first_line if p.blocks else p.first_orphan
    if first_data is not None:
        return ReadError(
            "no header row naming time, stroke and force columns before the first data row; "
            f"expected e.g. 'time_s,stroke_mm,force_n' (accepted names: {ACCEPTED_NAMES})",
            label,
            first_data,
        )
    # no data row at all: the whole text was searched
    where = f"lines 1-{p.text[-1][0]}: " if p.text and p.text[-1][0] > 1 else ""
    return ReadError(
        f"{where}no header row naming time, stroke and force columns; expected e.g. "
        f"'time_s,stroke_mm,force_n' (accepted names: {ACCEPTED_NAMES})",
        label,
        1 if not where else None,
    )
