"""Bending of a woven sample or composite (METHOD.md section 8).

The bodies of sides xmin and xmax clamp the warp yarns' end sections (and,
in a composite, the matrix faces) and turn by opposite angles about y, half
the bending ``angle`` each; xmax is free to move along x (the sample is not
stretched), their other components held. The weft yarns' ends are free.

Curve: the moment about y on the xmax body against the bending angle (the
angle between the two sides), in degrees; figure: the small-angle bending
stiffness, moment per width (the warp yarn count times their spacing) per
unit curvature (angle over the distance between the sides).
"""
from __future__ import annotations

from .rotation_test import RotationTest


class Bending(RotationTest):
    """Bending by opposite rotations about y (module docstring)."""

    name = "bending"
    axis = "ry"
    xlabel = "bending angle [deg]"
    ylabel = "moment about y on side xmax"
