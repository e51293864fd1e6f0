"""Tetrahedral meshes of the matrix (dolfinx meshes).

Mesh creation and input for the matrix side live here and in
:mod:`textile.effects.elastic_block`, the only modules that call dolfinx's
mesh and finite-element API, so a port to a newer dolfinx touches them only.
Lengths are in the user's length unit, as for fibres.
"""
from __future__ import annotations

import numpy as np
from dolfinx import mesh as _mesh


def box_mesh(comm, corner0, corner1, n) -> _mesh.Mesh:
    """Tetrahedral mesh of the box [corner0, corner1] with n = (nx, ny, nz)
    hexahedral cells, each split into six tetrahedra, partitioned over
    ``comm`` (cells ghosted across shared facets)."""
    p0 = np.asarray(corner0, dtype=float)
    p1 = np.asarray(corner1, dtype=float)
    if p0.shape != (3,) or p1.shape != (3,) or not np.all(np.isfinite(np.r_[p0, p1])):
        raise ValueError(f"box_mesh: corners must be finite 3-vectors, got {corner0!r}, {corner1!r}")
    if np.any(p1 <= p0):
        raise ValueError(f"box_mesh: need corner0 < corner1 in every direction, got {p0}, {p1}")
    cells = np.asarray(n)
    if cells.shape != (3,) or cells.dtype.kind not in "iu" or np.any(cells < 1):
        raise ValueError(f"box_mesh: n must be three positive integers, got {n!r}")
    return _mesh.create_box(comm, [p0, p1], [int(c) for c in cells],
                            cell_type=_mesh.CellType.tetrahedron,
                            ghost_mode=_mesh.GhostMode.shared_facet)
