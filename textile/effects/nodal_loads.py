"""Dead nodal forces and end moments on fibre nodes (values from schedules)."""
from __future__ import annotations

import numpy as np
from mpi4py import MPI

from .. import _cpp
from ..scene.loading import Handle, Schedule
from .base import Effect, State


class NodalForces(Effect):
    """Dead (constant-direction) generalized forces on node unknowns.

    ``add(node, dofs, values)`` adds a force on unknowns ``dofs`` of global
    ``node`` (N for x0 components; N times length-unit for section
    vectors), reached at the end of the first stage (see
    :mod:`textile.scene.loading`).
    """

    fields = ("beam",)
    symmetric_tangent = True  # dead loads: no tangent at all
    external_from_schedules = True

    def __init__(self):
        self.schedule = Schedule("nodal forces")
        self._items: list[tuple[int, int]] = []  # (node, dof) per component

    def add(self, node: int, dofs, values, label: str) -> Handle:
        h = self.schedule.add(values, label)
        self._items += [(node, d) for d in dofs]
        return h

    def schedules(self) -> list:
        return [self.schedule]

    def setup(self, model) -> None:
        mesh = model.mesh
        nodes = np.array([n for n, _ in self._items], dtype=np.int64)
        local = mesh.global_to_local(nodes)
        # owned nodes only: each force is added once over all ranks
        own = (local >= 0) & (local < mesh.num_owned)
        self._idx = np.array([9 * l + d for l, (_, d) in zip(local, self._items)],
                             dtype=np.int64)[own]
        self._own = np.flatnonzero(own)

    def residual(self, state: State, b) -> None:
        np.add.at(b["beam"], self._idx, -self.schedule.values(state.load_factor)[self._own])

    def external(self, state: State, b) -> None:
        np.add.at(b["beam"], self._idx, self.schedule.values(state.load_factor)[self._own])


class EndMoments(Effect):
    """Moments applied to node sections through their section vectors.

    See ``cpp/textile/loads/end_moment.h``: generalized forces
    f_a = M* x g_a on g1, g2 with M* = M - (M.n) n / 2; M (fixed direction
    in space) comes from the schedule. The tangent is not symmetric.
    """

    fields = ("beam",)

    def __init__(self):
        self.schedule = Schedule("end moments")
        self._nodes: list[int] = []

    def add(self, node: int, moment, label: str) -> Handle:
        self._nodes.append(node)
        return self.schedule.add(moment, label)

    def schedules(self) -> list:
        return [self.schedule]

    def setup(self, model) -> None:
        mesh = model.mesh
        local = mesh.global_to_local(self._nodes)
        self._local = [(int(l), k) for k, l in enumerate(local) if 0 <= l < mesh.num_owned]
        self._X = mesh.X_local

    def _g(self, state: State, l: int) -> np.ndarray:
        return self._X[l, 3:9] + state.u["beam"][9 * l + 3:9 * l + 9]

    def _moments(self, state: State):
        M = self.schedule.values(state.load_factor).reshape(-1, 3)
        return [(l, M[k]) for l, k in self._local]

    def residual(self, state: State, b) -> None:
        for l, M in self._moments(state):
            f, _ = _cpp.end_moment(M, self._g(state, l))
            b["beam"][9 * l + 3:9 * l + 9] -= f

    def external(self, state: State, b) -> None:
        for l, M in self._moments(state):
            f, _ = _cpp.end_moment(M, self._g(state, l))
            b["beam"][9 * l + 3:9 * l + 9] += f

    def jacobian(self, state: State, A) -> None:
        for l, M in self._moments(state):
            _, J = _cpp.end_moment(M, self._g(state, l))
            idx = state.dofs["beam"][9 * l + 3:9 * l + 9]
            _cpp.add_block(A, idx, idx, np.ascontiguousarray(-J))


class ReleasedForces(Effect):
    """A dead generalized-force vector on the fibres' unknowns that starts
    at full value and goes to zero over the first stage (unless a stage
    ramps its ``handle`` otherwise): forces that held a loaded state,
    exerted by something the scene no longer has, handed over to the
    scene's own effects step by step instead of all at once.

    What it is for: a sample starts from a woven state with friction
    afresh (every contact sticking, no tangential force:
    ``FibreContact.reset_friction``). The friction forces the reset removes
    held the fibres of a bundle together where the yarns cross; removed at
    once, the bundle rearranges in one Newton solve and an element folds.
    Released over the first stage, they pass to the sticking contacts
    gradually (:class:`~textile.fabric.sample.Sample`).

    Sign: ``forces`` as a residual contribution (internal minus external,
    9 per node in the fibre mesh's global node order, as
    ``ContactSet.nodal_forces`` gives a contact's): the residual with them
    at full value is the residual the removed forces gave.
    """

    fields = ("beam",)
    symmetric_tangent = True  # dead loads: no tangent at all
    external_from_schedules = True
    state_name = "released forces"

    def __init__(self, label: str):
        self.schedule = Schedule(label)
        #: the scale of the forces (1: full value); the first stage ramps it to 0
        self.handle = self.schedule.add([0.0], label)
        self._local = None     # owned rows, ghost rows zero; None: no forces

    def schedules(self) -> list:
        return [self.schedule]

    def setup(self, model) -> None:
        self._model, self._mesh, self._comm = model, model.mesh, model.comm

    def scale(self, load_factor: float | None = None) -> float:
        """The forces' scale (1: full value, 0: released) at ``load_factor``
        of the current stage (default: the model's)."""
        s = self._model.load_factor if load_factor is None else load_factor
        return float(self.schedule.values(s)[self.handle.index[0]])

    def set(self, forces: np.ndarray) -> None:
        """Hold ``forces`` (this rank's share, 9 per global node: the ranks'
        shares add up) at full value from the current stage's start, to be
        released over that stage (collective). All zero: nothing is held."""
        mesh = self._mesh
        f = np.asarray(forces, dtype=float)
        if f.shape != (9 * mesh.num_nodes_global,) or not np.all(np.isfinite(f)):
            raise ValueError(f"ReleasedForces: forces must be {9 * mesh.num_nodes_global} "
                             f"finite values, got shape {f.shape}")
        self._take(self._comm.allreduce(f, op=MPI.SUM))
        full = self._local is not None
        self.schedule.start[self.handle.index] = 1.0 if full else 0.0
        self.schedule.target[self.handle.index] = 0.0

    def _take(self, total: np.ndarray) -> None:
        """Keep the owned rows of the summed forces (each row once over the
        ranks), or nothing if they are all zero."""
        mesh = self._mesh
        if not np.any(total):
            self._local = None
            return
        rows = total.reshape(-1, 9)[mesh.local_to_global[:mesh.num_owned]]
        self._local = np.concatenate([rows.ravel(),
                                      np.zeros(9 * (len(mesh.local_to_global) - mesh.num_owned))])

    def residual(self, state: State, b) -> None:
        if self._local is not None:
            s = self.scale(state.load_factor)
            if s != 0.0:
                b["beam"] += s * self._local

    def external(self, state: State, b) -> None:
        # the held forces count as applied loads (the convergence test's scale)
        if self._local is not None:
            s = self.scale(state.load_factor)
            if s != 0.0:
                b["beam"] -= s * self._local

    # -- saved states: the forces (the scale is the schedule's) ---------------------
    def save_state(self, model) -> dict:
        if self._local is None:
            return {}
        mesh = self._mesh
        total = np.zeros((mesh.num_nodes_global, 9))
        total[mesh.local_to_global[:mesh.num_owned]] = self._local[:9 * mesh.num_owned].reshape(
            -1, 9)
        total = self._comm.reduce(total, op=MPI.SUM, root=0)
        return {"forces": total.ravel()} if self._comm.rank == 0 else {}

    def check_state(self, model, data: dict) -> None:
        n = 9 * model.mesh.num_nodes_global
        if data and np.shape(data["forces"]) != (n,):
            raise ValueError(f"the state file's released forces have {np.size(data['forces'])} "
                             f"values, this model's fibres {n} unknowns")

    def load_state(self, model, data: dict) -> None:
        self._take(np.asarray(data["forces"], dtype=float) if data
                   else np.zeros(9 * model.mesh.num_nodes_global))
