"""The report's tables as text: Table 2 (the processed tests) and Table 3 (the fits), cell by cell.

Public, so that the command line prints and the tests check the very text the page shows.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from bendpam.identify.diagnose import at_bound
from bendpam.present.report.text import MODEL_LABEL, finite, fmt_pct, fmt_value

__all__ = ["T3_PARAMS", "param_text", "shear_modulus", "table2_rows", "table3_rows"]

#: Table 3's parameter columns: short names.
T3_PARAMS = ("alpha0", "C10", "C01")


def shear_modulus(res) -> tuple[float | None, float | None]:
    """The shear modulus mu = 2 (C10 + C01) and its standard error (kPa), or (None, None) without C10, C01.

    From the fit's own material identification where it has one, else from C10, C01 and their correlation.

    >>> import numpy as np
    >>> from types import SimpleNamespace as NS
    >>> c10, c01 = NS(value=100.0, stderr=3.0, vary=True), NS(value=300.0, stderr=4.0, vary=True)
    >>> shear_modulus(NS(material=None, parameters={"C10": c10, "C01": c01}, correlation=np.eye(2),
    ...                  correlation_names=["C10", "C01"]))
    (800.0, 10.0)
    """
    mat = getattr(res, "material", None)
    mu_mat = getattr(mat, "shear_modulus_kpa", None)
    if mu_mat is not None and finite(mu_mat):
        se = getattr(mat, "se_shear_modulus_kpa", None)
        return float(mu_mat), (float(se) if se is not None and finite(se) else None)
    params = res.parameters
    c10, c01 = params.get("C10"), params.get("C01")
    if c10 is None or c01 is None:
        return None, None
    mu = 2.0 * (c10.value + c01.value)
    s10 = c10.stderr if (c10.vary and finite(c10.stderr)) else 0.0
    s01 = c01.stderr if (c01.vary and finite(c01.stderr)) else 0.0
    if (c10.vary and not finite(c10.stderr)) or (c01.vary and not finite(c01.stderr)):
        return mu, None
    r = 0.0
    names = list(res.correlation_names)
    if "C10" in names and "C01" in names:
        rr = res.correlation[names.index("C10"), names.index("C01")]
        r = float(rr) if finite(rr) else 0.0
    var = s10 * s10 + s01 * s01 + 2.0 * r * s10 * s01
    se = 2.0 * math.sqrt(max(var, 0.0)) if (c10.vary or c01.vary) else None
    return mu, se


def param_text(p) -> str:
    """A parameter's cell: ``value ± SE`` (`` *`` at a bound of its range), ``(fixed)``, or an em dash.

    >>> from types import SimpleNamespace as NS
    >>> param_text(NS(value=69.7345, stderr=0.0119, min=62.73, max=76.67, vary=True))
    '69.735 ± 0.012'
    >>> param_text(NS(value=68.0, stderr=None, min=0.0, max=98.0, vary=False)), param_text(None)
    ('68.00 (fixed)', '—')
    """
    if p is None:
        return "—"
    if not p.vary:
        return f"{fmt_value(p.value)} (fixed)"
    text = fmt_value(p.value, p.stderr)
    if not finite(p.stderr):
        text += " ± n/a"
    return text + (" *" if at_bound(p) else "")


def table2_rows(summary: dict) -> list[dict[str, str]]:
    """The text of Table 2's body cells, one dict per pressure, from ``ProcessedSet.summary()``.

    >>> row = {"pressure_kpa": 100.0, "cycles": 3, "blocked_moment_nmm": 80.0626, "blocked_moment_se_nmm": 0.8145,
    ...        "free_curvature_per_mm": 0.0121, "free_curvature_se_per_mm": 0.0021, "energy_loss_ratio": 0.1876}
    >>> list(table2_rows({"pressures": [row]})[0].values())
    ['100', '3', '80.06 ± 0.81', '0.0121 ± 0.0021', '18.8']
    """
    rows = []
    for r in summary["pressures"]:
        rows.append({
            "pressure_kpa": f"{float(r['pressure_kpa']):g}",
            "cycles": str(int(r["cycles"])),
            "blocked_moment_nmm": fmt_value(r["blocked_moment_nmm"], r["blocked_moment_se_nmm"]),
            "free_curvature_per_mm": fmt_value(r["free_curvature_per_mm"], r["free_curvature_se_per_mm"]),
            "energy_loss_percent": fmt_pct(r["energy_loss_ratio"]),
        })
    return rows


def table3_rows(fits: Mapping) -> list[dict[str, str]]:
    """The text of Table 3's body cells, one dict per model, from ``{model: FitResult}``.

    Keys: ``model``, ``alpha0``, ``C10``, ``C01`` (value ± SE, `` *`` at a bound, ``(fixed)``),
    ``mu`` (the shear modulus 2 (C10 + C01) ± SE, kPa) and the NRMSEs in % ``nrmse_cycles``,
    ``nrmse_blocked_moment``, ``nrmse_free_curvature``.

    >>> import numpy as np
    >>> from types import SimpleNamespace as NS
    >>> alpha0 = NS(value=69.7345, stderr=0.0119, min=62.73, max=76.67, vary=True)
    >>> res = NS(parameters={"alpha0": alpha0}, material=None, correlation=np.eye(1), correlation_names=["alpha0"],
    ...          metrics=NS(nrmse_cycles=0.0412, nrmse_blocked_moment=0.031, nrmse_free_curvature=0.052))
    >>> list(table3_rows({"energy": res})[0].values())
    ['energy model', '69.735 ± 0.012', '—', '—', '—', '4.12', '3.10', '5.20']
    """
    rows = []
    for model, res in fits.items():
        m = res.metrics
        row = {"model": f"{MODEL_LABEL.get(model, model)} model"}
        for name in T3_PARAMS:
            row[name] = param_text(res.parameters.get(name))
        mu, mu_se = shear_modulus(res)
        row["mu"] = fmt_value(mu, mu_se) if mu is not None else "—"
        row["nrmse_cycles"] = fmt_pct(m.nrmse_cycles)
        row["nrmse_blocked_moment"] = fmt_pct(m.nrmse_blocked_moment)
        row["nrmse_free_curvature"] = fmt_pct(m.nrmse_free_curvature)
        rows.append(row)
    return rows

