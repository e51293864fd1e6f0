"""Elastic energy of all fibre elements (Durville beams with deformable sections)."""
from __future__ import annotations

import os

import numpy as np

from .. import _cpp
from .base import Effect, State


def element_threads() -> int:
    """Threads for the beam element loops: ``$TEXTILE_NUM_THREADS`` if set,
    else the cores this process may run on divided by the MPI ranks started
    on its node (one rank on a 2-core machine: 2; ``mpirun -n 2``: 1 each).
    Not collective: the launcher's environment says how many ranks share
    the node."""
    env = os.environ.get("TEXTILE_NUM_THREADS")
    if env:
        if not env.isdigit() or int(env) < 1:
            raise ValueError(f"TEXTILE_NUM_THREADS must be a positive integer, got {env!r}")
        return int(env)
    local = os.environ.get("OMPI_COMM_WORLD_LOCAL_SIZE") or os.environ.get("MPI_LOCALNRANKS")
    node_ranks = int(local) if local and local.isdigit() else 1
    return max(1, len(os.sched_getaffinity(0)) // node_ranks)


class BeamElasticity(Effect):
    """Internal forces and exact tangent of the fibres' beam elements.

    The element kernel and its assembly loop are in C++
    (``cpp/textile/beam/beam_element.*``, ``cpp/textile/assembly/``).
    """

    fields = ("beam",)
    symmetric_tangent = True  # the Hessian of the stored energy (MIP keeps it symmetric)

    def setup(self, model) -> None:
        mesh, el = model.mesh, model.element
        rule = _cpp.ElementRule(el.order + 1, el.axial_points, el.poisson_cure)
        mats = [_cpp.Material(f.material.young, f.material.poisson) for f in mesh.fibres]
        secs = [_cpp.SectionQuadrature(f.radius, el.section_order) for f in mesh.fibres]
        ids = mesh.local_element_ids
        groups = mesh.element_fibre[ids].astype(np.int32)
        # number of each element within its fibre (elements are numbered fibre by fibre)
        numbers = (ids - np.searchsorted(mesh.element_fibre, groups)).astype(np.int32)
        self._assembler = _cpp.BeamAssembler(rule, mesh.elements_local, groups, mats, secs,
                                             np.ascontiguousarray(mesh.X_local.ravel()),
                                             numbers)
        self._assembler.num_threads = element_threads()
        self._mesh = mesh
        self.energy = 0.0

    def add_sparsity(self, sparsity) -> None:
        for e in self._mesh.elements_local:
            sparsity.insert("beam", "beam", e, e)

    def residual(self, state: State, b) -> None:
        self.energy = self._assembler.assemble_vector(state.u["beam"], b["beam"])

    def jacobian(self, state: State, A) -> None:
        # with the last Newton update (SolverOptions(newton="mip")) the
        # geometric stiffness uses the linearly extrapolated (MIP) stress
        self._assembler.assemble_matrix(A, state.u["beam"], state.dofs["beam"],
                                        state.du.get("beam"), state.du_weights.get("beam"))

    def element_fields(self, u_beam: np.ndarray) -> np.ndarray:
        """(local elements, 12): section-averaged GL strain and 2nd PK stress
        (Voigt 11, 22, 33, 23, 13, 12; local frame, 3 = fibre axis)."""
        return self._assembler.fields(u_beam)
