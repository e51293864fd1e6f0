"""Nodes of an elastic block that a rigid body holds (e.g. a matrix end face).

:class:`BlockNodes` names the nodes of an
:class:`~textile.effects.elastic_block.ElasticBlock` by a marker over their
reference coordinates (like dolfinx's ``locate_*`` functions) or by local node
indices; :func:`select_block_nodes` turns that into the local nodes of this
rank. The selection is a function of its own so that it can later take a
named side (a gmsh physical group) as well.
"""
from __future__ import annotations

import numpy as np


class BlockNodes:
    """Nodes of ``block`` chosen by ``where``.

    Parameters
    ----------
    block:
        The :class:`~textile.effects.elastic_block.ElasticBlock` (add it to
        the model too).
    where:
        A marker ``x -> bool array`` with x of shape (3, n), the reference
        coordinates of the block's local nodes; or an array of local node
        indices of this rank (owned and ghost numbering of
        ``block.node_coordinates()``).
    """

    def __init__(self, block, where):
        from .effects.elastic_block import ElasticBlock

        if not isinstance(block, ElasticBlock):
            raise TypeError(f"BlockNodes: block must be an ElasticBlock, got "
                            f"{type(block).__name__}")
        if not callable(where):
            idx = np.asarray(where)
            if idx.ndim != 1 or (len(idx) and idx.dtype.kind not in "iu"):
                raise ValueError("BlockNodes: where must be a marker x -> bool array or a 1D "
                                 "array of local node indices")
        self.block, self.where = block, where

    def __repr__(self) -> str:
        return f"BlockNodes({self.block.name!r})"


def select_block_nodes(block, where) -> np.ndarray:
    """Local node indices (owned and ghost numbering, sorted, unique) of the
    block's nodes selected by ``where`` (a marker over reference coordinates
    x of shape (3, n), or local node indices). Not collective."""
    X = block.node_coordinates()
    if callable(where):
        marked = np.asarray(where(np.ascontiguousarray(X.T)), dtype=bool)
        if marked.shape != (len(X),):
            raise ValueError(f"BlockNodes: the marker must return one bool per node "
                             f"({len(X)}), got shape {marked.shape}")
        return np.flatnonzero(marked).astype(np.int32)
    idx = np.unique(np.asarray(where, dtype=np.int64))
    if len(idx) and (idx[0] < 0 or idx[-1] >= len(X)):
        raise ValueError(f"BlockNodes: local node indices must lie in [0, {len(X)}), got "
                         f"{idx[0]}..{idx[-1]}")
    return idx.astype(np.int32)
