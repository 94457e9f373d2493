"""The outcome of an inverse design: :class:`DesignResult` (JSON, files, summary) and its :class:`ParetoFront`."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from bendpam.design.targets import Target, Variable
from bendpam.infra.accessors import figure
from bendpam.infra.atomic import atomic_write_text
from bendpam.infra.display import summary_html, summary_text
from bendpam.infra.outputs import to_json
from bendpam.physics.actuator import Actuator
from bendpam.version import __version__

__all__ = [
    "DesignResult",
    "ParetoFront",
    "fmt_margin",
]


@dataclass
class ParetoFront:
    """Non-dominated designs in two target quantities (sorted by the first).

    Attributes
    ----------
    targets : the two :class:`Target` objects (their quantities and pressures; the Pareto sense is
        larger is better for ``>=``/``=``, smaller for ``<=``).
    quantities : ``(K, 2)`` the two magnitudes of each design, in the targets' units.
    X : ``(K, n)`` the variables of each design (:attr:`DesignResult.variables` order).
    min_margin : ``(K,)`` the smallest safety margin of each design.

    Examples
    --------
    >>> import numpy as np
    >>> from bendpam.design.targets import Target
    >>> pf = ParetoFront((Target.parse("blocked_moment_nmm>=300@150"), Target.parse("free_angle_deg>=60@150")),
    ...                  np.array([[300.0, 80.0], [350.0, 70.0]]), np.array([[70.0], [75.0]]),
    ...                  np.array([1.5, 1.2]), ("alpha0_deg",))
    >>> print(pf.to_csv(), end="")
    blocked_moment_nmm@150kpa,free_angle_deg@150kpa,alpha0_deg,min_margin
    300,80,70,1.5
    350,70,75,1.2
    """

    targets: tuple[Target, Target]
    quantities: np.ndarray
    X: np.ndarray
    min_margin: np.ndarray
    variable_names: tuple[str, ...]

    def columns(self) -> dict[str, np.ndarray]:
        out = {self.targets[0].key: self.quantities[:, 0], self.targets[1].key: self.quantities[:, 1]}
        out.update({n: self.X[:, j] for j, n in enumerate(self.variable_names)})
        out["min_margin"] = self.min_margin
        return out

    def to_csv(self) -> str:
        cols = self.columns()
        lines = [",".join(cols)]
        for r in range(len(self.quantities)):
            lines.append(",".join(f"{float(v[r]):.10g}" for v in cols.values()))
        return "\n".join(lines) + "\n"


@dataclass
class DesignResult:
    """The outcome of :func:`design_actuator`.

    Attributes
    ----------
    actuator : the best design (the closest one when the targets cannot be met), an
        :class:`~bendpam.Actuator` whose ``model`` field records the model.
    model : the moment model.
    targets, variables : the problem.
    values : ``{variable: value}`` at the best design.
    achieved : ``(n_targets,)`` the magnitudes predicted for the best design by the public
        functions (:func:`bendpam.blocked_moment`, :func:`bendpam.free_curvature`,
        :func:`bendpam.tangent_stiffness`, :func:`bendpam.free_branch`,
        :func:`bendpam.design.blocked_tip_force`), independently of the search.
    relative_error : ``achieved / value - 1`` per target; ``met`` whether each target is met (0.1 %).
    feasible : every target met and every margin >= ``min_margin`` (to 0.1 %).
    message : a plain-words account (why not, when not feasible).
    binding : the targets (texts) or limits that prevent meeting the rest (empty when feasible).
    active : the bounds and margins at their limit at the best design.
    closest : the variables of the closest design (== ``values``) when not feasible, else None.
    margins : ``{name: value}`` the smallest of each margin over the operating pressures.
    margins_by_pressure : ``{pressure_kpa: {name: value}}`` at the target and operating pressures.
    min_margin, min_margin_required, max_pressure_kpa : the smallest margin, the required one,
        the operating pressure (kPa; None when no target has a pressure).
    sensitivities : ``{target key: {variable: d ln(quantity) / d ln(variable)}}`` at the best
        design (central differences; ``min_margin`` too when finite).
    coarse : the coarse map: ``X`` (N, n), ``quantities`` (N, n_targets), ``violation`` (N,),
        ``min_margin`` (N,), and ``method`` (``"sobol"`` or ``"grid"``).
    pareto : the :class:`ParetoFront` (two targets) or None.
    search : seed, sizes, evaluations and the elapsed time.
    deadband : the deadband study: ``P_start_kpa`` and ``R0_start_mm`` of the design, ``assumed``
        (True: the search kept the base actuator's P_start and prestrain ratio, not modelled from the
        geometry) and ``moved``, one
        row per factor 0.8 and 1.2 on ``P_start``: ``achieved``, ``relative_error`` and ``met`` per target.

    Infinite margins mean no demand (or no limit given): ``margins`` holds ``inf``; :meth:`to_dict`
    writes the string ``"inf"`` and says which in ``margin_notes``.

    Examples
    --------
    >>> import bendpam
    >>> from bendpam.design.inverse import design_actuator
    >>> res = design_actuator(bendpam.physics.presets.be_pam(), ["blocked_moment_nmm=400@200"],
    ...                       ["alpha0_deg=60:80"], n_coarse=64, n_starts=1)
    >>> res.met.tolist(), res.binding, round(res.actuator.alpha0_deg, 2)
    ([True], (), 79.87)
    """

    actuator: Actuator
    model: str
    targets: tuple[Target, ...]
    variables: tuple[Variable, ...]
    values: dict[str, float]
    achieved: np.ndarray
    relative_error: np.ndarray
    met: np.ndarray
    feasible: bool
    message: str
    binding: tuple[str, ...]
    active: tuple[str, ...]
    closest: dict[str, float] | None
    margins: dict[str, float]
    margins_by_pressure: dict[float, dict[str, float]]
    min_margin: float
    min_margin_required: float
    max_pressure_kpa: float | None
    sensitivities: dict[str, dict[str, float]]
    coarse: dict[str, Any] = field(repr=False)
    pareto: ParetoFront | None = field(repr=False)
    search: dict[str, Any] = field(default_factory=dict)
    deadband: dict[str, Any] | None = None

    def _margin_notes(self) -> dict[str, str]:
        """Why each infinite margin is infinite: ``"no demand"`` or ``"no limit given"``."""
        no_limit = {"frame_strength_margin": self.actuator.frame_strength_mpa is None,
                    "bladder_stretch_margin": self.actuator.bladder_stretch_limit is None}
        return {k: "no limit given" if no_limit.get(k) else "no demand"
                for k, v in self.margins.items() if v == math.inf}

    def to_dict(self) -> dict[str, Any]:
        """design.json's content (units in the key names; a margin ``"inf"``: no demand or no limit, see
        ``margin_notes``; ``null`` = not defined, never infinite)."""
        return {
            "bendpam_version": __version__,
            "model": self.model,
            "feasible": self.feasible,
            "message": self.message,
            "binding": list(self.binding),
            "active": list(self.active),
            "targets": [
                {"target": t.text, "quantity": t.quantity, "unit": t.unit, "comparison": t.sense, "value": t.value,
                 "pressure_kpa": t.pressure_kpa, "achieved": float(a), "relative_error": float(e), "met": bool(m),
                 "compared": "magnitude"}
                for t, a, e, m in zip(self.targets, self.achieved, self.relative_error, self.met, strict=True)],
            "variables": [{"name": v.name, "low": v.low, "high": v.high, "value": self.values[v.name]}
                          for v in self.variables],
            "closest_design": self.closest,
            "constraints": {"min_margin": self.min_margin_required, "max_pressure_kpa": self.max_pressure_kpa},
            "margins": {k: _margin_json(v) for k, v in self.margins.items()},
            "margin_notes": self._margin_notes(),
            "min_margin": _margin_json(self.min_margin),
            "margins_by_pressure": [{"pressure_kpa": p, **{k: _margin_json(v) for k, v in m.items()}}
                                    for p, m in self.margins_by_pressure.items()],
            "sensitivities": {"meaning": "d ln(quantity) / d ln(variable) at the design", **self.sensitivities},
            "actuator": self.actuator.to_dict(),
            "pareto": None if self.pareto is None else {
                "quantities": [t.key for t in self.pareto.targets], "n_designs": len(self.pareto.quantities),
                "better": ["larger" if t.larger_is_better else "smaller" for t in self.pareto.targets],
                "file": "pareto.csv"},
            "search": dict(self.search),
            "deadband": self.deadband,
            "inf_means": "a margin with no demand (or no limit given; see margin_notes)",
            "null_means": "not defined (missing); infinity (no demand, no limit, an unbounded free-bending branch) "
                          "is the string \"inf\"",
        }

    def to_json(self) -> str:
        """design.json's text (:meth:`to_dict` as JSON)."""
        return to_json(self.to_dict())

    def save(self, out_dir, *, figures: bool = True, figure_format: str = "png") -> dict[str, str]:
        """Write design.json, design.toml, coarse_map.csv, pareto.csv and figures into ``out_dir``.

        ``figure_format``: png, pdf or svg (the figures ``coarse_map`` and ``pareto`` get its suffix).

        Each file is written atomically (for a whole set, use :class:`bendpam.infra.outputs.OutputSet`,
        as ``bendpam design --out`` does).  Returns ``{file name: path}``.
        """
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        files: dict[str, str] = {}

        def put(name: str, text: str) -> None:
            atomic_write_text(out / name, text)
            files[name] = str(out / name)

        put("design.json", self.to_json())
        put("design.toml", self.actuator.to_toml())
        cols = {v.name: self.coarse["X"][:, j] for j, v in enumerate(self.variables)}
        cols.update({t.key: self.coarse["quantities"][:, i] for i, t in enumerate(self.targets)})
        cols["violation"] = self.coarse["violation"]
        cols["min_margin"] = self.coarse["min_margin"]
        lines = [",".join(cols)] + [",".join(f"{float(c[r]):.8g}" for c in cols.values())
                                    for r in range(len(self.coarse["X"]))]
        put("coarse_map.csv", "\n".join(lines) + "\n")
        if self.pareto is not None:
            put("pareto.csv", self.pareto.to_csv())
        if figures:  # drawn and saved by bendpam.present.figures, reached by name
            save_figure = figure("save_figure")
            for name in ("coarse_map", "pareto") if self.pareto is not None else ("coarse_map",):
                target = out / f"{name}.{figure_format}"
                save_figure(figure(name)(self), target, format=figure_format)
                files[target.name] = str(target)
        return files

    def summary(self) -> str:
        """A short human summary: targets against achieved values, feasibility, margins."""
        head = "feasible: every target met" if self.feasible else "NOT FEASIBLE: the targets cannot all be met"
        lines = [f"design ({self.model.replace('_', '-')} model): {head}"]
        w = max(len(t.text) for t in self.targets)
        for t, a, e, m in zip(self.targets, self.achieved, self.relative_error, self.met, strict=True):
            a_s = f"{a:.5g}" if np.isfinite(a) else ("inf" if a == np.inf else "none")
            e_s = f"{100 * e:+.3f} %" if np.isfinite(e) else "—"
            lines.append(f"  {t.text:<{w}}  achieved {a_s} {t.unit} ({e_s}) {'ok' if m else 'MISSED'}")
        lines.append("  variables: " + ", ".join(f"{k} = {v:.5g}" for k, v in self.values.items()))
        if self.margins:
            ms = ", ".join(f"{k} {fmt_margin(v)}" for k, v in self.margins.items())
            lines.append(f"  margins (>= {self.min_margin_required:g} required"
                         + (f" up to {self.max_pressure_kpa:g} kPa" if self.max_pressure_kpa else "") + f"): {ms}")
        if self.active:
            lines.append(f"  at their limit: {', '.join(self.active)}")
        lines.append(f"  {self.message}")
        lines.extend(self._deadband_lines())
        return "\n".join(lines)

    def _deadband_lines(self) -> list[str]:
        """The summary's account of the deadband: assumed, and the targets if it moves by -20 % / +20 %."""
        db = self.deadband
        if not db:
            return []
        how = "assumed (the base actuator's; not modelled from the geometry)" if db["assumed"] else "designed"
        lines = [f"  deadband P_start = {db['P_start_kpa']:.4g} kPa {how}; if it moves:"]
        for row in db["moved"]:
            head = f"    x{row['factor']:g} ({row['P_start_kpa']:.4g} kPa): "
            if row["achieved"] is None:
                lines.append(head + f"no answer ({row['note']})")
                continue
            parts = [f"{t.text} -> {_fmt_q(a)} ({_fmt_pct(e)}, {'ok' if m else 'MISSED'})"
                     for t, a, e, m in zip(self.targets, row["achieved"], row["relative_error"], row["met"],
                                           strict=True)]
            lines.append(head + "; ".join(parts))
        return lines

    def _summary(self) -> tuple[str, list[tuple[str, Any]], list[str], list[list[Any]]]:
        items: list[tuple[str, Any]] = [("smallest margin", self.min_margin),
                                        ("required margin", self.min_margin_required)]
        items += [(f"target {t.text}", f"{a:.4g} ({'met' if ok else 'not met'})")
                  for t, a, ok in zip(self.targets, self.achieved, self.met, strict=True)]
        return (f"DesignResult: {'feasible' if self.feasible else 'NOT feasible'} ({self.model.replace('_', '-')} "
                "model)", items, ["variable", "value"], [[k, v] for k, v in self.values.items()])

    def __repr__(self) -> str:
        """A short summary: feasible or not, the targets, the design's variables (``str()`` explains)."""
        return summary_text(*self._summary())

    def _repr_html_(self) -> str:
        """The summary of :meth:`__repr__` for a notebook (HTML)."""
        return summary_html(*self._summary())

    def __str__(self) -> str:
        return self.summary()


def _margin_json(v: float) -> float | str | None:
    """A margin for JSON: the number, ``"inf"`` (no demand or no limit) or None (not defined)."""
    return "inf" if v == math.inf else (float(v) if np.isfinite(v) else None)


def _fmt_q(a: float) -> str:
    return f"{a:.5g}" if np.isfinite(a) else ("inf" if a == np.inf else "none")


def _fmt_pct(e: float) -> str:
    return f"{100 * e:+.1f} %" if np.isfinite(e) else "—"


def fmt_margin(v: float) -> str:
    """A safety margin in words: ``inf`` (no demand or no limit), ``none`` (not defined) or 3 digits.

    >>> fmt_margin(1.23456), fmt_margin(float("inf")), fmt_margin(float("nan"))
    ('1.23', 'inf', 'none')
    """
    return "inf" if v == math.inf else ("none" if not np.isfinite(v) else f"{v:.3g}")
