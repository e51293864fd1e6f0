"""Bending of a woven sample or composite (docs/method.md §10).

The bodies of sides xmin and xmax clamp the warp yarns' end sections (and,
in a composite, the matrix faces) and turn by opposite angles about y, half
the bending ``angle`` each; xmax is free to move along x (the sample is not
stretched), their other components held. The weft yarns' ends are free.

A positive angle turns xmax by +angle/2 about y: its face's normal tilts
downwards, (cos, 0, -sin), the sample bends convex upwards; the side above
its mid-plane is stretched and the side below compressed (a negative angle:
the other way round). The mid-plane: the middle of the fibres' z range in
the woven configuration (in a composite, the matrix box's).

Curve: the moment about y on the xmax body against the bending angle (the
angle between the two sides), in degrees; figure: the small-angle bending
stiffness, moment per width (the warp yarn count times their spacing) per
unit curvature (angle over the distance between the sides).

Voids (with fibre-fibre contact; :mod:`~textile.virtual_tests.voids`): per
step, the largest fibre-to-fibre gap opening since the start of loading
among the fibre pairs on the compressed side, its two fibres, the number of
pairs followed there and of those lost (opened beyond the contact's reach);
the summary holds the last step's.
"""
from __future__ import annotations

from .rotation_test import RotationTest
from .voids import GapOpening

#: step figures of the voids (GapOpening.measure's keys -> Bending's)
VOIDS = {"largest gap opening": "largest gap opening on the compressed side",
         "its fibres": "fibres of the largest gap opening",
         "pairs": "fibre pairs on the compressed side",
         "lost pairs": "fibre pairs lost on the compressed side"}


class Bending(RotationTest):
    """Bending by opposite rotations about y (module docstring)."""

    name = "bending"
    axis = "ry"
    xlabel = "bending angle [deg]"
    ylabel = "moment about y on side xmax"

    def __init__(self, fabric, woven, angle: float, **options):
        super().__init__(fabric, woven, angle, **options)
        # the mid-plane: the middle of the fibres' z range in the woven
        # configuration (a composite's matrix box is symmetric about it)
        z = self.sample.configuration[:, 2]
        contact = self.sample.contact
        self.voids = None if contact is None else \
            GapOpening(contact, 0.5 * (z.min() + z.max()),
                       side="below" if self.angle > 0 else "above")

    def measure(self, s: float):
        x, y, figures = super().measure(s)
        if self.voids is not None:
            if s == 0.0:     # the start of loading (the released sample)
                self.voids.start(self.sample.model)
            else:
                figures.update({VOIDS[k]: v for k, v in
                                self.voids.measure(self.sample.model).items()})
        return x, y, figures

    def summarize(self, result) -> dict:
        out = super().summarize(result)
        if self.voids is not None and result.steps:
            key = VOIDS["largest gap opening"]
            out[key] = result.steps[-1][key]
        return out
