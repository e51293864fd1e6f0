"""Stability: is an equilibrium stable, and how does it lose stability?

- :mod:`.inertia`: the negative eigenvalues of a converged tangent from its
  LDL^T factorization (:class:`Inertia`), the critical modes (SLEPc);
- :mod:`.zero_motions`: the motions nothing resists (null vectors of the
  tangent), told by their shape and energy;
- :mod:`.buckling`: linearized buckling of small models (dense
  eigenproblems), for validation and studies.

The solver runs them after converged steps
(:class:`textile.solver.stability_check.StabilityCheck`).
"""
from .inertia import Inertia, critical_modes, factor_negative_pivots, zero_motion_pivots
from .zero_motions import ZeroMotion, describe, zero_energy_motions

__all__ = ["Inertia", "ZeroMotion", "critical_modes", "describe", "factor_negative_pivots",
           "zero_energy_motions", "zero_motion_pivots"]
