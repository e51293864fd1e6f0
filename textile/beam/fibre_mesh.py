"""The fibres' nodes and elements, numbered globally and split over ranks.

Nodes are numbered fibre after fibre: a node's *global number* is the same
on every rank and for every partition, and it is what the scene, the
effects and the saved states use. Which rank owns a node is the partition's
(:mod:`.node_partition`: by place by default, or by number); an element
belongs to the rank owning its first node, and the other nodes it needs
are ghosts. One fibre may thus be cut between ranks, so beam assembly is
genuinely distributed. Geometry is small (9 numbers a node) and is
replicated on every rank; unknowns are not.

The index map (and so the global system) numbers the nodes rank after rank,
each rank's own in the order of their global numbers: :attr:`FibreMesh.imap_index`
turns a global node number into that index.
"""
from __future__ import annotations

import numpy as np

from ..system.dolfinx_core import load as _load_core
from .fibre import Fibre
from .node_partition import node_owners

_cpp = _load_core()   # dolfinx's compiled core alone (textile.system.dolfinx_core)

#: Names of a node's 9 unknowns, in storage order.
DOF_NAMES = ("x", "y", "z", "g1x", "g1y", "g1z", "g2x", "g2y", "g2z")
#: Groups of unknowns accepted wherever dofs are named.
DOF_GROUPS = {
    "position": (0, 1, 2),
    "g1": (3, 4, 5),
    "g2": (6, 7, 8),
    "section": (3, 4, 5, 6, 7, 8),
    "all": tuple(range(9)),
}


def dof_indices(dofs) -> tuple[int, ...]:
    """Indices (0..8) of dof names, groups or integers; ValueError otherwise."""
    if isinstance(dofs, (str, int, np.integer)):
        dofs = [dofs]
    out = []
    for d in dofs:
        if isinstance(d, str):
            if d in DOF_GROUPS:
                out.extend(DOF_GROUPS[d])
            elif d in DOF_NAMES:
                out.append(DOF_NAMES.index(d))
            else:
                raise ValueError(f"unknown dof name {d!r}; use one of {DOF_NAMES} "
                                 f"or a group {tuple(DOF_GROUPS)}")
        elif isinstance(d, (int, np.integer)) and not isinstance(d, bool) and 0 <= d < 9:
            out.append(int(d))
        else:
            raise ValueError(f"unknown dof {d!r}: expected a name or an index in 0..8")
    return tuple(dict.fromkeys(out))


class FibreMesh:
    """Global numbering and MPI distribution of all fibres' nodes and elements.

    ``partition``: how nodes are shared out over the ranks, ``"place"``
    (default) or ``"numbers"`` (:mod:`.node_partition`).
    """

    def __init__(self, comm, fibres: list[Fibre], order: int, partition: str = "place"):
        if order not in (1, 2):
            raise ValueError(f"element order must be 1 or 2, got {order!r}")
        if not fibres:
            raise ValueError("fibres: at least one fibre is needed")
        self.comm = comm
        self.fibres = list(fibres)
        self.order = order
        nn = order + 1
        first, elements, groups = [], [], []
        n0 = 0
        for f, fib in enumerate(self.fibres):
            if not isinstance(fib, Fibre):
                raise TypeError(f"fibres[{f}] is not a textile.Fibre")
            if (fib.num_nodes - 1) % order:
                raise ValueError(f"fibres[{f}] has {fib.num_nodes} nodes: quadratic elements need "
                                 "an odd number of nodes")
            first.append(n0)
            ne = (fib.num_nodes - 1) // order
            elements.append(n0 + order * np.arange(ne)[:, None] + np.arange(nn)[None, :])
            groups.append(np.full(ne, f, dtype=np.int32))
            n0 += fib.num_nodes
        self.first_node = np.array(first + [n0], dtype=np.int64)
        self.num_nodes_global = n0
        self.elements_global = np.vstack(elements).astype(np.int64)
        self.element_fibre = np.concatenate(groups)
        self.X_global = np.vstack([fib.reference_dofs() for fib in self.fibres])

        # who owns each node, and the index map's numbering: rank after rank
        size, rank = comm.size, comm.rank
        self.partition = partition
        self.rank = rank
        self.node_owner = node_owners(partition, size, self.X_global, self.elements_global)
        by_rank = np.argsort(self.node_owner, kind="stable")
        self.imap_index = np.empty(n0, dtype=np.int64)
        self.imap_index[by_rank] = np.arange(n0)
        #: nodes each rank owns
        self.owned_counts = np.bincount(self.node_owner, minlength=size).astype(np.int64)
        #: global numbers of the nodes in the index map's order (rank after rank)
        self.nodes_by_rank = by_rank
        self.owned_nodes = np.flatnonzero(self.node_owner == rank)
        mine = self.node_owner[self.elements_global[:, 0]] == rank
        self.local_element_ids = np.flatnonzero(mine)
        elems = self.elements_global[mine]
        self._index_map = None
        self._set_ghosts(elems[self.node_owner[elems] != rank])

    def _set_ghosts(self, nodes) -> None:
        """(Re)number the local nodes: owned ones, then the sorted ghosts."""
        self.ghosts = np.unique(np.asarray(nodes, dtype=np.int64))
        self._ghost_owners = self.node_owner[self.ghosts]
        self.local_to_global = np.concatenate([self.owned_nodes, self.ghosts])
        self._local_of = np.full(self.num_nodes_global, -1, dtype=np.int64)
        self._local_of[self.local_to_global] = np.arange(len(self.local_to_global))
        elems = self.elements_global[self.local_element_ids]
        self.elements_local = self.global_to_local(elems).astype(np.int32)
        self.X_local = self.X_global[self.local_to_global]

    @property
    def index_map(self):
        """IndexMap of the nodes (owned range, then ghosts). Built on first
        use, which is collective (``Model.setup``); the local numbering is
        final from then on."""
        if self._index_map is None:
            self._index_map = _cpp.common.IndexMap(self.comm, len(self.owned_nodes),
                                                   self.imap_index[self.ghosts],
                                                   self._ghost_owners)
        return self._index_map

    @property
    def numbering_final(self) -> bool:
        """Is the local numbering final (the index map built at
        ``Model.setup``)? Then no node can become a ghost any more."""
        return self._index_map is not None

    def add_ghosts(self, nodes) -> None:
        """Make global ``nodes`` local on this rank (ghosts where not owned).

        For effects assembled on a rank that does not own the fibre nodes
        they couple: a fibre-matrix junction is assembled by the rank owning
        its matrix cell. Not collective. Only before the index map is built
        (``Model.setup``), since it renumbers the ghosts.
        """
        if self.numbering_final:
            raise RuntimeError("FibreMesh.add_ghosts: the local numbering is final once the "
                               "model is set up; create junctions before setting up or solving")
        nodes = np.asarray(nodes, dtype=np.int64).ravel()
        if np.any((nodes < 0) | (nodes >= self.num_nodes_global)):
            raise ValueError(f"FibreMesh.add_ghosts: node numbers must lie in "
                             f"[0, {self.num_nodes_global}), got {nodes.min()}..{nodes.max()}")
        extra = nodes[self.node_owner[nodes] != self.rank]
        if len(np.setdiff1d(extra, self.ghosts)):
            self._set_ghosts(np.concatenate([self.ghosts, extra]))

    # -- numbering ----------------------------------------------------------
    @property
    def num_owned(self) -> int:
        return len(self.owned_nodes)

    @property
    def num_local(self) -> int:
        return len(self.local_to_global)

    def global_to_local(self, nodes) -> np.ndarray:
        """Local index (owned then ghosts) of global nodes; -1 if absent."""
        return self._local_of[np.asarray(nodes, dtype=np.int64)]

    def owns(self, nodes) -> np.ndarray | bool:
        """Whether this rank owns the global ``nodes``."""
        return self.node_owner[nodes] == self.rank

    def node(self, fibre: int | Fibre, node: int) -> int:
        """Global number of node ``node`` of ``fibre`` (negative counts from the end)."""
        f = self.fibre_index(fibre)
        n = self.fibres[f].num_nodes
        if isinstance(node, bool) or not isinstance(node, (int, np.integer)) or not -n <= node < n:
            raise ValueError(f"node {node!r} out of range for fibre {f} with {n} nodes")
        return int(self.first_node[f] + (node % n))

    def fibre_index(self, fibre) -> int:
        if isinstance(fibre, Fibre):
            for i, f in enumerate(self.fibres):
                if f is fibre:
                    return i
            raise ValueError("fibre is not part of this model")
        if isinstance(fibre, (int, np.integer)) and 0 <= fibre < len(self.fibres):
            return int(fibre)
        raise ValueError(f"unknown fibre {fibre!r}")

    def fibre_nodes(self, fibre) -> np.ndarray:
        f = self.fibre_index(fibre)
        return np.arange(self.first_node[f], self.first_node[f + 1])
