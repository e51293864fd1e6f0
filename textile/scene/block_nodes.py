"""Nodes of an elastic block that a rigid body holds (e.g. a matrix end face).

:class:`BlockNodes` names the nodes of an
:class:`~textile.effects.elastic_block.ElasticBlock` by a marker over their
reference coordinates (like dolfinx's ``locate_*`` functions) or by local node
indices; :func:`select_block_nodes` turns that into the local nodes of this
rank; a named side (a gmsh physical group) selects the nodes of its
facets.
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
        A side name of the block's mesh ("xmin" ... "zmax" for
        :func:`textile.composite.matrix_mesh.gmsh_box`) or a list of them; a marker
        ``x -> bool array`` with x of shape (3, n), the reference
        coordinates of the block's local nodes; or an array of local node
        indices of this rank (owned and ghost numbering of
        ``block.node_coordinates()``).
    """

    def __init__(self, block, where):
        from ..effects.elastic_block import ElasticBlock

        if not isinstance(block, ElasticBlock):
            raise TypeError(f"BlockNodes: block must be an ElasticBlock, got "
                            f"{type(block).__name__}")
        if not callable(where) and not _is_side(where):
            idx = np.asarray(where)
            if idx.ndim != 1 or (len(idx) and idx.dtype.kind not in "iu"):
                raise ValueError("BlockNodes: where must be a side name (or a list of them), "
                                 "a marker x -> bool array or a 1D array of local node indices")
        self.block, self.where = block, where

    def __repr__(self) -> str:
        return f"BlockNodes({self.block.name!r})"


def _is_side(where) -> bool:
    """A side name of the block's mesh ("xmax") or a list of them."""
    return isinstance(where, str) or (isinstance(where, (list, tuple)) and len(where) > 0
                                      and all(isinstance(w, str) for w in where))


def select_block_nodes(block, where) -> np.ndarray:
    """Local node indices (owned and ghost numbering, sorted, unique) of the
    block's nodes selected by ``where``: a side name of its mesh (a gmsh
    physical group, e.g. "xmax") or a list of them, a marker over reference
    coordinates x of shape (3, n), or local node indices. Not collective."""
    if _is_side(where):
        return np.asarray(block.side_nodes(where)[0], dtype=np.int32)
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
