"""The fast path: evaluate the moment law from cached spline tables.

The table itself is :class:`bendpam.MomentTable`, owned by the law
(:meth:`bendpam.MomentLaw.tabulated`): ``A(k')`` and ``B(k')/k'`` on Chebyshev-Lobatto knots on
each side of ``k' = 0``, interpolated by a C2 cubic spline, with the interpolation error measured
at build time against the exact path and the knots doubled until it is below ``tol``.  This
module gives the shortcut :func:`moment_table` (the cached table of an actuator and model).

>>> import bendpam
>>> from bendpam.physics.fast import moment_table
>>> t = moment_table(bendpam.physics.presets.be_pam())
>>> t.max_rel_error < 1e-6
True
>>> round(float(t(200.0, 0.0)), 1)
310.3
"""

from __future__ import annotations

from bendpam.physics.actuator import Actuator
from bendpam.physics.law import MomentLaw, MomentTable

__all__ = ["MomentTable", "moment_table"]


def moment_table(actuator: Actuator, model: str | None = None, *, eq19_factor: bool = True,
                 tol: float = 1e-6) -> MomentTable:
    """The cached :class:`MomentTable` of ``actuator`` and ``model`` (built on first use).

    Examples
    --------
    >>> import bendpam
    >>> table = moment_table(bendpam.physics.presets.bc_pam(), "force_balance")
    >>> table is moment_table(bendpam.physics.presets.bc_pam(), "force_balance"), table.max_rel_error < 1e-6
    (True, True)
    """
    return MomentLaw.of(actuator, model, eq19_factor=eq19_factor).tabulated(tol)
