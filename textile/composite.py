"""A textile composite: a woven fabric embedded in an elastic matrix
(METHOD.md sections 6 and 7), driven through side rigid bodies.

The scene:

- the fibres of a :class:`~textile.fabric.Fabric`, in the state a weaving
  run saved (``woven``: :func:`textile.save_state`), so they keep their
  crimp and their pre-stress; or straight if no state is given;
- fibre-fibre contact, with the saved contact history;
- the matrix: a gmsh box around the woven fibres (:mod:`textile.matrix_mesh`),
  through the thickness enclosing every fibre under a thin skin
  (``overlap``), in the plane the bounding box of the fibres' centre lines,
  so the yarn ends lie on its sides; meshed with tetrahedra of size ``size``
  (coarse: several fibre diameters) and assembled by dolfinx
  (:class:`~textile.effects.elastic_block.ElasticBlock`). The matrix is
  stress-free in the woven configuration: its reference is that state;
- junctions (:class:`~textile.effects.fibre_matrix_junction.FibreMatrixJunctions`)
  between fibre particles and the matrix points where they sit in that
  configuration, a penalty of ``junction_stiffness`` per unit fibre length;
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

from . import fabric_measures
from .block_nodes import BlockNodes
from .effects.elastic_block import ElasticBlock
from .effects.fibre_contact import FibreContact
from .effects.fibre_matrix_junction import FibreMatrixJunctions
from .fabric import Fabric
from .io import fabric_labels
from .io.state_file import load_fibres, saved_configuration
from .loading import Stage
from .material import Material
from .matrix_mesh import gmsh_box
from .model import Model
from .output import Output
from .rigid_body import RigidBody

#: The sides a body can drive, with the yarn direction ending there and which end.
SIDES = {"xmin": ("warp", 0), "xmax": ("warp", -1), "ymin": ("weft", 0), "ymax": ("weft", -1)}


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


class Composite:
    """A fabric in a matrix, with side bodies (module docstring).

    Parameters
    ----------
    fabric:
        The :class:`~textile.fabric.Fabric` (the same as the weaving run's).
    woven:
        Path of a saved woven state of that fabric, or None (straight yarns).
    matrix:
        The matrix's :class:`~textile.material.Material` (Young's modulus,
        Poisson ratio).
    size:
        Target edge length of the matrix tetrahedra (default four fibre
        diameters).
    overlap:
        Matrix skin above the highest and below the lowest fibre surface
        (default a quarter of the fibre radius).
    degree:
        1 or 2 (default): Lagrange degree of the matrix displacement. A
        thin composite has one or two coarse tetrahedra through its
        thickness: linear ones lock in bending (the 2 x 2 demo composite
        comes out 4.6 times too stiff with P1), quadratic ones do not.
    law:
        "neo-hookean" (default) or "svk" for the matrix.
    junction_stiffness:
        Penalty of the junctions per unit fibre length (force per length
        squared; default the matrix's Young's modulus).
    sides:
        Names of the sides that get a rigid body (among xmin, xmax, ymin,
        ymax). A matrix edge node shared by two bodies would be held twice:
        drive two opposite sides, or give all four and let them slide.
    contact:
        :class:`~textile.effects.fibre_contact.ContactOptions` or a dict, or
        False for no fibre-fibre contact.
    comm:
        MPI communicator.
    """

    def __init__(self, fabric: Fabric, woven: str | None, matrix: Material,
                 size: float | None = None, overlap: float | None = None, degree: int = 2,
                 law: str = "neo-hookean", junction_stiffness: float | None = None,
                 sides=("xmin", "xmax"), contact=None, comm=MPI.COMM_WORLD):
        if not isinstance(fabric, Fabric):
            raise TypeError(f"Composite: fabric must be a textile.fabric.Fabric, got "
                            f"{type(fabric).__name__}")
        if not isinstance(matrix, Material):
            raise TypeError(f"Composite: matrix must be a textile.Material, got "
                            f"{type(matrix).__name__}")
        sides = (sides,) if isinstance(sides, str) else tuple(sides)
        unknown = [s for s in sides if s not in SIDES]
        if unknown or not sides or len(set(sides)) != len(sides):
            raise ValueError(f"Composite: sides must be distinct names among {tuple(SIDES)}, "
                             f"got {sides!r}")
        fibres = fabric.fibres()
        radius = max(f.radius for f in fibres)
        size = 8.0 * radius if size is None else size
        overlap = 0.25 * radius if overlap is None else overlap
        for name, v in (("size", size), ("overlap", overlap)):
            if isinstance(v, bool) or not isinstance(v, numbers.Real) or not np.isfinite(v) \
                    or v < 0 or (name == "size" and v == 0):
                raise ValueError(f"Composite: {name} must be a positive length, got {v!r}")
        self.fabric, self.woven = fabric, woven
        # the configuration everything is built around: the woven one
        configuration = None
        if woven is not None:
            configuration = comm.bcast(saved_configuration(woven) if comm.rank == 0 else None,
                                       root=0)
        self.model = Model(fibres, comm=comm)
        mesh = self.model.mesh
        if configuration is None:
            configuration = mesh.X_global
        if configuration.shape != mesh.X_global.shape:
            raise ValueError(f"Composite: the woven state has {len(configuration)} fibre nodes, "
                             f"this fabric {len(mesh.X_global)}: give the weaving run's fabric")
        node_radius = np.repeat([f.radius for f in fibres], [f.num_nodes for f in fibres])
        self.corners = woven_box(configuration, node_radius, overlap)
        self.matrix_mesh = gmsh_box(comm, *self.corners, size)
        self.contact = None
        if contact is not False:
            self.contact = FibreContact(contact)
            self.model.add_effect(self.contact)
        self.block = ElasticBlock(self.matrix_mesh, matrix.young, matrix.poisson, law=law,
                                  degree=degree)
        self.model.add_effect(self.block)
        self.junctions = FibreMatrixJunctions(self.model, self.block,
                                              stiffness=junction_stiffness,
                                              positions=configuration)
        self.model.add_effect(self.junctions)
        self.sides: dict[str, RigidBody] = {}
        held = set()
        for side in sides:
            ends = self._yarn_ends(side)
            body = RigidBody(side, sections=ends, block_nodes=BlockNodes(self.block, side))
            self.model.add_rigid_body(body)
            self.sides[side] = body
            held.update(ends)
        # the yarn ends no body holds: what held them in the weaving run
        # (its yarn-end bodies) is replaced by a force, released over the
        # first stage (release_stage)
        self._free_ends = [e for side in SIDES for e in self._yarn_ends(side) if e not in held]
        self._release = [self.model.add_force(f, k, np.zeros(9), dofs="all")
                         for f, k in self._free_ends] if woven is not None else []
        self.model.setup()
        if woven is not None:
            load_fibres(self.model, woven)
            self._hold_free_ends()

    def _yarn_ends(self, side: str) -> list[tuple[int, int]]:
        """(fibre, node) of the yarn ends on ``side``."""
        direction, end = SIDES[side]
        fabric = self.fabric
        yarns = [k for k in range(fabric.num_yarns) if fabric.yarn_direction(k) == direction]
        return [(int(f), end) for f in np.flatnonzero(np.isin(fabric.fibre_yarn, yarns))]

    def _hold_free_ends(self) -> None:
        """Set the release forces to the generalized forces (9 a node) the
        loaded state is out of balance by at the free yarn ends, so that it
        starts in equilibrium (collective)."""
        model, mesh = self.model, self.model.mesh
        b = model.x.duplicate()
        model.residual(None, model.x, b)
        r = b.getArray(readonly=True)
        imbalance = np.zeros((len(self._free_ends), 9))
        local = mesh.global_to_local([mesh.node(f, k) for f, k in self._free_ends])
        mine = np.flatnonzero((local >= 0) & (local < mesh.num_owned))
        if len(mine):
            rows = model.layout.offset("beam") + 9 * local[mine][:, None] + np.arange(9)
            imbalance[mine] = r[model._owned_position(rows.ravel())].reshape(-1, 9)
        imbalance = model.comm.allreduce(imbalance)
        b.destroy()
        for h, f in zip(self._release, imbalance):
            h.schedule.start[h.index] = f
            h.schedule.target[h.index] = f

    def release_stage(self, steps: int = 2) -> Stage:
        """The first stage: the forces that stand for the weaving run's
        yarn-end bodies at the ends no side body holds go to zero (the
        fabric is let go, its matrix takes the yarns' pre-stress); the side
        bodies hold their components at zero."""
        return Stage("release", ramp={h: 0.0 for h in self._release},
                     solver=dict(initial_step=1.0 / steps, max_step=1.0 / steps))

    def output(self, directory: str, **options) -> Output:
        """An :class:`~textile.output.Output` writing fibres (with their yarn)
        and matrix every step, and the fabric's figures."""
        return Output(directory, **fabric_labels(self.fabric),
                      extra=lambda model: fabric_measures.summary(self.fabric, model), **options)

    def side_reaction(self, side: str) -> np.ndarray:
        """(6,) force and moment the side body exerts on what it holds
        (fibre ends and matrix face), about its current centre."""
        return np.asarray(self.model.rigid_bodies.reaction(self.sides[side]))
