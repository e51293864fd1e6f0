"""Prescribed displacements of fibre node unknowns (Model.fix, Model.clamp).

A constraint like every other effect's: it declares, per load factor, which
local unknowns of the ``beam`` field it holds and their values; the model
replaces those rows by u - u_prescribed. It adds no residual or tangent.
"""
from __future__ import annotations

import numpy as np

from ..scene.loading import Handle, Schedule
from .base import Effect


class PrescribedDisplacements(Effect):
    """Displacements of fibre node unknowns, one schedule component per
    (global node, dof); values in the unknown's unit (m for positions, 1
    for section-vector components). A stage's release frees a component
    (its ``active`` flag), so the constrained set is read from the schedule
    at every call."""

    fields = ("beam",)
    symmetric_tangent = True   # no tangent at all

    def __init__(self):
        self.schedule = Schedule("prescribed displacements")
        self._keys: list[tuple[int, int]] = []
        self._index: dict[tuple[int, int], int] = {}
        self._mesh = None
        self._local_map = None   # (active flags, local dofs, components)

    def __len__(self) -> int:
        return len(self._keys)

    def add(self, node: int, dofs, label: str) -> Handle:
        """The handle of the components of global ``node``'s unknowns
        ``dofs`` (indices 0..8), new ones starting at 0; a dof prescribed
        again keeps its component (its value is replaced by the caller)."""
        comps = []
        for d in dofs:
            key = (int(node), int(d))
            if key not in self._index:
                self._index[key] = len(self._keys)
                self._keys.append(key)
                self.schedule.add(0.0, f"node {key[0]} dof {key[1]}")
            comps.append(self._index[key])
        return Handle(self.schedule, np.array(comps), label)

    def schedules(self) -> list:
        return [self.schedule]

    def setup(self, model) -> None:
        self._mesh = model.mesh
        self._local_map = None

    def _local(self) -> tuple[np.ndarray, np.ndarray]:
        """(local unrolled dofs on this rank, owned or ghost; their schedule
        components) of the active components."""
        active = np.asarray(self.schedule.active, dtype=bool)
        if self._local_map is None or not np.array_equal(self._local_map[0], active):
            comps = np.flatnonzero(active)
            nodes = np.array([self._keys[k][0] for k in comps], dtype=np.int64)
            local = (self._mesh.global_to_local(nodes) if comps.size
                     else np.zeros(0, dtype=np.int64))
            have = local >= 0
            dofs = np.array([self._keys[k][1] for k in comps], dtype=np.int64)[have]
            self._local_map = (active.copy(), 9 * local[have].astype(np.int64) + dofs,
                               comps[have].astype(np.int64))
        return self._local_map[1], self._local_map[2]

    def constraints(self, load_factor: float) -> dict:
        dofs, comps = self._local()
        return {"beam": (dofs, self.schedule.values(load_factor)[comps])}
