"""Virtual tests on woven samples and composites (docs/method.md §10):
tension, shear (the paper's set-up and the picture frame), bending and
twisting, each driven by side rigid bodies from a saved woven state, with a
load curve (CSV, PNG), ParaView output per step and the test's figures."""
from .bending import Bending
from .load_curve import LoadCurve
from .picture_frame import PictureFrame
from .shear import Shear
from .tension import Tension
from .twisting import Twisting
from .virtual_test import (START_FIGURE, IncompleteTest, VirtualTest, VirtualTestResult,
                           figures_table)

__all__ = ["START_FIGURE", "Bending", "IncompleteTest", "LoadCurve", "PictureFrame", "Shear",
           "Tension", "Twisting", "VirtualTest", "VirtualTestResult", "figures_table"]
