"""A textile composite: a woven fabric embedded in an elastic matrix
(docs/method.md §7-8), driven through side rigid bodies.

The scene:

- the fibres of a :class:`~textile.fabric.Fabric`, in the state a weaving
  run saved (``woven``: :func:`textile.save_state`), so they keep their
  crimp and their pre-stress; or straight if no state is given;
- fibre-fibre contact, with the saved contact history;
- the matrix: a gmsh box around the woven fibres (:mod:`textile.composite.matrix_mesh`),
  through the thickness enclosing every fibre under a thin skin
  (``overlap``), in the plane the bounding box of the fibres' centre lines,
  so the yarn ends lie on its sides; meshed with tetrahedra of size ``size``
  (coarse: several fibre diameters) and assembled by dolfinx
  (:class:`~textile.effects.elastic_block.ElasticBlock`). The matrix is
  stress-free in the woven configuration: its reference is that state;
- junctions (:class:`~textile.effects.fibre_matrix_junction.FibreMatrixJunctions`)
  between fibre particles and the matrix points where they sit in that
  configuration, a penalty of ``junction_stiffness`` per unit fibre length,
  their stations about ``junction_spacing`` apart along the fibres;
- one rigid body per driven side of the sample (``sides``: names among
  xmin, xmax, ymin, ymax): it gathers the end sections of the yarns ending
  on that side (warp yarns run along x, weft yarns along y) and the matrix
  nodes of that face. Each body component is then prescribed or loaded by
  the caller (``composite.sides["xmax"].prescribe("ry", angle)``).

Units: those of the fabric (lengths of its spacing and radii, forces of its
materials' Young's modulus times an area); the matrix's Young's modulus in
the same force per length squared.
"""
from __future__ import annotations

import numbers

import numpy as np
from mpi4py import MPI

from .. import presets
from ..beam.material import Material
from ..scene.block_nodes import BlockNodes
from ..effects.elastic_block import DEGREES, LAWS, ElasticBlock
from ..effects.fibre_matrix_junction import FibreMatrixJunctions
from ..fabric.fabric import Fabric
from ..fabric.sample import SIDES, Sample  # noqa: F401  (SIDES: re-exported)
from .matrix_mesh import gmsh_box


def woven_box(configuration: np.ndarray, radius: np.ndarray, overlap: float):
    """Corners of the matrix box around fibres in ``configuration``
    ((nodes, >= 3) centre-line positions, ``radius`` per node): in x and y
    the centre lines' bounding box (yarn ends on the sides), in z every
    fibre surface plus ``overlap`` above and below."""
    x = np.asarray(configuration)[:, 0:3]
    p0, p1 = x.min(axis=0), x.max(axis=0)
    p0[2] = np.min(x[:, 2] - radius) - overlap
    p1[2] = np.max(x[:, 2] + radius) + overlap
    return p0, p1


#: most junction stations an element (FibreMatrixJunctions' limit)
MAX_STATIONS = 20


def junction_stations(mesh, configuration: np.ndarray, spacing: float) -> int:
    """Junction stations per fibre element for stations ``spacing`` apart:
    the longest element's length in ``configuration`` ((nodes, >= 3)
    centre-line positions; the polyline through its nodes) over
    ``spacing``, rounded, at least 1 (the fabric's elements are about
    equally long). ValueError above :data:`MAX_STATIONS`."""
    x = np.asarray(configuration)[:, 0:3][mesh.elements_global]      # (elements, nodes, 3)
    longest = float(np.linalg.norm(np.diff(x, axis=1), axis=2).sum(axis=1).max())
    n = max(1, int(round(longest / spacing)))
    if n > MAX_STATIONS:
        raise ValueError(f"Composite: junction_spacing {spacing:.4g} asks for {n} junction "
                         f"stations on fibre elements {longest:.4g} long (at most "
                         f"{MAX_STATIONS}): a larger spacing, or more fibre elements")
    return n


class Composite(Sample):
    """A fabric in a matrix, with side bodies (module docstring); the
    fabric-only scene, its stages and results are :class:`~textile.fabric.sample.Sample`'s.

    Parameters
    ----------
    fabric, woven, contact, preset, comm:
        As :class:`~textile.fabric.sample.Sample`'s; the accuracy
        ``preset`` (:mod:`textile.presets`; None: "standard") also sets
        ``size`` and ``degree`` unless they are given.
    matrix:
        The matrix's :class:`~textile.beam.material.Material` (Young's modulus,
        Poisson ratio).
    size:
        Target edge length of the matrix tetrahedra (default the preset's,
        in fibre radii: standard 8, four fibre diameters).
    overlap:
        Matrix skin above the highest and below the lowest fibre surface
        (default a quarter of the fibre radius).
    degree:
        1 or 2 (default: the preset's, 2 in each): Lagrange degree of the matrix displacement. A
        thin composite has one or two coarse tetrahedra through its
        thickness: linear ones lock in bending (4.12 times the P2
        stiffness on the tests' 2 x 2 monofilament composite,
        tests/virtual/test_composite_tests.py), quadratic ones do not.
    law:
        "neo-hookean" (default) or "svk" for the matrix.
    junction_stiffness:
        Penalty of the junctions per unit fibre length (force per length
        squared; default the matrix's Young's modulus).
    junction_spacing:
        Distance between the junction stations along a fibre (a length,
        in the fabric's unit; each station ties a fibre's centroid and
        four section points to the matrix): every fibre element gets
        :func:`junction_stations` of them, its length over the spacing
        rounded, at the points of a Gauss-Legendre rule. Default None: the
        beam element's axial points (two an element). At most 20 an
        element.
    sides:
        Names of the sides that get a rigid body (among xmin, xmax, ymin,
        ymax). A matrix edge node shared by two bodies would be held twice:
        drive two opposite sides, or give all four and let them slide.
    """

    def __init__(self, fabric: Fabric, woven: str | None, matrix: Material,
                 size: float | None = None, overlap: float | None = None,
                 degree: int | None = None, law: str = "neo-hookean",
                 junction_stiffness: float | None = None, junction_spacing: float | None = None,
                 sides=("xmin", "xmax"), contact=None, preset: str | None = None,
                 comm=MPI.COMM_WORLD):
        if not isinstance(fabric, Fabric):
            raise TypeError(f"Composite: fabric must be a textile.fabric.Fabric, got "
                            f"{type(fabric).__name__}")
        if not isinstance(matrix, Material):
            raise TypeError(f"Composite: matrix must be a textile.Material, got "
                            f"{type(matrix).__name__}")
        preset = presets.checked(preset, "Composite")
        radius = max(f.radius for f in fabric.fibres())
        size = presets.knob(preset, "matrix", "size_radii") * radius if size is None else size
        degree = presets.knob(preset, "matrix", "degree", degree)
        overlap = 0.25 * radius if overlap is None else overlap
        for name, v in (("size", size), ("overlap", overlap)):
            if isinstance(v, bool) or not isinstance(v, numbers.Real) or not np.isfinite(v) \
                    or v < 0 or (name == "size" and v == 0):
                raise ValueError(f"Composite: {name} must be a positive length, got {v!r}")
        # checked here, before the matrix is meshed (the block and the
        # junctions check them again)
        if isinstance(degree, bool) or not isinstance(degree, numbers.Integral) \
                or degree not in DEGREES:
            raise ValueError(f"Composite: degree must be one of {DEGREES}, got {degree!r}")
        if law not in LAWS:
            raise ValueError(f"Composite: law must be one of {LAWS}, got {law!r}")
        for value, name, what in ((junction_stiffness, "junction_stiffness",
                                   "a positive number (force per length squared)"),
                                  (junction_spacing, "junction_spacing",
                                   "a positive length (the fabric's unit)")):
            if value is not None and (isinstance(value, bool)
                                      or not isinstance(value, numbers.Real)
                                      or not np.isfinite(value) or value <= 0):
                raise ValueError(f"Composite: {name} must be {what} or None, got {value!r}")
        self._matrix = dict(material=matrix, size=size, overlap=overlap, degree=degree, law=law,
                            junction_stiffness=junction_stiffness,
                            junction_spacing=junction_spacing)
        super().__init__(fabric, woven, sides=sides, contact=contact, free_ends="fibres",
                         preset=preset, comm=comm)

    @property
    def matrix(self) -> Material:
        """The matrix's material."""
        return self._matrix["material"]

    def _add_matrix(self, configuration: np.ndarray) -> None:
        """The matrix box around ``configuration``, its block and the junctions."""
        o, model = self._matrix, self.model
        fibres = model.mesh.fibres
        node_radius = np.repeat([f.radius for f in fibres], [f.num_nodes for f in fibres])
        # checked before the matrix is meshed
        stations = None if o["junction_spacing"] is None else \
            junction_stations(model.mesh, configuration, o["junction_spacing"])
        self.corners = woven_box(configuration, node_radius, o["overlap"])
        self.matrix_mesh = gmsh_box(model.comm, *self.corners, o["size"])
        self.block = ElasticBlock(self.matrix_mesh, o["material"].young, o["material"].poisson,
                                  law=o["law"], degree=o["degree"])
        model.add_effect(self.block)
        self.junctions = FibreMatrixJunctions(model, self.block,
                                              stiffness=o["junction_stiffness"],
                                              positions=configuration,
                                              particles_per_element=stations)
        model.add_effect(self.junctions)

    def _side_block(self, side: str) -> dict:
        return dict(block_nodes=BlockNodes(self.block, side))
