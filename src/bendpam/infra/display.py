"""Short summaries of results for a terminal and a notebook (``__repr__`` and ``_repr_html_``).

A result shows a title, a few ``name: value`` lines and, where it has one row per pressure (or per
design), a small table cut to :data:`MAX_ROWS` rows -- never whole arrays.  The HTML is escaped
and needs no style sheet.
"""

from __future__ import annotations

import html
import math
from collections.abc import Sequence
from typing import Any

__all__ = ["MAX_ROWS", "fmt_cell", "summary_html", "summary_text"]

#: The most table rows a summary shows (the rest are counted in one line).
MAX_ROWS = 12


def fmt_cell(value: Any, digits: int = 4) -> str:
    """A table cell: numbers to ``digits`` significant digits, ``inf``, a dash for NaN/None.

    >>> fmt_cell(310.3345), fmt_cell(float("inf")), fmt_cell(None), fmt_cell("fold")
    ('310.3', 'inf', '—', 'fold')
    """
    if value is None:
        return "—"
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, int | float) or hasattr(value, "item"):
        v = float(value) + 0.0  # no "-0"
        if math.isnan(v):
            return "—"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return f"{v:.{digits}g}"
    return str(value)


def _cut(rows: Sequence[Sequence[Any]]) -> tuple[list[Sequence[Any]], int]:
    rows = list(rows)
    return rows[:MAX_ROWS], max(len(rows) - MAX_ROWS, 0)


def summary_text(title: str, items: Sequence[tuple[str, Any]] = (), header: Sequence[str] = (),
                 rows: Sequence[Sequence[Any]] = ()) -> str:
    """A few lines: the title, ``name: value`` items and a small aligned table.

    >>> print(summary_text("BE-PAM", [("model", "energy")], ["P (kPa)", "M (N·mm)"], [[100, 75.23], [200, 310.3]]))
    BE-PAM
      model: energy
      P (kPa)  M (N·mm)
          100     75.23
          200     310.3
    """
    lines = [title] + [f"  {k}: {fmt_cell(v)}" for k, v in items]
    if header:
        shown, more = _cut(rows)
        cells = [[fmt_cell(c) for c in r] for r in shown]
        widths = [max([len(h), *(len(r[i]) for r in cells)]) for i, h in enumerate(header)]
        lines.append("  " + "  ".join(h.rjust(w) for h, w in zip(header, widths, strict=True)))
        lines += ["  " + "  ".join(c.rjust(w) for c, w in zip(r, widths, strict=True)) for r in cells]
        if more:
            lines.append(f"  ... {more} more rows")
    return "\n".join(lines)


def summary_html(title: str, items: Sequence[tuple[str, Any]] = (), header: Sequence[str] = (),
                 rows: Sequence[Sequence[Any]] = ()) -> str:
    """The same summary as an HTML fragment (a bold title, a list of items, a small table).

    >>> print(summary_html("BE-PAM", [("model", "energy")]))
    <div><b>BE-PAM</b><ul style="margin:0"><li>model: energy</li></ul></div>
    """
    esc = html.escape
    parts = [f"<div><b>{esc(title)}</b>"]
    if items:
        parts.append('<ul style="margin:0">' + "".join(f"<li>{esc(k)}: {esc(fmt_cell(v))}</li>" for k, v in items)
                     + "</ul>")
    if header:
        shown, more = _cut(rows)
        parts.append("<table><tr>" + "".join(f"<th>{esc(h)}</th>" for h in header) + "</tr>")
        parts += ["<tr>" + "".join(f"<td>{esc(fmt_cell(c))}</td>" for c in r) + "</tr>" for r in shown]
        parts.append("</table>")
        if more:
            parts.append(f"<p>... {more} more rows</p>")
    return "".join(parts) + "</div>"
