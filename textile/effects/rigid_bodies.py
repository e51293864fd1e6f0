"""Rigid bodies in the monolithic system: their unknowns, couplings and loads.

Fields:

- ``rigid``: 6 unknowns per body, [u, theta]: the displacement of the
  reference centre and an *incremental* rotation vector, R = exp([theta]) R_n
  with R_n the rotation accumulated over the accepted steps. At each
  accepted step theta is folded into R_n and reset to zero, so the unknowns
  stay small and smooth whatever the total rotation (a turn of 2 pi brings
  R back to the identity to round-off). All bodies are owned by rank 0 and
  ghosted on the others.
- ``rigid_multipliers``: Lagrange multipliers of the couplings, 9 per held
  section (x0, g1, g2), 3 per pin, owned by the rank owning the fibre node.

The couplings are exact (:mod:`cpp/textile/rigid/rigid_coupling.h`): a held
end section keeps its reference shape (no Poisson contraction at the body,
which stiffens about one radius of fibre next to it). The system becomes a
saddle point with one negative eigenvalue per multiplier: the stability
check discounts them (``saddle_point_rows``). Each multiplier row is scaled
by s = E A / h (the end element's axial stiffness; times R^2 for the
section-vector rows) so that the saddle-point system stays balanced.
"""
from __future__ import annotations

import numpy as np
from dolfinx import cpp as _dcpp
from mpi4py import MPI

from .. import _cpp
from ..layout import Field
from ..rigid_body import BODY_DOFS, RigidBody
from .base import Effect, State


class RigidBodies(Effect):
    """All rigid bodies of a model (add them with ``Model.add_rigid_body``)."""

    fields = ("beam", "rigid", "rigid_multipliers")

    def __init__(self):
        self.bodies: list[RigidBody] = []

    def add(self, body: RigidBody) -> None:
        if not isinstance(body, RigidBody):
            raise TypeError(f"expected a textile.RigidBody, got {type(body).__name__}")
        if any(b.name == body.name for b in self.bodies):
            raise ValueError(f"a rigid body named {body.name!r} is already in the model")
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
        if comm.rank == 0:
            bodies = _dcpp.common.IndexMap(comm, n, np.zeros(0, dtype=np.int64),
                                           np.zeros(0, dtype=np.int32))
        else:
            bodies = _dcpp.common.IndexMap(comm, 0, np.arange(n, dtype=np.int64),
                                           np.zeros(n, dtype=np.int32))
        # couplings held on this rank: those of its owned fibre nodes
        self._held = []  # (body, global node, section?)
        lo, hi = mesh.owned
        for b, body in enumerate(self.bodies):
            for kind, pairs in ((True, body.sections), (False, body.pins)):
                for f, node in pairs:
                    g = mesh.node(f, node)
                    if lo <= g < hi:
                        self._held.append((b, g, kind))
        blocks = sum(3 if s else 1 for _, _, s in self._held)
        multipliers = _dcpp.common.IndexMap(comm, blocks, np.zeros(0, dtype=np.int64),
                                            np.zeros(0, dtype=np.int32))
        return [Field("rigid", bodies, 6), Field("rigid_multipliers", multipliers, 3)]

    def setup(self, model) -> None:
        mesh, comm = model.mesh, model.comm
        self.model = model
        n = len(self.bodies)
        # reference centres (every rank: the geometry is replicated)
        self.centres = np.zeros((n, 3))
        for b, body in enumerate(self.bodies):
            nodes = [mesh.node(f, k) for f, k in body.sections + body.pins]
            self.centres[b] = body.centre if body.centre is not None \
                else mesh.X_global[nodes, 0:3].mean(axis=0)
        self.rotation = np.tile(np.eye(3), (n, 1, 1))   # R_n, accumulated
        self.turned = np.zeros((n, 3))                  # accumulated rotation increments
        X = mesh.X_global
        held = self._held
        self._node_local = mesh.global_to_local([g for _, g, _ in held]).astype(np.int32)
        self._body = np.array([b for b, _, _ in held], dtype=np.int32)
        self._section = np.array([s for _, _, s in held], dtype=bool)
        rows = np.where(self._section, 9, 3)
        self._multiplier = np.concatenate([[0], np.cumsum(rows)[:-1]]).astype(np.int32) \
            if len(rows) else np.zeros(0, dtype=np.int32)
        self._ref_offset = X[[g for _, g, _ in held], 0:3] - self.centres[self._body] \
            if held else np.zeros((0, 3))
        self._ref_g1 = X[[g for _, g, _ in held], 3:6] if held else np.zeros((0, 3))
        self._ref_g2 = X[[g for _, g, _ in held], 6:9] if held else np.zeros((0, 3))
        # row scales: the end element's axial stiffness E A / h
        scale = np.zeros(len(held))
        for i, (_, g, _) in enumerate(held):
            f = int(np.searchsorted(mesh.first_node, g, side="right") - 1)
            fib = mesh.fibres[f]
            h = fib.length / ((fib.num_nodes - 1) // mesh.order)
            scale[i] = fib.material.young * np.pi * fib.radius ** 2 / h
        radius = np.array([mesh.fibres[int(np.searchsorted(mesh.first_node, g, side="right") - 1)]
                           .radius for _, g, _ in held])
        self._scale_position = scale
        self._scale_section = scale * radius ** 2 if held else scale
        self.set = _cpp.RigidBodySet()
        self.set.set_centres(self.centres)
        self._set_couplings()
        self._X = np.ascontiguousarray(mesh.X_local.ravel())
        self._saddle = comm.allreduce(int(rows.sum()) if len(rows) else 0)

    def _set_couplings(self) -> None:
        R = self.rotation[self._body] if len(self._body) else np.zeros((0, 3, 3))
        turn = lambda v: np.ascontiguousarray(np.einsum("nij,nj->ni", R, v))  # noqa: E731
        self.set.set_couplings(self._body, self._node_local, self._multiplier, self._section,
                               turn(self._ref_offset), turn(self._ref_g1), turn(self._ref_g2),
                               self._scale_position, self._scale_section)

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

    def residual(self, state: State, b) -> None:
        self._set_loads(state.load_factor)
        self.set.assemble_vector(self._X, state.u["beam"], state.u["rigid"],
                                 state.u["rigid_multipliers"], b["beam"], b["rigid"],
                                 b["rigid_multipliers"])

    def external(self, state: State, b) -> None:
        loads = self._loads(state.load_factor)
        if len(loads):
            b["rigid"][:6 * len(loads)] += loads.ravel()

    def add_sparsity(self, sparsity) -> None:
        for i, (node, body, section) in enumerate(zip(self._node_local, self._body,
                                                      self._section)):
            mult = np.arange(3 if section else 1, dtype=np.int32) + self._multiplier[i] // 3
            blocks = {"beam": np.array([node], dtype=np.int32),
                      "rigid": np.array([body], dtype=np.int32), "rigid_multipliers": mult}
            for r, rows in blocks.items():
                for c, cols in blocks.items():
                    sparsity.insert(r, c, rows, cols)
        if self.model.comm.rank == 0:
            for k in range(len(self.bodies)):
                sparsity.insert("rigid", "rigid", np.array([k], dtype=np.int32),
                                np.array([k], dtype=np.int32))

    def jacobian(self, state: State, A) -> None:
        self._set_loads(state.load_factor)
        self.set.assemble_matrix(A, self._X, state.u["beam"], state.u["rigid"],
                                 state.u["rigid_multipliers"], state.dofs["beam"],
                                 state.dofs["rigid"], state.dofs["rigid_multipliers"])

    # -- load steps ------------------------------------------------------------
    def commit(self, model) -> None:
        """Fold each body's incremental rotation into R_n and reset it."""
        st = model.state()
        u = st.u["rigid"].reshape(-1, 6)
        for b in range(len(self.bodies)):
            theta = u[b, 3:6]
            self.rotation[b] = _cpp.rotation_matrix(np.ascontiguousarray(theta)) @ self.rotation[b]
            self.turned[b] += theta
        self._set_couplings()
        arrays = [a.copy() for a in model.layout.get_local(model.x)]
        arrays[model.layout.index("rigid")].reshape(-1, 6)[:, 3:6] = 0.0
        model.layout.scatter(model.x, arrays)
        self._statistics(model)

    # -- saved states (textile.io.state_file) ----------------------------------
    state_name = "rigid bodies"

    def save_state(self, model) -> dict:
        """Bodies' unknowns and accumulated rotations, multipliers by
        coupling (body, fibre node): independent of the MPI partition.
        Collective; the result is complete on rank 0."""
        st = model.state()
        lam = st.u["rigid_multipliers"]
        held = [(int(b), int(model.mesh.local_to_global[n]), int(s))
                for b, n, s in zip(self._body, self._node_local, self._section)]
        values = [np.pad(lam[m:m + (9 if s else 3)], (0, 0 if s else 6))
                  for m, s in zip(self._multiplier, self._section)]
        keys = sum(model.comm.gather(held, root=0) or [], [])
        vals = sum(model.comm.gather(values, root=0) or [], [])
        return dict(unknowns=st.u["rigid"].reshape(-1, 6)[:len(self.bodies)],
                    rotation=self.rotation, turned=self.turned,
                    coupling_keys=np.array(keys, dtype=np.int64).reshape(-1, 3),
                    multipliers=np.array(vals).reshape(-1, 9))

    def load_state(self, model, data: dict) -> None:
        if not data:
            raise ValueError("the state file holds no rigid bodies, the model has some")
        if data["unknowns"].shape != (len(self.bodies), 6):
            raise ValueError(f"the state file holds {len(data['unknowns'])} rigid bodies, the "
                             f"model has {len(self.bodies)}")
        self.rotation = np.array(data["rotation"])
        self.turned = np.array(data["turned"])
        self._set_couplings()
        saved = {tuple(k): v for k, v in zip(data["coupling_keys"].tolist(), data["multipliers"])}
        arrays = [a.copy() for a in model.layout.get_local(model.x)]
        arrays[model.layout.index("rigid")][:] = data["unknowns"].ravel()
        lam = arrays[model.layout.index("rigid_multipliers")]
        for b, n, s, m in zip(self._body, self._node_local, self._section, self._multiplier):
            key = (int(b), int(model.mesh.local_to_global[n]), int(s))
            if key not in saved:
                raise ValueError(f"the state file has no coupling of body {b} to node {key[1]}")
            lam[m:m + (9 if s else 3)] = saved[key][:9 if s else 3]
        model.layout.scatter(model.x, arrays)

    # -- results ---------------------------------------------------------------
    def reactions(self, model=None) -> np.ndarray:
        """(bodies, 6): force and moment (about the current centre) each body
        exerts on what it holds, at the model's current state (collective)."""
        model = model or self.model
        st = model.state()
        r = self.set.reactions(self._X, st.u["beam"], st.u["rigid"], st.u["rigid_multipliers"])
        return model.comm.allreduce(r, op=MPI.SUM)

    def positions(self, model=None) -> np.ndarray:
        """(bodies, 3) current centres."""
        model = model or self.model
        u = model.state().u["rigid"].reshape(-1, 6)
        return self.centres + u[:, 0:3]

    def _statistics(self, model) -> None:
        r = self.reactions(model)
        c = self.positions(model)
        self.stats = {}
        for b, body in enumerate(self.bodies):
            self.stats[f"body {body.name} force"] = r[b, 0:3].tolist()
            self.stats[f"body {body.name} moment"] = r[b, 3:6].tolist()
            self.stats[f"body {body.name} centre"] = c[b].tolist()
            self.stats[f"body {body.name} rotation"] = self.turned[b].tolist()

    def statistics(self) -> dict:
        return dict(getattr(self, "stats", {}))


__all__ = ["RigidBodies", "BODY_DOFS"]
