"""Physics terms of the global system ("effects").

Each effect adds its residual and tangent to the blocks of the fields it
touches, and only the effects a scene has are assembled. A new physical
term is a new file here implementing :class:`~textile.effects.base.Effect`.
"""
from .base import Effect, State
from .beam_elasticity import BeamElasticity
from .nodal_loads import EndMoments, NodalForces

__all__ = ["Effect", "State", "BeamElasticity", "NodalForces", "EndMoments"]
