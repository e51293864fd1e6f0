"""A hyperelastic solid meshed with tetrahedra (dolfinx), assembled as one field.

The block brings the field ``name`` (default "matrix"): the unknowns of a
vector Lagrange dolfinx function space of degree 1 (P1) or 2 (P2) on
first-order (affine) tetrahedra, numbered by dolfinx's own index map
(block size 3), so its forms assemble unchanged into the stacked global
system. Unknowns are displacements (length unit); E is in
force per length squared, so residuals are forces (N) consistent with the
fibres. The law is compressible neo-Hookean (finite strain):

    psi(F) = mu/2 (tr C - 3) - mu ln J + lambda/2 (ln J)^2,   C = F^T F,  J = det F,

with the Lame constants of (E, nu); it reduces to linear isotropic
elasticity with (E, nu) at small strain. ``law="svk"`` gives St Venant-
Kirchhoff instead, psi = lambda/2 (tr E)^2 + mu tr(E^2), E = (C - I)/2.
Integration: one point for P1 (the strain is constant in a cell), the
4-point degree-2 rule for P2 (exact for the small-strain stiffness).

Inverted elements: a state in which det F <= 0 at a check point of an
owned cell is outside the model's domain. :meth:`ElasticBlock.residual`
raises :class:`textile.GeometryError` naming the cell, so the solver cuts
the step; it is never assembled (neo-Hookean's ln J would be NaN) nor
accepted (St Venant-Kirchhoff would happily carry on). Check points: the
cell's integration points and its element nodes (for P1 the single point,
as J is constant in a cell; for P2 the 4 integration points, where the
energy is evaluated, and the 10 nodes, where the quadratic J can go
negative first); all cells at once in compiled code.

Every dolfinx call of the matrix side is in this module (and in
:mod:`textile.composite.matrix_mesh`), so a port to a newer dolfinx touches only them.
"""
from __future__ import annotations

import numbers
import os

import basix
import numpy as np
import ufl
from dolfinx import cpp as _dcpp
from dolfinx import fem, geometry, la
from dolfinx import mesh as _mesh
from mpi4py import MPI

from .. import _cpp
from ..system.layout import Field
from ..composite.matrix_mesh import MatrixMesh
from .base import Effect, State

LAWS = ("neo-hookean", "svk")
DEGREES = (1, 2)


def _as_points(points) -> np.ndarray:
    p = np.asarray(points, dtype=float)
    if p.ndim == 1:
        p = p.reshape(1, -1)
    if p.ndim != 2 or p.shape[1] != 3 or not np.all(np.isfinite(p)):
        raise ValueError(f"points must be finite 3D points of shape (n, 3), got shape {p.shape}")
    return np.ascontiguousarray(p)


def _unique_pieces(pvtu: str) -> None:
    """dolfinx 0.5.2's VTKFile lists every rank's piece once per function
    written: a reader would load the block that many times over. Keep each
    piece once (in place, rank 0)."""
    import xml.etree.ElementTree as ET

    tree = ET.parse(pvtu)
    grid = tree.getroot().find("PUnstructuredGrid")
    seen = set()
    for piece in grid.findall("Piece"):
        if piece.get("Source") in seen:
            grid.remove(piece)
        seen.add(piece.get("Source"))
    tree.write(pvtu, xml_declaration=True, encoding="utf-8")


class ElasticBlock(Effect):
    """A tetrahedral hyperelastic solid, optionally clamped on part of its boundary.

    Parameters
    ----------
    mesh:
        A :class:`textile.composite.matrix_mesh.MatrixMesh` (mesh with named sides,
        e.g. from :func:`~textile.composite.matrix_mesh.gmsh_box`) or a plain dolfinx
        tetrahedral mesh in 3D (e.g. :func:`~textile.composite.matrix_mesh.box_mesh`),
        on the model's communicator, first-order (affine) cells.
    young, poisson:
        Young's modulus E > 0 and Poisson ratio nu in (-1, 0.5).
    clamp:
        Optional: a side name (``"xmin"``), a list of side names (the mesh
        must have named sides), or a marker ``x -> bool array`` (x of shape
        (3, n), reference coordinates) selecting boundary facets. The nodes
        of those facets are fixed (zero displacement).
    law:
        "neo-hookean" (default) or "svk".
    name:
        Name of the block's field (distinct names for several blocks).
    degree:
        1 (P1, default) or 2 (P2) Lagrange displacement field.
    """

    symmetric_tangent = True  # hyperelastic: the tangent is a Hessian

    def __init__(self, mesh, young: float, poisson: float, clamp=None, law: str = "neo-hookean",
                 name: str = "matrix", degree: int = 1):
        tagged = mesh if isinstance(mesh, MatrixMesh) else MatrixMesh(mesh)
        mesh = tagged.mesh
        if not isinstance(mesh, _mesh.Mesh):
            raise TypeError(f"mesh must be a dolfinx.mesh.Mesh or a MatrixMesh, got "
                            f"{type(mesh).__name__}")
        if mesh.topology.cell_type != _mesh.CellType.tetrahedron or mesh.geometry.dim != 3:
            raise ValueError(f"ElasticBlock needs a tetrahedral mesh in 3D, got "
                             f"{mesh.topology.cell_type.name} cells in {mesh.geometry.dim}D")
        if mesh.geometry.cmap.degree != 1:
            raise ValueError("ElasticBlock needs first-order (straight-edged) tetrahedra; for a "
                             "quadratic field use degree=2 on a linear mesh")
        for label, v in (("young", young), ("poisson", poisson)):
            if isinstance(v, bool) or not isinstance(v, numbers.Real) or not np.isfinite(v):
                raise ValueError(f"ElasticBlock: {label} must be a finite real number, got {v!r}")
        if young <= 0:
            raise ValueError(f"ElasticBlock: young must be positive, got {young}")
        if not -1.0 < poisson < 0.5:
            raise ValueError(f"ElasticBlock: poisson must lie in (-1, 0.5), got {poisson}")
        if law not in LAWS:
            raise ValueError(f"ElasticBlock: law must be one of {LAWS}, got {law!r}")
        if isinstance(degree, bool) or degree not in DEGREES:
            raise ValueError(f"ElasticBlock: degree must be one of {DEGREES}, got {degree!r}")
        if not isinstance(name, str) or not name or name == "beam":
            raise ValueError(f"ElasticBlock: name must be a non-empty string other than 'beam', "
                             f"got {name!r}")
        self.mesh, self.young, self.poisson, self.law, self.name = mesh, float(young), \
            float(poisson), law, name
        self.degree = int(degree)
        self.facet_tags, self.sides = tagged.facet_tags, dict(tagged.sides)
        self.fields = (name,)
        self.V = fem.VectorFunctionSpace(mesh, ("Lagrange", self.degree))
        self.u = fem.Function(self.V, name="displacement")
        #: integration rule: 1 point for P1, the degree-2 (4-point) rule for P2
        self.quadrature_degree = 1 if self.degree == 1 else 2
        self._R_form, self._J_form = self._forms()
        self._det_F, self._det_F_points = self._det_F_expression()
        self._clamp_dofs = self._unrolled(self._boundary_nodes(clamp, "clamp")) \
            if clamp is not None else np.zeros(0, dtype=np.int64)
        self._tree = None
        self._model = None
        self._sub = [self.V.sub(c) for c in range(self.V.dofmap.index_map_bs)]
        self._bcs, self._bcs_key = [], None
        self._outputs = None

    # -- physics --------------------------------------------------------------
    def _lame(self) -> tuple[float, float]:
        E, nu = self.young, self.poisson
        return E / (2.0 * (1.0 + nu)), E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))

    def _deformation_gradient(self):
        return ufl.variable(ufl.Identity(3) + ufl.grad(self.u))

    def _energy_density(self, F):
        mu, lmbda = self._lame()
        if self.law == "neo-hookean":
            J = ufl.det(F)
            return mu / 2 * (ufl.tr(F.T * F) - 3) - mu * ufl.ln(J) + lmbda / 2 * ufl.ln(J) ** 2
        Eg = (F.T * F - ufl.Identity(3)) / 2
        return lmbda / 2 * ufl.tr(Eg) ** 2 + mu * ufl.inner(Eg, Eg)

    def _forms(self):
        v = ufl.TestFunction(self.V)
        F = self._deformation_gradient()
        dx = ufl.dx(metadata={"quadrature_degree": self.quadrature_degree})
        R = ufl.inner(ufl.diff(self._energy_density(F), F), ufl.grad(v)) * dx
        dR = ufl.derivative(R, self.u, ufl.TrialFunction(self.V))
        return fem.form(R), fem.form(dR)

    def _det_F_expression(self):
        """det F at the check points of a cell (see the module docstring):
        the integration points (FFCx's default rule of the forms' degree,
        i.e. basix's) and, for P2, the element's nodes."""
        cell = basix.CellType.tetrahedron
        points, _ = basix.make_quadrature(cell, self.quadrature_degree)
        if self.degree > 1:
            points = np.vstack([points, self.V.element.basix_element.points])
        expr = fem.Expression(ufl.det(self._deformation_gradient()), points)
        return expr, points

    def _owned_cells(self) -> np.ndarray:
        return np.arange(self.mesh.topology.index_map(3).size_local, dtype=np.int32)

    def check_inverted(self, u: np.ndarray) -> None:
        """Raise :class:`textile.GeometryError` if an owned cell has det F <= 0
        at one of its check points at displacement ``u`` (local owned +
        ghost array); NaN displacements are left to the NaN residual test."""
        self.u.x.array[:] = u
        J = self._det_F.eval(self._owned_cells())
        worst = J.min(axis=1)
        bad = np.flatnonzero(worst <= 0.0)
        if len(bad):
            c = bad[np.argmin(worst[bad])]
            imap = self.mesh.topology.index_map(3)
            centre = self.mesh.geometry.x[self.mesh.geometry.dofmap.links(c)].mean(axis=0)
            raise _cpp.GeometryError(
                f"inverted matrix element: cell {imap.local_range[0] + c} of block "
                f"'{self.name}' (reference centre {np.array2string(centre, precision=4)}) has "
                f"det F = {worst[c]:.3g} <= 0; {len(bad)} inverted cell(s) on rank "
                f"{self.mesh.comm.rank}")

    def min_det_F(self) -> float:
        """Smallest det F over every check point of every cell at the model's
        current solution, over all ranks (collective)."""
        if self._model is None:
            raise RuntimeError("ElasticBlock.min_det_F: the model is not set up yet")
        self.u.x.array[:] = self._model.state().u[self.name]
        J = self._det_F.eval(self._owned_cells())
        local = float(J.min()) if J.size else np.inf
        return self.mesh.comm.allreduce(local, op=MPI.MIN)

    def statistics(self) -> dict:
        """Per converged step (results.json): the block's smallest det F."""
        return {f"{self.name}_min_det_F": self.min_det_F()}

    def _boundary_nodes(self, where, what: str) -> np.ndarray:
        """Local block dofs (nodes, owned + ghost, sorted) on the boundary
        facets selected by ``where``: a side name, a list of side names or a
        marker x -> bool array on reference coordinates."""
        fdim = self.mesh.topology.dim - 1
        if callable(where):
            facets = _mesh.locate_entities_boundary(self.mesh, fdim, where)
        else:
            names = [where] if isinstance(where, str) else list(where) \
                if isinstance(where, (list, tuple)) else None
            if not names or not all(isinstance(n, str) for n in names):
                raise ValueError(f"ElasticBlock {what}: give a side name, a list of side names "
                                 f"or a callable x -> bool array, got {where!r}")
            if self.facet_tags is None or not self.sides:
                raise ValueError(f"ElasticBlock {what}: the mesh has no named sides (use a "
                                 f"MatrixMesh from textile.composite, or a marker)")
            unknown = [n for n in names if n not in self.sides]
            if unknown:
                raise ValueError(f"ElasticBlock {what}: unknown side(s) {unknown}; the mesh has "
                                 f"{sorted(self.sides)}")
            tags = [self.sides[n] for n in names]
            facets = self.facet_tags.indices[np.isin(self.facet_tags.values, tags)]
        # remote=True: also the ghosts whose facet lies on another rank
        nodes = fem.locate_dofs_topological(self.V, fdim, facets, remote=True)
        return np.unique(np.asarray(nodes, dtype=np.int32))

    def _unrolled(self, nodes: np.ndarray) -> np.ndarray:
        bs = self.V.dofmap.index_map_bs
        return (bs * np.asarray(nodes, dtype=np.int64)[:, None] + np.arange(bs)).ravel()

    def _assemble_force(self, u: np.ndarray, b: np.ndarray) -> None:
        """b += internal force dPi/du at displacement u (local owned + ghost arrays)."""
        self.u.x.array[:] = u
        _dcpp.fem.assemble_vector(b, self._R_form, _dcpp.fem.pack_constants(self._R_form),
                                  _dcpp.fem.pack_coefficients(self._R_form))

    # -- Effect interface -----------------------------------------------------
    def add_fields(self, model) -> list:
        if MPI.Comm.Compare(model.comm, self.mesh.comm) not in (MPI.IDENT, MPI.CONGRUENT):
            raise ValueError("ElasticBlock: the mesh must live on the model's communicator")
        imap = self.V.dofmap.index_map
        return [Field(self.name, imap, self.V.dofmap.index_map_bs)]

    def reference_values(self) -> dict[str, np.ndarray]:
        # the junctions and rigid couplings place the node at X + u
        return {self.name: np.ascontiguousarray(self.node_coordinates().ravel())}

    def block_keys(self, field: str) -> np.ndarray:
        return self.node_keys()

    # -- saved states (textile.io.state_file) ----------------------------------
    @property
    def state_name(self) -> str:
        return f"elastic block {self.name}"

    def save_state(self, model) -> dict:
        """No history (a hyperelastic solid: its state is its displacement,
        saved by node key as the field's unknowns); its law, material and
        degree, to recognize the scene."""
        return dict(law=np.bytes_(self.law), young=self.young, poisson=self.poisson,
                    degree=np.int64(self.degree))

    def check_state(self, model, data: dict) -> None:
        label = f"the state file's block {self.name!r}"
        if not data:
            raise ValueError(f"the state file has no elastic block {self.name!r}; the model has "
                             f"one: save the state with the matrix in the scene")
        saved = (bytes(data["law"]).decode(), float(data["young"]), float(data["poisson"]),
                 int(data["degree"]))
        mine = (self.law, self.young, self.poisson, self.degree)
        if saved != mine:
            raise ValueError(f"{label} is (law, E, nu, degree) = {saved}, this model's "
                             f"{mine}")

    def setup(self, model) -> None:
        self._model = model
        layout = model.layout
        self._is = _dcpp.la.petsc.create_index_sets(layout.maps)[layout.index(self.name)]

    def add_sparsity(self, sparsity) -> None:
        sparsity.set_pattern(self.name, self.name, fem.create_sparsity_pattern(self._J_form))

    def constraints(self, load_factor: float) -> dict:
        if not len(self._clamp_dofs):
            return {}
        return {self.name: (self._clamp_dofs, np.zeros(len(self._clamp_dofs)))}

    def residual(self, state: State, b) -> None:
        out = b[self.name]
        if not out.flags.c_contiguous:
            raise ValueError("ElasticBlock.residual: b must hold contiguous arrays")
        # an inverted cell is a domain error before anything is assembled
        self.check_inverted(state.u[self.name])
        self._assemble_force(state.u[self.name], out)

    def jacobian(self, state: State, A) -> None:
        self.u.x.array[:] = state.u[self.name]
        # rows and columns of every constrained dof of the field (the
        # clamp's and any other effect's) stay empty; the Model puts the
        # unit diagonal on them
        bcs = self._zero_bcs(np.flatnonzero(state.dofs[self.name] < 0))
        Asub = A.getLocalSubMatrix(self._is, self._is)
        _dcpp.fem.petsc.assemble_matrix(Asub, self._J_form,
                                        _dcpp.fem.pack_constants(self._J_form),
                                        _dcpp.fem.pack_coefficients(self._J_form),
                                        bcs, True)
        A.restoreLocalSubMatrix(self._is, self._is, Asub)

    def _zero_bcs(self, fixed: np.ndarray) -> list:
        """Dirichlet conditions on the unrolled local dofs ``fixed``, one per
        component (sub-space), only to zero their rows and columns.

        dolfinx 0.5.2's marker overload of assemble_matrix is unusable (its
        check rejects every 1D column marker), hence DirichletBC objects;
        they are rebuilt only when the constrained set changes.
        """
        key = fixed.tobytes()
        if self._bcs_key != key:
            bs = self.V.dofmap.index_map_bs
            self._bcs = [fem.dirichletbc(np.float64(0.0), fixed[fixed % bs == c].astype(np.int32),
                                         self._sub[c]) for c in range(bs)]
            self._bcs_key = key
        return self._bcs

    # -- results ---------------------------------------------------------------
    def reaction(self, side=None) -> np.ndarray:
        """Total force (3,) at a set of the block's nodes: the sum of the
        block's internal force dPi/du over them, at the model's current
        solution, over all ranks (collective). Default: the clamped nodes
        (the support force; in equilibrium it balances the other forces on
        the block; forces that other effects apply directly on clamped nodes
        are not included). ``side``: a side name, list of names or marker
        as for :meth:`side_nodes`, e.g. the nodes another effect prescribes
        (a pulled side gives +F along a pull F: internal force, the
        convention of textile's reactions)."""
        if self._model is None:
            raise RuntimeError("ElasticBlock.reaction: the model is not set up yet")
        bs = self.V.dofmap.index_map_bs
        if side is None:
            if not self._num_clamped():
                raise ValueError("ElasticBlock.reaction: the block has no clamp")
            dofs = self._clamp_dofs
        else:
            dofs = self._unrolled(self._boundary_nodes(side, "reaction"))
        u = self._model.state().u[self.name]
        imap = self.V.dofmap.index_map
        f = la.vector(imap, bs)
        f.array[:] = 0.0
        self._assemble_force(u, f.array)
        f.scatter_reverse(la.ScatterMode.add)
        own = dofs[dofs < imap.size_local * bs]
        out = np.bincount(own % bs, weights=f.array[own], minlength=bs)
        return self.mesh.comm.allreduce(out, op=MPI.SUM)

    def _num_clamped(self) -> int:
        """Number of clamped dofs over all ranks (collective)."""
        n = self.V.dofmap.index_map.size_local * self.V.dofmap.index_map_bs
        return self.mesh.comm.allreduce(int(np.count_nonzero(self._clamp_dofs < n)), op=MPI.SUM)

    # -- junction and rigid-body support ------------------------------------------
    @property
    def nodes_per_cell(self) -> int:
        """Nodes (block dofs) of a cell: 4 for P1, 10 for P2."""
        return self.V.dofmap.dof_layout.num_dofs

    @property
    def num_owned_nodes(self) -> int:
        """Nodes this rank owns; local node indices below it are owned, the
        others ghosts."""
        return self.V.dofmap.index_map.size_local

    def point_basis(self, points) -> tuple[np.ndarray, np.ndarray]:
        """Cells containing reference ``points`` (n, 3) and the basis there.

        Collective. Returns (cells, phi): the local index of the owned cell
        containing each point, or -1 where another rank takes it (a point on
        a partition interface goes to the lowest rank that owns a cell
        containing it, so each point is taken exactly once), and phi
        (n, :attr:`nodes_per_cell`) the basis values of the cell's nodes, in
        the order of :meth:`cell_dofs` (zero rows where cells is -1).
        ValueError if a point lies outside the mesh.
        """
        pts = _as_points(points)
        msh = self.mesh
        tdim = msh.topology.dim
        if self._tree is None:
            n_owned = msh.topology.index_map(tdim).size_local
            self._tree = geometry.BoundingBoxTree(msh, tdim, np.arange(n_owned, dtype=np.int32))
        hits = geometry.compute_colliding_cells(msh, geometry.compute_collisions(self._tree, pts),
                                                pts)
        comm = msh.comm
        found = np.diff(hits.offsets) > 0
        owner = np.where(found, comm.rank, comm.size).astype(np.int32)
        comm.Allreduce(MPI.IN_PLACE, owner, op=MPI.MIN)
        outside = np.flatnonzero(owner == comm.size)
        if len(outside):
            raise ValueError(f"point_basis: {len(outside)} point(s) outside the matrix mesh, "
                             f"first {pts[outside[0]]}")
        cells = np.full(len(pts), -1, dtype=np.int32)
        phi = np.zeros((len(pts), self.nodes_per_cell))
        mine = np.flatnonzero(owner == comm.rank)
        if len(mine):
            c = hits.array[hits.offsets[mine]]
            # affine cells: X = K^-1 (x - x_0), K the columns x_i - x_0
            gdofs = msh.geometry.dofmap.array.reshape(-1, 4)[c]
            xv = msh.geometry.x[gdofs]
            K = np.transpose(xv[:, 1:] - xv[:, :1], (0, 2, 1))
            X = np.linalg.solve(K, (pts[mine] - xv[:, 0])[..., None])[..., 0]
            cells[mine] = c
            phi[mine] = self.V.element.basix_element.tabulate(0, X)[0, :, :, 0]
        return cells, phi

    def node_coordinates(self) -> np.ndarray:
        """(local nodes, 3) reference coordinates of the field's nodes (block
        dofs, owned then ghosts)."""
        return self.V.tabulate_dof_coordinates()

    def node_keys(self) -> np.ndarray:
        """(local nodes, 2) int64: each node of the field (owned then ghost)
        named independently of the partition, from the mesh's input vertex
        indices (the vertices' order in the mesh as read or generated,
        ``geometry.input_global_indices``): a vertex node (v, v), an edge
        node of P2 (a, b) with a < b its edge's vertices."""
        msh = self.mesh
        inputs = np.asarray(msh.geometry.input_global_indices, dtype=np.int64)
        # affine cells: the geometry's cell nodes are the cell's vertices, in
        # the reference order the field's dof layout refers to
        vertices = inputs[msh.geometry.dofmap.array.reshape(-1, 4)]
        cell_nodes = self.V.dofmap.list.array.reshape(-1, self.nodes_per_cell)
        layout = self.V.dofmap.dof_layout
        topology = basix.topology(basix.CellType.tetrahedron)
        imap = self.V.dofmap.index_map
        keys = np.full((imap.size_local + imap.num_ghosts, 2), -1, dtype=np.int64)
        for dim, entities in enumerate(topology):
            for e, verts in enumerate(entities):
                dofs = layout.entity_dofs(dim, e)
                if (len(dofs) and dim > 1) or len(dofs) > 1:
                    raise NotImplementedError("ElasticBlock.node_keys: nodes on faces, cells or "
                                              "several on an edge (degree > 2)")
                if len(dofs):
                    v = np.sort(vertices[:, verts], axis=1)
                    keys[cell_nodes[:, dofs[0]]] = v[:, [0, -1]]
        if np.any(keys < 0):
            raise RuntimeError("ElasticBlock.node_keys: a node of the field lies in no local cell")
        return keys

    def cell_dofs(self, cells) -> np.ndarray:
        """(n, :attr:`nodes_per_cell`) local block dofs (node indices of the
        field) of local cells."""
        cells = np.asarray(cells, dtype=np.int32).ravel()
        return self.V.dofmap.list.array.reshape(-1, self.nodes_per_cell)[cells]

    def side_nodes(self, side) -> tuple[np.ndarray, np.ndarray]:
        """The block's nodes on a boundary part, for a side rigid body.

        ``side``: a side name of the mesh (``"xmax"``), a list of them, or a
        marker ``x -> bool array`` on reference coordinates selecting
        boundary facets. Returns (nodes, X): this rank's local node indices
        (block dofs, sorted; owned ones are below :attr:`num_owned_nodes`,
        ghosts above, so sum over owned nodes for totals) on those facets,
        P2 edge nodes included, and their reference coordinates (n, 3).
        Unrolled dof of component c (0, 1, 2 = x, y, z) of node n:
        3 n + c, in the field's local arrays (``State.u[block.name]``).
        """
        nodes = self._boundary_nodes(side, "side_nodes")
        return nodes, self.node_coordinates()[nodes]

    # -- output -----------------------------------------------------------------
    def _output_functions(self) -> list:
        """The fields written for ParaView: the displacement (the block's own
        space) and, per cell (DG0, at the cell centre), det F ("J") and the
        von Mises equivalent of the Cauchy stress ("von_mises", force per
        length squared). Compiled once, on the first write."""
        if self._outputs is None:
            F = self._deformation_gradient()
            J = ufl.det(F)
            sigma = ufl.diff(self._energy_density(F), F) * F.T / J
            s = sigma - ufl.tr(sigma) / 3 * ufl.Identity(3)
            centre = np.full((1, 3), 0.25)
            W = fem.FunctionSpace(self.mesh, ("DG", 0))
            self._outputs = []
            for label, e in (("J", J), ("von_mises", ufl.sqrt(1.5 * ufl.inner(s, s)))):
                self._outputs.append((fem.Function(W, name=label), fem.Expression(e, centre)))
        for f, e in self._outputs:
            f.interpolate(e)
        return [self.u] + [f for f, _ in self._outputs]

    def _vertex_nodes(self) -> tuple[np.ndarray, np.ndarray]:
        """(geometry nodes, field nodes) of the mesh vertices: a Lagrange
        cell's first four nodes are its vertices, in the order of the
        (affine) geometry's dofmap."""
        gdofs = self.mesh.geometry.dofmap.array.reshape(-1, 4)
        vdofs = self.V.dofmap.list.array.reshape(-1, self.nodes_per_cell)[:, :4]
        return gdofs.ravel(), vdofs.ravel()

    @property
    def vtk_name(self) -> str:
        """The block's ParaView part (Effect.vtk_name): its name."""
        return self.name

    def write_vtk(self, directory: str, stem: str, time: float) -> str:
        """Write the block at the model's current state with dolfinx's
        VTKFile (collective): ``<directory>/<stem>000000.pvtu`` and one
        ``.vtu`` piece per rank (and VTKFile's one-entry ``<stem>.pvd``).
        Points are at their current positions (vertices at X + u; a P2
        field's edge nodes on the straight edges between them), with the
        point field ``displacement`` and the cell fields ``J`` and
        ``von_mises``. Returns the .pvtu path."""
        from dolfinx.io import VTKFile

        if self._model is None:
            raise RuntimeError("ElasticBlock.write_vtk: the model is not set up yet")
        self.u.x.array[:] = self._model.state().u[self.name]
        functions = self._output_functions()
        x = self.mesh.geometry.x
        reference = x.copy()
        g, v = self._vertex_nodes()
        x[g] += self.u.x.array.reshape(-1, 3)[v]
        try:
            # a file per step, closed at once: VTKFile writes its .pvd only
            # on close, and a run that fails must keep every written step
            with VTKFile(self.mesh.comm, os.path.join(directory, stem + ".pvd"), "w") as f:
                f.write_function(functions, time)
        finally:
            x[:] = reference
        pvtu = os.path.join(directory, stem + "000000.pvtu")
        if self.mesh.comm.rank == 0:
            _unique_pieces(pvtu)
        return pvtu
