"""The assembled system of a scene: layout, vectors, matrix, constraints.

A :class:`System` is built once from a scene (:class:`textile.Model`) when
it is set up: the stacked layout of every field (:mod:`.layout`), the
solution and residual vectors, the system matrix and its pattern, the one
constrained set (:mod:`.constraint_set`) and the residual groups of the
convergence test. It evaluates the residual and the tangent the PETSc SNES
asks for by summing the scene's effects, and it is what the solver parts
(:mod:`textile.solver`) and the effects' hooks work on. The scene keeps
what the user built: fibres, prescribed unknowns, loads, effects and their
schedules, and the stages.

Units and signs: the residual is internal minus external generalized
force (docs/method.md §9); on a constrained row it is u - u_prescribed.
"""
from __future__ import annotations

import time

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from .. import _cpp
from ..effects import State
from ..effects.base import Effect
from ..solver.convergence import ResidualGroups
from .constraint_set import ConstraintSet
from .layout import DofLayout, Field, SparsityBuilder
from .node_gather import NodeGather


class System:
    """The monolithic system of a scene's effects on its fibres.

    Parameters
    ----------
    comm:
        The scene's MPI communicator.
    mesh:
        The scene's :class:`~textile.beam.fibre_mesh.FibreMesh`.
    element:
        Its :class:`~textile.BeamElement`.
    effects:
        The scene's effects, in assembly order (the beam first); the scene
        is closed once its system is built, so the list is fixed.
    force_scale:
        The largest fibre axial stiffness E A (N): the scale of the
        internal forces (absolute tolerances, residual groups).
    load_factor:
        Where the scene's schedules stand.
    """

    def __init__(self, comm, mesh, element, effects: list[Effect], force_scale: float,
                 load_factor: float = 0.0):
        self.comm, self.mesh, self.element = comm, mesh, element
        self.effects: list[Effect] = list(effects)
        #: the fibres' elasticity (its energy is recorded at every step)
        self.beam = self.effects[0]
        self.force_scale = force_scale
        self.load_factor = load_factor
        #: Newton variant of the tangents SNES asks for: "standard" (exact
        #: tangent) or "mip" (effects may use the last Newton update, see
        #: State.du); set by the solver
        self.newton = "standard"
        self._linearization_point: PETSc.Vec | None = None
        #: a predicted state's extrapolated stress for the next tangent:
        #: [(weight, difference of states)] (set_predicted_stress)
        self._predicted_stress: list | None = None
        self.last_tangent_update = 0.0
        #: tangents assembled since the solver last ran the effects'
        #: prepare or update (State.tangent_index; see start_newton)
        self._tangents_since_update = 0
        self._beam_global_dofs = None
        self._floor_tangent = None
        self._external_work: PETSc.Vec | None = None   # _applied_forces
        self._applied_kept = None                        # _applied_forces
        self._reaction_values = np.zeros(0)
        for e in self.effects:
            nodes = e.fibre_ghosts(self.mesh)
            if len(nodes):
                self.mesh.add_ghosts(nodes)
        fields = [Field("beam", self.mesh.index_map, 9)]
        #: field name -> the effect that brings it (None: the fibres')
        self._field_owner = {"beam": None}
        for e in self.effects:
            brought = e.add_fields(self)
            self._field_owner.update({f.name: e for f in brought})
            fields += brought
        self.layout = DofLayout(self.comm, fields)
        for e in self.effects:
            e.setup(self)
        sp = SparsityBuilder(self.layout)
        for e in self.effects:
            e.add_sparsity(sp)
        self.A = sp.create_matrix()
        # effects with couplings that change (contact) extend this base
        # pattern when they change: see rebuild_matrix
        self._A_base = self.A
        self._base_pattern = None     # its rows, read at the first rebuild
        self.matrix_stale = False
        self.x = self.layout.create_vector()
        self.b = self.layout.create_vector()
        # global-index contributions skip constrained dofs (index -1)
        self.b.setOption(PETSc.Vec.Option.IGNORE_NEGATIVE_INDICES, True)
        self.constraint_set = ConstraintSet(self.layout, lambda: self.effects)
        self._setup_constraints()
        self._setup_residual_groups()
        # the unknowns as the kernels see them: q = u + X_q (fibre positions,
        # matrix node and rigid body coordinates: the couplings compute X + u)
        reference = {"beam": self.mesh.X_local.ravel()}
        for e in self.effects:
            reference.update(e.reference_values())
        self._X_q = self.layout.create_vector()
        self.layout.scatter(self._X_q, [reference.get(f.name, np.zeros(f.size_ghosted))
                                        for f in self.layout.fields])
        self.residual_norms = None
        self.residual_floors = None
        self._floor_tangent = None
        self.force_reference = None
        self.domain_error: Exception | None = None
        #: (effect class, "residual" | "jacobian") -> seconds of assembly on this rank
        self.effect_seconds: dict[tuple[str, str], float] = {}

    @property
    def saddle_point_rows(self) -> int:
        """Negative eigenvalues the effects' multipliers add to the tangent."""
        return sum(e.saddle_point_rows() for e in self.effects)

    def update_constraints(self) -> bool:
        """The schedules changed (a stage began, a saved state was loaded):
        set the constrained set up again at the current load factor.
        Returns True when it changed (the system matrix is then new)."""
        changed = self._setup_constraints()
        # the new matrix is collective: a release of unknowns that only one
        # rank holds changes every rank's system
        changed = self.comm.allreduce(bool(changed), op=MPI.LOR)
        if changed:
            self._setup_residual_groups()
            self._rebuild_pattern()
        return changed

    def invalidate_constraints(self) -> None:
        """Forget the prescribed values computed for the current load factor
        (they are recomputed at the next use): call it after changing what
        a schedule gives at the same load factor (e.g. a load factor set and
        set back, Solver's load pattern)."""
        if self.constraint_set is not None:
            self.constraint_set.invalidate()

    @property
    def constraint_version(self) -> int:
        """Counts the changes of the constrained set, the same on every
        rank (ConstraintSet.version; 0 before setup)."""
        return 0 if self.constraint_set is None else self.constraint_set.version

    def request_matrix_rebuild(self) -> None:
        """An effect with dynamic_sparsity has couplings the system matrix
        has no room for (called in its prepare or update): the solver builds
        a new matrix before the next Newton solve (rebuild_matrix, which
        asks every such effect's add_dynamic_pattern)."""
        self.matrix_stale = True

    def start_newton(self) -> None:
        """The solver ran the effects' prepare or update: a Newton solve
        follows, whose tangents count from 0 (State.tangent_index)."""
        self._tangents_since_update = 0

    def _rebuild_pattern(self) -> None:
        """A new system matrix from the effects' sparsity (a released
        prescription needs its rows' full pattern back)."""
        sp = SparsityBuilder(self.layout)
        for e in self.effects:
            e.add_sparsity(sp)
        if self.A is not self._A_base:
            self.A.destroy()
        self._A_base.destroy()
        self.A = sp.create_matrix()
        self._A_base = self.A
        self._base_pattern = None
        self.matrix_stale = any(e.dynamic_sparsity for e in self.effects)

    def _setup_constraints(self) -> bool:
        """The constrained set every effect sees (the effects'
        constraints: prescribed displacements, rigid bodies' couplings, ...)
        read again; True when it changed on this rank."""
        self._beam_global_dofs = None
        return self.constraint_set.setup(self.load_factor)

    def _setup_residual_groups(self) -> None:
        """Rows of the owned global vector by group (see textile.solver.convergence):
        the free rows of each group, and which reactions (constrained rows,
        in the order of ``ConstraintSet.owned``) belong to it."""
        constrained = self.owned_positions(self.constraint_set.owned(0.0)[0])
        owned_constrained = np.unique(constrained)
        rows, scale, reactions, start = {}, {}, {}, 0
        rmax = max(f.radius for f in self.mesh.fibres)

        def split(name, free_rows, force_scale, select):
            rows[name], scale[name] = free_rows, force_scale
            reactions[name] = np.flatnonzero(select)

        for f in self.layout.fields:
            pos = np.arange(start, start + f.size_local)
            free = pos[~np.isin(pos, owned_constrained)]
            mine = (constrained >= start) & (constrained < start + f.size_local)
            if f.name == "beam":
                comp, rcomp = (free - start) % 9, (constrained - start) % 9
                split("positions", free[comp < 3], self.force_scale, mine & (rcomp < 3))
                split("sections", free[comp >= 3], self.force_scale * rmax, mine & (rcomp >= 3))
            else:
                split(f.name, free, self.force_scale, mine)
            start += f.size_local
        split("constraints", owned_constrained.astype(np.int64),
              max(f.length for f in self.mesh.fibres), np.zeros(len(constrained), dtype=bool))
        self.residual_groups = ResidualGroups(self.comm, list(rows), rows, scale, reactions)

    def field_owner(self, field: str) -> Effect | None:
        """The effect that brings ``field`` (None for the fibres' "beam")."""
        return self._field_owner[field]

    def reference_values(self) -> dict[str, np.ndarray]:
        """Field name -> the reference values the kernels add to its
        unknowns (owned then ghost, unrolled; zero where an effect gives
        none): fibre node [X0, G1, G2], matrix node coordinates, body
        centres (see Effect.reference_values)."""
        arrays = self.layout.get_local(self._X_q)
        return {f.name: a.copy() for f, a in zip(self.layout.fields, arrays)}

    def reference_norm(self) -> float:
        """Norm of the reference values of every field (reference_values):
        with the unknowns' norm, the size of the unknowns as the kernels
        see them (the scale of a negligible Newton update). Collective."""
        return self._X_q.norm()

    def set_field_values(self, field: str, change) -> None:
        """Change the unknowns of ``field`` in the solution: ``change`` gets
        this rank's local array of the field (owned then ghost, unrolled, a
        copy) and edits it in place; the vector is then set from every
        field's local array, and the ghosts from their owners. Collective.
        The way an effect changes its own field's unknowns (e.g. rigid
        bodies folding the rotation increment into their rotation at
        commit): the same change on every rank."""
        arrays = [a.copy() for a in self.layout.get_local(self.x)]
        change(arrays[self.layout.index(field)])
        self.layout.scatter(self.x, arrays)
        self.x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)

    def block_keys(self, field: str) -> np.ndarray:
        """(local blocks, k) int64 partition-independent names of the
        blocks of ``field`` (owned then ghost): a fibre node's global index,
        or what the effect bringing the field says (Effect.block_keys)."""
        owner = self._field_owner[field]
        if owner is None:
            return self.mesh.local_to_global.astype(np.int64)[:, None]
        return np.asarray(owner.block_keys(field), dtype=np.int64)

    def state(self, x: PETSc.Vec | None = None) -> State:
        """Local view of the unknowns in x (default: the system's solution)."""
        x = self.x if x is None else x
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        arrays = self.layout.get_local(x)
        st = State(self.load_factor, vector=x)
        for f, a in zip(self.layout.fields, arrays):
            st.u[f.name] = a
            st.dofs[f.name] = self.constraint_set.masked[f.name]
        return st

    def apply_constraints(self, x: PETSc.Vec) -> None:
        """Set prescribed values at the current load factor into x."""
        self.constraint_set.apply(x, self.load_factor)

    def rebuild_matrix(self) -> PETSc.Mat:
        """Recreate the system matrix with the base pattern plus the entries
        that effects with dynamic sparsity declare now (collective)."""
        if not self._A_base.isAssembled():
            # the base pattern is read from an assembled matrix: fill it once
            # with the tangent of the effects whose couplings are fixed
            st = self.state()
            self._A_base.zeroEntries()
            for e in self.effects:
                if not e.dynamic_sparsity:
                    e.jacobian(st, self._A_base)
            idx, _ = self.constraint_set.owned(self.load_factor)
            _cpp.add_diagonal(self._A_base, idx.astype(np.int32), 1.0)
            self._A_base.assemble()
        if self._base_pattern is None:
            # read once: every rebuild starts from the base's rows
            self._base_pattern = _cpp.SparsityPattern(self._A_base)
        for e in self.effects:
            if e.dynamic_sparsity:
                e.add_dynamic_pattern(self, self._base_pattern)
        # block size 1, not the base's: with block size 9 the capstan's slip
        # reversal (tests/contact/test_capstan.py) classifies stick and slip
        # at its first iterate by round-off, and two ranks then cycle where
        # one converges; kept until that tie is decided deterministically
        A = self._base_pattern.create_matrix(self._A_base)
        if self.A is not self._A_base:
            self.A.destroy()
        self.A = A
        self.matrix_stale = False
        return A

    def constrained_positions(self) -> np.ndarray:
        """Positions, in this rank's owned part of the global vector, of the
        unknowns constrained at the current load factor."""
        idx, _ = self.constraint_set.owned(self.load_factor)
        return self.owned_positions(idx)

    def residual(self, snes, x: PETSc.Vec, b: PETSc.Vec) -> None:
        """SNES function: r(u) with constrained rows replaced by u - u_prescribed.

        A state outside the scene's domain (an effect raises
        :class:`textile.GeometryError`, e.g. a folded element) is recorded in
        ``domain_error`` and gives an infinite residual: SNES stops and the
        solver cuts the step. Any other exception propagates."""
        st = self.state(x)
        local = {f.name: np.zeros(f.size_ghosted) for f in self.layout.fields}
        error = None
        try:
            for e in self.effects:
                t0 = time.perf_counter()
                e.residual(st, local)
                self._time(e, "residual", t0)
        except _cpp.GeometryError as exc:
            error = exc
        if self._domain_error(error, b):
            return
        applied = self._applied_forces(st)
        self.layout.scatter(b, [local[f.name] for f in self.layout.fields])
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        added = []
        try:
            for e in self.effects:
                t0 = time.perf_counter()
                added.append(e.residual_global(st, b))
                self._time(e, "residual", t0)
        except _cpp.GeometryError as exc:
            error = exc
        if self._domain_error(error, b):
            return
        if self.comm.allreduce(any(added), op=MPI.LOR):
            b.assemble()
        # owned part of the stacked local numbering -> position in the owned array
        pos, _, vals = self.constraint_set.owned_rows(self.load_factor)
        barr = b.getArray()
        xarr = x.getArray(readonly=True)
        self._reaction_values = barr[pos].copy()   # internal - external force at supports
        barr[pos] = xarr[pos] - vals
        if not np.all(np.isfinite(barr)):
            # a non-finite residual makes SNES stop with DIVERGED_FNORM_NAN:
            # the load step is then cut, never accepted
            barr[~np.isfinite(barr)] = np.inf
        self.residual_norms = self.residual_groups.norms(barr)
        # the force scale of each group: applied loads and support reactions
        self.force_reference = np.hypot(applied, self.residual_groups.reaction_norms(
            self._reaction_values))

    def residual_record(self) -> tuple:
        """What the last residual evaluation recorded (group norms, force
        scale, support reactions) with the load factor and constraints it
        was made at: restore_residual_record sets it back (the solver's
        predictor keeps its last evaluation for Newton's first)."""
        return (self.load_factor, self.constraint_set.key, self.residual_norms,
                self.force_reference, self._reaction_values)

    def residual_record_current(self, record: tuple) -> bool:
        """Was record made at the current load factor and constraints?"""
        return record[0] == self.load_factor and record[1] is self.constraint_set.key

    def restore_residual_record(self, record: tuple) -> None:
        self.residual_norms, self.force_reference, self._reaction_values = record[2:]

    def _time(self, effect: Effect, kind: str, t0: float) -> None:
        """Add the seconds since t0 to the effect's assembly time."""
        key = (type(effect).__name__, kind)
        self.effect_seconds[key] = self.effect_seconds.get(key, 0.0) + time.perf_counter() - t0

    def _domain_error(self, error, b: PETSc.Vec) -> bool:
        """Collective: did any rank meet a domain error? Then record it and
        make the residual infinite (every rank takes the same branch)."""
        if not self.comm.allreduce(error is not None, op=MPI.LOR):
            return False
        self.domain_error = error or _cpp.GeometryError("domain error on another rank")
        b.assemble()  # values an effect added before it met the error
        b.set(np.inf)
        self.residual_norms = np.full(len(self.residual_groups.names), np.inf)
        return True

    def _applied_forces(self, st: State) -> np.ndarray:
        """Norm per residual group of the external generalized forces the
        effects apply at this state (collective)."""
        loads = [e for e in self.effects if type(e).external is not Effect.external]
        if not loads:
            return np.zeros(len(self.residual_groups.names))
        key = None
        if all(type(e).external_from_schedules for e in loads):
            # dead loads: the same norms while their schedules' values are
            key = [s.values(st.load_factor) for e in loads for s in e.schedules()]
            kept = self._applied_kept
            if (kept is not None and kept[0] is self.residual_groups and len(kept[1]) == len(key)
                    and all(np.array_equal(a, b) for a, b in zip(kept[1], key))):
                return kept[2]
        ext = {f.name: np.zeros(f.size_ghosted) for f in self.layout.fields}
        for e in loads:
            e.external(st, ext)
        # one work vector for the run (the layout is fixed once set up):
        # the scatter overwrites its owned and ghost entries
        v = self._external_work
        if v is None:
            v = self._external_work = self.layout.create_vector()
        self.layout.scatter(v, [ext[f.name] for f in self.layout.fields])
        v.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        out = self.residual_groups.norms(v.getArray(readonly=True))
        out.setflags(write=False)
        self._applied_kept = None if key is None else (self.residual_groups, key, out)
        return out

    def owned_positions(self, stacked_local: np.ndarray) -> np.ndarray:
        """Map stacked local indices of owned dofs to positions in the owned
        part of the global vector (DofLayout.owned_positions)."""
        return self.layout.owned_positions(stacked_local)

    def set_linearization_point(self, x: PETSc.Vec | None = None) -> None:
        """Remember x (default: the solution) as the last linearization point:
        the next SNES tangent sees du = iterate - x (see State.du). The solver
        calls it with the converged state at the start of every step."""
        x = self.x if x is None else x
        if self._linearization_point is None:
            self._linearization_point = x.duplicate()
        x.copy(self._linearization_point)
        self._drop_predicted_stress()

    def _drop_predicted_stress(self) -> None:
        for _, d in self._predicted_stress or []:
            d.destroy()
        self._predicted_stress = None

    def set_predicted_stress(self, updates: list) -> None:
        """The next MIP tangent, at a predicted state x, takes its stress
        from the strain E(x) - 1/2 sum_k c_k h(d_k)^T h(d_k) instead of the
        linear extrapolation from the last linearization point; ``updates``
        = [(c_k, d_k)], d_k differences of states (PETSc vectors, kept until
        that tangent, copied). The predictor sets it (contact_loop.py): with
        the weights of an extrapolation of converged states, it is their
        strains extrapolated alike, as their stresses are."""
        self._drop_predicted_stress()
        kept = []
        for c, d in updates:
            v = self.x.duplicate()  # ghosted, as the state
            d.copy(v)
            kept.append((float(c), v))
        self._predicted_stress = kept

    def jacobian(self, snes, x: PETSc.Vec, J: PETSc.Mat, P: PETSc.Mat) -> None:
        """SNES Jacobian: sum of the effects' tangents, identity on constrained rows."""
        st = self.state(x)
        st.tangent_index = self._tangents_since_update
        self._tangents_since_update += 1
        if self.newton == "mip":
            if self._linearization_point is None:
                self.set_linearization_point(x)
            ref = self._linearization_point
            if self._predicted_stress is not None:
                weights = np.array([c for c, _ in self._predicted_stress])
                parts = []
                for _, d in self._predicted_stress:
                    d.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
                    parts.append(self.layout.get_local(d))
                for i, f in enumerate(self.layout.fields):
                    st.du[f.name] = np.concatenate([p[i] for p in parts])
                    st.du_weights[f.name] = weights
                size = sum(abs(c) * sum(float(np.dot(a, a)) for a in p)
                           for c, p in zip(weights, parts))
                self._drop_predicted_stress()
            else:
                ref.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
                for f, a in zip(self.layout.fields, self.layout.get_local(ref)):
                    st.du[f.name] = st.u[f.name] - a
                size = sum(float(np.dot(d, d)) for d in st.du.values())
            #: size of the update the last MIP tangent extrapolated over (its
            #: geometric stiffness is exact only when this is small)
            self.last_tangent_update = float(np.sqrt(self.comm.allreduce(size)))
            x.copy(ref)
        self._assemble_tangent(st, P, J)
        self._floor_tangent = P

    def _assemble_tangent(self, st: State, P: PETSc.Mat, J: PETSc.Mat) -> None:
        P.zeroEntries()
        error = None
        # constant tangents first: P is still assembled then (zeroEntries
        # keeps it so, the first insertion ends it), see Effect.constant_tangent
        for e in sorted(self.effects, key=lambda e: not e.constant_tangent):
            # every effect assembles even after another's domain error: some
            # assemblies are collective (contact blocks sent between ranks)
            t0 = time.perf_counter()
            try:
                e.jacobian(st, P)
            except _cpp.GeometryError as exc:
                error = error or exc
            self._time(e, "jacobian", t0)
        if self.comm.allreduce(error is not None, op=MPI.LOR):
            # the residual at this state passed: keep SNES going on an
            # identity, the convergence test stops it (domain_error is set)
            self.domain_error = error or _cpp.GeometryError("domain error on another rank")
        _, idx32, _ = self.constraint_set.owned_rows(self.load_factor)
        _cpp.add_diagonal(P, idx32, 1.0)
        P.assemble()
        if J != P:
            J.assemble()

    def floors(self, x: PETSc.Vec) -> np.ndarray | None:
        """Round-off floor of each residual group at x: | (|K| |q|)_g |, K
        the last assembled tangent, q the unknowns as the kernels see them
        (textile.solver.convergence); None before any tangent. Collective; computed
        only when the convergence test needs it (a pass over the matrix)."""
        K = self._floor_tangent
        if K is None:
            return None
        q = x.copy()
        q.axpy(1.0, self._X_q)
        y = self.b.duplicate()
        _cpp.absolute_product(K, q, y)
        self.residual_floors = self.residual_groups.norms(y.getArray(readonly=True))
        q.destroy()
        y.destroy()
        return self.residual_floors

    def _gather_beam(self, values: np.ndarray) -> np.ndarray:
        """All ranks: (global nodes, 9) from each rank's owned node values."""
        owned = np.ascontiguousarray(values[: 9 * self.mesh.num_owned])
        if self.comm.size == 1:
            return owned.reshape(-1, 9)
        out = np.empty((self.mesh.num_nodes_global, 9))
        out[self.mesh.nodes_by_rank] = np.concatenate(self.comm.allgather(owned)).reshape(-1, 9)
        return out

    def beam_values(self, x: PETSc.Vec) -> np.ndarray:
        """All ranks: (global nodes, 9) values of the beam unknowns in a
        global vector x (each rank's owned part; the beam field comes first
        in it). Collective."""
        return self._gather_beam(x.getArray(readonly=True)[: 9 * self.mesh.num_owned])

    def beam_positions(self, state: State) -> np.ndarray:
        """All ranks: (global nodes, 9) current [x0, g1, g2] from a state."""
        return self.mesh.X_global + self._gather_beam(state.u["beam"])

    def node_gather(self, nodes) -> NodeGather:
        """A :class:`NodeGather` of global fibre ``nodes`` (collective)."""
        return NodeGather(self, nodes)

    def beam_global_dofs(self, state: State | None = None,
                         constrained: bool = False) -> np.ndarray:
        """All ranks: global system index of every beam unknown (9 per
        global node), -1 where constrained (the constrained set is fixed for
        a run; computed once). ``constrained=True``: the constrained ones
        keep their index too: a residual may write their rows, which
        :meth:`residual` records as support reactions and then replaces
        (a tangent must not: its constrained rows are the identity)."""
        if self._beam_global_dofs is None:
            self._beam_global_dofs = self._compute_beam_global_dofs()
        return self._beam_global_dofs[1 if constrained else 0]

    def _compute_beam_global_dofs(self) -> tuple[np.ndarray, np.ndarray]:
        """(masked, all): the global dofs with and without -1 at constrained ones."""
        mesh = self.mesh
        nodes = np.arange(mesh.num_nodes_global)
        dofs = self.layout.global_dofs("beam", mesh.imap_index[nodes],
                                       mesh.node_owner[nodes]).ravel().astype(np.int32)
        # the one constrained set (prescribed dofs and effects' constraints),
        # from every rank's local part
        local = self.constraint_set.dofs.get("beam", np.zeros(0, dtype=np.int64))
        unrolled = 9 * mesh.local_to_global[local // 9] + local % 9
        masked = dofs.copy()
        masked[np.concatenate(self.comm.allgather(unrolled)).astype(np.int64)] = -1
        return masked, dofs

    def nodal_unknowns(self) -> np.ndarray:
        """Current (global nodes, 9) values [x0, g1, g2] (positions, not
        displacements), identical on every rank. Collective."""
        return self.mesh.X_global + self._gather_beam(self.state().u["beam"])

    def reaction_values(self, node: int, dofs) -> np.ndarray:
        """Support reactions on the constrained ``dofs`` (indices 0..8) of
        global fibre node ``node`` from the last residual evaluation
        (internal minus external generalized force), summed over the ranks
        (the owner's values). Collective."""
        out = np.zeros(len(dofs))
        local = self.mesh.global_to_local([node])[0]
        if 0 <= local < self.mesh.num_owned:
            offs, _ = self.constraint_set.owned(self.load_factor)
            for k, d in enumerate(dofs):
                hit = np.flatnonzero(offs == self.layout.offset("beam") + 9 * local + d)
                if len(hit) == 0:
                    raise ValueError(f"dof {d} of global node {node} is not constrained: "
                                     f"no reaction")
                out[k] = self._reaction_values[hit[0]]
        return self.comm.allreduce(out, op=MPI.SUM)
