"""The constrained unknowns of an assembled system, one source of truth.

Every constraint is an effect's (:meth:`textile.effects.base.Effect.constraints`:
prescribed fibre displacements, rigid bodies' prescribed components, a
matrix's Dirichlet conditions, ...). The set of constrained unknowns is
fixed within a stage (their values change with the load factor): every
effect sees the same mask (State.dofs, -1 where constrained), and the
system's constrained rows are u - u_prescribed with an identity tangent.
"""
from __future__ import annotations

import numpy as np
from petsc4py import PETSc

from .layout import DofLayout


class ConstraintSet:
    """The constrained unknowns of ``layout`` that ``effects()`` (a callable
    returning the scene's effects) declare, with their prescribed values per
    load factor, in the layout's local (stacked, owned then ghost) and owned
    numberings."""

    def __init__(self, layout: DofLayout, effects):
        self.layout = layout
        self._effects = effects
        self._at = None                 # (load factor, field -> (dofs, values))
        self._owned_cache = None        # (the _at it was made from, (idx, values))
        self._positions_cache = None    # (idx, positions, idx32)
        #: field name -> local unrolled dofs constrained in this stage
        self.dofs: dict[str, np.ndarray] = {}
        #: field name -> local dofs with -1 where constrained (State.dofs)
        self.masked: dict[str, np.ndarray] = {}
        #: counts the changes of the constrained set, the same on every rank
        #: (a rank-local key, such as an array's id, may repeat on one rank
        #: only and split a collective check)
        self.version = 0

    def setup(self, load_factor: float) -> bool:
        """Read the constrained set from the effects at ``load_factor``;
        returns True when it differs from the one before (on this rank)."""
        before = self.dofs
        self.invalidate()
        self.dofs = {name: dofs for name, (dofs, _) in self.at(load_factor).items()}
        self.version += 1
        self.masked = {}
        for f in self.layout.fields:
            d = self.layout.local_dofs(f.name).copy()
            if f.name in self.dofs:
                d[self.dofs[f.name]] = -1
            self.masked[f.name] = d
        return before.keys() != self.dofs.keys() or any(
            len(before[k]) != len(v) or np.any(before[k] != v) for k, v in self.dofs.items())

    def invalidate(self) -> None:
        """Forget the values computed for the current load factor."""
        self._at = None

    @property
    def key(self):
        """An object that stays the same while the prescribed values do
        (compared by identity: Model.residual_record)."""
        return self._at

    def at(self, t: float) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Field -> (local unrolled dofs, prescribed displacement at t)."""
        if self._at is not None and self._at[0] == t:
            return self._at[1]
        out = {"beam": (np.zeros(0, dtype=np.int64), np.zeros(0))}
        for e in self._effects():
            for name, (dofs, v) in e.constraints(t).items():
                if name in out:
                    d0, v0 = out[name]
                    out[name] = (np.concatenate([d0, dofs]), np.concatenate([v0, v]))
                else:
                    out[name] = (np.asarray(dofs, dtype=np.int64), np.asarray(v, dtype=float))
        self._at = (t, out)
        return out

    def apply(self, x: PETSc.Vec, t: float) -> None:
        """Set the prescribed values at t into x (owned and ghosts)."""
        arrays = [a.copy() for a in self.layout.get_local(x)]
        for name, (dofs, vals) in self.at(t).items():
            arrays[self.layout.index(name)][dofs] = vals
        self.layout.scatter(x, arrays)
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)

    def owned(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Stacked local indices (owned only) and values of the constrained
        dofs at t (read-only arrays, kept while the values at t are)."""
        cons = self.at(t)
        cached = self._owned_cache
        if cached is not None and cached[0] is cons:
            return cached[1]
        idx, vals = [], []
        for name, (dofs, v) in cons.items():
            f = self.layout.field(name)
            own = dofs < f.size_local
            idx.append(self.layout.offset(name) + dofs[own])
            vals.append(v[own])
        out = (np.concatenate(idx).astype(np.int64) if idx else np.zeros(0, np.int64),
               np.concatenate(vals) if vals else np.zeros(0))
        for a in out:
            a.setflags(write=False)
        self._owned_cache = (cons, out)
        return out

    def owned_rows(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(positions in the owned part of the global vector, int32 stacked
        local indices, values) of the constrained dofs at t."""
        idx, vals = self.owned(t)
        cached = self._positions_cache
        if cached is None or cached[0] is not idx:
            pos = self.layout.owned_positions(idx)
            pos.setflags(write=False)
            idx32 = idx.astype(np.int32)
            idx32.setflags(write=False)
            cached = self._positions_cache = (idx, pos, idx32)
        return cached[1], cached[2], vals
