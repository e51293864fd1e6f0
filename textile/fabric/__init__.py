"""Woven fabrics: yarns, weave patterns, the fabric, weaving, measures.

- :mod:`.yarn`: :class:`Yarn`, a yarn's fibres (count, packing, twist);
- :mod:`.weave_pattern`: :class:`WeavePattern`, which yarn is on top where;
- :mod:`.fabric`: :class:`Fabric`, yarns laid out in a weave (the fibres
  of its starting, interpenetrating state);
- :mod:`.weaving`: :class:`Weaving`, the solve that pushes the yarns
  apart into a woven state (:func:`woven_state`);
- :mod:`.sample`: :class:`Sample`, a woven fabric with its clamps and
  contact, ready for a virtual test;
- :mod:`.measures`: what a woven fabric measures (crimp, thickness,
  crossing separation, ...).
"""
from .fabric import Fabric
from .sample import SIDES, Sample
from .weave_pattern import WeavePattern
from .weaving import Weaving, woven_state
from .yarn import Yarn

__all__ = ["Fabric", "SIDES", "Sample", "WeavePattern", "Weaving", "Yarn", "woven_state"]
