"""Discretization choices of the fibre elements (the accuracy knobs)."""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class BeamElement:
    """Element type shared by all fibres of a model.

    Parameters
    ----------
    order:
        Polynomial order along the fibre: 1 (2-node) or 2 (3-node).
    axial_points:
        Gauss points per element along the fibre; default ``order`` (reduced
        integration). Quadratic elements with 2 points are the default: free
        of shear and membrane locking (a cantilever's tip is exact on 4
        elements), and a free element has only the 6 rigid-body zero-energy
        modes (``cpp/tests/test_beam_element.cpp``). Full integration (3
        points) locks: a cantilever is 1.5% off on 4 elements (O(h^2)), a
        roll-up of a slender fibre still 0.8% off on 64 elements; linear elements
        need 1 point (O(h^2)); 2 points lock severely.
    section_order:
        Polynomial degree integrated exactly over the round section (>= 2).
        4 is exact for the straight beam's strain energy, force and tangent;
        orders 4 and 5 use Radon's 7-point rule (exact to degree 5), the
        others a polar product rule ((order // 2 + 1) x (order + 1) points).
    poisson_cure:
        Use the section-split law that removes Poisson locking (keep True;
        False only to show the locking).
    """

    order: int = 2
    axial_points: int | None = None
    section_order: int = 4
    poisson_cure: bool = True

    def __post_init__(self):
        if self.order not in (1, 2):
            raise ValueError(f"BeamElement.order must be 1 or 2, got {self.order!r}")
        if self.axial_points is None:
            object.__setattr__(self, "axial_points", self.order)
        if not isinstance(self.axial_points, int) or not 1 <= self.axial_points <= 10:
            raise ValueError(f"BeamElement.axial_points must be an integer in 1..10, "
                             f"got {self.axial_points!r}")
        if not isinstance(self.section_order, int) or not 2 <= self.section_order <= 40:
            raise ValueError(f"BeamElement.section_order must be an integer in 2..40, "
                             f"got {self.section_order!r}")
