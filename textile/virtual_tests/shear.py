"""In-plane shear of a woven sample as in the paper (docs/method.md §10).

The body of side xmin clamps the warp yarns' start sections (fixed); the
body of xmax clamps their end sections and is moved parallel to itself,
along y, by ``displacement``; its displacement along x (orthogonal to the
side) is free, its other components held; the weft yarns' ends (sides ymin
and ymax) are free.

Curve: the force on the xmax body along y against the shear angle
gamma = atan(u / L) (u its displacement, L the distance between the two
sides), in degrees; figures: the small-angle shear stiffness (force per
width, the warp yarn count times their spacing, per radian), the angle
where the tangent stiffness has risen tenfold (None when the computed
range does not reach it), and beside it the pin-joint locking bound
arccos(w/p) (:func:`locking_bound`).
"""
from __future__ import annotations

import math
import numbers

import numpy as np

from .virtual_test import VirtualTest


class Shear(VirtualTest):
    """The paper's shear test (module docstring); ``displacement``: of side
    xmax along y at the end of loading (its sign sets the direction)."""

    name = "shear"
    xlabel = "shear angle [deg]"
    ylabel = "force on side xmax along y"

    def __init__(self, fabric, woven, displacement: float, **options):
        if isinstance(displacement, bool) or not isinstance(displacement, numbers.Real) \
                or not np.isfinite(displacement) or displacement == 0:
            raise ValueError(f"Shear: displacement must be a non-zero length, got "
                             f"{displacement!r}")
        self.displacement = float(displacement)
        super().__init__(fabric, woven, **options)

    def drive(self) -> dict:
        sides = self.sample.sides
        sides["xmin"].fix("all")
        sides["xmax"].fix(("z", "rx", "ry", "rz"))
        return {sides["xmax"].prescribe("y", 0.0): self.displacement}

    def measure(self, s: float):
        force = self.sample.side_reaction("xmax")
        u = s * self.displacement
        return math.degrees(math.atan2(u, self.gauge)), float(force[1]), {"displacement": u}

    def summarize(self, result) -> dict:
        width = self.sample.side_width("x")
        stiffness = result.curve.initial_slope() * 180.0 / math.pi
        return {"shear stiffness (force per width per radian)": stiffness / width,
                "tenfold stiffening angle [deg]": result.curve.stiffening_point(10.0),
                "pin-joint locking bound arccos(w/p) [deg]": locking_bound(self.sample.fabric),
                "width": width, "gauge length": self.gauge}


def locking_bound(fabric) -> float:
    """The pin-joint bound of the shear locking angle, arccos(w/p) in
    degrees (docs/references.md §12): the shear angle at which neighbouring
    parallel yarns, of width w and spacing p, touch side to side (the
    narrower of the two directions' bounds)."""
    ratios = [min(1.0, fabric.warp.width / fabric.spacing[0]),
              min(1.0, fabric.weft.width / fabric.spacing[1])]
    return math.degrees(math.acos(max(ratios)))
