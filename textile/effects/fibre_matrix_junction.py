"""Fibre-matrix junction elements: fibre material particles tied to the matrix.

Each junction pairs a *material particle* of a fibre element -- a point of
its section at section coordinates (c1, c2) and element coordinate xi --
with the material point of an
:class:`~textile.effects.elastic_block.ElasticBlock` at the same place
(docs/method.md §1.1 and §8.2), and stores the penalty energy

    E_j = 1/2 k w_j |x_f - x_m|^2,
    x_f = sum_a N_a(xi) (x0_a + c1 g1_a + c2 g2_a)   (fibre particle),
    x_m = X_m + sum_b phi_b u_b       (matrix point, phi the matrix cell's basis),

linear in the fibre nodes' 9 unknowns (x0, g1, g2), so the energy is
quadratic and the tangent constant.

Stations and particles. The junction *stations* of an element are the
points of a Gauss-Legendre rule on [-1, 1] (by default the beam element's
own axial Gauss points). At each station the particles are

* with ``section_particles=True`` (default): the centroid (0, 0) and the
  four section points (+-rho, 0), (0, +-rho), rho = SECTION_FRACTION * r
  (r the fibre radius, SECTION_FRACTION = sqrt(5/8) = 0.79), each with a
  fifth of the station's weight. This 5-point rule integrates every
  polynomial of degree <= 3 over the disk exactly (mean of c1^2 over the
  disk r^2/4 = 2/5 rho^2), so the junctions integrate the penalty
  k/(pi r^2) |x_f - x_m|^2 over the section as well as along the fibre
  for gaps up to quadratic in (c1, c2). The section particles tie the
  section vectors to the matrix: an embedded fibre cannot turn about its
  own axis at zero energy (torsional penalty k rho^2 (4/5) theta^2 / 2 =
  k r^2 theta^2 / 4 per unit length, the disk's value).
* with ``section_particles=False``: the centroid only (the centre line),
  with the whole station weight; the sections then turn freely about the
  fibre axis unless something else holds them.

Weighting, per unit fibre length:

* k is the stiffness per unit fibre length (N/m^2). Default: the block's
  Young's modulus, k = STIFFNESS_FACTOR * E_m with STIFFNESS_FACTOR = 1.
* the station's weight is (Gauss weight) x |dx0/dxi| in the configuration
  where the junctions are made, the fibre length it stands for; it is split
  over the station's particles (weights adding up to it). The junctions thus
  integrate 1/2 k |x_f - x_m|^2 along the fibre (averaged over the section):
  a gap uniform over the section (a translation) sees exactly k per unit
  length with or without section particles, and the total stiffness does
  not depend on how many stations an element has nor on the element or
  matrix mesh sizes.

Junctions are made in the fibres' configuration at creation (``positions``,
default the reference geometry), so a woven, pre-stressed fibre state can
be embedded in an unstressed matrix: X_m is the particle's position then,
x0 + c1 g1 + c2 g2 with the station's interpolated centroid and section
vectors, searched in the matrix's reference mesh (bounding-box tree of
dolfinx's geometry module, then :meth:`ElasticBlock.point_basis`): the
particles of one station may lie in different cells (and be assembled on
different ranks). Particles outside the matrix mesh get no junction
(counted in :meth:`statistics`).

The residual is k w gap distributed by N_a (1, c1, c2) on (x0, g1, g2) and
by -phi_b on the matrix. All junctions are assembled together in C++
(``_cpp.JunctionSet``, ``cpp/textile/junction/``), one tangent block per
distinct (fibre element, matrix cell) pair.

Parallel: a junction is assembled by the one rank owning the matrix cell
containing its point (point_basis's rule: the lowest rank for a point on a
partition interface). The fibre element nodes it couples become ghosts of
the fibre mesh there (:meth:`fibre_ghosts`) when the junctions are
created, which must therefore happen before the model is set up. The share
of (junction, fibre node) couplings whose node another rank owns is
``statistics()["junction_off_rank_fraction"]``.
"""
from __future__ import annotations

import numbers

import numpy as np
from dolfinx import geometry
from mpi4py import MPI
from petsc4py import PETSc

from .. import _cpp
from .base import SAME_SCENE_RTOL, Effect, State
from .elastic_block import ElasticBlock

#: default stiffness per unit fibre length = STIFFNESS_FACTOR * E_m (N/m^2)
STIFFNESS_FACTOR = 1.0

#: section particles at (+-rho, 0), (0, +-rho), rho = SECTION_FRACTION * radius;
#: with the centroid and equal weights a disk rule exact to degree 3
SECTION_FRACTION = float(np.sqrt(5.0 / 8.0))


def section_rule(radius: float) -> tuple[np.ndarray, np.ndarray]:
    """The section particles of a station of a fibre of this radius:
    coordinates (5, 2) (centroid, (+-rho, 0), (0, +-rho)) and weights (5,)
    (fractions of the station's weight, 1/5 each, adding up to 1)."""
    rho = SECTION_FRACTION * radius
    c = np.array([[0.0, 0.0], [rho, 0.0], [-rho, 0.0], [0.0, rho], [0.0, -rho]])
    return c, np.full(5, 0.2)


def _shape(order: int, xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Lagrange shape functions (n, order + 1) and their xi-derivatives at
    xi, in the node order of cpp/textile/beam/shape_functions.h."""
    xi = np.asarray(xi, dtype=float)
    if order == 1:
        N = np.stack([0.5 * (1 - xi), 0.5 * (1 + xi)], axis=1)
        dN = np.stack([np.full_like(xi, -0.5), np.full_like(xi, 0.5)], axis=1)
    else:
        N = np.stack([0.5 * xi * (xi - 1), 1 - xi * xi, 0.5 * xi * (xi + 1)], axis=1)
        dN = np.stack([xi - 0.5, -2 * xi, xi + 0.5], axis=1)
    return N, dN


def _inside(block: ElasticBlock, points: np.ndarray) -> np.ndarray:
    """Collective: True for points inside the block's (reference) mesh on some rank."""
    msh = block.mesh
    tdim = msh.topology.dim
    n_owned = msh.topology.index_map(tdim).size_local
    tree = geometry.BoundingBoxTree(msh, tdim, np.arange(n_owned, dtype=np.int32))
    hits = geometry.compute_colliding_cells(msh, geometry.compute_collisions(tree, points),
                                            points)
    found = (np.diff(hits.offsets) > 0).astype(np.int32)
    msh.comm.Allreduce(MPI.IN_PLACE, found, op=MPI.MAX)
    return found.astype(bool)


class FibreMatrixJunctions(Effect):
    """Ties fibre material particles to the matrix points where they sit.

    Parameters
    ----------
    model:
        The :class:`~textile.Model` whose fibres are embedded (collective
        call: every rank of the model's communicator creates the junctions,
        before the model is set up).
    block:
        The :class:`ElasticBlock` (the matrix); add it to the model before
        the junctions.
    fibres:
        Optional subset of fibres (objects or indices); default all.
    particles_per_element:
        Particles per fibre element, at the points of the Gauss-Legendre rule
        of that order; default the beam element's axial Gauss points
        (``model.element.axial_points``).
    stiffness:
        Penalty stiffness per unit fibre length k (N/m^2); default
        ``STIFFNESS_FACTOR * block.young`` (factor 1).
    positions:
        Optional (global nodes, 9) current nodal unknowns of the fibres
        (x0, g1, g2, e.g. ``other_model.nodal_unknowns()``) in which the
        junctions are made; default the fibres' reference geometry. With
        ``section_particles=False`` 3 columns (positions) suffice.
    section_particles:
        True (default): tie the centroid and four section particles of each
        station (module docstring); False: the centre line only.
    """

    symmetric_tangent = True  # a quadratic penalty potential
    constant_tangent = True   # ... with constant coefficients (jacobian adds a cached copy)

    def __init__(self, model, block: ElasticBlock, fibres=None, particles_per_element=None,
                 stiffness=None, positions=None, section_particles=True):
        if not isinstance(block, ElasticBlock):
            raise TypeError(f"block must be an ElasticBlock, got {type(block).__name__}")
        if stiffness is None:
            stiffness = STIFFNESS_FACTOR * block.young
        if isinstance(stiffness, bool) or not isinstance(stiffness, numbers.Real) \
                or not np.isfinite(stiffness) or stiffness <= 0:
            raise ValueError(f"FibreMatrixJunctions: stiffness must be positive and finite, "
                             f"got {stiffness!r}")
        mesh = model.mesh
        if particles_per_element is None:
            particles_per_element = model.element.axial_points
        if isinstance(particles_per_element, bool) \
                or not isinstance(particles_per_element, numbers.Integral) \
                or not 1 <= particles_per_element <= 20:
            raise ValueError(f"FibreMatrixJunctions: particles_per_element must be an integer "
                             f"in 1..20, got {particles_per_element!r}")
        if fibres is None:
            selected = np.arange(len(mesh.fibres))
        else:
            selected = np.unique([mesh.fibre_index(f) for f in fibres])
        if not isinstance(section_particles, (bool, np.bool_)):
            raise ValueError(f"FibreMatrixJunctions: section_particles must be True or False, "
                             f"got {section_particles!r}")
        section_particles = bool(section_particles)
        ncol = 9 if section_particles else 3
        if positions is None:
            x = mesh.X_global[:, 0:ncol]
        else:
            x = np.asarray(positions, dtype=float)
            if x.ndim != 2 or x.shape[0] != mesh.num_nodes_global or x.shape[1] < ncol \
                    or not np.all(np.isfinite(x[:, :ncol])):
                need = "9" if section_particles else "3 or 9"
                raise ValueError(f"FibreMatrixJunctions: positions must be finite, of shape "
                                 f"({mesh.num_nodes_global}, {need}), got {x.shape}")
            x = x[:, 0:ncol]
        # particles of every selected element (replicated geometry: every
        # rank computes all of them, then keeps those of its matrix cells)
        elements = np.flatnonzero(np.isin(mesh.element_fibre, selected))
        xi_q, w_q = _cpp.gauss_legendre(int(particles_per_element))
        N, dN = _shape(mesh.order, xi_q)
        nq = len(xi_q)
        xe = x[mesh.elements_global[elements]]                 # (ne, nf, 3 or 9)
        station = np.einsum("qa,eac->eqc", N, xe)              # (ne, nq, 3 or 9)
        jac = np.linalg.norm(np.einsum("qa,eac->eqc", dN, xe[:, :, 0:3]), axis=2)
        weight = (jac * w_q[None, :]).ravel()                  # per station
        elem = np.repeat(elements, nq)
        xi = np.tile(xi_q, len(elements))
        if section_particles:
            # particles (station, section point): x0 + c1 g1 + c2 g2
            radius = np.array([f.radius for f in mesh.fibres])[mesh.element_fibre[elem]]
            c_unit, beta = section_rule(1.0)
            section = radius[:, None, None] * c_unit[None, :, :]       # (ns, 5, 2)
            st = station.reshape(-1, 9)
            pts = (st[:, None, 0:3] + section[:, :, 0:1] * st[:, None, 3:6]
                   + section[:, :, 1:2] * st[:, None, 6:9]).reshape(-1, 3)
            npart = len(beta)
            elem, xi = np.repeat(elem, npart), np.repeat(xi, npart)
            weight = (weight[:, None] * beta[None, :]).ravel()
            section = section.reshape(-1, 2)
        else:
            pts = station.reshape(-1, 3)
            section = np.zeros((len(xi), 2))
            npart = 1
        self.particles_per_element = int(particles_per_element)
        self.section_particles = section_particles
        self.particles_per_station = npart
        self._make(model, block, float(stiffness), elem, xi, weight, pts, section)

    def _make(self, model, block, stiffness, elem, xi, weight, pts, section=None) -> None:
        """Junctions of the particles (global element, xi, weight, position,
        section coordinates, default the centre line) that lie inside the
        block (collective)."""
        if section is None:
            section = np.zeros((len(xi), 2))
        mesh = model.mesh
        if mesh.numbering_final:
            # the junctions' fibre nodes could not become ghosts (fibre_ghosts)
            raise RuntimeError("FibreMatrixJunction: the fibre mesh's local numbering is final "
                               "once the model is set up; create junctions before setting up "
                               "or solving")
        self.fields = ("beam", block.name)
        self.block, self.stiffness = block, stiffness
        self._model = model
        inside = _inside(block, np.ascontiguousarray(pts))
        self.num_particles = len(pts)
        self.num_outside = int(np.count_nonzero(~inside))
        if inside.any():   # the same on every rank: point_basis is collective
            cells, phi = block.point_basis(pts[inside])
        else:
            cells, phi = np.zeros(0, dtype=np.int32), np.zeros((0, 0))
        mine = cells >= 0
        sel = np.flatnonzero(inside)[mine]
        self._elem_global = elem[sel]
        self._xi, self._weight, self._points = xi[sel], weight[sel], pts[sel]
        self._section = np.ascontiguousarray(section[sel], dtype=float).reshape(-1, 2)
        self._cells, self._phi = cells[mine], phi[mine]
        nodes = mesh.elements_global[self._elem_global]           # (n, nf)
        self._nodes_global = nodes   # their off-rank nodes become ghosts: fibre_ghosts

        # couplings (junction, fibre node) whose node this rank does not own
        off = int(np.count_nonzero(~mesh.owns(nodes)))
        comm = model.comm
        self.num_junctions = comm.allreduce(len(sel), op=MPI.SUM)
        total_couplings = comm.allreduce(nodes.size, op=MPI.SUM)
        self.num_off_rank_couplings = comm.allreduce(off, op=MPI.SUM)
        self.off_rank_fraction = (self.num_off_rank_couplings / total_couplings
                                  if total_couplings else 0.0)
        self.total_weight = comm.allreduce(float(self._weight.sum()), op=MPI.SUM)
        self._set = None
        #: the constant tangent in A's pattern, and the matrix and pattern it
        #: was made for (jacobian); how many times it was assembled
        self._tangent, self._tangent_key = None, None
        self.tangent_assemblies = 0

    # -- Effect interface -------------------------------------------------
    def fibre_ghosts(self, mesh) -> np.ndarray:
        # the fibre nodes of this rank's junctions (their elements')
        return self._nodes_global.ravel()

    def setup(self, model) -> None:
        if model.mesh is not self._model.mesh:   # model: the scene's System
            raise ValueError("FibreMatrixJunctions: the junctions belong to another model")
        effects = model.effects
        if self.block not in effects or effects.index(self.block) > effects.index(self):
            # the block's set_pattern would replace the pattern filled here
            raise ValueError("FibreMatrixJunctions: add the ElasticBlock to the model before "
                             "its junctions")
        mesh = model.mesh
        local = mesh.global_to_local(self._nodes_global)
        assert np.all(local >= 0), "junction nodes are local by construction (fibre_ghosts)"
        self._local = local.astype(np.int32)
        self._cell_nodes = np.ascontiguousarray(self.block.cell_dofs(self._cells), dtype=np.int32)
        if not len(self._phi):
            self._phi = np.zeros((0, self._cell_nodes.shape[1]))
        if self._phi.shape[1] != self._cell_nodes.shape[1]:
            raise RuntimeError("FibreMatrixJunctions: point_basis and cell_dofs disagree on the "
                               "number of cell nodes")
        # all junctions in one batch (C++): no Python loop per junction
        self._set = _cpp.JunctionSet(
            self.stiffness, mesh.order + 1, self._local.ravel(), self._xi,
            self._section.ravel(), self._weight,
            np.ascontiguousarray(mesh.X_local[:, 0:9]).ravel(),
            np.ascontiguousarray(self._points).ravel(), self._cell_nodes.ravel(),
            np.ascontiguousarray(self._phi, dtype=float).ravel())

    def add_sparsity(self, sparsity) -> None:
        m = self.block.name
        if not len(self._local):
            return
        # one block per distinct (fibre element, matrix cell) pair; the
        # beam field's blocks are whole nodes (9 unknowns: x0, g1, g2), so
        # the section particles' couplings of g1, g2 are in the pattern too
        key = np.column_stack([self._local, self._cell_nodes])
        for row in np.unique(key, axis=0):
            nodes, dofs = row[: self._local.shape[1]], row[self._local.shape[1]:]
            sparsity.insert("beam", "beam", nodes, nodes)
            sparsity.insert("beam", m, nodes, dofs)
            sparsity.insert(m, "beam", dofs, nodes)
            sparsity.insert(m, m, dofs, dofs)

    def residual(self, state: State, b) -> None:
        self.energy = self._set.assemble_vector(state.u["beam"], state.u[self.block.name],
                                                b["beam"], b[self.block.name])

    def jacobian(self, state: State, A) -> None:
        """The junctions' tangent is constant (a quadratic energy): it is
        assembled once into a copy of A's pattern, which every later call
        adds to A in one pass over its values (MatAXPY, same pattern), with
        no kernel, no insertion and nothing sent between ranks. Again when A
        is a new matrix or its pattern changed (collective)."""
        if not A.isAssembled():
            # a pattern being built (the model's base matrix, its first
            # tangent): insert
            self._set.assemble_matrix(A, state.dofs["beam"], state.dofs[self.block.name])
            return
        key = (A.handle, _cpp.nonzero_state(A))
        if self._model.comm.allreduce(key != self._tangent_key, op=MPI.LOR):
            if self._tangent is not None:
                self._tangent.destroy()
            self._tangent = A.duplicate(copy=False)
            self._set.assemble_matrix(self._tangent, state.dofs["beam"],
                                      state.dofs[self.block.name])
            self._tangent.assemble()
            self._tangent_key = key
            self.tangent_assemblies += 1
        A.axpy(1.0, self._tangent, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)

    def statistics(self) -> dict:
        """Constants of the junction set (the same on every rank, not collective):
        "junctions" (particles tied: stations x particles_per_station, less
        those outside), "junctions_outside" (particles outside the matrix,
        no junction), "junction_length" (fibre length the junctions stand
        for, sum of w), "junction_off_rank_fraction" (share of (junction,
        fibre node) couplings whose node the assembling rank does not own),
        "junction_tangent_assemblies" (times the constant tangent was
        assembled: once per system matrix and pattern, see jacobian)."""
        return {"junctions": self.num_junctions, "junctions_outside": self.num_outside,
                "junction_length": self.total_weight,
                "junction_off_rank_fraction": self.off_rank_fraction,
                "junction_tangent_assemblies": self.tangent_assemblies}

    # -- saved states (textile.io.state_file) ---------------------------------
    @property
    def state_name(self) -> str:
        return f"junctions {self.block.name}"

    #: columns of a saved junction: where it was made and how stiff
    SAVED = ("element", "xi", "c1", "c2", "weight", "stiffness", "x", "y", "z")

    def _all_junctions(self, everywhere: bool) -> np.ndarray:
        """(junctions, 9) of every rank (columns SAVED), sorted: on every
        rank, or complete on rank 0 only (collective)."""
        mine = np.column_stack([self._elem_global.astype(float), self._xi, self._section,
                                self._weight, np.full(len(self._xi), self.stiffness),
                                self._points]).reshape(-1, 9)
        comm = self._model.comm
        parts = comm.allgather(mine) if everywhere else comm.gather(mine, root=0)
        if parts is None:
            return np.zeros((0, 9))
        out = np.concatenate(parts)
        return out[np.lexsort(out.T[::-1])]

    def save_state(self, model) -> dict:
        """No history (a quadratic penalty between fibre and matrix
        unknowns, both saved); where the junctions were made and how stiff
        they are (the scene)."""
        return dict(junctions=self._all_junctions(everywhere=False))

    def check_state(self, model, data: dict) -> None:
        name = self.block.name
        if not data:
            raise ValueError(f"the state file has no junctions to block {name!r}; the model has "
                             f"{self.num_junctions}")
        saved, mine = np.asarray(data["junctions"]), self._all_junctions(everywhere=True)
        if saved.shape != mine.shape:
            raise ValueError(f"the state file has {len(saved)} junctions to block {name!r}, "
                             f"this model {len(mine)}")
        scale = np.maximum(np.abs(mine).max(axis=0, initial=0.0), np.finfo(float).tiny)
        differ = (np.abs(saved - mine) > SAME_SCENE_RTOL * scale).any(axis=0)
        if differ.any():
            cols = [w for w, d in zip(self.SAVED, differ) if d]
            raise ValueError(f"the junctions to block {name!r} in the state file differ from "
                             f"this model's in {cols} (another fabric, woven state or "
                             f"stiffness)")

    # -- results ------------------------------------------------------------
    def _state(self):
        if self._set is None:
            raise RuntimeError("FibreMatrixJunctions: the model is not set up yet")
        st = self._model.state()
        return st.u["beam"], st.u[self.block.name]

    def points(self) -> np.ndarray:
        """(n, 3) where this rank's junctions were made (X_m)."""
        return self._points.copy()

    def section_coordinates(self) -> np.ndarray:
        """(n, 2) section coordinates (c1, c2) of this rank's junction particles."""
        return self._section.copy()

    def weights(self) -> np.ndarray:
        """(n,) fibre length each of this rank's junctions stands for."""
        return self._weight.copy()

    def gaps(self) -> np.ndarray:
        """(n, 3) x_f - x_m of this rank's junctions at the current solution."""
        return self._set.gaps(*self._state())

    def forces(self) -> np.ndarray:
        """(n, 3) force k w (x_f - x_m) each of this rank's junctions exerts on
        the matrix (the fibre receives the opposite), at the current solution."""
        return self._set.forces(*self._state())

    def total_force(self) -> np.ndarray:
        """Total force (3,) the junctions exert on the matrix (collective)."""
        return self._model.comm.allreduce(self._set.total_force(*self._state()), op=MPI.SUM)
