"""Bending and twisting share their drive: opposite rotations of the bodies
of sides xmin and xmax about one axis, xmax free to move along x."""
from __future__ import annotations

import math
import numbers

import numpy as np

from .virtual_test import VirtualTest

_COMPONENT = {"rx": 3, "ry": 4, "rz": 5}


class RotationTest(VirtualTest):
    """Opposite rotations by half of ``angle`` (radians) each about
    :attr:`axis` of the sides xmin (-) and xmax (+)."""

    axis = "ry"

    def __init__(self, fabric, woven, angle: float, **options):
        if isinstance(angle, bool) or not isinstance(angle, numbers.Real) \
                or not np.isfinite(angle) or angle == 0:
            raise ValueError(f"{type(self).__name__}: angle must be a non-zero angle in "
                             f"radians, got {angle!r}")
        self.angle = float(angle)
        super().__init__(fabric, woven, **options)

    def drive(self) -> dict:
        sides = self.sample.sides
        others = tuple(c for c in ("rx", "ry", "rz") if c != self.axis)
        sides["xmin"].fix(("x", "y", "z") + others)
        sides["xmax"].fix(("y", "z") + others)
        half = 0.5 * self.angle
        return {sides["xmin"].prescribe(self.axis, 0.0): -half,
                sides["xmax"].prescribe(self.axis, 0.0): half}

    def measure(self, s: float):
        moment = self.sample.side_reaction("xmax")[_COMPONENT[self.axis]]
        return math.degrees(s * self.angle), float(moment), {}

    def summarize(self, result) -> dict:
        per_radian = result.curve.initial_slope() * 180.0 / math.pi
        out = {"stiffness (moment per unit curvature)": per_radian * self.gauge,
               "gauge length": self.gauge}
        if self.axis == "ry":
            width = self.sample.side_width("x")
            out["bending stiffness per width (moment per width per unit curvature)"] = \
                per_radian * self.gauge / width
        return out
