"""Where damage would start: how hard each fibre is loaded.

Per element of the fibres, from the current state, three figures:

- **axial strain**: the element's section-averaged Green-Lagrange strain
  along the fibre axis, E33 of the beam's element fields
  (``BeamElasticity.element_fields``: local frame, 3 = fibre axis);
  dimensionless; > 0 stretched, < 0 shortened. A stretch lambda gives
  (lambda^2 - 1) / 2 = eps + eps^2 / 2 for lambda = 1 + eps.
- **curvature** of the centre line: at each inner node of a fibre, the
  turning angle between its two segments (the polyline through the nodes)
  divided by the mean length of the two segments; 0 at a fibre's end
  nodes. An element's curvature is the largest of its nodes'. In 1 / the
  length unit of the coordinates; unsigned (>= 0, no bending direction).
- **surface stress**: an estimate of the largest axial stress on the
  section's surface, |S33| + E r kappa: the section-averaged second
  Piola-Kirchhoff axial stress S33 plus the bending stress of a round
  section's outermost point (linear bending: E kappa y, largest at y = r),
  with E the fibre's Young's modulus, r its (reference) radius and kappa the
  element's curvature. In the unit of ``Material.young``; >= 0, as if axial
  and bending stress added on the more loaded side (an upper estimate: on
  the other side they subtract). Shear, torsion and the section-plane
  stresses are not in it.

Per fibre, the maxima over its elements: ``max_axial_strain`` (largest
|E33|, so unsigned), ``max_curvature`` and ``max_stress`` (the largest
surface stress of one element: not the sum of the other two maxima), and
``most_loaded``, the fibres ordered by decreasing ``max_stress``. Fibres
are numbered as in the model (``model.mesh.fibres``), from 0.

:func:`fibre_loads` computes them for a model (collective under MPI, the
same result on every rank); :func:`ranked_table` prints the most loaded
fibres. :class:`~textile.Output` writes the per-element figures and the
per-fibre maxima to ParaView and the top fibres of each step to
results.json. :func:`node_curvatures` is the one implementation of the
centre-line curvature (:func:`textile.fabric.measures.fibre_curvatures`
uses it).
"""
from __future__ import annotations

import numpy as np

#: Per-fibre figures, with the words for their units in tables.
FIGURES = {"max_axial_strain": "axial strain (GL, -)",
           "max_curvature": "curvature (1/length)",
           "max_stress": "surface stress (E's unit, e.g. Pa)"}
_AXIAL_STRAIN, _AXIAL_STRESS = 2, 8   # E33 and S33 in the element fields (Voigt 33)


def node_curvatures(first_node: np.ndarray, x: np.ndarray) -> np.ndarray:
    """(nodes,) centre-line curvature at every node of all fibres at once.

    ``first_node``: (fibres + 1,) first global node of each fibre, then the
    node count (``FibreMesh.first_node``); ``x``: (nodes, 3) positions.
    Inner nodes: turning angle of the two adjacent segments (atan2 of the
    cross and dot products of their directions: accurate for small angles
    too) over their mean length; fibre ends: 0.
    """
    first_node = np.asarray(first_node, dtype=np.int64)
    kappa = np.zeros(len(x))
    inner = np.ones(len(x), dtype=bool)
    inner[first_node[:-1]] = False
    inner[first_node[1:] - 1] = False
    i = np.flatnonzero(inner)
    if not len(i):
        return kappa
    a = x[i] - x[i - 1]
    b = x[i + 1] - x[i]
    la, lb = np.linalg.norm(a, axis=1), np.linalg.norm(b, axis=1)
    turn = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.sum(a * b, axis=1))
    kappa[i] = turn / (0.5 * (la + lb))
    return kappa


def gathered_element_fields(model, root: int | None = None) -> np.ndarray | None:
    """(global elements, 12) element fields of the beam (strain then stress,
    Voigt 11, 22, 33, 23, 13, 12, local frame), in global element order.
    Collective: on every rank (``root=None``) or on rank ``root`` only
    (None elsewhere)."""
    mesh = model.mesh
    part = (mesh.local_element_ids, model.beam.element_fields(model.state().u["beam"]))
    if root is None:
        parts = model.comm.allgather(part)
    else:
        parts = model.comm.gather(part, root=root)
        if model.comm.rank != root:
            return None
    vals = np.zeros((len(mesh.elements_global), 12))
    for ids, v in parts:
        vals[ids] = v
    return vals


def element_loads(mesh, x: np.ndarray, fields: np.ndarray) -> dict:
    """Per global element: ``axial_strain`` (signed E33), ``curvature`` and
    ``surface_stress`` (module docstring), from the (nodes, 3) positions
    ``x`` and the gathered element fields (:func:`gathered_element_fields`).
    Not collective."""
    kappa = node_curvatures(mesh.first_node, x)[mesh.elements_global].max(axis=1)
    fibre = mesh.element_fibre
    young = np.array([f.material.young for f in mesh.fibres])[fibre]
    radius = np.array([f.radius for f in mesh.fibres])[fibre]
    return dict(axial_strain=fields[:, _AXIAL_STRAIN], curvature=kappa,
                surface_stress=np.abs(fields[:, _AXIAL_STRESS]) + young * radius * kappa)


def fibre_maxima(mesh, elements: dict) -> dict:
    """The per-fibre figures (module docstring) from :func:`element_loads`."""
    # elements are numbered fibre after fibre, each fibre has at least one
    starts = np.searchsorted(mesh.element_fibre, np.arange(len(mesh.fibres)))
    out = {"max_axial_strain": np.maximum.reduceat(np.abs(elements["axial_strain"]), starts),
           "max_curvature": np.maximum.reduceat(elements["curvature"], starts),
           "max_stress": np.maximum.reduceat(elements["surface_stress"], starts)}
    out["most_loaded"] = ranking(out)
    return out


def ranking(loads: dict, by: str = "max_stress") -> np.ndarray:
    """Fibre indices by decreasing ``loads[by]`` (ties: lower index first)."""
    if by not in FIGURES:
        raise ValueError(f"by must be one of {tuple(FIGURES)}, got {by!r}")
    return np.argsort(-np.asarray(loads[by]), kind="stable")


def fibre_loads(model) -> dict:
    """Per fibre (arrays of length number of fibres, model fibre order):
    ``max_axial_strain``, ``max_curvature``, ``max_stress``, and
    ``most_loaded`` (fibre indices by decreasing ``max_stress``); figures,
    units and signs in the module docstring. Collective: call on every
    rank; every rank gets the same result."""
    x = model.nodal_unknowns()[:, 0:3]
    fields = gathered_element_fields(model)
    return fibre_maxima(model.mesh, element_loads(model.mesh, x, fields))


def top_fibres(loads: dict, count: int = 5, by: str = "max_stress") -> dict:
    """The ``count`` most loaded fibres as {"fibre": [indices], and per
    figure its values in the same order} (plain Python lists, for
    results.json: more compact there than one dict per fibre)."""
    order = ranking(loads, by)[:count]
    return {"fibre": [int(f) for f in order],
            **{k: [float(v) for v in np.asarray(loads[k])[order]] for k in FIGURES}}


def ranked_table(loads: dict, count: int = 10, by: str = "max_stress", yarn=None) -> str:
    """A printable table of the ``count`` fibres with the largest
    ``loads[by]`` (``by``: one of ``max_axial_strain``, ``max_curvature``,
    ``max_stress``): rank, fibre, the fibre's ``yarn`` label if given (one
    label per fibre, e.g. ``fabric.fibre_yarn``), and the three figures with
    their units. ``loads``: from :func:`fibre_loads`."""
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
        raise ValueError(f"count must be a positive integer, got {count!r}")
    order = ranking(loads, by)[:count]
    n = len(loads["max_stress"])
    if yarn is not None and len(yarn) != n:
        raise ValueError(f"yarn has {len(yarn)} labels but there are {n} fibres")
    head = ["rank", "fibre"] + (["yarn"] if yarn is not None else []) + list(FIGURES.values())
    rows = [[str(r + 1), str(f)] + ([str(yarn[f])] if yarn is not None else [])
            + [f"{loads[k][f]:.4g}" for k in FIGURES] for r, f in enumerate(order)]
    widths = [max(len(h), *(len(row[c]) for row in rows)) for c, h in enumerate(head)]
    title = f"{len(order)} most loaded of {n} fibres, by {FIGURES[by]}"
    lines = [title, "  ".join(h.rjust(w) for h, w in zip(head, widths))]
    lines += ["  ".join(v.rjust(w) for v, w in zip(row, widths)) for row in rows]
    return "\n".join(lines)
