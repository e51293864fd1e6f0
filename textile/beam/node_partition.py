"""Which rank owns each fibre node: by place, or by node number.

Two partitions of the fibres' elements over ``size`` ranks, each a pure
function of the (replicated) reference geometry, so every rank computes the
same one without communicating:

- ``"place"`` (the default): recursive coordinate bisection of the
  elements' reference midpoints. The element set is cut across its longest
  extent at the point that shares the elements between the two halves of
  the ranks, and each half is cut again until one rank is left. A rank gets
  a box of the fabric: the pieces of the warp and the weft fibres that cross
  there, so contacts (which are local in space) and a fibre's neighbours
  mostly stay on one rank, and only the fibres crossing a cut have ghosts.
- ``"numbers"``: contiguous, balanced ranges of node numbers (fibre after
  fibre), the split by fibre number. A woven fabric then puts the warp on
  one rank and the weft on the other: every warp-weft contact couples the
  two ranks.

Nodes follow their elements: a node belongs to the rank of the element it
starts (so an element's first node is its rank's own: the rule by which
effects find who assembles an element), a fibre's last node and the inner
nodes of quadratic elements to their element's rank.
"""
from __future__ import annotations

import numpy as np

#: the partitions :func:`node_owners` knows
PARTITIONS = ("place", "numbers")


def bisection(points: np.ndarray, size: int) -> np.ndarray:
    """Rank (0..size-1) of each point by recursive coordinate bisection:
    ranks get counts within one of each other. Deterministic (stable sorts)."""
    points = np.asarray(points, dtype=float)
    owner = np.zeros(len(points), dtype=np.int32)

    def split(idx: np.ndarray, first: int, ranks: int) -> None:
        if ranks == 1 or len(idx) == 0:
            owner[idx] = first
            return
        left = ranks // 2
        extent = points[idx].max(axis=0) - points[idx].min(axis=0)
        axis = int(np.argmax(extent))
        idx = idx[np.argsort(points[idx, axis], kind="stable")]
        cut = (len(idx) * left) // ranks
        split(idx[:cut], first, left)
        split(idx[cut:], first + left, ranks - left)

    split(np.arange(len(points)), 0, size)
    return owner


def node_owners(partition: str, size: int, X: np.ndarray, elements: np.ndarray) -> np.ndarray:
    """Owning rank of every global node (int32), for ``partition`` over
    ``size`` ranks. ``X``: (nodes, >= 3) reference unknowns (positions
    first); ``elements``: (elements, nodes per element) global node numbers,
    fibre after fibre."""
    if partition not in PARTITIONS:
        raise ValueError(f"unknown partition {partition!r}: use one of {PARTITIONS}")
    n = len(X)
    if partition == "numbers":
        bounds = (np.arange(size + 1) * n) // size
        # do not start a rank's range in the middle of an element
        starts = elements[:, 0]
        for r in range(1, size):
            k = np.searchsorted(starts, bounds[r])
            bounds[r] = starts[k] if k < len(starts) else n
        bounds = np.maximum.accumulate(bounds)
        return (np.searchsorted(bounds, np.arange(n), side="right") - 1).astype(np.int32)
    element_owner = bisection(X[elements, :3].mean(axis=1), size)
    owner = np.zeros(n, dtype=np.int32)   # a node of no element (none today): rank 0
    owner[elements[:, -1]] = element_owner
    owner[elements[:, 1:-1]] = element_owner[:, None]
    owner[elements[:, 0]] = element_owner
    return owner
