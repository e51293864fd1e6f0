"""Fibre material: isotropic St Venant-Kirchhoff (Young's modulus, Poisson ratio)."""
from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Material:
    """Isotropic St Venant-Kirchhoff material.

    Parameters
    ----------
    young:
        Young's modulus E (Pa, or any unit consistent with lengths and forces).
    poisson:
        Poisson ratio nu, in (-1, 0.5).
    """

    young: float
    poisson: float = 0.3

    def __post_init__(self):
        for name in ("young", "poisson"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise TypeError(f"Material.{name} must be a real number, got {type(v).__name__}")
            if not math.isfinite(v):
                raise ValueError(f"Material.{name} must be finite, got {v}")
        if self.young <= 0:
            raise ValueError(f"Material.young must be positive, got {self.young}")
        if not -1.0 < self.poisson < 0.5:
            raise ValueError(f"Material.poisson must lie in (-1, 0.5), got {self.poisson}")

    @property
    def shear_modulus(self) -> float:
        """G = E / (2 (1 + nu))."""
        return self.young / (2.0 * (1.0 + self.poisson))
