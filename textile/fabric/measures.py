"""What a textile researcher measures on a woven state (docs/references.md §11).

All from the fibres' current centre lines (``Model.nodal_unknowns``) and
the :class:`~textile.fabric.Fabric` that built them:

- **yarn centre line**: the mean of its fibres' centre lines, node by node
  (the fibres of a yarn share their parametrization);
- **crimp** of a yarn: (yarn length - fabric length) / fabric length, the
  yarn length being the arclength of its centre line and the fabric length
  the distance between its ends along the yarn's direction;
- **shrinkage**: 1 - fabric length / initial yarn length;
- **section shape** at a crossing: width (across the yarn, in the fabric
  plane) and height (vertical) of the yarn's fibres where they cut the
  plane through the crossing orthogonal to the yarn, fibre radius included;
  a crossing lies where the two yarns now are in the fabric plane (the mean
  position of each one's fibre nodes across its direction), not where they
  started (a compacted fabric's yarns have moved);
- **curvature** of the fibres: per node, the turning angle of the centre
  line divided by the mean length of the two segments.
"""
from __future__ import annotations

import numpy as np

from ..beam.fibre_loads import node_curvatures


def _fibres_of(fabric, yarn: int) -> np.ndarray:
    fabric.fibres()
    return np.flatnonzero(fabric.fibre_yarn == yarn)


def yarn_centrelines(fabric, model) -> list[np.ndarray]:
    """Current centre line (nodes, 3) of every yarn."""
    q = model.nodal_unknowns()
    out = []
    for k in range(fabric.num_yarns):
        lines = [q[model.mesh.fibre_nodes(f), 0:3] for f in _fibres_of(fabric, k)]
        out.append(np.mean(lines, axis=0))
    return out


def _direction(fabric, k: int) -> np.ndarray:
    return np.array([1.0, 0, 0]) if fabric.yarn_direction(k) == "warp" else np.array([0, 1.0, 0])


def crimp(fabric, model) -> np.ndarray:
    """Crimp of every yarn (warps first)."""
    out = []
    for k, line in enumerate(yarn_centrelines(fabric, model)):
        length = np.linalg.norm(np.diff(line, axis=0), axis=1).sum()
        span = abs(np.dot(line[-1] - line[0], _direction(fabric, k)))
        out.append((length - span) / span)
    return np.array(out)


def shrinkage(fabric, model) -> np.ndarray:
    """Shrinkage of every yarn: 1 - its span / its initial length."""
    out = []
    for k, line in enumerate(yarn_centrelines(fabric, model)):
        a, b = fabric.yarn_axis(k)
        span = abs(np.dot(line[-1] - line[0], _direction(fabric, k)))
        out.append(1 - span / np.linalg.norm(b - a))
    return np.array(out)


def _cut(fabric, model, q: np.ndarray, k: int, along: int, cut: float) -> np.ndarray:
    """(fibres, 3) points where the fibres of yarn k cross the plane
    x[along] = cut (linear between nodes)."""
    pts = []
    for f in _fibres_of(fabric, k):
        x = q[model.mesh.fibre_nodes(f), 0:3]
        s = x[:, along]
        n = int(np.clip(np.searchsorted(s, cut), 1, len(s) - 1))
        w = (cut - s[n - 1]) / (s[n] - s[n - 1]) if s[n] != s[n - 1] else 0.0
        pts.append((1 - w) * x[n - 1] + w * x[n])
    return np.array(pts)


def _crossings(fabric, model, q: np.ndarray):
    """``fabric.crossings()`` with each point where warp j and weft i now
    cross in the fabric plane: the mean y of warp j's fibre nodes, the mean
    x of weft i's."""
    def across(k, axis):
        return float(np.mean([q[model.mesh.fibre_nodes(f), axis].mean()
                              for f in _fibres_of(fabric, k)]))
    for i, j, point, warp_on_top in fabric.crossings():
        now = np.array([across(fabric.num_warp + i, 0), across(j, 1)])
        yield i, j, now, warp_on_top


def section_shapes(fabric, model) -> list[dict]:
    """Width and height of each yarn at each of its crossings."""
    q = model.nodal_unknowns()
    out = []
    for i, j, point, warp_on_top in _crossings(fabric, model, q):
        for k, along in ((j, 0), (fabric.num_warp + i, 1)):
            across = 1 - along
            yarn = fabric.yarn(k)
            pts = _cut(fabric, model, q, k, along, point[along])
            out.append(dict(weft=i, warp=j, yarn=k, direction=fabric.yarn_direction(k),
                            width=float(np.ptp(pts[:, across]) + 2 * yarn.radius),
                            height=float(np.ptp(pts[:, 2]) + 2 * yarn.radius),
                            centre_height=float(pts[:, 2].mean())))
    return out


def crossing_separation(fabric, model) -> np.ndarray:
    """Per crossing (``fabric.crossings()`` order), the lowest fibre of the
    yarn the pattern puts on top minus the highest fibre of the other, in
    the vertical, centre lines taken where they pass the crossing: > 0 when
    every fibre of the upper yarn lies above every fibre of the lower one.
    (Not a gap: the radii are not subtracted.)"""
    q = model.nodal_unknowns()
    out = []
    for i, j, point, warp_on_top in _crossings(fabric, model, q):
        warp = _cut(fabric, model, q, j, 0, point[0])[:, 2]
        weft = _cut(fabric, model, q, fabric.num_warp + i, 1, point[1])[:, 2]
        top, bottom = (warp, weft) if warp_on_top else (weft, warp)
        out.append(top.min() - bottom.max())
    return np.array(out)


def fibre_curvatures(model) -> np.ndarray:
    """(nodes,) curvature of the fibres' centre lines at their inner nodes
    (0 at fibre ends): :func:`textile.beam.fibre_loads.node_curvatures`."""
    return node_curvatures(model.mesh.first_node, model.nodal_unknowns()[:, 0:3])


def summary(fabric, model) -> dict:
    """The woven state's figures: crimp and shrinkage per direction (mean),
    section shapes (mean width and height per direction), fibre curvature
    (mean and max)."""
    c, s = crimp(fabric, model), shrinkage(fabric, model)
    shapes = section_shapes(fabric, model)
    kappa = fibre_curvatures(model)
    out = {}
    for name, sel in (("warp", slice(0, fabric.num_warp)), ("weft", slice(fabric.num_warp, None))):
        out[f"{name} crimp"] = float(np.mean(c[sel]))
        out[f"{name} shrinkage"] = float(np.mean(s[sel]))
        mine = [x for x in shapes if x["direction"] == name]
        out[f"{name} section width"] = float(np.mean([x["width"] for x in mine]))
        out[f"{name} section height"] = float(np.mean([x["height"] for x in mine]))
    out["mean fibre curvature"] = float(kappa.mean())
    out["max fibre curvature"] = float(kappa.max())
    return out
