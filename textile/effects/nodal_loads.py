"""Dead nodal forces and end moments on fibre nodes (values from schedules)."""
from __future__ import annotations

import numpy as np

from .. import _cpp
from ..loading import Handle, Schedule
from .base import Effect, State


class NodalForces(Effect):
    """Dead (constant-direction) generalized forces on node unknowns.

    ``add(node, dofs, values)`` adds a force on unknowns ``dofs`` of global
    ``node`` (N for x0 components; N times length-unit for section
    vectors), reached at the end of the first stage (see
    :mod:`textile.loading`).
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
