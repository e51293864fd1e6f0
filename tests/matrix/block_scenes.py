"""Helpers of the matrix-block tests: a side displacement prescribed
through the Effect interface, and a model that holds only a block."""
import numpy as np

import textile
from textile.effects.base import Effect


class SideDisplacement(Effect):
    """Prescribes displacement components of a block's nodes on a side:
    ``values`` (one per component) reached at load factor 1, ramped
    linearly. Uses ElasticBlock.side_nodes, as a side rigid body would."""

    def __init__(self, block, side, components, values):
        nodes, self.X = block.side_nodes(side)
        self.block = block
        self.fields = (block.name,)
        comps = np.asarray(components, dtype=np.int64)
        self.dofs = (3 * nodes[:, None] + comps).ravel()
        self.values = np.tile(np.asarray(values, dtype=float), len(nodes))

    def constraints(self, load_factor):
        return {self.block.name: (self.dofs, load_factor * self.values)}


def block_model(comm, block, force_scale=1.0):
    """A model whose only deformable part is ``block``: the model needs a
    fibre, so a short one far away is clamped at every node (its E A sets
    the convergence test's absolute scale: give it the block's force scale).
    Four elements, so that each of two ranks owns some: a rank without beam
    elements skips the beam's sparsity block, whose creation is collective
    (textile.system.layout.SparsityBuilder.pattern), and the set-up hangs."""
    R = 0.1
    E = force_scale / (np.pi * R ** 2)
    fibre = textile.straight_fibre([100, 0, 0], [101, 0, 0], R, textile.Material(E, 0.3),
                                   num_elements=4)
    model = textile.Model([fibre], comm=comm)
    for node in range(fibre.num_nodes):
        model.clamp(fibre, node)
    model.add_effect(block)
    return model
