"""Rigid bodies in the monolithic system: their unknowns, couplings and loads.

Fields:

- ``rigid``: 6 unknowns per body, [u, theta]: the displacement of the
  reference centre and an *incremental* rotation vector, R = exp([theta]) R_n
  with R_n the rotation accumulated over the accepted steps. At each
  accepted step theta is folded into R_n and reset to zero, so the unknowns
  stay small and smooth whatever the total rotation (a turn of 2 pi brings
  R back to the identity to round-off). All bodies are owned by rank 0 and
  ghosted on the others. Member bodies (nesting, :mod:`textile.scene.rigid_body`)
  have no unknowns: their parent holds what they hold.
- ``rigid_multipliers``: Lagrange multipliers of the couplings, one per
  constraint row (block size 1): 9 per held section (x0, g1, g2), 3 per pin
  or held block node, and for a sliding body (frictionless plate) 4 per
  section and 1 per pin or block node. Each coupling's multipliers are
  owned by the rank owning its node: fibre nodes by the fibre mesh's
  owner, block nodes by the owner in the block's index map (a ghost node is
  never coupled twice).

The couplings are exact (``cpp/textile/rigid/rigid_coupling.h``, and
``sliding_coupling.h`` for sliding bodies) and are assembled in one C++
call for all of them. A fully held end section keeps its reference shape (no
Poisson contraction at the body, which stiffens about one radius of fibre
next to it). The system becomes a saddle point with one negative eigenvalue
per multiplier: the stability check discounts them (``saddle_point_rows``).
Each multiplier row is scaled by s = E A / h (the end element's axial
stiffness; times R^2 for the section-vector rows), or E_m h for a block
node (h the block's mean node spacing), so that the saddle-point system
stays balanced.

Held block nodes are not constrained dofs: they remain unknowns of the
block, and the multipliers carry the body's force into them. A block node
(or fibre unknown) that is both held by a body and prescribed elsewhere (an
ElasticBlock clamp, ``Model.fix``) would be constrained twice: that is an
error, found from the one constrained set every effect sees (state.dofs).
"""
from __future__ import annotations

import numpy as np
from mpi4py import MPI

from .. import _cpp
from ..scene.block_nodes import select_block_nodes
from ..system.dolfinx_core import load as _load_core
from ..system.layout import Field
from ..scene.rigid_body import BODY_DOFS, RigidBody
from .base import Effect, State

_dcpp = _load_core()   # dolfinx's compiled core alone (textile.system.dolfinx_core)

#: Coupling kinds (the third entry of saved coupling keys).
PIN, SECTION, BLOCK_NODE = 0, 1, 2


class RigidBodies(Effect):
    """All rigid bodies of a model (add them with ``Model.add_rigid_body``)."""

    fields = ("beam", "rigid", "rigid_multipliers")

    def __init__(self):
        self.bodies: list[RigidBody] = []

    def add(self, body: RigidBody) -> None:
        if not isinstance(body, RigidBody):
            raise TypeError(f"expected a textile.RigidBody, got {type(body).__name__}")
        if body.parent is not None:
            raise ValueError(f"RigidBody {body.name!r} is gathered by {body.parent.name!r}: add "
                             f"the gathering body to the model, not its members")
        for m in body.bodies:
            m.check_member()
        names = [b.name for top in self.bodies for b in [top] + top.members()]
        for b in [body] + body.members():
            if b.name in names:
                raise ValueError(f"a rigid body named {b.name!r} is already in the model")
            names.append(b.name)
        self.bodies.append(body)

    @property
    def symmetric_tangent(self) -> bool:
        return not any(b.has_moment for b in self.bodies)

    def schedules(self) -> list:
        """The schedules of the bodies' prescriptions and loads (stages)."""
        return [s for b in self.bodies for s in (b.prescriptions, b.loads)]

    # -- layout --------------------------------------------------------------
    def add_fields(self, model) -> list:
        comm, mesh = model.comm, model.mesh
        n = len(self.bodies)
        for body in self.bodies:
            for m in body.bodies:
                m.check_member()  # members may have been driven after gathering
            self._check_sliding(body)
        if comm.rank == 0:
            bodies = _dcpp.common.IndexMap(comm, n, np.zeros(0, dtype=np.int64),
                                           np.zeros(0, dtype=np.int32))
        else:
            bodies = _dcpp.common.IndexMap(comm, 0, np.arange(n, dtype=np.int64),
                                           np.zeros(n, dtype=np.int32))
        # couplings held on this rank: (body, holder, kind, node) with node
        # the global fibre node (pins, sections) or the local block node
        self._held = []
        self.block = None
        fibre_nodes_all = []
        for b, body in enumerate(self.bodies):
            for holder in [body] + body.members():
                for kind, pairs in ((SECTION, holder.sections), (PIN, holder.pins)):
                    for f, node in pairs:
                        g = mesh.node(f, node)
                        fibre_nodes_all.append((g, body.slide is not None))
                        if mesh.owns(g):
                            self._held.append((b, holder, kind, g))
                for entry in holder.block_nodes:
                    self._use_block(entry.block, model)
                    nodes = select_block_nodes(entry.block, entry.where)
                    owned = nodes[nodes < entry.block.V.dofmap.index_map.size_local]
                    self._held += [(b, holder, BLOCK_NODE, int(k)) for k in owned]
        # a node may be held by several bodies only if they all slide (each
        # holds its own component: a corner of two plates)
        if self._held_twice(fibre_nodes_all):  # the same list on every rank
            raise ValueError("a fibre node is held twice by rigid bodies (two bodies, or a body "
                             "and its member), not all sliding: hold each end once")
        blocks = [(g, self.bodies[b].slide is not None) for b, _, k, g in self._held
                  if k == BLOCK_NODE]
        if comm.allreduce(self._held_twice(blocks), op=MPI.LOR):
            raise ValueError("a block node is held twice by rigid bodies, not all sliding: "
                             "select each node once")
        # each coupling's holder (the body or member that lists it), by index
        self._holders = [h for top in self.bodies for h in [top] + top.members()]
        index = {id(h): i for i, h in enumerate(self._holders)}
        self._holder = np.array([index[id(h)] for _, h, _, _ in self._held], dtype=np.int64)
        self._rows = np.array([self._coupling_rows(self.bodies[b], kind)
                               for b, _, kind, _ in self._held], dtype=np.int32)
        multipliers = _dcpp.common.IndexMap(comm, int(self._rows.sum()),
                                            np.zeros(0, dtype=np.int64),
                                            np.zeros(0, dtype=np.int32))
        return [Field("rigid", bodies, 6), Field("rigid_multipliers", multipliers, 1)]

    @staticmethod
    def _held_twice(nodes) -> bool:
        """True if a node of [(node, sliding)] appears twice, not all sliding."""
        seen = {}
        for g, sliding in nodes:
            seen.setdefault(g, []).append(sliding)
        return any(len(v) > 1 and not all(v) for v in seen.values())

    def _use_block(self, block, model) -> None:
        if block not in model.effects:
            raise ValueError(f"RigidBody holds nodes of the ElasticBlock {block.name!r}, which "
                             f"is not in the model: add it (model.add_effect) first")
        if self.block is not None and self.block is not block:
            raise NotImplementedError("rigid bodies hold nodes of one ElasticBlock per model")
        self.block = block
        if block.name not in self.fields:
            self.fields = self.fields + (block.name,)

    @staticmethod
    def _coupling_rows(body: RigidBody, kind: int) -> int:
        if body.slide is None:
            return 9 if kind == SECTION else 3
        return 4 if kind == SECTION else 1

    @staticmethod
    def _check_sliding(body: RigidBody) -> None:
        """A sliding body's translations in its plane (and its rotation about
        the normal, unless it holds sections) act on nothing: they must be
        prescribed. Checked for axis-aligned normals."""
        n = body.slide
        if n is None:
            return
        axis = np.flatnonzero(np.isclose(np.abs(n), 1.0))
        if not len(axis):
            return
        a = int(axis[0])
        need = [d for d in range(3) if d != a]
        if not body.held("sections"):
            need.append(3 + a)
        missing = [BODY_DOFS[d] for d in need if not body.prescriptions.active[d]]
        if missing:
            raise ValueError(f"RigidBody {body.name!r} slides in the plane normal to "
                             f"{BODY_DOFS[a]}: nothing resists its components {missing}; "
                             f"prescribe them (e.g. body.fix({missing}))")

    def setup(self, model) -> None:
        mesh, comm = model.mesh, model.comm
        self.model = model
        held = self._held
        kind = np.array([k for _, _, k, _ in held], dtype=np.int32)
        self._body = np.array([b for b, _, _, _ in held], dtype=np.int32)
        self._kind = kind
        self._section = kind == SECTION
        self._is_block = kind == BLOCK_NODE
        self._Xb_ref = self.block.node_coordinates() if self.block is not None \
            else np.zeros((0, 3))
        self._Xb = np.ascontiguousarray(self._Xb_ref.ravel())
        fibre = ~self._is_block
        nodes = np.array([g for _, _, _, g in held], dtype=np.int64)
        self._held_nodes = nodes
        self._node_local = np.zeros(len(held), dtype=np.int32)
        self._node_local[fibre] = mesh.global_to_local(nodes[fibre])
        self._node_local[self._is_block] = nodes[self._is_block]
        rows = self._rows
        self._multiplier = np.concatenate([[0], np.cumsum(rows)[:-1]]).astype(np.int32) \
            if len(rows) else np.zeros(0, dtype=np.int32)
        self._scale_position, self._scale_section = self._row_scales(model, nodes)
        self.set = _cpp.RigidBodySet()
        self._grab(model, mesh.X_global)
        self._X = np.ascontiguousarray(mesh.X_local.ravel())
        self._saddle = comm.allreduce(int(rows.sum()))
        self._checked_dofs = None

    def _grab(self, model, configuration: np.ndarray) -> None:
        """The bodies take hold of what they hold as it is in
        ``configuration`` ((global fibre nodes, 9) [x0, g1, g2]; block nodes
        at their reference): their centres (unless given), the offsets and
        section vectors they keep, with zero rotation so far. Collective."""
        mesh, comm = model.mesh, model.comm
        n = len(self.bodies)
        held = self._held
        fibre = ~self._is_block
        X = configuration
        Xb = self._Xb_ref
        nodes = self._held_nodes
        # positions of what is held: [x0, g1, g2] (block nodes: x0 only)
        ref = np.zeros((len(held), 9))
        ref[fibre] = X[nodes[fibre]]
        ref[self._is_block, 0:3] = Xb[nodes[self._is_block]]
        # reference centres: the mean of what each body holds, each fibre
        # node once (geometry replicated: counted on rank 0) and each block
        # node once (by its owner)
        sums, counts = np.zeros((n, 3)), np.zeros(n)
        if comm.rank == 0:
            for b, body in enumerate(self.bodies):
                g = [mesh.node(f, k) for f, k in body.held("sections") + body.held("pins")]
                sums[b] += X[g, 0:3].sum(axis=0) if g else 0.0
                counts[b] += len(g)
        np.add.at(sums, self._body[self._is_block], ref[self._is_block, 0:3])
        np.add.at(counts, self._body[self._is_block], 1.0)
        sums, counts = comm.allreduce(sums, op=MPI.SUM), comm.allreduce(counts, op=MPI.SUM)
        self.centres = np.zeros((n, 3))
        for b, body in enumerate(self.bodies):
            if body.centre is not None:
                self.centres[b] = body.centre
            elif counts[b] == 0:
                raise ValueError(f"RigidBody {body.name!r} holds nothing in this model (its "
                                 f"block-node selection is empty)")
            else:
                self.centres[b] = sums[b] / counts[b]
        self.rotation = np.tile(np.eye(3), (n, 1, 1))   # R_n, accumulated
        self.turned = np.zeros((n, 3))                  # accumulated rotation increments
        self._ref_offset = ref[:, 0:3] - self.centres[self._body] if held else np.zeros((0, 3))
        self._ref_g1, self._ref_g2 = ref[:, 3:6], ref[:, 6:9]
        self._sliding_rows(ref)
        self.set.set_centres(self.centres)
        self._set_couplings()

    def load_fibres(self, model, data: dict) -> None:
        """A new scene starts from saved fibres (:func:`textile.load_fibres`):
        the bodies take hold of the fibres as loaded (deformed, pre-stressed),
        at zero body displacement and rotation and zero multipliers (the
        saved bodies, if any, belong to the old scene). The first Newton
        iteration finds the forces that hold the loaded state."""
        mesh = model.mesh
        u = model.beam_values(model.x)
        self._grab(model, mesh.X_global + u)

        def zero(a):
            a[:] = 0.0

        for name in ("rigid", "rigid_multipliers"):
            model.set_field_values(name, zero)

    def _row_scales(self, model, nodes) -> tuple[np.ndarray, np.ndarray]:
        """Row scales s: fibres E A / h of the end element (x0 rows), times
        R^2 for section-vector rows; block nodes E_m h_b, h_b the block's
        mean node spacing (the stiffness of a P1 node)."""
        mesh = model.mesh
        position, section = np.zeros(len(nodes)), np.zeros(len(nodes))
        for i in np.flatnonzero(~self._is_block):
            fib = mesh.fibres[int(np.searchsorted(mesh.first_node, nodes[i], side="right") - 1)]
            h = fib.length / ((fib.num_nodes - 1) // mesh.order)
            position[i] = fib.material.young * np.pi * fib.radius ** 2 / h
            section[i] = position[i] * fib.radius ** 2
        if self.block is not None:
            comm = model.comm
            Xb = self.block.node_coordinates()
            lo = Xb.min(axis=0) if len(Xb) else np.full(3, np.inf)
            hi = Xb.max(axis=0) if len(Xb) else np.full(3, -np.inf)
            comm.Allreduce(MPI.IN_PLACE, lo, op=MPI.MIN)
            comm.Allreduce(MPI.IN_PLACE, hi, op=MPI.MAX)
            count = self.block.V.dofmap.index_map.size_global
            h_b = (np.prod(np.maximum(hi - lo, 1e-300)) / count) ** (1 / 3)
            position[self._is_block] = section[self._is_block] = self.block.young * h_b
        return position, section

    def _sliding_rows(self, ref) -> None:
        """Rows of the couplings of sliding bodies: (held vector, direction
        in the reference frame). Sections: x0, g1, g2 along the normal, and
        g1 along G2 (the twist about the normal); points: x0 along it."""
        count, vector, direction, body = [], [], [], []
        for i, (b, _, kind, _) in enumerate(self._held):
            nrm = self.bodies[b].slide
            if nrm is None:
                count.append(0)
                continue
            rows = [(0, nrm)]
            if kind == SECTION:
                G2 = ref[i, 6:9]
                rows += [(1, nrm), (2, nrm), (1, G2 / np.linalg.norm(G2))]
            count.append(len(rows))
            vector += [v for v, _ in rows]
            direction += [d for _, d in rows]
            body += [b] * len(rows)
        self._sliding_count = np.array(count, dtype=np.int32)
        self._sliding_start = np.concatenate([[0], np.cumsum(count)]).astype(np.int64)
        self._row_vector = np.array(vector, dtype=np.int32)
        self._row_direction = np.array(direction, dtype=float).reshape(-1, 3)
        self._row_body = np.array(body, dtype=np.int32)

    def _set_couplings(self) -> None:
        R = self.rotation[self._body] if len(self._body) else np.zeros((0, 3, 3))
        turn = lambda v: np.ascontiguousarray(np.einsum("nij,nj->ni", R, v))  # noqa: E731
        Rrow = self.rotation[self._row_body] if len(self._row_body) else np.zeros((0, 3, 3))
        directions = np.ascontiguousarray(np.einsum("nij,nj->ni", Rrow, self._row_direction))
        self.set.set_couplings(self._body, self._node_local, self._multiplier, self._section,
                               self._is_block, turn(self._ref_offset), turn(self._ref_g1),
                               turn(self._ref_g2), self._scale_position, self._scale_section,
                               self._sliding_count, self._row_vector, directions)

    def saddle_point_rows(self) -> int:
        """Negative eigenvalues the multipliers add to the tangent (global)."""
        return self._saddle

    # -- constraints and loads -------------------------------------------------
    def constraints(self, load_factor: float) -> dict:
        dofs, vals = [], []
        for b, body in enumerate(self.bodies):
            values = body.prescriptions.values(load_factor)
            for d in body.prescribed:
                dofs.append(6 * b + d)
                # rotations: the increment still to make about the fixed axis
                vals.append(values[d] - self.turned[b, d - 3] if d >= 3 else values[d])
        return {"rigid": (np.array(dofs, dtype=np.int64), np.array(vals))}

    def _loads(self, s: float) -> np.ndarray:
        """(bodies, 6) current force and moment, on the bodies' owner (rank
        0) only: elsewhere (0, 6), so that each load is added once."""
        if self.model.comm.rank != 0:
            return np.zeros((0, 6))
        return np.array([body.loads.values(s) for body in self.bodies]).reshape(-1, 6)

    def _set_loads(self, s: float) -> None:
        loads = self._loads(s)
        self.set.set_loads(np.ascontiguousarray(loads[:, 0:3]),
                           np.ascontiguousarray(loads[:, 3:6]))

    def _block_u(self, state: State) -> np.ndarray:
        return state.u[self.block.name] if self.block is not None else np.zeros(0)

    def residual(self, state: State, b) -> None:
        self._set_loads(state.load_factor)
        b_block = b[self.block.name] if self.block is not None else np.zeros(0)
        self.set.assemble_vector(self._X, state.u["beam"], state.u["rigid"],
                                 state.u["rigid_multipliers"], self._Xb, self._block_u(state),
                                 b["beam"], b["rigid"], b["rigid_multipliers"], b_block)

    def external(self, state: State, b) -> None:
        loads = self._loads(state.load_factor)
        if len(loads):
            b["rigid"][:6 * len(loads)] += loads.ravel()

    def reference_values(self) -> dict[str, np.ndarray]:
        # a body's couplings place it at centre + u (every rank holds all
        # bodies: owned on rank 0, ghosts elsewhere); rotations start at 0
        reference = np.zeros((len(self.bodies), 6))
        reference[:, 0:3] = self.centres
        return {"rigid": reference.ravel()}

    def add_sparsity(self, sparsity) -> None:
        # per body, its nodes x its unknowns and its multipliers x its
        # unknowns are dense products (one insertion each); node-multiplier
        # pairs are one per coupling
        field = {False: "beam", True: self.block.name if self.block is not None else None}
        one = lambda k: np.array([k], dtype=np.int32)  # noqa: E731
        rows_of = [np.arange(m, m + r, dtype=np.int32)
                   for m, r in zip(self._multiplier, self._rows)]
        for b in range(len(self.bodies)):
            mine = self._body == b
            for is_block in (False, True):
                nodes = self._node_local[mine & (self._is_block == is_block)]
                if len(nodes):
                    sparsity.insert(field[is_block], "rigid", nodes, one(b))
                    sparsity.insert("rigid", field[is_block], one(b), nodes)
            if mine.any():
                mult = np.concatenate([rows_of[i] for i in np.flatnonzero(mine)])
                sparsity.insert("rigid_multipliers", "rigid", mult, one(b))
                sparsity.insert("rigid", "rigid_multipliers", one(b), mult)
        for i, (node, is_block) in enumerate(zip(self._node_local, self._is_block)):
            sparsity.insert(field[bool(is_block)], "rigid_multipliers", one(node), rows_of[i])
            sparsity.insert("rigid_multipliers", field[bool(is_block)], rows_of[i], one(node))
        # an explicit (zero) diagonal on every multiplier row
        sparsity.pattern("rigid_multipliers", "rigid_multipliers").insert_diagonal(
            np.arange(int(self._rows.sum()), dtype=np.int32))
        if self.model.comm.rank == 0:
            for k in range(len(self.bodies)):
                sparsity.insert("rigid", "rigid", one(k), one(k))

    def jacobian(self, state: State, A) -> None:
        self._set_loads(state.load_factor)
        dofs_block = state.dofs[self.block.name] if self.block is not None \
            else np.zeros(0, dtype=np.int32)
        self.set.assemble_matrix(A, self._X, state.u["beam"], state.u["rigid"],
                                 state.u["rigid_multipliers"], self._Xb, self._block_u(state),
                                 state.dofs["beam"], state.dofs["rigid"],
                                 state.dofs["rigid_multipliers"], dofs_block)

    # -- load steps ------------------------------------------------------------
    def prepare(self, model) -> None:
        """Refuse unknowns that a body holds and something else prescribes
        (checked when the constrained set changes: per stage)."""
        if self._checked_dofs == model.constraint_version:
            return
        self._checked_dofs = model.constraint_version
        dofs = model.state().dofs
        bad = []
        for i, (b, holder, kind, _) in enumerate(self._held):
            d = dofs[self.block.name] if kind == BLOCK_NODE else dofs["beam"]
            stride = 3 if kind == BLOCK_NODE else 9
            held = self._held_components(i, kind)
            if np.any(d[stride * self._node_local[i] + held] < 0):
                what = "block node" if kind == BLOCK_NODE else "fibre node"
                bad.append(f"{holder.name!r} ({what})")
        bad = sum(model.comm.allgather(bad[:3]), [])
        if bad:
            raise ValueError(f"rigid bodies hold unknowns that are also prescribed (a clamp or "
                             f"Model.fix): {', '.join(bad[:3])}; a held unknown follows its body "
                             f"only")

    def _held_components(self, i: int, kind: int) -> np.ndarray:
        """Unknowns (0..8) of coupling i that its rows constrain."""
        if self._sliding_count[i] == 0:
            return np.arange(9 if kind == SECTION else 3)
        rows = slice(self._sliding_start[i], self._sliding_start[i + 1])
        out = []
        for v, d in zip(self._row_vector[rows], self._row_direction[rows]):
            out += [3 * v + k for k in range(3) if abs(d[k]) > 1e-12]
        return np.unique(np.array(out, dtype=np.int64))

    def commit(self, model) -> None:
        """Fold each body's incremental rotation into R_n and reset it."""
        st = model.state()
        u = st.u["rigid"].reshape(-1, 6)
        for b in range(len(self.bodies)):
            theta = u[b, 3:6]
            self.rotation[b] = _cpp.rotation_matrix(np.ascontiguousarray(theta)) @ self.rotation[b]
            self.turned[b] += theta
        self._set_couplings()

        def unturn(a):  # the increment is in R_n now
            a.reshape(-1, 6)[:, 3:6] = 0.0

        model.set_field_values("rigid", unturn)
        self._statistics(model)

    # -- saved states (textile.io.state_file) ----------------------------------
    state_name = "rigid bodies"

    def block_keys(self, field: str) -> np.ndarray:
        """"rigid": the body's index (every rank holds every body).
        "rigid_multipliers": per constraint row (body, kind, what it holds:
        the global fibre node and -1, or the block node's key
        (ElasticBlock.node_keys), row of the coupling)."""
        if field == "rigid":
            return np.arange(len(self.bodies), dtype=np.int64)[:, None]
        held = np.zeros((len(self._held), 2), dtype=np.int64)
        fibre = ~self._is_block
        held[fibre, 0] = self._held_nodes[fibre]
        held[fibre, 1] = -1
        if self._is_block.any():
            held[self._is_block] = self.block.node_keys()[self._node_local[self._is_block]]
        coupling = np.repeat(np.arange(len(self._held)), self._rows)
        row = np.arange(int(self._rows.sum())) - np.repeat(self._multiplier, self._rows)
        return np.column_stack([self._body[coupling], self._kind[coupling], held[coupling],
                                row]).astype(np.int64).reshape(-1, 5)

    def save_state(self, model) -> dict:
        """The bodies' names and accumulated rotations (R_n, and the sum of
        the increments); their unknowns and the couplings' multipliers are
        the fields "rigid" and "rigid_multipliers", saved by key."""
        return dict(names=np.array([b.name for b in self.bodies], dtype=np.bytes_),
                    rotation=self.rotation, turned=self.turned)

    def check_state(self, model, data: dict) -> None:
        mine = [b.name for b in self.bodies]
        if not data:
            raise ValueError(f"the state file has no rigid bodies; the model has {mine}")
        saved = [bytes(n).decode() for n in np.atleast_1d(data["names"])]
        if saved != mine:
            raise ValueError(f"the state file's rigid bodies are {saved}, this model's {mine}")

    def load_state(self, model, data: dict) -> None:
        self.rotation = np.array(data["rotation"], dtype=float).reshape(-1, 3, 3)
        self.turned = np.array(data["turned"], dtype=float).reshape(-1, 3)
        self._set_couplings()

    # -- results ---------------------------------------------------------------
    def _reactions(self, model, couplings: np.ndarray | None) -> np.ndarray:
        """(bodies, 6) from the couplings selected by the mask ``couplings``
        (None: all): a coupling's force on what it holds is s lambda, so the
        others' multipliers are set to zero. Collective."""
        model = model or self.model
        st = model.state()
        lam = st.u["rigid_multipliers"]
        if couplings is not None:
            lam = lam * np.repeat(couplings, self._rows)
        r = self.set.reactions(self._X, st.u["beam"], st.u["rigid"], lam, self._Xb,
                               self._block_u(st))
        return model.comm.allreduce(r, op=MPI.SUM)

    def reactions(self, model=None, part: str = "all") -> np.ndarray:
        """(bodies, 6): force and moment (about the current centre) each body
        exerts on what it holds, at the model's current state (collective).
        ``part``: "all", "fibres" (sections and pins) or "block" (the block
        nodes' share)."""
        masks = {"all": None, "fibres": ~self._is_block, "block": self._is_block}
        if part not in masks:
            raise ValueError(f"part must be one of {tuple(masks)}, got {part!r}")
        return self._reactions(model, masks[part])

    def reaction(self, body: RigidBody, model=None) -> np.ndarray:
        """(6,) force and moment that ``body`` (a body of the model or a
        member of one) transmits to what it holds, its own members' included;
        the moment is about the current centre of the body of the model that
        gathers it. Collective."""
        top = body
        while top.parent is not None:
            top = top.parent
        if not any(top is b for b in self.bodies):
            raise ValueError(f"RigidBody {body.name!r} is not in the model")
        group = {id(g) for g in [body] + body.members()}
        mask = np.isin(self._holder, [i for i, h in enumerate(self._holders) if id(h) in group])
        b = next(i for i, t in enumerate(self.bodies) if t is top)
        return self._reactions(model, mask)[b]

    def positions(self, model=None) -> np.ndarray:
        """(bodies, 3) current centres."""
        model = model or self.model
        u = model.state().u["rigid"].reshape(-1, 6)
        return self.centres + u[:, 0:3]

    def _statistics(self, model) -> None:
        r = self.reactions(model)
        rb = self.reactions(model, "block") if self.block is not None else None
        c = self.positions(model)
        self.stats = {}
        for b, body in enumerate(self.bodies):
            self.stats[f"body {body.name} force"] = r[b, 0:3].tolist()
            self.stats[f"body {body.name} moment"] = r[b, 3:6].tolist()
            self.stats[f"body {body.name} centre"] = c[b].tolist()
            self.stats[f"body {body.name} rotation"] = self.turned[b].tolist()
            if rb is not None and body.held("block_nodes"):
                self.stats[f"body {body.name} block force"] = rb[b, 0:3].tolist()
                self.stats[f"body {body.name} block moment"] = rb[b, 3:6].tolist()
            for m in body.members():
                self.stats[f"body {m.name} force"] = self.reaction(m, model)[0:3].tolist()

    def statistics(self) -> dict:
        return dict(getattr(self, "stats", {}))


__all__ = ["RigidBodies", "BODY_DOFS"]
