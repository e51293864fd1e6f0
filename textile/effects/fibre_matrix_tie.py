"""Penalty ties between fibre nodes and the matrix points they sit in.

A thin case of :class:`~textile.effects.fibre_matrix_junction.FibreMatrixJunctions`:
each tie is a junction whose particle is the node itself (the element
coordinate of the node in one of its elements; its centroid only, no section
particles: the node's section vectors are not tied), with weight w = 1 and the
stiffness k in N/m per tie (not per unit length), energy 1/2 k |gap|^2,
gap = x_node - x_m. Prefer the junctions along the fibre, whose stiffness
per unit length does not depend on the node spacing.

Parallel: as for the junctions, a tie is assembled by the rank owning its
matrix cell, and the node's element becomes local there; ties must be
created before the model is set up.
"""
from __future__ import annotations

import numbers

import numpy as np

from .elastic_block import ElasticBlock
from .fibre_matrix_junction import FibreMatrixJunctions


class FibreMatrixTie(FibreMatrixJunctions):
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
        Penalty stiffness k (N/m) of each tie, > 0.
    """

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
        self.nodes = g
        # the node as a particle: its first element and its coordinate there
        # (xi = -1, 0, +1 for the element's first, middle, last node)
        hit = mesh.elements_global[:, :, None] == g[None, None, :]       # (ne, nf, n)
        elem = np.argmax(hit.any(axis=1), axis=0)
        local = np.argmax(hit[elem, :, np.arange(len(g))], axis=1)
        xi = -1.0 + 2.0 * local / mesh.order
        self.particles_per_element = 0
        self.section_particles, self.particles_per_station = False, 1
        self._make(model, block, float(stiffness), elem, xi, np.ones(len(g)),
                   mesh.X_global[g, 0:3])
        if self.num_outside:
            raise ValueError(f"FibreMatrixTie: {self.num_outside} tied node(s) outside the "
                             "matrix mesh")

    def tie_forces(self) -> np.ndarray:
        """Total force (3,) the ties exert on the matrix, sum of k gap over
        all ties at the model's current solution (N; collective). The
        fibres receive the opposite force."""
        return self.total_force()
