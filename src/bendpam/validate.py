"""Validation at the boundary: numbers, ranges and pressures, with one-line messages.

Every public function validates its arguments with these helpers before any numerics, so a bad
value gives one :class:`~bendpam.errors.InputError` naming the argument, the value and the
allowed range, never a NaN or a traceback from deep inside.

Pressures are in kPa at every public edge.  :func:`pressure_kpa` warns (:class:`UnitWarning`)
when every nonzero value is below 5 kPa: a bending PAM does nothing there, and the likely mistake
is a pressure in MPa passed where kPa is expected.
"""

from __future__ import annotations

import math
import numbers
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from bendpam.errors import InputError

__all__ = [
    "KNOWN_SUFFIXES", "MPA_SUSPECT_KPA", "UnitWarning", "boolean", "did_you_mean", "file_format", "finite_number",
    "float_array", "integer", "number", "pressure_kpa", "quadrature_order",
]

#: Below this (kPa), a set of pressures is suspected to be in MPa.
MPA_SUSPECT_KPA = 5.0


class UnitWarning(UserWarning):
    """A value whose size suggests a unit mistake (e.g. MPa passed as kPa).

    >>> import warnings, bendpam
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     _ = bendpam.blocked_moment(bendpam.physics.presets.be_pam(), 0.2)     # 0.2 MPa meant
    >>> caught[0].category is UnitWarning
    True
    """


def _range_text(lo, hi, lo_open, hi_open) -> str:
    lo_s = "(" if lo_open or lo is None else "["
    hi_s = ")" if hi_open or hi is None else "]"
    return f"{lo_s}{'-inf' if lo is None else f'{lo:g}'}, {'inf' if hi is None else f'{hi:g}'}{hi_s}"


def number(name: str, value: Any, lo: float | None = None, hi: float | None = None, *, lo_open: bool = False,
           hi_open: bool = False, unit: str = "") -> float:
    """``value`` as a float inside the interval, or a one-line :class:`InputError`.

    A bool or a string is not a number (a TOML ``alpha0_deg = true`` or ``"70"`` is refused).

    >>> number("width_mm", 5, 0.0, lo_open=True, unit="mm")
    5.0
    """
    if isinstance(value, bool | str | bytes) or not isinstance(value, numbers.Real | np.floating | np.integer):
        raise InputError(f"{name} = {value!r} is not a number ({unit or 'a real number'} expected)")
    v = float(value)
    u = f" {unit}" if unit else ""
    rng = _range_text(lo, hi, lo_open, hi_open)
    if not math.isfinite(v):
        raise InputError(f"{name} = {value!r}{u} is not finite; allowed range {rng}{u}")
    bad_lo = lo is not None and (v <= lo if lo_open else v < lo)
    bad_hi = hi is not None and (v >= hi if hi_open else v > hi)
    if bad_lo or bad_hi:
        raise InputError(f"{name} = {v:g}{u} is outside the allowed range {rng}{u}")
    return v


def finite_number(name: str, value: Any, unit: str = "") -> float:
    """``value`` as a finite float (anything :class:`float` takes but a bool or a string), else a one-line
    :class:`InputError`.

    Examples
    --------
    >>> finite_number("mu", 0.6, "MPa")
    0.6
    >>> finite_number("shape", float("nan"))
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: shape = nan is not finite
    """
    u = f" {unit}" if unit else ""
    if isinstance(value, bool | str | bytes):
        raise InputError(f"{name} = {value!r} is not a number")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} = {value!r} is not a number") from None
    if not math.isfinite(v):
        raise InputError(f"{name} = {value!r}{u} is not finite")
    return v


def integer(name: str, value: Any, lo: int, hi: int) -> int:
    """``value`` as an int in ``[lo, hi]`` (a Python or NumPy integer, not a bool), else a one-line :class:`InputError`.

    Examples
    --------
    >>> integer("n_phi", 181, 2, 100_000)
    181
    >>> integer("n_phi", 1.5, 2, 100_000)
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: n_phi = 1.5 must be an integer in [2, 100000]
    """
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or not lo <= int(value) <= hi:
        raise InputError(f"{name} = {value!r} must be an integer in [{lo}, {hi}]")
    return int(value)


def boolean(name: str, value: Any) -> bool:
    """``value`` as a bool (Python or NumPy), else a one-line :class:`InputError`; 0 and 1 are not booleans.

    Examples
    --------
    >>> boolean("eq19_factor", True)
    True
    >>> boolean("eq19_factor", "yes")
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: eq19_factor = 'yes' must be True or False
    """
    if not isinstance(value, bool | np.bool_):
        raise InputError(f"{name} = {value!r} must be True or False")
    return bool(value)


def quadrature_order(order: Any) -> int:
    """The order of the section integrals: 0 (closed form) or N in [4, 1024] Gauss-Legendre nodes on [0, pi].

    Examples
    --------
    >>> quadrature_order(0), quadrature_order(32)
    (0, 32)
    >>> quadrature_order(2)
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: order = 2 is outside the allowed range: 0 (closed form) or [4, 1024]
    """
    if isinstance(order, bool) or not isinstance(order, int | np.integer):
        raise InputError(f"order = {order!r} must be an integer (Gauss-Legendre nodes on [0, pi])")
    if int(order) != 0 and not 4 <= int(order) <= 1024:  # 0: bendpam.physics.braid.CLOSED_FORM
        raise InputError(f"order = {order} is outside the allowed range: 0 (closed form) or [4, 1024]")
    return int(order)


def float_array(name: str, value: Any, unit: str) -> np.ndarray:
    """``value`` as a float array, or a one-line :class:`InputError` (a bool or a string is not a number).

    Examples
    --------
    >>> float_array("curvature_per_mm", [0, 0.01], "1/mm").tolist()
    [0.0, 0.01]
    >>> float_array("curvature_per_mm", "0.01", "1/mm")
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: curvature_per_mm = '0.01' is not a number (1/mm expected)
    """
    if isinstance(value, bool | str | bytes):
        raise InputError(f"{name} = {value!r} is not a number ({unit} expected)")
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} = {value!r} is not numeric ({unit} expected)") from None


def pressure_kpa(value: Any, name: str = "pressure_kpa", *, warn: bool = True) -> np.ndarray:
    """Gauge pressures in kPa as a float array: finite and >= 0, else a one-line :class:`InputError`.

    Warns with :class:`UnitWarning` when every nonzero value is below 5 kPa (MPa passed as kPa?).

    >>> pressure_kpa([100, 150]).tolist()
    [100.0, 150.0]
    """
    p = float_array(name, value, "kPa")
    if p.size and not np.all(np.isfinite(p)):
        i = int(np.flatnonzero(~np.isfinite(p.ravel()))[0])
        raise InputError(f"{name} has a non-finite value {p.ravel()[i]!r} at index {i}; allowed range [0, inf) kPa")
    if p.size and np.any(p < 0.0):
        i = int(np.flatnonzero(p.ravel() < 0.0)[0])
        raise InputError(
            f"{name} = {p.ravel()[i]:g} kPa at index {i} is below zero; allowed range [0, inf) kPa (gauge)")
    if warn and p.size:
        nz = p[p > 0.0]
        if nz.size and float(nz.max()) < MPA_SUSPECT_KPA:
            warnings.warn(
                f"{name}: every nonzero pressure is below {MPA_SUSPECT_KPA:g} kPa (largest {float(nz.max()):g}); "
                "pressures are in kPa: was a value in MPa passed (0.2 MPa = 200 kPa)?",
                UnitWarning, stacklevel=3,
            )
    return p


#: File name suffixes that name a format (a suffix outside this list is just part of the name).
KNOWN_SUFFIXES = {".png": "png", ".pdf": "pdf", ".svg": "svg", ".nc": "nc", ".csv": "csv", ".parquet": "parquet",
                  ".pq": "parquet", ".jpg": "jpg", ".jpeg": "jpg", ".eps": "eps", ".ps": "ps", ".tif": "tif",
                  ".tiff": "tif", ".json": "json", ".toml": "toml", ".txt": "txt", ".html": "html"}


def file_format(path: Any, fmt: Any, formats: tuple[str, ...], *, option: str = "path",
                format_option: str = "format", default: str | None = None) -> str:
    """The format of an output file: ``fmt`` if given, else the suffix of ``path``; one rule for API and CLI.

    A suffix that names a format (:data:`KNOWN_SUFFIXES`) must be one of ``formats`` and agree with
    ``fmt``; a name without a recognised suffix (none, or digits as in ``run.1``) takes ``fmt``,
    else ``default``.  Every refusal is one :class:`~bendpam.errors.InputError` line naming
    ``option`` (the path's argument or CLI option) and ``format_option``.

    Examples
    --------
    >>> file_format("fig.PDF", None, ("png", "pdf", "svg")), file_format("fig", "svg", ("png", "svg"))
    ('pdf', 'svg')
    >>> file_format("sweep.1", None, ("nc", "csv"), default="nc")
    'nc'
    """
    value = getattr(fmt, "value", fmt)
    if value is not None:
        value = str(value).lower().lstrip(".")
        if value not in formats:
            raise InputError(f"{format_option} {value!r} is not a format of {option}; choose from {', '.join(formats)}")
    suffix = Path(str(path)).suffix.lower()
    from_name = KNOWN_SUFFIXES.get(suffix)
    if from_name is not None:
        if from_name not in formats:
            raise InputError(f"{option} {str(path)!r}: {suffix} is not a format of {option}; use a "
                             + ", ".join(f".{f}" for f in formats) + " file")
        if value is not None and value != from_name:
            raise InputError(f"{option} {str(path)!r} is a {suffix} file but {format_option} is {value!r}; "
                             f"give a matching file name or drop {format_option}")
        return from_name
    if value is not None:
        return value
    if default is not None and (not suffix or suffix[1:].isdigit()):
        return default
    raise InputError(f"{option} {str(path)!r}: no format in the file name; use "
                     + ", ".join(f".{f}" for f in formats) + f" or give {format_option}")


def did_you_mean(name: Any, known) -> str:
    """``" (did you mean 'alpha0_deg'?)"`` for a mistyped name close to one of ``known``, else ``""``.

    Examples
    --------
    >>> did_you_mean("alpha_deg", ["alpha0_deg", "R0_mm"]), did_you_mean("zzz", ["R0_mm"])
    (" (did you mean 'alpha0_deg'?)", '')
    """
    import difflib

    near = difflib.get_close_matches(str(name), [str(k) for k in known], n=1, cutoff=0.5)
    return f" (did you mean {near[0]!r}?)" if near else ""
