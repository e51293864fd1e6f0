"""The current unknowns of chosen fibre nodes on this rank, from their owners.

An effect that couples nodes of other ranks (contact: an element between
two fibres may read nodes of both ranks) needs their current values at
every residual and tangent. Gathering the whole fibre state to every rank
costs memory and communication that grow with the whole problem; a
:class:`NodeGather` moves only the chosen nodes' values, with one PETSc
scatter from the global vector, set up once for a set of nodes (contact:
once per detection pass) and run once per evaluation.
"""
from __future__ import annotations

import numpy as np
from petsc4py import PETSc


class NodeGather:
    """[x0, g1, g2] of global fibre nodes ``nodes`` from a global vector.

    ``system``: the assembled :class:`~textile.system.system.System` (its
    layout numbers the unknowns). Creating one and calling
    :meth:`positions` are collective: every rank does both at the same
    moments, with its own nodes (possibly none).
    """

    def __init__(self, system, nodes):
        self.nodes = np.unique(np.asarray(nodes, dtype=np.int64))
        mesh = system.mesh
        dofs = system.beam_global_dofs(constrained=True).reshape(-1, 9)[self.nodes]
        self._reference = mesh.X_global[self.nodes]
        #: unknowns of other ranks' nodes among them (what travels at each call)
        self.num_remote = 9 * int(np.count_nonzero(mesh.node_owner[self.nodes] != mesh.rank))
        self._values = PETSc.Vec().createSeq(dofs.size, comm=PETSc.COMM_SELF)
        index = PETSc.IS().createGeneral(dofs.ravel().astype(PETSc.IntType), comm=PETSc.COMM_SELF)
        self._scatter = PETSc.Scatter().create(system.x, index, self._values, None)
        index.destroy()
        # nodes not asked for stay NaN: a kernel reading one is a bug to see
        self._q = np.full((mesh.num_nodes_global, 9), np.nan)

    @property
    def num_values(self) -> int:
        """Unknowns gathered at each call (this rank's own among them)."""
        return self._values.getSize()

    def positions(self, x: PETSc.Vec) -> np.ndarray:
        """(global nodes, 9) current [x0, g1, g2]: reference plus the
        displacement in the global vector ``x`` at the chosen nodes, NaN
        at the others. Collective."""
        self._scatter.scatter(x, self._values, addv=PETSc.InsertMode.INSERT,
                              mode=PETSc.ScatterMode.FORWARD)
        self._q[self.nodes] = self._reference + self._values.getArray(readonly=True).reshape(-1, 9)
        return self._q

    def destroy(self) -> None:
        self._scatter.destroy()
        self._values.destroy()
