"""Physics terms of the global system ("effects").

Each effect adds its residual and tangent to the blocks of the fields it
touches, and only the effects a scene has are assembled. A new physical
term is a new file here implementing :class:`~textile.effects.base.Effect`.
"""
from .base import Effect, State
from .beam_elasticity import BeamElasticity
from .heddles import Heddles
from .nodal_loads import EndMoments, NodalForces, ReleasedForces
from .viscous_drag import ViscousDrag

__all__ = ["Effect", "State", "BeamElasticity", "NodalForces", "EndMoments", "ReleasedForces",
           "ViscousDrag", "Heddles",
           "ElasticBlock",
           "FibreMatrixTie", "FibreMatrixJunctions"]

# Effects that need dolfinx's form machinery (UFL, JIT) are imported on
# first use: a scene without a matrix does not pay for them.
_LAZY = {"ElasticBlock": "elastic_block", "FibreMatrixTie": "fibre_matrix_tie",
         "FibreMatrixJunctions": "fibre_matrix_junction"}


def __getattr__(name):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
