"""The figure of a design sweep: one output against one or two of the swept dimensions.

Registered as ``"sweep"`` (:mod:`bendpam.infra.accessors`); drawn with the object-oriented API
(:func:`~bendpam.present.figures.style.new_figure`) inside the journal style.
"""

from __future__ import annotations

import numpy as np

from bendpam.errors import InputError
from bendpam.infra.accessors import register
from bendpam.present.figures.style import SINGLE_COLUMN_IN, figure_size, new_figure, styled, wrap_text

__all__ = ["sweep_figure"]


def _axes_and_fixed(da_, var: str, x: str | None, y: str | None, at: dict[str, float]):
    """The plotted dimensions ``(x, y or None)`` and the index at which every other one is fixed."""
    dims = list(da_.dims)
    for d in at:
        if d not in dims:
            raise InputError(f"cannot fix {d!r} (at): it is not a dimension of {var}; choose from {', '.join(dims)}")
    free = [str(d) for d in dims if da_[d].size > 1 and d not in at]
    xd: str = x or (free[0] if free else str(dims[0]))
    yd: str | None = y or next((d for d in free if d != xd), None)
    for dim in (xd, yd):
        if dim is not None and dim not in dims:
            raise InputError(f"{dim!r} is not a dimension of {var}; choose from {', '.join(dims)}")
    index = {}
    for d in dims:
        if d in (xd, yd):
            continue
        vals = np.asarray(da_[d].values, dtype=float)
        index[d] = int(np.argmin(np.abs(vals - float(at[d])))) if d in at else vals.size // 2
    return xd, yd, index


@register("sweep")
@styled
def sweep_figure(ds, var: str = "free_angle_deg", x: str | None = None, y: str | None = None,
                 at: dict[str, float] | None = None):
    """Colour map (or line) of one sweep output against one or two of its dimensions.

    ``x`` and ``y`` default to the first two dimensions of ``var`` with more than one value (a
    single pressure is not an axis).  The other dimensions are fixed at ``at`` (``{dim: value}``,
    the nearest value is taken) or else at their middle value; the title names them.

    Examples
    --------
    >>> from bendpam.physics import presets
    >>> from bendpam.sweeps import sweep
    >>> ds = sweep(presets.be_pam(), [100.0, 200.0], alpha0_deg=[66, 70, 74], t0_mm=[2.0, 2.5])
    >>> fig = sweep_figure(ds, at={"t0_mm": 2.5})
    >>> ax = fig.axes[0]
    >>> ax.get_xlabel(), ax.get_ylabel(), ax.get_title().splitlines()[-1]
    ('alpha0_deg', 'pressure_kpa', 't0_mm = 2.5')
    """
    if var not in ds.data_vars:
        raise InputError(f"variable {var!r} is not a sweep output; choose from {', '.join(ds.data_vars)}")
    da_ = ds[var]
    xd, yd, index = _axes_and_fixed(da_, var, x, y, dict(at or {}))
    fixed = {d: float(da_[d].values[i]) for d, i in index.items()}
    sel = da_.isel(index) if index else da_
    fig = new_figure(figure_size("single", 0.85))
    ax = fig.add_subplot()
    if yd is None:
        ax.plot(sel[xd].values, np.asarray(sel.values, dtype=float), "-o", ms=3)
        ax.set_ylabel(f"{var} ({da_.attrs.get('units', '')})")
    else:
        z = np.asarray(sel.transpose(yd, xd).values, dtype=float)
        m = ax.pcolormesh(sel[xd].values, sel[yd].values, np.ma.masked_invalid(z), shading="auto", cmap="viridis")
        fig.colorbar(m, ax=ax, label=f"{var} ({da_.attrs.get('units', '')})")
        if np.any(~np.isfinite(z)):
            ax.contour(sel[xd].values, sel[yd].values, np.isfinite(z).astype(float), levels=[0.5], colors="crimson",
                       linewidths=1.0)
        ax.set_ylabel(yd)
    ax.set_xlabel(xd)
    title = wrap_text(da_.attrs.get("long_name", var), 0.8 * SINGLE_COLUMN_IN)
    if fixed:
        title += "\n" + wrap_text(", ".join(f"{d} = {v:g}" for d, v in fixed.items()), 0.8 * SINGLE_COLUMN_IN)
    ax.set_title(title)
    fig.tight_layout()
    return fig
