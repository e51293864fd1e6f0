"""Tension of a woven sample, uniaxial or biaxial.

Uniaxial: the body of side xmin holds the warp yarns' start sections fixed;
the body of xmax holds their end sections and moves along x to the nominal
strain ``strain`` (of the distance between the two sides), its other
components held; the weft yarns' ends are free.

Biaxial (``ratio`` given): every yarn end is clamped by a body of its own
(a multi-clamp rig), moved with the homogeneous in-plane stretch of the
sample about its centre: strain ``strain`` along x, ``ratio * strain``
along y, so that the yarn ends of a side spread as the other direction
stretches (a rigid side would hold them at their woven spacing); their
other components are held.
Crimp interchange shows in the biaxial curves: a yarn direction stretched
less than the other straightens less and is stiffer.

Curve: the force on the xmax body along x against the nominal strain;
figure: the membrane stiffness, force per unit width (the warp yarn count
times their spacing) per unit strain, from the small-strain part.
"""
from __future__ import annotations

import numbers

import numpy as np

from .virtual_test import VirtualTest


class Tension(VirtualTest):
    """Uniaxial (``ratio=None``) or biaxial tension (module docstring);
    ``strain``: nominal strain of the warp direction at the end of loading."""

    name = "tension"
    xlabel = "nominal strain along x [-]"
    ylabel = "force on side xmax along x"

    def __init__(self, fabric, woven, strain: float, ratio: float | None = None, **options):
        if isinstance(strain, bool) or not isinstance(strain, numbers.Real) \
                or not np.isfinite(strain) or strain == 0:
            raise ValueError(f"Tension: strain must be a non-zero number, got {strain!r}")
        if ratio is not None and (isinstance(ratio, bool) or not isinstance(ratio, numbers.Real)
                                  or not np.isfinite(ratio)):
            raise ValueError(f"Tension: ratio must be a number or None, got {ratio!r}")
        self.strain, self.ratio = float(strain), ratio
        if ratio is not None:
            self.name = "biaxial_tension"
            self.sides = self.split = ("xmin", "xmax", "ymin", "ymax")
            if options.get("matrix") is not None:
                raise ValueError("Tension: biaxial tension of a composite is not available "
                                 "(its sides' bodies would share the matrix's edge nodes)")
        super().__init__(fabric, woven, **options)

    def drive(self) -> dict:
        sides = self.sample.sides
        if self.ratio is None:
            sides["xmin"].fix("all")
            sides["xmax"].fix(("y", "z", "rx", "ry", "rz"))
            return {sides["xmax"].prescribe("x", 0.0): self.strain * self.gauge}
        # each yarn end follows the homogeneous stretch about the centre
        ends = np.vstack([self.sample.end_positions(side) for side in self.sides])
        centre = 0.5 * (ends.min(axis=0) + ends.max(axis=0))
        strain = np.array([self.strain, self.ratio * self.strain])
        targets = {}
        for side, bodies in self.sample.yarn_bodies.items():
            for k, body in bodies.items():
                x = self.sample.end_positions(side, yarn=k).mean(axis=0)
                body.fix(("z", "rx", "ry", "rz"))
                for axis, name in enumerate(("x", "y")):
                    targets[body.prescribe(name, 0.0)] = strain[axis] * (x[axis] - centre[axis])
        return targets

    def measure(self, s: float):
        force = self.sample.side_reaction("xmax")
        figures = {}
        if self.ratio is not None:
            figures["force on side ymax along y"] = float(self.sample.side_reaction("ymax")[1])
            figures["strain along y"] = s * self.ratio * self.strain
        return s * self.strain, float(force[0]), figures

    def summarize(self, result) -> dict:
        width = self.sample.side_width("x")
        out = {"membrane stiffness (force per width per strain)":
               result.curve.initial_slope() / width,
               "width": width, "gauge length": self.gauge}
        if self.ratio is not None:
            out["weft force per width at the end"] = \
                result.steps[-1]["force on side ymax along y"] / self.sample.side_width("y")
        return out
