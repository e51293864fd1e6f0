"""Voids: fibre-to-fibre gaps that open under load (the paper's Fig. 15:
in bending of the composite, gaps open between fibres on the compressed
side).

The pairs followed are the contact elements of
:class:`~textile.effects.fibre_contact.FibreContact` at the start of
loading: pairs of facing points of two fibres in proximity (closed contacts
and open ones within the contact's search distance), fibre i at abscissa
s_i and fibre j at s_j (element coordinates). The contact re-detects its
elements at every step, so a pair is followed through the current element
of the same two fibres nearest to it (|ds_i| + |ds_j| at most one element);
its gap is that element's (along the contact normal, between the sections'
surfaces: < 0 where the fibres interpenetrate). A pair with no such element
any more has opened beyond the contact's search distance (or its zone
moved): it is counted as lost, without a gap.

The figure: the largest increase of gap since the start of loading among
the pairs on one side of a plane z = ``plane`` (a bending test gives the
sample's mid-plane); a pair's side is that of its midpoint (the middle of
its two points) at the start of loading, pairs within ``tolerance`` of the
plane belonging to neither side. In a plain weave of monofilaments every
pair is a crossing, and the crossings' midpoints lie within a few
hundredths of a radius of the mid-plane: the figure then follows the
crossings a little below it (or above).

Collective: every rank gets the same figures.
"""
from __future__ import annotations

import numpy as np

#: the columns of the contact elements this measure needs
_COLUMNS = ("fibre_i", "fibre_j", "s_i", "s_j", "gap")


def _elements(contact, comm) -> dict:
    """Every rank's contact elements (columns of ``ContactSet.data()``),
    each pair written with its lower (fibre, abscissa) first; and their
    midpoints."""
    d = contact.set.data()
    mine = {k: np.asarray(d[k]) for k in _COLUMNS}
    mine["midpoint"] = 0.5 * (np.asarray(d["position_i"]).reshape(-1, 3)
                              + np.asarray(d["position_j"]).reshape(-1, 3))
    parts = comm.allgather(mine) if comm.size > 1 else [mine]
    out = {k: np.concatenate([p[k] for p in parts]) for k in mine}
    swap = (out["fibre_i"] > out["fibre_j"]) | \
        ((out["fibre_i"] == out["fibre_j"]) & (out["s_i"] > out["s_j"]))
    for a, b in (("fibre_i", "fibre_j"), ("s_i", "s_j")):
        out[a], out[b] = np.where(swap, out[b], out[a]), np.where(swap, out[a], out[b])
    return out


class GapOpening:
    """The largest gap opening since the start of loading between fibre
    pairs on one side of the mid-plane (module docstring).

    Parameters
    ----------
    contact:
        The sample's :class:`~textile.effects.fibre_contact.FibreContact`.
    plane:
        z of the plane that splits the pairs into two sides.
    side:
        "below" or "above" the plane.
    tolerance:
        Pairs whose midpoint is closer than this to the plane belong to
        neither side (default 1e-6 of the smallest fibre radius: round-off).
    """

    def __init__(self, contact, plane: float, side: str = "below",
                 tolerance: float | None = None):
        if side not in ("below", "above"):
            raise ValueError(f"GapOpening: side must be 'below' or 'above', got {side!r}")
        self.contact, self.plane, self.side = contact, float(plane), side
        self.tolerance = tolerance
        self.pairs = None

    def start(self, model) -> None:
        """Take the pairs and their gaps at the current state: the start of
        loading (collective)."""
        pairs = _elements(self.contact, model.comm)
        tolerance = 1e-6 * float(np.min(self.contact.radius)) if self.tolerance is None \
            else self.tolerance
        offset = pairs["midpoint"][:, 2] - self.plane
        chosen = offset < -tolerance if self.side == "below" else offset > tolerance
        self.pairs = {k: v[chosen] for k, v in pairs.items()}

    def measure(self, model) -> dict:
        """At the current state (collective): the largest gap opening (a
        length; None without pairs) and its two fibres, the number of pairs
        on the side and of those lost."""
        if self.pairs is None:
            raise RuntimeError("GapOpening.measure before start")
        now = _elements(self.contact, model.comm)
        p = self.pairs
        opening = np.full(len(p["gap"]), np.nan)
        for k in range(len(opening)):
            same = np.flatnonzero((now["fibre_i"] == p["fibre_i"][k])
                                  & (now["fibre_j"] == p["fibre_j"][k]))
            if not len(same):
                continue
            distance = (np.abs(now["s_i"][same] - p["s_i"][k])
                        + np.abs(now["s_j"][same] - p["s_j"][k]))
            best = int(np.argmin(distance))
            if distance[best] <= 1.0:
                opening[k] = now["gap"][same[best]] - p["gap"][k]
        found = np.flatnonzero(np.isfinite(opening))
        largest, fibres = None, None
        if len(found):
            k = int(found[np.argmax(opening[found])])
            largest, fibres = float(opening[k]), [int(p["fibre_i"][k]), int(p["fibre_j"][k])]
        return {"largest gap opening": largest, "its fibres": fibres,
                "pairs": int(len(opening)), "lost pairs": int(len(opening) - len(found))}
