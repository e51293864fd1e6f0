"""Penalty ties between fibre nodes and the matrix points they sit in.

Each tie joins the centroid x0 of a fibre node to the material point of an
:class:`~textile.effects.elastic_block.ElasticBlock` at the same reference
position, with the energy 1/2 k |gap|^2, gap = u_node - sum_i phi_i u_i
(k in N/m; phi_i the P1 basis of the matrix cell at the point). The kernel
is ``_cpp.point_tie`` (``cpp/textile/junction/point_tie.h``).

Parallel: a tie is assembled by the one rank owning its matrix cell (the
lowest such rank for a point on a partition interface). That rank may not
own the fibre node, so the tie makes the node a ghost of the fibre mesh
there (:meth:`FibreMesh.add_ghosts`) when it is created; ties must
therefore be created before the model is set up.
"""
from __future__ import annotations

import numbers

import numpy as np
from mpi4py import MPI

from .. import _cpp
from .base import Effect, State
from .elastic_block import ElasticBlock


class FibreMatrixTie(Effect):
    """Ties fibre nodes' centroids to the matrix points where they sit.

    Parameters
    ----------
    model:
        The :class:`~textile.Model` whose fibres are tied (collective call:
        every rank of the model's communicator creates the tie).
    block:
        The :class:`ElasticBlock` the nodes sit in; add it to the model
        before this tie.
    nodes:
        Sequence of (fibre, node) pairs (fibre object or index; node index,
        negative from the end), each inside the block's reference mesh.
    stiffness:
        Penalty stiffness k (N/m), > 0.
    """

    symmetric_tangent = True  # a quadratic penalty potential

    def __init__(self, model, block: ElasticBlock, nodes, stiffness: float):
        if not isinstance(block, ElasticBlock):
            raise TypeError(f"block must be an ElasticBlock, got {type(block).__name__}")
        if isinstance(stiffness, bool) or not isinstance(stiffness, numbers.Real) \
                or not np.isfinite(stiffness) or stiffness <= 0:
            raise ValueError(f"FibreMatrixTie: stiffness must be positive and finite, "
                             f"got {stiffness!r}")
        try:
            pairs = [(f, n) for f, n in nodes]
        except (TypeError, ValueError) as e:
            raise ValueError("FibreMatrixTie: nodes must be a sequence of (fibre, node) "
                             "pairs") from e
        if not pairs:
            raise ValueError("FibreMatrixTie: nodes is empty")
        mesh = model.mesh
        g = np.array([mesh.node(f, n) for f, n in pairs], dtype=np.int64)
        if len(np.unique(g)) != len(g):
            raise ValueError("FibreMatrixTie: a node is tied twice")
        self.fields = ("beam", block.name)
        self.block, self.stiffness = block, float(stiffness)
        self.nodes = g
        self._model = model
        cells, phi = block.point_basis(mesh.X_global[g, 0:3])
        mine = cells >= 0
        self._nodes_here = g[mine]
        self._cells = cells[mine]
        self._phi = phi[mine]
        mesh.add_ghosts(self._nodes_here)

    # -- Effect interface -------------------------------------------------
    def setup(self, model) -> None:
        if model is not self._model:
            raise ValueError("FibreMatrixTie: the tie belongs to another model")
        effects = model.effects
        if self.block not in effects or effects.index(self.block) > effects.index(self):
            # the block's set_pattern would replace the pattern this tie fills
            raise ValueError("FibreMatrixTie: add the ElasticBlock to the model before its ties")
        local = model.mesh.global_to_local(self._nodes_here)
        assert np.all(local >= 0), "tied nodes are local by construction (add_ghosts)"
        self._local = local.astype(np.int32)
        self._dofs = self.block.cell_dofs(self._cells)
        # all ties in one batch (C++): no Python loop per tie
        self._set = _cpp.PointTieSet(self.stiffness, self._local,
                                     np.ascontiguousarray(self._dofs, dtype=np.int32).ravel(),
                                     np.ascontiguousarray(self._phi, dtype=float).ravel())

    def add_sparsity(self, sparsity) -> None:
        m = self.block.name
        for l, dofs in zip(self._local, self._dofs):
            node = np.array([l], dtype=np.int32)
            sparsity.insert("beam", "beam", node, node)
            sparsity.insert("beam", m, node, dofs)
            sparsity.insert(m, "beam", dofs, node)
            sparsity.insert(m, m, dofs, dofs)

    def residual(self, state: State, b) -> None:
        self._set.assemble_vector(state.u["beam"], state.u[self.block.name], b["beam"],
                                  b[self.block.name])

    def jacobian(self, state: State, A) -> None:
        self._set.assemble_matrix(A, state.dofs["beam"], state.dofs[self.block.name])

    # -- results ------------------------------------------------------------
    def tie_forces(self) -> np.ndarray:
        """Total force (3,) the ties exert on the matrix, sum of k gap over
        all ties at the model's current solution (N; collective). The
        fibres receive the opposite force."""
        st = self._model.state()
        total = self._set.total_force(st.u["beam"], st.u[self.block.name])
        return self._model.comm.allreduce(total, op=MPI.SUM)
