"""Twisting of a woven sample or composite (docs/method.md §10).

The bodies of sides xmin and xmax clamp the warp yarns' end sections (and,
in a composite, the matrix faces) and turn by opposite angles about x, the
sides' normal, half the twist ``angle`` each; xmax is free to move along x,
their other components held. The weft yarns' ends are free.

Curve: the moment about x on the xmax body against the twist angle, in
degrees; figure: the small-angle torsional stiffness, moment per unit twist
(angle over the distance between the sides).
"""
from __future__ import annotations

from .rotation_test import RotationTest


class Twisting(RotationTest):
    """Twisting by opposite rotations about x (module docstring)."""

    name = "twisting"
    axis = "rx"
    xlabel = "twist angle [deg]"
    ylabel = "moment about x on side xmax"
