"""Tetrahedral meshes of the matrix (dolfinx meshes), with named sides.

Mesh creation and input for the matrix side live here and in
:mod:`textile.effects.elastic_block`, the only modules that call dolfinx's
mesh and finite-element API, so a port to a newer dolfinx touches them only.
Lengths are in the user's length unit, as for fibres.

A matrix mesh is a :class:`MatrixMesh`: the dolfinx mesh, its facet tags
and the names of its tagged sides. Three ways to get one:

- :func:`gmsh_box` meshes an axis-aligned box with gmsh (first-order
  tetrahedra of a target size) and names its six sides ``xmin``, ``xmax``,
  ``ymin``, ``ymax``, ``zmin``, ``zmax`` (physical groups 1 to 6; the volume
  is the physical group 7, ``matrix``);
- :func:`box_around_fibres` does the same around a set of fibres
  (:func:`fibre_box` gives the box, the choice is documented there);
- :func:`read_msh` reads a user's gmsh ``.msh`` file; its named physical
  surface groups become the sides (``meshes/matrix_box.py`` writes such a
  file from the command line).

gmsh is imported only inside these functions: a scene without a matrix
never imports it (nor builds a dolfinx mesh). :func:`box_mesh` is a
structured box without gmsh and without side names.
"""
from __future__ import annotations

import contextlib
from dataclasses import dataclass, field

import numpy as np
from dolfinx import mesh as _mesh

#: Physical-group tags of the box sides written by :func:`build_gmsh_box`.
SIDE_TAGS = {"xmin": 1, "xmax": 2, "ymin": 3, "ymax": 4, "zmin": 5, "zmax": 6}
#: Physical-group tag and name of the box's volume.
VOLUME_TAG, VOLUME_NAME = 7, "matrix"


@dataclass(frozen=True)
class MatrixMesh:
    """A matrix mesh and its named boundary parts.

    Attributes
    ----------
    mesh:
        dolfinx tetrahedral mesh in 3D, distributed over its communicator.
    facet_tags:
        dolfinx MeshTags of the facets (physical surface groups), or None.
    sides:
        Side name -> facet tag value (e.g. ``{"xmin": 1, ...}``), identical
        on every rank.
    corners:
        (corner0, corner1) of the box when the mesh is one, else None.
    """

    mesh: _mesh.Mesh
    facet_tags: object = None
    sides: dict = field(default_factory=dict)
    corners: tuple | None = None


def _checked_corners(corner0, corner1, who: str) -> tuple[np.ndarray, np.ndarray]:
    p0 = np.asarray(corner0, dtype=float)
    p1 = np.asarray(corner1, dtype=float)
    if p0.shape != (3,) or p1.shape != (3,) or not np.all(np.isfinite(np.r_[p0, p1])):
        raise ValueError(f"{who}: corners must be finite 3-vectors, got {corner0!r}, {corner1!r}")
    if np.any(p1 <= p0):
        raise ValueError(f"{who}: need corner0 < corner1 in every direction, got {p0}, {p1}")
    return p0, p1


def box_mesh(comm, corner0, corner1, n) -> _mesh.Mesh:
    """Tetrahedral mesh of the box [corner0, corner1] with n = (nx, ny, nz)
    hexahedral cells, each split into six tetrahedra, partitioned over
    ``comm`` (cells ghosted across shared facets)."""
    p0, p1 = _checked_corners(corner0, corner1, "box_mesh")
    cells = np.asarray(n)
    if cells.shape != (3,) or cells.dtype.kind not in "iu" or np.any(cells < 1):
        raise ValueError(f"box_mesh: n must be three positive integers, got {n!r}")
    return _mesh.create_box(comm, [p0, p1], [int(c) for c in cells],
                            cell_type=_mesh.CellType.tetrahedron,
                            ghost_mode=_mesh.GhostMode.shared_facet)


# -- gmsh ------------------------------------------------------------------------
@contextlib.contextmanager
def gmsh_session():
    """gmsh initialized for the block (without reading the user's gmsh
    configuration files, silent), finalized after it. gmsh 4.8 cannot tell
    whether it is initialized already: do not call this (nor the functions
    that use it) inside a gmsh session of your own; write a .msh and use
    :func:`read_msh` instead."""
    import gmsh

    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        yield gmsh
    finally:
        gmsh.finalize()


def build_gmsh_box(gmsh, corner0, corner1, size: float) -> None:
    """Mesh the box [corner0, corner1] in the current gmsh model: first-order
    tetrahedra of target edge length ``size`` (uniform), physical surface
    groups named by :data:`SIDE_TAGS`, the volume group ``matrix``.
    Deterministic (one thread, Delaunay), so every run gives the same mesh."""
    p0, p1 = _checked_corners(corner0, corner1, "gmsh box")
    if not np.isfinite(size) or size <= 0:
        raise ValueError(f"gmsh box: size must be positive and finite, got {size!r}")
    occ = gmsh.model.occ
    volume = occ.addBox(*p0, *(p1 - p0))
    occ.synchronize()
    tol = 1e-9 * float(np.max(p1 - p0))
    for s in gmsh.model.getBoundary([(3, volume)], oriented=False):
        centre = np.asarray(gmsh.model.occ.getCenterOfMass(2, s[1]))
        axis = int(np.argmax([min(abs(centre[k] - p0[k]), abs(centre[k] - p1[k])) < tol
                              for k in range(3)]))
        end = "min" if abs(centre[axis] - p0[axis]) < tol else "max"
        name = "xyz"[axis] + end
        gmsh.model.addPhysicalGroup(2, [s[1]], SIDE_TAGS[name])
        gmsh.model.setPhysicalName(2, SIDE_TAGS[name], name)
    gmsh.model.addPhysicalGroup(3, [volume], VOLUME_TAG)
    gmsh.model.setPhysicalName(3, VOLUME_TAG, VOLUME_NAME)
    gmsh.option.setNumber("General.NumThreads", 1)
    gmsh.option.setNumber("Mesh.MeshSizeMin", size)
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.ElementOrder", 1)
    gmsh.model.mesh.generate(3)


def _model_to_matrix_mesh(gmsh, comm, root: int, source: str, corners=None) -> MatrixMesh:
    """dolfinx mesh, facet tags and side names of gmsh's current model on
    rank ``root`` (collective; the model is read there only)."""
    from dolfinx.io import gmshio

    error, sides = "", {}
    if comm.rank == root:
        if not gmsh.model.getPhysicalGroups(3):
            error = (f"{source}: no physical volume group: tag the matrix volume (and name "
                     f"its sides as physical surfaces); gmsh imports physical groups only")
        else:
            for dim, tag in gmsh.model.getPhysicalGroups(2):
                name = gmsh.model.getPhysicalName(dim, tag) or str(tag)
                sides[name] = int(tag)
            types = gmsh.model.mesh.getElementTypes(3)
            if len(types) != 1 or gmsh.model.mesh.getElementProperties(types[0])[0] \
                    not in ("Tetrahedron 4", "Tetrahedron 10"):
                error = f"{source}: the volume must be meshed with tetrahedra only"
    error, sides = comm.bcast((error, sides), root=root)
    if error:
        raise ValueError(error)
    msh, _, facet_tags = gmshio.model_to_mesh(gmsh.model, comm, root, gdim=3)
    return MatrixMesh(msh, facet_tags, sides, corners)


def gmsh_box(comm, corner0, corner1, size: float, msh_path: str | None = None) -> MatrixMesh:
    """Box [corner0, corner1] meshed by gmsh with tetrahedra of edge length
    about ``size`` (coarse for a composite: several fibre diameters), sides
    named ``xmin`` ... ``zmax``. Collective: gmsh runs on rank 0 and dolfinx
    distributes the mesh (cells ghosted across shared facets). ``msh_path``:
    also write the gmsh mesh there (rank 0)."""
    p0, p1 = _checked_corners(corner0, corner1, "gmsh_box")
    with gmsh_session() as gmsh:
        if comm.rank == 0:
            gmsh.model.add("textile matrix box")
            build_gmsh_box(gmsh, p0, p1, float(size))
            if msh_path is not None:
                gmsh.write(str(msh_path))
        try:
            return _model_to_matrix_mesh(gmsh, comm, 0, "gmsh_box", (p0, p1))
        finally:
            if comm.rank == 0:
                gmsh.model.remove()


def read_msh(comm, path: str) -> MatrixMesh:
    """A gmsh ``.msh`` file as a matrix mesh (collective; rank 0 reads it).

    The file must hold a physical volume group of tetrahedra; its named
    physical surface groups become the sides (an unnamed group is named by
    its tag number). Only physical groups are imported (dolfinx's gmshio).
    dolfinx 0.5.2's ``gmshio.read_from_msh`` is broken on Debian, hence
    ``gmsh.open`` and ``model_to_mesh``."""
    import os

    if comm.rank == 0 and not os.path.isfile(path):
        error = f"read_msh: no such file {path!r}"
    else:
        error = ""
    error = comm.bcast(error, root=0)
    if error:
        raise FileNotFoundError(error)
    with gmsh_session() as gmsh:
        if comm.rank == 0:
            gmsh.open(str(path))
        try:
            return _model_to_matrix_mesh(gmsh, comm, 0, f"read_msh({path!r})")
        finally:
            if comm.rank == 0:
                gmsh.model.remove()


# -- a box around fibres ------------------------------------------------------------
def fibre_box(fibres, margin: float | None = None, overlap: float | None = None,
              axis=None) -> tuple[np.ndarray, np.ndarray]:
    """Corners of the matrix box around ``fibres`` (reference geometry).

    The choice: through the thickness (``axis``: "x", "y", "z" or 0-2;
    default the direction in which the centre-line nodes spread least) the
    box encloses the fibres' volumes, from the lowest fibre surface
    (centre-line node minus its radius) to the highest, plus ``overlap`` on
    both faces (default a quarter of the largest radius): the outer fibres
    are fully inside the matrix, under a thin skin, so every fibre particle
    of a junction lies in a matrix cell. In the other two directions the
    box is the bounding box of the centre-line nodes plus ``margin`` on
    each side (default the largest radius: the outer fibres' lateral
    surfaces are inside too; with ``margin=0`` fibre ends lie on the
    sides, as in a cell cut from a larger fabric).

    ``fibres``: a :class:`textile.Model` or a sequence of
    :class:`textile.Fibre`.
    """
    fibre_list = getattr(getattr(fibres, "mesh", None), "fibres", fibres)
    if not len(fibre_list):
        raise ValueError("fibre_box: no fibres")
    points = np.vstack([np.asarray(f.points, dtype=float) for f in fibre_list])
    radii = np.concatenate([np.full(len(f.points), float(f.radius)) for f in fibre_list])
    rmax = float(radii.max())
    margin = rmax if margin is None else float(margin)
    overlap = 0.25 * rmax if overlap is None else float(overlap)
    if not (np.isfinite(margin) and margin >= 0 and np.isfinite(overlap) and overlap >= 0):
        raise ValueError(f"fibre_box: margin and overlap must be >= 0, got {margin}, {overlap}")
    if axis is None:
        axis = int(np.argmin(np.ptp(points, axis=0)))
    elif isinstance(axis, str):
        if axis not in ("x", "y", "z"):
            raise ValueError(f"fibre_box: axis must be 'x', 'y', 'z' or 0-2, got {axis!r}")
        axis = "xyz".index(axis)
    elif axis not in (0, 1, 2):
        raise ValueError(f"fibre_box: axis must be 'x', 'y', 'z' or 0-2, got {axis!r}")
    p0 = points.min(axis=0) - margin
    p1 = points.max(axis=0) + margin
    p0[axis] = np.min(points[:, axis] - radii) - overlap
    p1[axis] = np.max(points[:, axis] + radii) + overlap
    return p0, p1


def box_around_fibres(comm, fibres, size: float | None = None, margin: float | None = None,
                      overlap: float | None = None, axis=None) -> MatrixMesh:
    """The matrix box of :func:`fibre_box` meshed by :func:`gmsh_box`;
    ``size`` defaults to four fibre diameters (of the largest radius)."""
    p0, p1 = fibre_box(fibres, margin, overlap, axis)
    if size is None:
        fibre_list = getattr(getattr(fibres, "mesh", None), "fibres", fibres)
        size = 8.0 * max(float(f.radius) for f in fibre_list)
    return gmsh_box(comm, p0, p1, size)
