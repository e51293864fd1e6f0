"""textile: fibre-scale simulation of woven fabrics and textile composites.

Fibres are finite-strain beams with deformable sections (9 unknowns a
node); every physics term is an *effect* assembled into one monolithic
PETSc SNES solve. See README.md ("Usage") and ``demos/``.
"""
import sys as _sys

# petsc4py must be initialized with the command line before dolfinx (and
# before the compiled module makes PETSc calls), or -snes_* options are lost.
import mpi4py  # noqa: F401
import petsc4py

petsc4py.init(_sys.argv)  # a no-op if PETSc is already initialized
from petsc4py import PETSc  # noqa: E402,F401

from . import _cpp  # noqa: E402
from . import log  # noqa: E402
from . import runtime  # noqa: E402

log.configure()  # the textile logger: rank in the lines, ranks > 0 quiet

# one OpenBLAS thread per core, shared by the ranks on a node (no
# oversubscription under mpirun); see textile.runtime
runtime.limit_blas_threads()
from ._cpp import GeometryError  # noqa: E402
from .beam.element import BeamElement  # noqa: E402
from .beam.fibre import Fibre, arc_fibre, straight_fibre  # noqa: E402
from .beam.material import Material  # noqa: E402
from .scene.model import Model  # noqa: E402
from .io.state_file import (SceneMismatchError, StateFileError, load_fibres,  # noqa: E402
                            load_state, save_state, saved_configuration, saved_fibres)
from .scene.loading import Stage  # noqa: E402
from .io.output import Output  # noqa: E402
from .scene.rigid_body import RigidBody  # noqa: E402
from .solver import ConvergenceError, Solver, SolverOptions  # noqa: E402

__all__ = ["BeamElement", "Fibre", "Material", "Model", "Solver", "SolverOptions",
           "ConvergenceError", "GeometryError", "Output", "RigidBody", "Stage", "save_state",
           "load_state", "load_fibres", "saved_configuration", "saved_fibres",
           "StateFileError", "SceneMismatchError", "straight_fibre", "arc_fibre", "PETSc", "_cpp"]
__version__ = "0.1.0"
