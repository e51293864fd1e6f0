"""A hyperelastic solid meshed with tetrahedra (dolfinx), assembled as one field.

The block brings the field ``name`` (default "matrix"): the unknowns of a
vector P1 (linear Lagrange) dolfinx function space, numbered by dolfinx's
own index map (block size 3), so its forms assemble unchanged into the
stacked global system. Unknowns are displacements (length unit); E is in
force per length squared, so residuals are forces (N) consistent with the
fibres. The law is compressible neo-Hookean (finite strain):

    psi(F) = mu/2 (tr C - 3) - mu ln J + lambda/2 (ln J)^2,   C = F^T F,  J = det F,

with the Lame constants of (E, nu); it reduces to linear isotropic
elasticity with (E, nu) at small strain. ``law="svk"`` gives St Venant-
Kirchhoff instead, psi = lambda/2 (tr E)^2 + mu tr(E^2), E = (C - I)/2.

Every dolfinx call of the matrix side is in this module (and in
:mod:`textile.matrix_mesh`), so a port to a newer dolfinx touches only them.
"""
from __future__ import annotations

import numbers

import numpy as np
import ufl
from dolfinx import cpp as _dcpp
from dolfinx import fem, geometry, la
from dolfinx import mesh as _mesh
from mpi4py import MPI

from ..layout import Field
from .base import Effect, State

LAWS = ("neo-hookean", "svk")


def _as_points(points) -> np.ndarray:
    p = np.asarray(points, dtype=float)
    if p.ndim == 1:
        p = p.reshape(1, -1)
    if p.ndim != 2 or p.shape[1] != 3 or not np.all(np.isfinite(p)):
        raise ValueError(f"points must be finite 3D points of shape (n, 3), got shape {p.shape}")
    return np.ascontiguousarray(p)


class ElasticBlock(Effect):
    """A tetrahedral hyperelastic solid, optionally clamped on part of its boundary.

    Parameters
    ----------
    mesh:
        dolfinx tetrahedral mesh in 3D (e.g. :func:`textile.matrix_mesh.box_mesh`),
        on the model's communicator.
    young, poisson:
        Young's modulus E > 0 and Poisson ratio nu in (-1, 0.5).
    clamp:
        Optional marker ``x -> bool array`` (x of shape (3, n), reference
        coordinates) selecting boundary facets whose nodes are fixed (zero
        displacement).
    law:
        "neo-hookean" (default) or "svk".
    name:
        Name of the block's field (distinct names for several blocks).
    """

    symmetric_tangent = True  # hyperelastic: the tangent is a Hessian

    def __init__(self, mesh, young: float, poisson: float, clamp=None, law: str = "neo-hookean",
                 name: str = "matrix"):
        if not isinstance(mesh, _mesh.Mesh):
            raise TypeError(f"mesh must be a dolfinx.mesh.Mesh, got {type(mesh).__name__}")
        if mesh.topology.cell_type != _mesh.CellType.tetrahedron or mesh.geometry.dim != 3:
            raise ValueError(f"ElasticBlock needs a tetrahedral mesh in 3D, got "
                             f"{mesh.topology.cell_type.name} cells in {mesh.geometry.dim}D")
        for label, v in (("young", young), ("poisson", poisson)):
            if isinstance(v, bool) or not isinstance(v, numbers.Real) or not np.isfinite(v):
                raise ValueError(f"ElasticBlock: {label} must be a finite real number, got {v!r}")
        if young <= 0:
            raise ValueError(f"ElasticBlock: young must be positive, got {young}")
        if not -1.0 < poisson < 0.5:
            raise ValueError(f"ElasticBlock: poisson must lie in (-1, 0.5), got {poisson}")
        if law not in LAWS:
            raise ValueError(f"ElasticBlock: law must be one of {LAWS}, got {law!r}")
        if clamp is not None and not callable(clamp):
            raise ValueError("ElasticBlock: clamp must be a callable x -> bool array, or None")
        if not isinstance(name, str) or not name or name == "beam":
            raise ValueError(f"ElasticBlock: name must be a non-empty string other than 'beam', "
                             f"got {name!r}")
        self.mesh, self.young, self.poisson, self.law, self.name = mesh, float(young), \
            float(poisson), law, name
        self.fields = (name,)
        self.V = fem.VectorFunctionSpace(mesh, ("Lagrange", 1))
        self.u = fem.Function(self.V)
        self._R_form, self._J_form = self._forms()
        self._clamp_dofs = self._locate_clamp(clamp)
        self._tree = None
        self._model = None
        self._sub = [self.V.sub(c) for c in range(self.V.dofmap.index_map_bs)]
        self._bcs, self._bcs_key = [], None

    # -- physics --------------------------------------------------------------
    def _forms(self):
        E, nu = self.young, self.poisson
        mu = E / (2.0 * (1.0 + nu))
        lmbda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
        u, v = self.u, ufl.TestFunction(self.V)
        F = ufl.variable(ufl.Identity(3) + ufl.grad(u))
        if self.law == "neo-hookean":
            J = ufl.det(F)
            psi = mu / 2 * (ufl.tr(F.T * F) - 3) - mu * ufl.ln(J) + lmbda / 2 * ufl.ln(J) ** 2
        else:
            Eg = (F.T * F - ufl.Identity(3)) / 2
            psi = lmbda / 2 * ufl.tr(Eg) ** 2 + mu * ufl.inner(Eg, Eg)
        R = ufl.inner(ufl.diff(psi, F), ufl.grad(v)) * ufl.dx
        dR = ufl.derivative(R, u, ufl.TrialFunction(self.V))
        return fem.form(R), fem.form(dR)

    def _locate_clamp(self, clamp) -> np.ndarray:
        """Unrolled local dofs (owned + ghost) of the clamped nodes."""
        if clamp is None:
            return np.zeros(0, dtype=np.int64)
        facets = _mesh.locate_entities_boundary(self.mesh, 2, clamp)
        # remote=True: also the ghosts whose facet lies on another rank
        nodes = fem.locate_dofs_topological(self.V, 2, facets, remote=True)
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
    def reaction(self) -> np.ndarray:
        """Total support force (3,) on the block at its clamped nodes: the sum
        of the block's internal force dPi/du over the clamped dofs, at the
        model's current solution, over all ranks (collective). In
        equilibrium it balances the other forces on the block; forces that
        other effects apply directly on clamped nodes are not included."""
        if self._model is None:
            raise RuntimeError("ElasticBlock.reaction: the model is not set up yet")
        if not self._num_clamped():
            raise ValueError("ElasticBlock.reaction: the block has no clamp")
        u = self._model.state().u[self.name]
        imap, bs = self.V.dofmap.index_map, self.V.dofmap.index_map_bs
        f = la.vector(imap, bs)
        f.array[:] = 0.0
        self._assemble_force(u, f.array)
        f.scatter_reverse(la.ScatterMode.add)
        own = self._clamp_dofs[self._clamp_dofs < imap.size_local * bs]
        out = np.bincount(own % bs, weights=f.array[own], minlength=bs)
        return self.mesh.comm.allreduce(out, op=MPI.SUM)

    def _num_clamped(self) -> int:
        """Number of clamped dofs over all ranks (collective)."""
        n = self.V.dofmap.index_map.size_local * self.V.dofmap.index_map_bs
        return self.mesh.comm.allreduce(int(np.count_nonzero(self._clamp_dofs < n)), op=MPI.SUM)

    # -- junction support --------------------------------------------------------
    def point_basis(self, points) -> tuple[np.ndarray, np.ndarray]:
        """Cells containing reference ``points`` (n, 3) and the P1 basis there.

        Collective. Returns (cells, phi): the local index of the owned cell
        containing each point, or -1 where another rank takes it (a point on
        a partition interface goes to the lowest rank that owns a cell
        containing it, so each point is taken exactly once), and phi (n, 4)
        the basis values of the cell's nodes, in the order of
        :meth:`cell_dofs` (zero rows where cells is -1). ValueError if a
        point lies outside the mesh.
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
        found = np.array([len(hits.links(i)) > 0 for i in range(len(pts))], dtype=bool)
        owner = np.where(found, comm.rank, comm.size).astype(np.int32)
        comm.Allreduce(MPI.IN_PLACE, owner, op=MPI.MIN)
        outside = np.flatnonzero(owner == comm.size)
        if len(outside):
            raise ValueError(f"point_basis: {len(outside)} point(s) outside the matrix mesh, "
                             f"first {pts[outside[0]]}")
        cells = np.full(len(pts), -1, dtype=np.int32)
        phi = np.zeros((len(pts), 4))
        cmap, xg, gdofs = msh.geometry.cmap, msh.geometry.x, msh.geometry.dofmap
        element = self.V.element.basix_element
        for i in np.flatnonzero(owner == comm.rank):
            c = hits.links(i)[0]
            X = cmap.pull_back(pts[i:i + 1], xg[gdofs.links(c)])
            cells[i] = c
            phi[i] = element.tabulate(0, X)[0, 0, :, 0]
        return cells, phi

    def node_coordinates(self) -> np.ndarray:
        """(local nodes, 3) reference coordinates of the field's nodes (block
        dofs, owned then ghosts)."""
        return self.V.tabulate_dof_coordinates()

    def cell_dofs(self, cells) -> np.ndarray:
        """(n, 4) local block dofs (node indices of the field) of local cells."""
        cells = np.asarray(cells, dtype=np.int32).ravel()
        out = np.empty((len(cells), 4), dtype=np.int32)
        for k, c in enumerate(cells):
            out[k] = self.V.dofmap.cell_dofs(int(c))
        return out
