"""Incompressible Mooney-Rivlin bladder material (paper eq 18, 32-33).

The strain-energy density, with the paper's misprint in eq 18 read as ``(I2 - 3)``
(see ``shared/paper/NOTES.md`` item 6) and ``C11 = 0``::

    W = C10 (I1 - 3) + C01 (I2 - 3)

with ``I1 = l1^2 + l2^2 + l3^2``, ``I2 = l1^-2 + l2^-2 + l3^-2`` and incompressibility
``l3 = 1 / (l1 l2)`` (eq 17, 36).  Units follow the package convention: the constants are in
MPa (N/mm^2), so ``W`` is an energy per reference volume in N*mm/mm^3 = MPa.

The class is small and pure so it can be tested in isolation (the way ``felupe`` and
``hyperelastic`` treat their material laws).  It accepts arrays and broadcasts.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["MooneyRivlin"]


@dataclass(frozen=True)
class MooneyRivlin:
    """Two-parameter incompressible Mooney-Rivlin solid.

    Parameters
    ----------
    C10, C01 : float
        Material constants in MPa.  Either may be negative (the paper's Table 3 fits are), but the
        initial shear modulus ``mu = 2 (C10 + C01)`` must be positive.
    """

    C10: float
    C01: float

    def __post_init__(self) -> None:
        for name in ("C10", "C01"):
            v = getattr(self, name)
            if not np.isfinite(v):
                raise ValueError(f"{name} = {v!r} MPa is not finite")
        if self.C10 + self.C01 <= 0:
            raise ValueError(
                f"C10 + C01 = {self.C10 + self.C01:g} MPa must be > 0 "
                "(the initial shear modulus 2(C10 + C01) must be positive)"
            )

    @property
    def shear_modulus(self) -> float:
        """Initial shear modulus ``mu = 2 (C10 + C01)`` in MPa."""
        return 2.0 * (self.C10 + self.C01)

    # -- energy and its derivatives, with l3 = 1/(l1 l2) eliminated ------------------------------
    def energy(self, l1, l2):
        """Strain-energy density W(l1, l2) in MPa (eq 18, corrected)."""
        l1 = np.asarray(l1, dtype=float)
        l2 = np.asarray(l2, dtype=float)
        a, b = l1 * l1, l2 * l2
        i1 = a + b + 1.0 / (a * b)
        i2 = 1.0 / a + 1.0 / b + a * b
        return self.C10 * (i1 - 3.0) + self.C01 * (i2 - 3.0)

    def dW_dl1(self, l1, l2):
        """Partial derivative of W with respect to l1 (l3 eliminated), MPa."""
        l1 = np.asarray(l1, dtype=float)
        l2 = np.asarray(l2, dtype=float)
        return 2.0 * self.C10 * (l1 - 1.0 / (l1**3 * l2 * l2)) + 2.0 * self.C01 * (
            l1 * l2 * l2 - 1.0 / l1**3
        )

    def dW_dl2(self, l1, l2):
        """Partial derivative of W with respect to l2 (l3 eliminated), MPa."""
        return self.dW_dl1(l2, l1)

    # -- stresses --------------------------------------------------------------------------------
    def cauchy_difference(self, la, lb):
        """Cauchy stress difference ``sigma_a - sigma_b`` (eq 32-33), MPa.

        ``sigma_a - sigma_b = 2 C10 (la^2 - lb^2) - 2 C01 (la^-2 - lb^-2)`` for two principal
        stretches of an incompressible Mooney-Rivlin solid.
        """
        la = np.asarray(la, dtype=float)
        lb = np.asarray(lb, dtype=float)
        return 2.0 * self.C10 * (la * la - lb * lb) - 2.0 * self.C01 * (1.0 / (la * la) - 1.0 / (lb * lb))

    def uniaxial_nominal_stress(self, stretch):
        """Nominal (engineering) stress in uniaxial tension, MPa.

        ``P = 2 (l - l^-2) (C10 + C01 / l)``: the standard result for an incompressible
        Mooney-Rivlin solid with ``l2 = l3 = l^-1/2``.
        """
        lam = np.asarray(stretch, dtype=float)
        return 2.0 * (lam - lam**-2) * (self.C10 + self.C01 / lam)
