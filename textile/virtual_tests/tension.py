"""Tension of a woven sample, uniaxial or biaxial.

Uniaxial: the body of side xmin holds the warp yarns' start sections fixed;
the body of xmax holds their end sections and moves along x to the nominal
strain ``strain`` (of the distance between the two sides), its other
components held; the weft yarns' ends are free.

Biaxial (``ratio`` given): the four sides get a body each, frictionless
plates (``slide``) so that the yarn ends of a side can spread or close
along it as the other direction stretches (a rigid clamp would hold them at
their woven spacing); xmax moves by ``strain`` along x, ymax by
``ratio * strain`` along y. Plates leave the sample free to move up and
down as a whole: the fibre node nearest the sample's centre is held in z
(it carries no load in equilibrium; its reaction is reported).
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
            self.sides = ("xmin", "xmax", "ymin", "ymax")
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
        raise NotImplementedError("biaxial tension: not yet available")

    def measure(self, s: float):
        force = self.sample.side_reaction("xmax")
        return s * self.strain, float(force[0]), {}

    def summarize(self, result) -> dict:
        width = self.sample.side_width("x")
        return {"membrane stiffness (force per width per strain)":
                result.curve.initial_slope() / width,
                "width": width, "gauge length": self.gauge}
