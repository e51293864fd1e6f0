"""The weaving contact mode's crossing order, from a fabric (docs/method.md §6.2).

During the weaving stage, contact between fibres of a warp yarn and a weft
yarn uses the vertical as its normal, oriented by which yarn lies on top at
their crossing (``FibreContact.configure(mode="weaving", ...)``). This
module turns a :class:`~textile.fabric.Fabric`'s weave into the arrays that
mode takes:

    stage = textile.Stage("weave", effects={contact: weaving_mode(fabric)})
    textile.Stage("relax", effects={contact: dict(mode="ordinary")})
"""
from __future__ import annotations

import numpy as np


def yarn_above(fabric) -> np.ndarray:
    """(yarns, yarns) int8 array: ``+1`` where yarn a lies above yarn b at
    their crossing, ``-1`` below, ``0`` for yarns of one direction (they do
    not cross). Yarns are numbered as in the fabric: warps first (warp j is
    yarn j), then wefts (weft i is yarn num_warp + i); ``fabric.order[i, j]
    = 1`` when warp j passes over weft i. Antisymmetric."""
    nw = fabric.num_warp
    order = np.asarray(fabric.order, dtype=bool)   # (num_weft, num_warp)
    warp_over = np.where(order.T, 1, -1).astype(np.int8)  # [warp j, weft i]
    above = np.zeros((fabric.num_yarns, fabric.num_yarns), dtype=np.int8)
    above[:nw, nw:] = warp_over
    above[nw:, :nw] = -warp_over.T
    return above


def weaving_mode(fabric, mode: str = "weaving") -> dict:
    """Stage options of :class:`~textile.effects.fibre_contact.FibreContact`
    for weaving ``fabric``: ``dict(mode=mode, fibre_yarn=..., yarn_above=...)``,
    the fibres numbered as ``fabric.fibres()``; ``mode`` "weaving" (ordered
    contact) or "within_yarns" (the crossing yarns pass through each other)."""
    fabric.fibres()  # numbers the fibres' yarns (built once)
    return dict(mode=mode, fibre_yarn=np.asarray(fabric.fibre_yarn),
                yarn_above=yarn_above(fabric))
