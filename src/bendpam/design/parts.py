"""Small pieces shared by the design modules: checked pressures and pairs, grams to newtons, JSON numbers.

Every public function of :mod:`bendpam.design` validates its pressures once, here
(:func:`checked_pressure_kpa`, :func:`checked_pressures_kpa`), and then runs its numerics inside
:func:`pressures_checked` so that the law, evaluated many times at the same pressures, does not
repeat the :class:`~bendpam.validate.UnitWarning` of a pressure that looks like MPa, nor the
:class:`~bendpam.errors.OutsideTestedRangeWarning` of a fitted actuator used outside its tested
pressures.  The warning is reported at the user's call (the first frame outside :mod:`bendpam.design`).

Units: kPa for every pressure, N for forces, g for masses (weights with g = 9.80665 m/s^2).
"""

from __future__ import annotations

import math
import sys
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType

import numpy as np

from bendpam.errors import InputError, OutsideTestedRangeWarning
from bendpam.validate import UnitWarning
from bendpam.validate import pressure_kpa as _check_pressures

__all__ = [
    "G_N_PER_G",
    "checked_pair",
    "checked_pressure_kpa",
    "checked_pressures_kpa",
    "checked_vector",
    "json_number",
    "pressures_checked",
]

#: weight of one gram, N (standard gravity 9.80665 m/s^2)
G_N_PER_G = 9.80665e-3

_PACKAGE = __name__.rpartition(".")[0]  # "bendpam.design": warnings point at the first frame outside it


def checked_pair(name: str, value, unit: str) -> tuple[float, float]:
    """Two finite numbers (a point, a force, a direction) as a tuple of floats, else an InputError.

    >>> checked_pair("tip_force_n", [0, -1.5], "N")
    (0.0, -1.5)
    >>> checked_pair("tip_force_n", "0,1", "N")
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: tip_force_n = '0,1' must be two numbers (N)
    """
    a = _numbers(name, value, unit, 2)
    return a[0], a[1]


def checked_vector(name: str, value, unit: str) -> tuple[float, float, float]:
    """Three finite numbers (a point, a force, a moment in space) as a tuple of floats, else an InputError.

    >>> checked_vector("tip_force_n", [0, 0, -1.5], "N")
    (0.0, 0.0, -1.5)
    >>> checked_vector("tip_force_n", [0, 1], "N")
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: tip_force_n = [0, 1] must be three finite numbers (N)
    """
    a = _numbers(name, value, unit, 3)
    return a[0], a[1], a[2]


def _numbers(name: str, value, unit: str, size: int) -> list[float]:
    words = {2: "two", 3: "three"}[size]
    if isinstance(value, str | bytes):
        raise InputError(f"{name} = {value!r} must be {words} numbers ({unit})")
    try:
        a = np.asarray(value, dtype=float).ravel()
    except (TypeError, ValueError):
        raise InputError(f"{name} = {value!r} must be {words} numbers ({unit})") from None
    if a.size != size or not np.all(np.isfinite(a)):
        raise InputError(f"{name} = {value!r} must be {words} finite numbers ({unit})")
    return [float(v) for v in a]


def _user_stacklevel() -> int:
    """``stacklevel`` (for a ``warnings.warn`` in the caller) of the first frame outside bendpam.design."""
    level = 1
    frame: FrameType | None = sys._getframe(1)
    while frame is not None and frame.f_globals.get("__name__", "").startswith(_PACKAGE):
        frame, level = frame.f_back, level + 1
    return level


def _numeric_pressures(value, name: str) -> np.ndarray:
    """:func:`bendpam.validate.pressure_kpa`, refusing strings and bools inside a list too ([100, "150"]).

    Its :class:`~bendpam.validate.UnitWarning` is reported at the user's call, not inside bendpam.design.
    """
    try:
        kind = np.asarray(value).dtype.kind
    except (TypeError, ValueError):  # ragged: left to the check's own message
        kind = "O"
    if kind in "USb":
        raise InputError(f"{name} = {value!r} is not numeric (kPa expected)")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        p = _check_pressures(value, name)
    if caught:
        level = _user_stacklevel()
        for w in caught:
            warnings.warn(w.message, stacklevel=level)
    return p


def checked_pressure_kpa(value, name: str = "pressure_kpa", actuator=None) -> float:
    """One gauge pressure in kPa as a float (:func:`bendpam.validate.pressure_kpa`, and a single value).

    A negative, non-finite or non-numeric value raises :class:`~bendpam.errors.InputError`; a
    nonzero value below 5 kPa warns with :class:`~bendpam.validate.UnitWarning` (MPa passed as kPa?).
    With ``actuator``, a pressure outside its tested range warns
    (:class:`~bendpam.errors.OutsideTestedRangeWarning`).

    >>> checked_pressure_kpa(150)
    150.0
    >>> checked_pressure_kpa([100, 150])
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: pressure_kpa has 2 values; give one pressure (kPa)
    """
    p = _numeric_pressures(value, name)
    if p.size != 1:
        raise InputError(f"{name} has {p.size} values; give one pressure (kPa)")
    if actuator is not None:
        actuator.outside_tested(p)
    return float(p.reshape(()))


def checked_pressures_kpa(value, name: str = "pressures_kpa", actuator=None) -> np.ndarray:
    """Gauge pressures in kPa as a 1-D float array (at least one), validated as :func:`checked_pressure_kpa`.

    >>> checked_pressures_kpa(150).tolist(), checked_pressures_kpa([100, 150]).tolist()
    ([150.0], [100.0, 150.0])
    """
    p = np.atleast_1d(_numeric_pressures(value, name)).ravel()
    if p.size == 0:
        raise InputError(f"{name} is empty; give at least one pressure (kPa)")
    if actuator is not None:
        actuator.outside_tested(p)
    return p


@contextmanager
def pressures_checked() -> Iterator[None]:
    """Run the numerics of a public function whose pressures were already validated.

    The entry point validates (and warns about a suspected MPa value, or a pressure outside the
    actuator's tested range) once; inside, the law is evaluated many times at the same pressures
    and must not repeat the :class:`~bendpam.validate.UnitWarning` or the
    :class:`~bendpam.errors.OutsideTestedRangeWarning`.

    >>> import warnings
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("error")
    ...     with pressures_checked():
    ...         warnings.warn("0.15 looks like MPa", UnitWarning)   # silenced inside
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UnitWarning)
        warnings.simplefilter("ignore", OutsideTestedRangeWarning)
        yield


def json_number(value) -> float | str | None:
    """``value`` as a float for a JSON record: None where it is not defined (NaN), ``"inf"``/``"-inf"`` where infinite.

    ``float()`` reads the strings back (docs/formats.md, "JSON": ``null`` means missing, never infinite).

    >>> json_number(2), json_number(float("nan")), json_number(float("inf"))
    (2.0, None, 'inf')
    """
    try:
        v = float(value)
    except (TypeError, ValueError):
        return None
    if math.isnan(v):
        return None
    return v if math.isfinite(v) else ("inf" if v > 0 else "-inf")
