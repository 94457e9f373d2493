"""Validation at the boundary: numbers, ranges and pressures, with one-line messages.

Every public function validates its arguments with these helpers before any numerics, so a bad
value gives one :class:`~bendpam.errors.InputError` naming the argument, the value and the
allowed range, never a NaN or a traceback from deep inside.

Pressures are in kPa at every public edge.  :func:`pressure_kpa` warns (:class:`UnitWarning`)
when every nonzero value is below 5 kPa: a bending PAM does nothing there, and the likely mistake
is a pressure in MPa passed where kPa is expected; given a burst limit (an actuator's
``max_pressure_kpa``, by default :data:`DEFAULT_MAX_PRESSURE_KPA` = 2 MPa) it refuses pressures above it.

Physical plausibility: :data:`PLAUSIBLE` is the one table of the ranges an actuator's parameters
may take (name -> :class:`Plausible`: low, high, unit and the physical reason), used by
:class:`~bendpam.Actuator` and by the sweeps' blocks of cases through :func:`plausible`;
docs/plausibility.md explains every bound.
"""

from __future__ import annotations

import math
import numbers
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from bendpam.errors import InputError, InputTypeError

__all__ = [
    "DEFAULT_MAX_PRESSURE_KPA", "KNOWN_SUFFIXES", "MPA_SUSPECT_KPA", "PLAUSIBLE", "Plausible", "UnitWarning",
    "boolean", "did_you_mean", "file_format", "finite_number", "float_array", "instance", "integer", "number",
    "plausible", "pressure_kpa", "quadrature_order",
]

#: Below this (kPa), a set of pressures is suspected to be in MPa.
MPA_SUSPECT_KPA = 5.0
#: The default burst limit (kPa): no pneumatic artificial muscle holds more than about 2 MPa.
DEFAULT_MAX_PRESSURE_KPA = 2000.0


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
        raise InputError(f"{name} = {_short(value)} is not a number ({unit or 'a real number'} expected)")
    try:
        v = float(value)
    except OverflowError:  # an int beyond the float range (a TOML integer of 400 digits)
        v = math.inf if str(value)[0] != "-" else -math.inf
    u = f" {unit}" if unit else ""
    rng = _range_text(lo, hi, lo_open, hi_open)
    if not math.isfinite(v):
        raise InputError(f"{name} = {_short(value)}{u} is not finite; allowed range {rng}{u}")
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
    except OverflowError:
        raise InputError(f"{name} = {value!r}{u} is not finite") from None
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
    if value is None or isinstance(value, bool | str | bytes):
        raise InputError(f"{name} = {value!r} is not a number ({unit} expected)")
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{name} = {_short(value)} is not numeric ({unit} expected)") from None


def _short(value: Any) -> str:
    """``repr(value)`` cut to 60 characters (a message stays one short line)."""
    text = " ".join(repr(value).split())
    return text if len(text) <= 60 else text[:57] + "..."


def pressure_kpa(value: Any, name: str = "pressure_kpa", *, warn: bool = True,
                 limit_kpa: float | None = None) -> np.ndarray:
    """Gauge pressures in kPa as a float array: finite, >= 0 and <= ``limit_kpa``, else a one-line :class:`InputError`.

    ``limit_kpa`` is the burst limit of the actuator the pressures are for (its
    ``max_pressure_kpa``, by default :data:`DEFAULT_MAX_PRESSURE_KPA`); ``None``: no upper limit.
    Warns with :class:`UnitWarning` when every nonzero value is below 5 kPa (MPa passed as kPa?).

    Examples
    --------
    >>> pressure_kpa([100, 150], limit_kpa=2000.0).tolist()
    [100.0, 150.0]
    >>> pressure_kpa(1e6, limit_kpa=2000.0)
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: pressure_kpa = 1e+06 kPa at index 0 is above the burst limit 2000 kPa ...
    """
    p = float_array(name, value, "kPa")
    top = "inf" if limit_kpa is None else f"{limit_kpa:g}"
    if p.size and not np.all(np.isfinite(p)):
        i = int(np.flatnonzero(~np.isfinite(p.ravel()))[0])
        raise InputError(f"{name} has a non-finite value {p.ravel()[i]!r} at index {i}; allowed range [0, {top}] kPa")
    if p.size and np.any(p < 0.0):
        i = int(np.flatnonzero(p.ravel() < 0.0)[0])
        raise InputError(
            f"{name} = {p.ravel()[i]:g} kPa at index {i} is below zero; allowed range [0, {top}] kPa (gauge)")
    if limit_kpa is not None and p.size and np.any(p > limit_kpa):
        i = int(np.flatnonzero(p.ravel() > limit_kpa)[0])
        raise InputError(
            f"{name} = {p.ravel()[i]:g} kPa at index {i} is above the burst limit {limit_kpa:g} kPa "
            f"(the actuator's max_pressure_kpa; no pneumatic artificial muscle holds more than about "
            f"{DEFAULT_MAX_PRESSURE_KPA / 1000:g} MPa): raise the actuator's max_pressure_kpa to go higher")
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
                  ".tiff": "tif", ".json": "json", ".toml": "toml", ".txt": "txt", ".html": "html",
                  ".zarr": "zarr"}


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


def instance(name: str, value: Any, kind: type | tuple[type, ...], expected: str) -> Any:
    """``value`` if it is a ``kind``, else a one-line :class:`~bendpam.errors.InputTypeError` (an InputError).

    Examples
    --------
    >>> instance("order", 3, int, "an integer")
    3
    >>> instance("actuator", None, int, "a bendpam.Actuator")
    Traceback (most recent call last):
    ...
    bendpam.errors.InputTypeError: actuator = None must be a bendpam.Actuator, got NoneType
    """
    if not isinstance(value, kind):
        raise InputTypeError(f"{name} = {_short(value)} must be {expected}, got {type(value).__name__}")
    return value


# ------------------------------------------------------------------------------------------------
# physical plausibility of an actuator's parameters
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Plausible:
    """The plausible range ``[lo, hi]`` (``unit``) of one actuator parameter and why.

    A bound is a multiple of another parameter where ``lo_of`` / ``hi_of`` names it (``R0_start_mm``
    within 1 to 3 times ``R0_mm``).
    ``hi_open``: the upper bound itself is not allowed (a wall as thick as the tube's radius).

    Examples
    --------
    >>> PLAUSIBLE["alpha0_deg"].lo, PLAUSIBLE["alpha0_deg"].hi, PLAUSIBLE["alpha0_deg"].unit
    (10.0, 88.0, 'deg')
    """

    lo: float
    hi: float
    unit: str
    reason: str
    lo_of: str | None = None
    hi_of: str | None = None
    hi_open: bool = False


#: name -> :class:`Plausible`: the one table of physical ranges (docs/plausibility.md gives the reasons at length).
PLAUSIBLE: dict[str, Plausible] = {
    "alpha0_deg": Plausible(10.0, 88.0, "deg", "braided sleeves exist, unjammed, between about 10 and 88 deg; "
                            "eq 1-5 (inextensible fibres on a circular section) describe real braids there"),
    "R0_mm": Plausible(0.5, 100.0, "mm", "bladder tubes of bending PAMs are 1 to 200 mm across"),
    "t0_mm": Plausible(0.01, 1.0, "mm", "a bladder wall is at least 10 um thick and thinner than the tube's "
                       "radius", hi_of="R0_mm", hi_open=True),
    "L0_mm": Plausible(1.0, 5000.0, "mm", "bending PAMs are 1 mm to 5 m long"),
    "frame_thickness_mm": Plausible(0.005, 50.0, "mm", "a frame strip is a 5 um film at the thinnest and a "
                                    "50 mm bar at the thickest"),
    "frame_width_mm": Plausible(0.05, 500.0, "mm", "a frame strip is 0.05 to 500 mm wide"),
    "frame_modulus_mpa": Plausible(0.5, 450_000.0, "MPa", "frame materials range from soft rubber (0.5 MPa) to "
                                   "steel and tungsten (200 to 410 GPa)"),
    "C10_kpa": Plausible(-100_000.0, 100_000.0, "kPa", "|C10| <= 100 MPa: rubbers' Mooney-Rivlin constants are "
                         "tens to thousands of kPa"),
    "C01_kpa": Plausible(-100_000.0, 100_000.0, "kPa", "|C01| <= 100 MPa: rubbers' Mooney-Rivlin constants are "
                         "tens to thousands of kPa"),
    "P_start_kpa": Plausible(0.0, 1.0, "kPa", "the threshold pressure lies below the burst limit",
                             hi_of="max_pressure_kpa"),
    "R0_start_mm": Plausible(1.0, 3.0, "mm", "the braid prestretches the bladder by a factor 1 to 3; more tears "
                             "a rubber tube", lo_of="R0_mm", hi_of="R0_mm"),
    "braid_thickness_mm": Plausible(0.01, 10.0, "mm", "braided sleeves are 0.01 to 10 mm thick"),
    "frame_strength_mpa": Plausible(1.0, 10_000.0, "MPa", "strengths range from soft plastics (a few MPa) to "
                                    "carbon fibre (about 6 GPa)"),
    "bladder_stretch_limit": Plausible(1.0, 20.0, "1", "rubbers break at stretches of 5 to 10"),
    "max_pressure_kpa": Plausible(1.0, 100_000.0, "kPa", "pneumatic PAMs burst below 2 MPa and hydraulic "
                                  "McKibben muscles run at up to about 20 MPa; 100 MPa is beyond any"),
    # the four-point bending fixture (bendpam.physics.fixture.Fixture)
    "fixture_d_mm": Plausible(1.0, 2000.0, "mm", "a testing machine's bending fixture spans 1 mm to 2 m"),
    "fixture_r_mm": Plausible(0.0, 200.0, "mm", "loading rollers are at most 200 mm in radius"),
    "fixture_t_mm": Plausible(0.0, 200.0, "mm", "connecting plates are at most 200 mm thick"),
    "stroke_mm": Plausible(-10_000.0, 10_000.0, "mm", "a testing machine's crosshead travels at most a few metres"),
    "force_n": Plausible(-1e7, 1e7, "N", "the largest testing machines apply 10 MN"),
    # a uniaxial tension test of the bladder rubber (bendpam.identify.tension)
    "stretch": Plausible(0.0, 20.0, "1", "rubbers break at stretches of 5 to 10"),
    "nominal_stress_kpa": Plausible(-100_000.0, 100_000.0, "kPa", "no rubber carries a nominal stress above "
                                    "100 MPa (they break at 5 to 50 MPa); is the force in N and the area in mm^2?"),
}


def _bound(b: Plausible, which: str, values: dict[str, Any]):
    """The lower or upper bound of ``b`` as a float or an array, with its text (``R0_mm = 8.5``)."""
    of = b.lo_of if which == "lo" else b.hi_of
    base = b.lo if which == "lo" else b.hi
    if of is None:
        return base, f"{base:g}"
    ref = values[of]
    value = base * (ref if isinstance(ref, float | int) else np.asarray(ref, dtype=float))
    what = of if base == 1.0 else f"{base:g} {of}"
    return value, what


def plausible(name: str, value: Any, values: dict[str, Any] | None = None, *, label: str | None = None,
              indexed: bool = False) -> None:
    """Refuse a value of actuator parameter ``name`` outside its :data:`PLAUSIBLE` range (one line, the reason).

    ``value`` is a number or an array (a block of sweep cases); ``values`` holds the parameters a
    relative bound refers to (``R0_mm`` for ``R0_start_mm``), of shapes that broadcast; ``label``
    names the value in the message (default ``name``); ``indexed``: the message gives the index of
    the first value out of range (a column of data).

    Examples
    --------
    >>> plausible("alpha0_deg", 70.0)
    >>> plausible("R0_start_mm", 1e22, {"R0_mm": 8.5})
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: R0_start_mm = 1e+22 mm is outside the plausible range [R0_mm, 3 R0_mm] = [8.5, 25.5] ...
    """
    b = PLAUSIBLE[name]
    vals = values or {}
    lo, lo_text = _bound(b, "lo", vals)
    hi, hi_text = _bound(b, "hi", vals)
    if isinstance(value, float | int) and np.ndim(lo) == 0 and np.ndim(hi) == 0:  # one actuator: the fast path
        if lo <= value and (value < hi if b.hi_open else value <= hi):
            return
    v = np.asarray(value, dtype=float)
    bad = (v < lo) | ((v >= hi) if b.hi_open else (v > hi))
    if not np.any(bad):
        return
    shape = np.broadcast_shapes(v.shape, np.shape(lo), np.shape(hi))
    i = int(np.flatnonzero(np.broadcast_to(bad, shape))[0])

    def at(x) -> float:
        return float(np.broadcast_to(x, shape).ravel()[i])

    close = ")" if b.hi_open else "]"
    unit = "" if b.unit == "1" else f" {b.unit}"
    rng = f"[{lo_text}, {hi_text}{close}"
    if b.lo_of is not None or b.hi_of is not None:
        rng += f" = [{at(lo):.6g}, {at(hi):.6g}{close}"
    where = f" at index {i}" if indexed else ""
    raise InputError(f"{label or name} = {at(v):g}{unit}{where} is outside the plausible range {rng}{unit}: "
                     f"{b.reason}")
