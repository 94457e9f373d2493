"""Numbers of a block of regular text lines, read by the C parser of :func:`pandas.read_csv`.

The detected reader (:mod:`bendpam.lab.parser`) and the declared reader (:mod:`bendpam.lab.declared`)
hand their blocks of data lines to :func:`c_numbers`; a block it cannot read (a line with another
number of cells, a cell that is not a finite number) comes back as None and the caller reads it
line by line, which finds the line and says what is wrong with it.
"""

from __future__ import annotations

import io
from collections.abc import Sequence

import numpy as np

__all__ = ["c_numbers"]


def c_numbers(text: str, *, sep: str, decimal: str, columns: Sequence[int], n_rows: int,
              skipinitialspace: bool = False, empty_nan: bool = False) -> list[np.ndarray] | None:  # fmt: skip
    """Columns ``columns`` (0-based, in that order, repeats allowed) of ``n_rows`` lines of numbers.

    Parameters
    ----------
    text : str
        The lines, joined with line breaks.
    sep : str
        One-character cell delimiter, or ``" "`` for runs of blanks.
    decimal : str
        Decimal mark, ``"."`` or ``","``.
    columns : sequence of int
        The columns wanted.
    n_rows : int
        Lines in ``text``; any other count of rows is an irregular block.
    skipinitialspace : bool
        Blanks after a delimiter are not part of the cell.
    empty_nan : bool
        An empty or missing cell is NaN instead of irregular (text, ``nan`` and infinities still are).

    Returns
    -------
    list of numpy.ndarray or None
        One float64 array per entry of ``columns``, or None when any line is irregular (another
        number of cells, an empty cell, text, a non-finite number) or the delimiter is the
        decimal mark.

    Examples
    --------
    >>> t, f = c_numbers("0,0;1,5\\n0,5;2,5", sep=";", decimal=",", columns=[0, 1], n_rows=2)
    >>> t.tolist(), f.tolist()
    ([0.0, 0.5], [1.5, 2.5])
    >>> c_numbers("0,1\\n0.5,x", sep=",", decimal=".", columns=[0, 1], n_rows=2) is None
    True
    >>> c_numbers("0,1\\n0.5,", sep=",", decimal=".", columns=[0, 1], n_rows=2, empty_nan=True)[1].tolist()
    [1.0, nan]
    """
    if sep == decimal or not columns:
        return None
    import pandas as pd

    try:
        frame = pd.read_csv(
            io.BytesIO(text.encode("utf-8", "surrogatepass")),
            sep=r"\s+" if sep == " " else sep,
            decimal=decimal,
            header=None,
            usecols=sorted(set(columns)),
            dtype=np.float64,
            engine="c",
            skip_blank_lines=False,
            quotechar='"',
            na_filter=empty_nan,
            na_values=[""] if empty_nan else None,
            keep_default_na=False,
            index_col=False,
            skipinitialspace=skipinitialspace,
        )
        arrs = [frame[i].to_numpy(dtype=np.float64) for i in columns]  # copies: the frame is dropped
    except Exception:  # any parser trouble: the caller's line-by-line path finds the line
        return None
    del frame
    if any(len(a) != n_rows or (np.isinf(a).any() if empty_nan else not np.isfinite(a).all()) for a in arrs):
        return None
    return arrs
