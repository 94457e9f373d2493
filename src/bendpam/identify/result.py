"""The result of an identification: :class:`FitResult` and its parts, as values you can save and load.

:func:`bendpam.identify.fitting.fit` returns a :class:`FitResult`: the fitted actuator, each
:class:`Parameter` (value, standard error, bounds), the :class:`Metrics` of eq 53-55, the bladder
as a :class:`MaterialFit`, the :class:`Profile` of alpha0, the :class:`JointInterval` of each
strongly correlated pair and, with a loop model, a :class:`HysteresisFit` with its
:class:`LossRatio` per test.  Every part has ``to_dict``/``from_dict``; the whole result
``save``/``load`` (``fit.json`` and ``fitted_actuator.toml``).  :meth:`FitResult.band` gives a
prediction with its uncertainty :class:`Band`.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from bendpam.errors import FileFormatError, InputError, OutsideTestedRangeWarning
from bendpam.infra.accessors import figure
from bendpam.infra.atomic import atomic_write_text, json_safe
from bendpam.infra.budgets import read_input_bytes
from bendpam.infra.display import summary_html, summary_text
from bendpam.infra.manifest import verify_input
from bendpam.physics.actuator import Actuator, FitIdentity, outside_tested_range
from bendpam.physics.law import MomentLaw

__all__ = [
    "HYST_PARAMETERS",
    "PARAMETERS",
    "PARAMETER_ORDER",
    "Band",
    "EnsembleMember",
    "ExtrapolationWarning",
    "FitResult",
    "HysteresisFit",
    "JointInterval",
    "LossRatio",
    "MaterialFit",
    "Metrics",
    "Parameter",
    "Profile",
    "UncertaintyBudget",
    "parameter_field",
    "parameter_unit",
    "parse_free",
]

#: Identifiable parameters: short name -> (Actuator field, unit).
PARAMETERS = {
    "alpha0": ("alpha0_deg", "deg"),
    "C10": ("C10_kpa", "kPa"),
    "C01": ("C01_kpa", "kPa"),
    "P_start": ("P_start_kpa", "kPa"),
    "E_f": ("frame_modulus_mpa", "MPa"),
    "R0_start": ("R0_start_mm", "mm"),
}

#: The identifiable parameters in the order a fit reports them.
PARAMETER_ORDER = ("alpha0", "C10", "C01", "P_start", "E_f", "R0_start")
_ALIASES = {
    "alpha0": "alpha0", "alpha0_deg": "alpha0", "a0": "alpha0", "alpha": "alpha0",
    "c10": "C10", "c10_kpa": "C10", "c1": "C10",
    "c01": "C01", "c01_kpa": "C01", "c2": "C01",
    "p_start": "P_start", "pstart": "P_start", "p_start_kpa": "P_start",
    "e_f": "E_f", "ef": "E_f", "frame_modulus_mpa": "E_f", "frame_modulus": "E_f",
    "r0_start": "R0_start", "r0start": "R0_start", "r0_start_mm": "R0_start",
}


def parse_free(free) -> list[str]:
    """Normalise a list (or comma string) of parameter names; unknown names raise InputError.

    >>> parse_free("c01, alpha0_deg")
    ['alpha0', 'C01']
    """
    if isinstance(free, str):
        free = [f for f in free.replace(" ", ",").split(",") if f]
    out = []
    for f in free:
        key = _ALIASES.get(str(f).strip().lower())
        if key is None:
            raise InputError(f"unknown parameter {f!r} to fit; choose from {', '.join(PARAMETERS)}")
        if key not in out:
            out.append(key)
    if not out:
        raise InputError(f"no parameter to fit; choose from {', '.join(PARAMETERS)}")
    return sorted(out, key=PARAMETER_ORDER.index)


#: Parameters of the loop model (:mod:`bendpam.physics.hysteresis`): short name -> (field, unit).
HYST_PARAMETERS = {"theta_h": ("theta_h_deg", "deg"), "a0": ("a0_nmm", "N*mm"), "a1": ("a1_nmm_per_kpa", "N*mm/kPa")}


def parameter_field(name: str) -> str:
    """The field name (unit-suffixed) of a parameter of the model or of its loop, by its short name.

    >>> parameter_field("alpha0"), parameter_field("a1")
    ('alpha0_deg', 'a1_nmm_per_kpa')
    """
    return (PARAMETERS.get(name) or HYST_PARAMETERS[name])[0]


def parameter_unit(name: str) -> str:
    """The unit of a parameter of the model or of its loop, by its short name.

    >>> parameter_unit("C10"), parameter_unit("theta_h")
    ('kPa', 'deg')
    """
    return (PARAMETERS.get(name) or HYST_PARAMETERS[name])[1]


#: The warning of a prediction outside the tested pressures: :class:`bendpam.errors.OutsideTestedRangeWarning`
#: (the name of 0.3, kept as an alias).
ExtrapolationWarning = OutsideTestedRangeWarning


@dataclass
class Parameter:
    """One identified parameter (lmfit-style): value, standard error, bounds, vary flag, unit.

    >>> p = Parameter("alpha0", "alpha0_deg", "deg", 69.71, 0.02, 62.73, 76.67, True, 69.7)
    >>> p.to_dict()["stderr"], Parameter.from_dict("alpha0", "alpha0_deg", p.to_dict()) == p
    (0.02, True)
    """

    name: str
    field: str
    unit: str
    value: float
    stderr: float | None
    min: float
    max: float
    vary: bool
    initial: float

    def to_dict(self) -> dict:
        """The parameter as JSON types (its name and field are the keys it is stored under)."""
        return {"value": self.value, "stderr": self.stderr, "min": self.min, "max": self.max, "vary": self.vary,
                "initial": self.initial, "unit": self.unit}

    @classmethod
    def from_dict(cls, name: str, field_name: str, d: dict) -> Parameter:
        """The parameter ``name`` (field ``field_name``) from :meth:`to_dict`'s dictionary."""
        return cls(name, field_name, d["unit"], float(d["value"]), None if d["stderr"] is None else float(d["stderr"]),
                   _num(d["min"]), _num(d["max"]), bool(d["vary"]), _num(d["initial"]))


@dataclass
class Metrics:
    """Paper metrics (eq 53-55) and plain RMSEs of a model against processed data.

    ``curves`` says what the model curves were: ``"mean curves"`` (the quasi-static model against
    the average of the branches, as the paper) or ``"loop"`` (the model with its loop against both
    branches; blocked moment and free curvature of the predicted cycle).

    >>> m = Metrics(0.04, 0.03, 0.05, 9.1, 6.5, 4e-4, [], [])
    >>> m.to_dict()["nrmse"]["cycles"], Metrics.from_dict(m.to_dict()) == m
    (0.04, True)
    """

    nrmse_cycles: float
    nrmse_blocked_moment: float
    nrmse_free_curvature: float
    rmse_cycles: float
    rmse_blocked_moment: float
    rmse_free_curvature: float
    per_pressure: list[dict]
    no_equilibrium_kpa: list[float]
    curves: str = "mean curves"

    def to_dict(self) -> dict:
        """The metrics as JSON types, with the keys of ``fit.json``."""
        return {
            "nrmse": {"cycles": self.nrmse_cycles, "blocked_moment": self.nrmse_blocked_moment,
                      "free_curvature": self.nrmse_free_curvature},
            "rmse": {"cycles_nmm": self.rmse_cycles, "blocked_moment_nmm": self.rmse_blocked_moment,
                     "free_curvature_per_mm": self.rmse_free_curvature},
            "per_pressure": self.per_pressure,
            "no_equilibrium_kpa": self.no_equilibrium_kpa,
            "metrics_curves": self.curves,
        }

    @classmethod
    def from_dict(cls, d: dict) -> Metrics:
        """The metrics from :meth:`to_dict`'s dictionary (or a ``fit.json``, which holds its keys)."""
        return cls(
            nrmse_cycles=_num(d["nrmse"]["cycles"]), nrmse_blocked_moment=_num(d["nrmse"]["blocked_moment"]),
            nrmse_free_curvature=_num(d["nrmse"]["free_curvature"]), rmse_cycles=_num(d["rmse"]["cycles_nmm"]),
            rmse_blocked_moment=_num(d["rmse"]["blocked_moment_nmm"]),
            rmse_free_curvature=_num(d["rmse"]["free_curvature_per_mm"]), per_pressure=d["per_pressure"],
            no_equilibrium_kpa=d["no_equilibrium_kpa"], curves=str(d.get("metrics_curves", "mean curves")))



@dataclass
class MaterialFit:
    """The bladder as identified: initial shear modulus and shape (kPa; see :mod:`bendpam.physics.material`).

    Attributes
    ----------
    shear_modulus_kpa, se_shear_modulus_kpa : ``mu = 2 (C10 + C01)`` and its standard error, kPa.
    shape, se_shape : ``beta = C01 / (C10 + C01)`` and its standard error.
    shape_bounds : the admissible shapes the fit was confined to.
    stretch_range : the principal stretches they hold over (data, tension test, prediction range).
    shape_at_bound : True when the shape sits on an admissibility bound (set by the rule, not the data).
    shape_identified : True when the data determine the shape (95 % interval within half the width).
    shape_held : the reason the shape was held fixed (a fold, the free list), or "".
    shape_study : why a narrow interval of the shape is not called determined (the calibration study's coverage
        for it does not hold, :func:`bendpam.identify.diagnose.study_coverage`), or "".

    Examples
    --------
    >>> mat = MaterialFit(828.0, 12.0, 0.72, 0.2, (-0.15, 1.07), (0.6, 1.6), False, False)
    >>> mat.to_dict()["shear_modulus_kpa"], MaterialFit.from_dict(mat.to_dict()) == mat
    (828.0, True)
    """

    shear_modulus_kpa: float
    se_shear_modulus_kpa: float | None
    shape: float
    se_shape: float | None
    shape_bounds: tuple[float, float]
    stretch_range: tuple[float, float]
    shape_at_bound: bool
    shape_identified: bool
    shape_held: str = ""
    shape_study: str = ""

    @property
    def shape_narrow(self) -> bool:
        """Whether the shape's interval is narrow (determined, or narrow but not claimed for the study's sake)."""
        return bool(self.shape_identified or self.shape_study)

    def to_dict(self) -> dict:
        """The fields as a dictionary."""
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict) -> MaterialFit:
        """The material from :meth:`to_dict`'s dictionary."""
        return cls(_num(d["shear_modulus_kpa"]), _opt(d.get("se_shear_modulus_kpa")), _num(d["shape"]),
                   _opt(d.get("se_shape")), _pair(d["shape_bounds"]), _pair(d["stretch_range"]),
                   bool(d["shape_at_bound"]), bool(d["shape_identified"]), str(d.get("shape_held", "")),
                   str(d.get("shape_study", "")))


@dataclass
class Profile:
    """The profile of alpha0: the fit objective minimised over every other parameter, against alpha0.

    ``objective`` is the weighted sum of squares of the reported loop law's fit (eq 53 scale: NRMSE^2 of
    its curves), smallest at that law's alpha0; ``interval_deg`` the reported alpha0 (with a loop, the
    ensemble's average over the loop laws) +- 2 standard errors (statistical and systematic).

    >>> prof = Profile([69.6, 69.7, 69.8], [2.1e-3, 1.6e-3, 2.2e-3], (69.65, 69.75))
    >>> Profile.from_dict(prof.to_dict()) == prof
    True
    """

    alpha0_deg: list[float]
    objective: list[float]
    interval_deg: tuple[float, float]

    def to_dict(self) -> dict:
        """The profile as JSON types."""
        return {"alpha0_deg": self.alpha0_deg, "objective": self.objective, "interval_deg": self.interval_deg}

    @classmethod
    def from_dict(cls, d: dict) -> Profile:
        """The profile from :meth:`to_dict`'s dictionary."""
        return cls([float(x) for x in d["alpha0_deg"]], [_num(x) for x in d["objective"]], _pair(d["interval_deg"]))


@dataclass
class JointInterval:
    """Two strongly correlated parameters: what the data determine of them.

    ``first + coefficient * second = value +- stderr`` is their best-determined combination;
    ``box`` the extent of their joint 95 % region (``{field: (lo, hi)}``); ``text`` a sentence.

    >>> j = JointInterval(("C10_kpa", "C01_kpa"), -0.99, 1.0, 414.0, 6.0,
    ...                   {"C10_kpa": (-200.0, 400.0), "C01_kpa": (10.0, 610.0)}, "C10_kpa + C01_kpa = 414 ± 12 kPa")
    >>> JointInterval.from_dict(j.to_dict()) == j
    True
    """

    names: tuple[str, str]
    correlation: float
    coefficient: float
    value: float
    stderr: float
    box: dict[str, tuple[float, float]]
    text: str

    def to_dict(self) -> dict:
        """The interval as JSON types."""
        return {"names": list(self.names), "correlation": self.correlation, "coefficient": self.coefficient,
                "value": self.value, "stderr": self.stderr, "box": {k: list(v) for k, v in self.box.items()},
                "text": self.text}

    @classmethod
    def from_dict(cls, d: dict) -> JointInterval:
        """The interval from :meth:`to_dict`'s dictionary."""
        return cls((str(d["names"][0]), str(d["names"][1])), _num(d["correlation"]), _num(d["coefficient"]),
                   _num(d["value"]), _num(d["stderr"]), {k: _pair(v) for k, v in d["box"].items()}, str(d["text"]))


@dataclass(frozen=True)
class Band:
    """A prediction with its uncertainty band (``value -+ level * SE``; NaN where none exists).

    Made by :meth:`FitResult.band`; ``extrapolated`` marks the pressures outside the tested ones.

    >>> b = Band("free_curvature", "1/mm", np.array([150.0]), np.array([7.3e-3]), np.array([7.1e-3]),
    ...          np.array([7.5e-3]), np.array([False]))
    >>> float(b.upper[0] - b.lower[0])
    0.0004
    """

    quantity: str
    unit: str
    pressure_kpa: np.ndarray
    value: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    extrapolated: np.ndarray  # bool: outside the tested pressures



@dataclass(frozen=True)
class LossRatio:
    """Energy-loss ratio of one test: measured (processing) and predicted (the fitted loop's free cycle).

    >>> LossRatio(150.0, 0.21, 0.2).predicted
    0.2
    """

    pressure_kpa: float
    measured: float
    predicted: float


@dataclass
class HysteresisFit:
    """The loop part of a fit: parameters, loss ratios, branch NRMSE, and the law's systematic shift.

    ``energy_loss_ratio`` holds, per test, the measured ratio and the one of the predicted free cycle
    (:func:`bendpam.physics.hysteresis.predict_cycles`, the computation of ``bendpam predict --cycle``).
    ``law_shift`` is the change of each model parameter when the other law is fitted instead
    (``{field: shift}``, empty when not computed), ``alternative_law`` that law.

    Examples
    --------
    >>> params = {n: Parameter(n, f, u, v, None, 0.0, 100.0, True, 0.0)
    ...           for (n, (f, u)), v in zip(HYST_PARAMETERS.items(), (5.0, 10.0, 0.05))}
    >>> h = HysteresisFit("pi", "linear", params, [LossRatio(150.0, 0.21, 0.2)], 0.03)
    >>> h.loop().theta_h_deg, HysteresisFit.from_dict(h.to_dict()) == h
    (5.0, True)
    """

    law: str
    amplitude: str
    parameters: dict[str, Parameter]
    energy_loss_ratio: list[LossRatio]
    nrmse_branches: float
    alternative_law: str = ""
    law_shift: dict[str, float] = field(default_factory=dict)

    def loop(self):
        """The fitted :class:`bendpam.physics.hysteresis.LoopModel`."""
        from bendpam.physics.hysteresis import LoopModel

        return LoopModel(law=self.law, amplitude=self.amplitude,
                         **{p.field: p.value for p in self.parameters.values()})

    def to_dict(self) -> dict:
        """The loop fit as JSON types."""
        return {"law": self.law, "amplitude": self.amplitude,
                "parameters": {p.field: p.to_dict() for p in self.parameters.values()},
                "energy_loss_ratio": [asdict(e) for e in self.energy_loss_ratio],
                "nrmse_branches": self.nrmse_branches,
                "alternative_law": self.alternative_law, "law_shift": self.law_shift}

    @classmethod
    def from_dict(cls, d: dict) -> HysteresisFit:
        """The loop fit from :meth:`to_dict`'s dictionary."""
        names = {v[0]: k for k, v in HYST_PARAMETERS.items()}
        params = {names[f]: Parameter.from_dict(names[f], f, v) for f, v in d["parameters"].items()}
        return cls(d["law"], d.get("amplitude", "linear"), params,
                   [LossRatio(**e) for e in d.get("energy_loss_ratio", [])], _num(d.get("nrmse_branches")),
                   str(d.get("alternative_law", "")), {k: _num(v) for k, v in d.get("law_shift", {}).items()})


@dataclass
class EnsembleMember:
    """One loop law of the ensemble behind the systematic uncertainty: its fit and its weight.

    ``values`` are the model parameters it gives (``{field: value}``, with ``shear_modulus_kpa`` and
    ``shape`` when the constants vary), ``nrmse`` the square root of its objective (eq 53).

    >>> m = EnsembleMember("bouc_wen", 0.25, 0.012, {"alpha0_deg": 69.8})
    >>> EnsembleMember.from_dict(m.to_dict()) == m
    True
    """

    law: str
    weight: float
    nrmse: float
    values: dict[str, float]

    def to_dict(self) -> dict:
        """The member as JSON types."""
        return {"law": self.law, "weight": self.weight, "nrmse": self.nrmse, "values": dict(self.values)}

    @classmethod
    def from_dict(cls, d: dict) -> EnsembleMember:
        """The member from :meth:`to_dict`'s dictionary."""
        return cls(str(d["law"]), _num(d["weight"]), _num(d["nrmse"]), {k: _num(v) for k, v in d["values"].items()})


@dataclass
class UncertaintyBudget:
    """The standard errors of a fit in their two parts (``{field: SE}``; the total is their root sum of squares).

    ``statistical`` is the noise's part: resampling the cycles of each test (the exact covariance
    of a block bootstrap over cycles) where a test has two cycles or more, the sandwich with its
    AR(1) inflation elsewhere (``resampling`` says which, in words).  ``systematic`` is the loop
    law's part: the weighted spread over the :class:`EnsembleMember` fits (``ensemble``), weighted by
    ``weighting``.  Both include ``shear_modulus_kpa`` and ``shape`` when the constants vary.
    ``instrument`` is a declared calibration's part (:class:`~bendpam.identify.uncertainty.Instrument`;
    empty when none was declared) and ``declared`` that declaration in words.

    >>> b = UncertaintyBudget({"alpha0_deg": 0.03}, {"alpha0_deg": 0.04}, "cycles", "Akaike", [])
    >>> round(b.total["alpha0_deg"], 3), UncertaintyBudget.from_dict(b.to_dict()) == b
    (0.05, True)
    >>> b.instrument, b.declared = {"alpha0_deg": 0.12}, "the force reading to 0.29 %"
    >>> round(b.total["alpha0_deg"], 3), UncertaintyBudget.from_dict(b.to_dict()) == b
    (0.13, True)
    """

    statistical: dict[str, float]
    systematic: dict[str, float]
    resampling: str
    weighting: str
    ensemble: list[EnsembleMember] = field(default_factory=list)
    instrument: dict[str, float] = field(default_factory=dict)
    declared: str = ""

    @property
    def total(self) -> dict[str, float]:
        """``sqrt(statistical^2 + systematic^2 + instrument^2)`` per quantity."""
        return {k: math.hypot(v, self.systematic.get(k, 0.0), self.instrument.get(k, 0.0))
                for k, v in self.statistical.items()}

    def to_dict(self) -> dict:
        """The budget as JSON types (``instrument`` and ``declared`` only when a calibration was declared)."""
        out = {"statistical": dict(self.statistical), "systematic": dict(self.systematic), "total": self.total,
               "resampling": self.resampling, "weighting": self.weighting,
               "ensemble": [m.to_dict() for m in self.ensemble]}
        return {**out, "instrument": dict(self.instrument), "declared": self.declared} if self.instrument else out

    @classmethod
    def from_dict(cls, d: dict) -> UncertaintyBudget:
        """The budget from :meth:`to_dict`'s dictionary."""
        return cls({k: _num(v) for k, v in d["statistical"].items()}, {k: _num(v) for k, v in d["systematic"].items()},
                   str(d.get("resampling", "")), str(d.get("weighting", "")),
                   [EnsembleMember.from_dict(m) for m in d.get("ensemble", [])],
                   {k: _num(v) for k, v in (d.get("instrument") or {}).items()}, str(d.get("declared", "")))


@dataclass
class FitResult:
    """Result of :func:`fit`: a value you can print, predict with, plot, save and load.

    Attributes
    ----------
    model : the model fitted (``"energy"`` or ``"force_balance"``).
    actuator : the fitted :class:`~bendpam.Actuator` (usable by every command).
    parameters : short name -> :class:`Parameter` (value, standard error, bounds, vary flag, unit).
    correlation, correlation_names : correlation matrix of the varied parameters.
    metrics : :class:`Metrics` (eq 53-55), against the model the fit used (with its loop if any).
    converged, message, nfev, time_s : about the search.
    flags : plain-language warnings (poorly identifiable pairs, parameters at a bound, folds).
    autocorrelation : mean lag-1 autocorrelation of the residuals (used in the standard errors).
    hysteresis : :class:`HysteresisFit` or None.
    material : :class:`MaterialFit` (shear modulus and shape) or None when neither constant varied.
    identifiability : sentences: which parameters and combinations the data determine.
    alpha0_profile : :class:`Profile` of alpha0 or None.
    joint_intervals : :class:`JointInterval` of each strongly correlated pair.
    covariance : covariance matrix of the varied parameters (``correlation_names`` order; statistical
        plus systematic), in their units.
    pressure_range_kpa : the tested pressures' range (predictions outside it are extrapolations).
    uncertainty : :class:`UncertaintyBudget`: the standard errors' statistical and systematic parts, and
        the ensemble of loop laws behind the latter (None without it).

    Examples
    --------
    A coarse fit of two virtual tests of the paper's BE-PAM, saved, loaded and printed:

    >>> import tempfile
    >>> from pathlib import Path
    >>> import bendpam
    >>> from bendpam.identify.fitting import fit
    >>> from bendpam.lab import RawTest
    >>> from bendpam.lab.processing import ProcessingOptions
    >>> from bendpam.lab.simulate import SimulationSettings, simulate_test
    >>> be = bendpam.physics.presets.be_pam()
    >>> settings = SimulationSettings(cycles=1, rate_hz=2.0, hysteresis=0.0, seed=1)
    >>> raws = [RawTest(simulate_test(be, p, settings=settings)[0], Path(f"be_{p:g}kPa.csv"), "csv", pressure_kpa=p)
    ...         for p in (100.0, 200.0)]
    >>> processed = bendpam.process_tests(raws, keep_series=False, options=ProcessingOptions(grid_points=21))
    >>> result = fit(processed, be)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     files = result.save(folder)
    ...     back = FitResult.load(folder)
    >>> sorted(files), back.to_json() == result.to_json()
    (['fit.json', 'fitted_actuator.toml'], True)
    >>> print(result)  # doctest: +ELLIPSIS
    energy model fit (converged, ... evaluations, ... s)
             alpha0_deg = ...
    """

    model: str
    actuator: Actuator
    parameters: dict[str, Parameter]
    correlation: np.ndarray
    correlation_names: list[str]
    metrics: Metrics
    converged: bool
    message: str
    nfev: int
    time_s: float
    flags: list[str] = field(default_factory=list)
    autocorrelation: float = 0.0
    hysteresis: HysteresisFit | None = None
    material: MaterialFit | None = None
    identifiability: list[str] = field(default_factory=list)
    alpha0_profile: Profile | None = None
    joint_intervals: list[JointInterval] = field(default_factory=list)
    covariance: np.ndarray | None = None
    pressure_range_kpa: tuple[float, float] = (math.nan, math.nan)
    uncertainty: UncertaintyBudget | None = None

    @property
    def loop(self):
        """The fitted loop (:class:`bendpam.physics.hysteresis.LoopModel`) or None."""
        return None if self.hysteresis is None else self.hysteresis.loop()

    def _warn_outside(self, pressure_kpa) -> np.ndarray:
        """Which pressures are outside the tested range; one :class:`OutsideTestedRangeWarning` if any are."""
        return outside_tested_range(self.pressure_range_kpa, pressure_kpa, self.actuator.name or self.actuator.kind)

    def predict(self, pressure_kpa, curvature_per_mm) -> np.ndarray:
        """The fitted model's quasi-static moment ``M(P, k')`` (N*mm), broadcasting (signed as the paper).

        Pressures outside the tested range raise an :class:`~bendpam.errors.OutsideTestedRangeWarning`.
        """
        self._warn_outside(pressure_kpa)
        return MomentLaw.of(self.actuator, self.model).moment(pressure_kpa, curvature_per_mm)

    def band(self, pressure_kpa, quantity: str = "free_curvature", curvature_per_mm: float = 0.0,
             level: float = 2.0) -> Band:
        """A prediction and its band ``value -+ level * SE`` from the parameters' covariance.

        Parameters
        ----------
        pressure_kpa : pressures, kPa (1-D).
        quantity : ``"free_curvature"`` (magnitude, 1/mm), ``"blocked_moment"`` (magnitude, N*mm)
            or ``"moment"`` (magnitude at ``curvature_per_mm`` along the bending direction, N*mm);
            of the quasi-static model (what ``bendpam predict`` gives).
        level : multiples of the standard error (2: the reported intervals).

        Returns
        -------
        :class:`Band`; ``extrapolated`` marks pressures outside the tested range.  The standard error
        is propagated to first order (central differences of the quantity in each varied
        parameter); NaN where the model or a perturbed one has no answer (above a fold).
        """
        from bendpam.validate import pressure_kpa as check_pressure

        P = np.atleast_1d(check_pressure(pressure_kpa)).astype(float).ravel()
        units = {"free_curvature": "1/mm", "blocked_moment": "N*mm", "moment": "N*mm"}
        if quantity not in units:
            raise InputError(f"quantity = {quantity!r}; choose one of {', '.join(units)}")
        lo, hi = self.pressure_range_kpa
        extrap = (P < lo) | (P > hi) if math.isfinite(lo) else np.zeros(P.size, bool)

        def value(act):
            law = MomentLaw.of(act, self.model)
            s = act.bend_sign or 1
            if quantity == "free_curvature":
                return np.abs(law.free_curvature_array(P))
            k = 0.0 if quantity == "blocked_moment" else s * abs(float(curvature_per_mm))
            return np.abs(law.moment(P, k))

        v0 = value(self.actuator)
        names = [n for n in self.correlation_names if n in PARAMETERS]
        var = np.zeros(P.size)
        if names and self.covariance is not None:
            idx = [self.correlation_names.index(n) for n in names]
            cov = np.asarray(self.covariance)[np.ix_(idx, idx)]
            G = np.empty((P.size, len(names)))
            for j, n in enumerate(names):
                f = PARAMETERS[n][0]
                x = float(getattr(self.actuator, f))
                h = max(1e-3 * math.sqrt(max(cov[j, j], 0.0)), 1e-7 * max(abs(x), 1.0))
                try:
                    up = value(self.actuator.replace(**{f: x + h}))
                    dn = value(self.actuator.replace(**{f: x - h}))
                except InputError:
                    up = dn = np.full(P.size, math.nan)
                G[:, j] = (up - dn) / (2 * h)
            var = np.einsum("ij,jk,ik->i", G, cov, G)
        sd = np.sqrt(np.clip(var, 0.0, None))
        return Band(quantity, units[quantity], P, v0, v0 - level * sd, v0 + level * sd, extrap)

    def plot(self, processed, title: str = ""):
        """Figure 7 (a matplotlib Figure): the fitted model against ``processed`` (a set or its folder)."""
        from bendpam.lab.processed import as_processed

        return figure("figure7")(as_processed(processed), self, title)

    def to_dict(self) -> dict:
        m = self.metrics.to_dict()
        return {
            "model": self.model,
            "parameters": {PARAMETERS[n][0]: p.to_dict() for n, p in self.parameters.items()},
            "correlation": {"names": [parameter_field(n) for n in self.correlation_names],
                            "matrix": self.correlation.tolist()},
            "covariance": None if self.covariance is None else np.asarray(self.covariance).tolist(),
            "nrmse": m["nrmse"],
            "rmse": m["rmse"],
            "metrics_curves": m["metrics_curves"],
            "per_pressure": m["per_pressure"],
            "no_equilibrium_kpa": m["no_equilibrium_kpa"],
            "pressure_range_kpa": list(self.pressure_range_kpa),
            "material": None if self.material is None else self.material.to_dict(),
            "identifiability": self.identifiability,
            "alpha0_profile": None if self.alpha0_profile is None else self.alpha0_profile.to_dict(),
            "joint_intervals": [j.to_dict() for j in self.joint_intervals],
            "flags": self.flags,
            "converged": self.converged,
            "message": self.message,
            "nfev": self.nfev,
            "time_s": self.time_s,
            "residual_autocorrelation": self.autocorrelation,
            "actuator": self.actuator.to_dict(),
            **({"hysteresis": self.hysteresis.to_dict()} if self.hysteresis is not None else {}),
            "uncertainty": None if self.uncertainty is None else self.uncertainty.to_dict(),
        }

    def to_json(self) -> str:
        """:meth:`to_dict` as JSON text (non-finite numbers as null)."""
        return json.dumps(json_safe(self.to_dict()), indent=2, allow_nan=False)

    def save(self, out_dir, *, processed: str = "", extra: dict | None = None) -> dict[str, str]:
        """Write ``fit.json`` and ``fitted_actuator.toml`` atomically into the folder ``out_dir``.

        The actuator file records the tested pressure range and the fit's identity
        (:class:`~bendpam.physics.actuator.FitIdentity`: the SHA-256 of the ``fit.json`` written beside it,
        ``processed``, the name of the processed test set, the date and bendpam's version).
        ``extra``: more top-level entries of ``fit.json`` (e.g. a tension fit), written before it is hashed.
        """
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        text = self.to_json() if not extra else json.dumps(json_safe({**self.to_dict(), **extra}), indent=2,
                                                                   allow_nan=False)
        atomic_write_text(out / "fit.json", text)
        ident = self.actuator.fit_identity or FitIdentity()
        ident = replace(ident, fit_json_sha256=hashlib.sha256(text.encode("utf-8")).hexdigest(),
                        processed=processed or ident.processed)
        act = self.actuator.replace(fit_identity=ident)
        if act.tested_pressure_kpa is None and all(math.isfinite(v) for v in self.pressure_range_kpa):
            act = act.replace(tested_pressure_kpa=self.pressure_range_kpa)
        text = act.to_toml()
        loop = self.loop
        if loop is not None:
            import tomli_w

            text += "\n" + tomli_w.dumps({"hysteresis": loop.to_dict()})
        atomic_write_text(out / "fitted_actuator.toml", text)
        return {"fit.json": str(out / "fit.json"), "fitted_actuator.toml": str(out / "fitted_actuator.toml")}

    @classmethod
    def from_dict(cls, d: dict, *, source: str = "") -> FitResult:
        """The result from :meth:`to_dict`'s dictionary (``source``: where it was read, for messages)."""
        act = Actuator.from_dict(d["actuator"], source=source)
        short = {v[0]: k for k, v in PARAMETERS.items()}
        params = {short[f]: Parameter.from_dict(short[f], f, v) for f, v in d["parameters"].items()}
        rev = {v[0]: k for k, v in {**PARAMETERS, **HYST_PARAMETERS}.items()}
        n = len(d["correlation"]["names"])
        cov = d.get("covariance")
        return cls(
            model=d["model"], actuator=act, parameters=params,
            correlation=np.array(d["correlation"]["matrix"], dtype=float).reshape(n, n),
            correlation_names=[rev[n] for n in d["correlation"]["names"]], metrics=Metrics.from_dict(d),
            converged=bool(d["converged"]), message=str(d["message"]), nfev=int(d["nfev"]),
            time_s=float(d["time_s"]), flags=list(d["flags"]),
            autocorrelation=float(d.get("residual_autocorrelation", 0.0)),
            hysteresis=HysteresisFit.from_dict(d["hysteresis"]) if d.get("hysteresis") else None,
            material=MaterialFit.from_dict(d["material"]) if d.get("material") else None,
            identifiability=[str(s) for s in d.get("identifiability", [])],
            alpha0_profile=Profile.from_dict(d["alpha0_profile"]) if d.get("alpha0_profile") else None,
            joint_intervals=[JointInterval.from_dict(j) for j in d.get("joint_intervals", [])],
            covariance=None if cov is None else np.array(cov, dtype=float).reshape(n, n),
            pressure_range_kpa=_pair(d.get("pressure_range_kpa", [None, None])),
            uncertainty=UncertaintyBudget.from_dict(d["uncertainty"]) if d.get("uncertainty") else None,
        )

    @classmethod
    def load(cls, path) -> FitResult:
        """Read a fit written by :meth:`save` (the folder or its ``fit.json``)."""
        p = Path(path)
        fj = p / "fit.json" if p.is_dir() else p
        if not fj.exists():
            raise FileFormatError(f"{fj}: no such fit file; give the output folder of 'bendpam fit'")
        data = read_input_bytes(fj, "fit file")  # a regular file of a sane size, read without blocking
        verify_input(fj)  # a fit that bendpam wrote is read only as it wrote it (its manifest's hashes)
        try:
            return cls.from_dict(json.loads(data.decode("utf-8")), source=str(fj))
        except FileNotFoundError:
            raise FileFormatError(f"{fj}: no such fit file; give the output folder of 'bendpam fit'") from None
        except (OSError, UnicodeDecodeError, json.JSONDecodeError, KeyError, TypeError, ValueError,
                RecursionError) as exc:
            raise FileFormatError(f"{fj}: not a bendpam fit.json ({type(exc).__name__}: {exc})") from None

    def _summary(self) -> tuple[str, list[tuple[str, object]], list[str], list[list[Any]]]:
        m = self.metrics
        items: list[tuple[str, object]] = [
            ("NRMSE cycles (%)", 100 * m.nrmse_cycles), ("NRMSE blocked moment (%)", 100 * m.nrmse_blocked_moment),
            ("NRMSE free curvature (%)", None if m.nrmse_free_curvature is None else 100 * m.nrmse_free_curvature),
            ("curves fitted", "both loop branches (hysteresis-aware)" if self.hysteresis is not None
             else "mean curves")]
        items += [("note", f) for f in self.flags[:3]]
        rows = [[PARAMETERS[n][0], p.value, p.stderr if p.vary else "fixed", PARAMETERS[n][1]]
                for n, p in self.parameters.items()]
        return (f"FitResult: {self.model.replace('_', '-')} model "
                f"({'converged' if self.converged else 'NOT converged'}, {self.nfev} evaluations)", items,
                ["parameter", "value", "std. error", "unit"], rows)

    def __repr__(self) -> str:
        """A short summary: the fit's quality and its parameters (``str()`` has every detail)."""
        return summary_text(*self._summary())

    def _repr_html_(self) -> str:
        """The summary of :meth:`__repr__` for a notebook (HTML)."""
        return summary_html(*self._summary())

    def __str__(self) -> str:
        lines = [f"{self.model.replace('_', '-')} model fit ({'converged' if self.converged else 'NOT converged'}, "
                 f"{self.nfev} evaluations, {self.time_s:.2f} s)"]
        for n, p in self.parameters.items():
            se = "fixed" if not p.vary else (f"± {p.stderr:.3g}" if p.stderr is not None else "± n/a")
            lines.append(f"  {PARAMETERS[n][0]:>18} = {p.value:10.4g} {se:>12}  [{p.min:g}, {p.max:g}]")
        mat = self.material
        if mat is not None:
            se_mu = f" ± {mat.se_shear_modulus_kpa:.3g}" if mat.se_shear_modulus_kpa is not None else ""
            se_b = f" ± {mat.se_shape:.2g}" if mat.se_shape is not None else ""
            lines.append(f"  shear modulus mu = 2(C10 + C01) = {mat.shear_modulus_kpa:.4g}{se_mu} kPa, shape "
                         f"C01/(C10 + C01) = {mat.shape:.3g}{se_b} (admissible [{mat.shape_bounds[0]:.3g}, "
                         f"{mat.shape_bounds[1]:.3g}])")
        m = self.metrics
        what = " (model with its loop, both branches)" if m.curves == "loop" else ""
        lines.append(f"  NRMSE cycles {100 * m.nrmse_cycles:.2f} %, "
                     f"blocked moment {100 * m.nrmse_blocked_moment:.2f} %, "
                     f"free curvature {_pct(m.nrmse_free_curvature)}{what}")
        h = self.hysteresis
        if h is not None:
            lines.append("  loop (" + h.law + "): " + ", ".join(
                f"{p.field} = {p.value:.4g}" + (f" ± {p.stderr:.2g}" if p.stderr is not None else "")
                for p in h.parameters.values()) + f"; NRMSE of the branches {100 * h.nrmse_branches:.2f} %")
            lines.append("  energy-loss ratio measured/predicted: " + ", ".join(
                f"{e.pressure_kpa:g} kPa {100 * e.measured:.1f}/{_pct(e.predicted, 1)}"
                for e in h.energy_loss_ratio))
        b = self.uncertainty
        if b is not None:
            keys = [k for k in b.statistical if k in (*(v[0] for v in PARAMETERS.values()), "shear_modulus_kpa",
                                                      "shape")]
            inst = " / instrument" if b.instrument else ""

            def part(x: float, k: str) -> str:  # a part below a millionth of the total is rounding: 0
                return f"{x if x > 1e-6 * b.total.get(k, 0.0) else 0.0:.2g}"

            lines.append(f"  standard errors, statistical / systematic{inst}: " + ", ".join(
                f"{k} {part(b.statistical[k], k)} / {part(b.systematic.get(k, 0.0), k)}"
                + (f" / {part(b.instrument.get(k, 0.0), k)}" if b.instrument else "") for k in keys))
            lines.append(f"  instrument, its declared calibration: {b.declared}" if b.instrument else
                         "  not included: the rig's calibration (a load cell or pressure gauge off, an untared "
                         "self-weight: every test moved alike, unseen in the curves); declare it with "
                         "--force-uncertainty-pct, --pressure-uncertainty-kpa; a known tare with "
                         "--zero-uncertainty-n, --pressure-force-uncertainty-n-per-kpa (fit(instrument=...))")
            if b.ensemble:
                lines.append("  loop laws (weight; the model parameters are their weighted average): "
                             + ", ".join(f"{m.law} {m.weight:.2f}" for m in b.ensemble))
        lines += [f"  identifiability: {s}" for s in self.identifiability]
        lines += [f"  note: {f}" for f in self.flags]
        return "\n".join(lines)


def _num(x) -> float:
    return math.nan if x is None else float(x)


def _opt(x) -> float | None:
    return None if x is None else float(x)


def _pair(x) -> tuple[float, float]:
    return _num(x[0]), _num(x[1])


def _pct(x, digits: int = 2):
    return "n/a" if x is None or not np.isfinite(x) else f"{100 * x:.{digits}f} %"

