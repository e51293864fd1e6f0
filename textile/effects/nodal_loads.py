"""Dead nodal forces and end moments on fibre nodes (scaled by the load factor)."""
from __future__ import annotations

import numpy as np

from .. import _cpp
from .base import Effect, State


class NodalForces(Effect):
    """Dead (constant-direction) generalized forces on node unknowns.

    ``add(node, dof, value)`` adds ``value`` (N for x0 components; N times
    length-unit for section vectors) on unknown ``dof`` of global ``node``;
    the applied force is load_factor * value.
    """

    fields = ("beam",)
    symmetric_tangent = True  # dead loads: no tangent at all

    def __init__(self):
        self._items: list[tuple[int, int, float]] = []

    def add(self, node: int, dof: int, value: float) -> None:
        self._items.append((node, dof, float(value)))

    def setup(self, model) -> None:
        mesh = model.mesh
        nodes = np.array([n for n, _, _ in self._items], dtype=np.int64)
        local = mesh.global_to_local(nodes)
        # owned nodes only: each force is added once over all ranks
        own = (local >= 0) & (local < mesh.num_owned)
        self._idx = np.array([9 * l + d for l, (_, d, _) in zip(local, self._items)],
                             dtype=np.int64)[own]
        self._val = np.array([v for _, _, v in self._items])[own]

    def residual(self, state: State, b) -> None:
        np.add.at(b["beam"], self._idx, -state.load_factor * self._val)

    def external(self, state: State, b) -> None:
        np.add.at(b["beam"], self._idx, state.load_factor * self._val)


class EndMoments(Effect):
    """Moments applied to node sections through their section vectors.

    See ``cpp/textile/loads/end_moment.h``: generalized forces
    f_a = M* x g_a on g1, g2 with M* = M - (M.n) n / 2; the applied moment is
    load_factor * M (fixed direction in space). The tangent is not symmetric.
    """

    fields = ("beam",)

    def __init__(self):
        self._items: list[tuple[int, np.ndarray]] = []

    def add(self, node: int, moment) -> None:
        self._items.append((node, np.asarray(moment, dtype=float)))

    def setup(self, model) -> None:
        mesh = model.mesh
        local = mesh.global_to_local([n for n, _ in self._items])
        self._local = [(int(l), m) for l, (_, m) in zip(local, self._items)
                       if 0 <= l < mesh.num_owned]
        self._X = mesh.X_local

    def _g(self, state: State, l: int) -> np.ndarray:
        return self._X[l, 3:9] + state.u["beam"][9 * l + 3:9 * l + 9]

    def residual(self, state: State, b) -> None:
        for l, M in self._local:
            f, _ = _cpp.end_moment(state.load_factor * M, self._g(state, l))
            b["beam"][9 * l + 3:9 * l + 9] -= f

    def external(self, state: State, b) -> None:
        for l, M in self._local:
            f, _ = _cpp.end_moment(state.load_factor * M, self._g(state, l))
            b["beam"][9 * l + 3:9 * l + 9] += f

    def jacobian(self, state: State, A) -> None:
        for l, M in self._local:
            _, J = _cpp.end_moment(state.load_factor * M, self._g(state, l))
            idx = state.dofs["beam"][9 * l + 3:9 * l + 9]
            _cpp.add_block(A, idx, idx, np.ascontiguousarray(-J))
