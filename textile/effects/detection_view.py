"""The fibres a rank detects contact among, and their current unknowns.

On one rank detection sees every fibre. On several, each rank evaluates
the contact elements of its own fibre elements (``evaluated_here`` in
``contact_set.h``), so it needs only the fibres that come within the
search distance of them: its *ghost fibres*. They are held whole, because
a proximity zone's extent along both fibres decides where its elements go
(a line contact between two fibres of a yarn runs along their whole
length), and every rank that finds a zone must find it alike.

The choice is made from boxes, without the whole fibre state: each rank
bounds, per fibre, its own elements (their nodes, widened by the search
reach ``search_factor * r`` and the chord sag of a quadratic element, as
the broad phase widens a segment, ``broad_phase.h``); the ranks exchange
these pieces (6 numbers a fibre piece); a fibre is present on a rank when
one of its pieces overlaps one of the rank's. Two elements whose widened
boxes do not overlap cannot form a close pair, so every zone with an
element of this rank is found here, exactly as a rank holding every fibre
finds it.
"""
from __future__ import annotations

import numpy as np


class DetectionView:
    """This rank's view for detection passes (created once a System exists).

    ``system``: the assembled System; ``radius``: per fibre;
    ``search_factor``: the detection criterion's factor (ContactOptions).
    Every method that moves data is collective.
    """

    def __init__(self, system, radius: np.ndarray, search_factor: float):
        mesh = system.mesh
        self.system, self.mesh = system, mesh
        self.comm = system.comm
        #: (own elements, order + 1) global nodes, and their fibres
        self.element_nodes = mesh.elements_global[mesh.local_element_ids]
        self.element_fibre = mesh.element_fibre[mesh.local_element_ids]
        #: the fibre of every global node
        self.fibre_of_node = np.repeat(np.arange(len(mesh.first_node) - 1),
                                       np.diff(mesh.first_node))
        self.own_fibres = np.unique(self.element_fibre)
        self.reach = search_factor * np.asarray(radius, dtype=float)
        self._own_gather = system.node_gather(self.element_nodes.ravel())
        #: the fibres of the last pass (present)
        self.last_present = np.ones(len(mesh.first_node) - 1, dtype=bool)
        #: what the last pass moved (see FibreContact.assembly_timing)
        self.counts = dict(detection_values=0, detection_pieces=0, ghost_fibres=0,
                           own_fibres=len(self.own_fibres))

    def pieces(self, x) -> tuple[np.ndarray, np.ndarray]:
        """(fibres, (n, 6) boxes lo, hi) of this rank's own elements at the
        global vector ``x``, one box a fibre, widened by the search reach."""
        q = self._own_gather.positions(x)[:, :3]
        if len(self.element_fibre) == 0:
            return np.zeros(0, dtype=np.int64), np.zeros((0, 6))
        p = q[self.element_nodes]                       # (elements, nodes, 3)
        sag = (np.linalg.norm(p[:, 0] - 2 * p[:, 1] + p[:, 2], axis=1) / 8
               if self.mesh.order == 2 else np.zeros(len(p)))
        widen = self.reach[self.element_fibre] + sag
        lo = p.min(axis=1) - widen[:, None]
        hi = p.max(axis=1) + widen[:, None]
        # round-off: boxes touching within it count as overlapping
        slack = 1e-9 * (np.abs(lo).max() + np.abs(hi).max() + 1.0)
        order = np.argsort(self.element_fibre, kind="stable")
        fibres, starts = np.unique(self.element_fibre[order], return_index=True)
        box = np.hstack([np.minimum.reduceat(lo[order], starts) - slack,
                         np.maximum.reduceat(hi[order], starts) + slack])
        return fibres, box

    def present(self, x, extra_fibres=()) -> np.ndarray:
        """One flag per fibre: the fibres this rank detects among, its own
        and its ghosts (see the module), plus ``extra_fibres`` (fibres of
        its last elements and of the history it was handed)."""
        fibres, box = self.pieces(x)
        parts = self.comm.allgather((fibres, box))
        all_fibres = np.concatenate([p[0] for p in parts])
        all_box = np.vstack([p[1] for p in parts])
        self.counts["detection_pieces"] += len(all_fibres) - len(fibres)
        flags = np.zeros(len(self.mesh.first_node) - 1, dtype=bool)
        flags[self.own_fibres] = True
        flags[np.asarray(extra_fibres, dtype=np.int64)] = True
        # overlap of every piece with every own piece, a block at a time
        for k in range(0, len(box), 256):
            mine = box[k:k + 256]
            hit = np.all((all_box[None, :, :3] <= mine[:, None, 3:])
                         & (mine[:, None, :3] <= all_box[None, :, 3:]), axis=2)
            flags[all_fibres[np.any(hit, axis=0)]] = True
        self.counts["ghost_fibres"] = int(flags.sum() - len(self.own_fibres))
        self.last_present = flags
        return flags

    def positions(self, x, flags: np.ndarray) -> np.ndarray:
        """(global nodes, 9) current [x0, g1, g2] of the present fibres'
        nodes (NaN at the others): one scatter, built for this pass."""
        nodes = np.flatnonzero(flags[self.fibre_of_node])
        gather = self.system.node_gather(nodes)
        try:
            self.counts["detection_values"] += gather.num_remote
            return gather.positions(x).copy()
        finally:
            gather.destroy()

    def destroy(self) -> None:
        self._own_gather.destroy()
