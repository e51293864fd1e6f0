"""A numerical drag on the fibres' centre lines: a path through instabilities.

Each fibre node's centre-line point x is held back, within a load step, by
a linear spring to where it was at the last accepted step, x_n:

    r += eta (x - x_n),    eta = coefficient * 12 E I / L^3,

E I the fibre's bending stiffness and L its mean element length (the
stiffness of one element bent as a clamped beam): the springs are of the
order of the fibres' own softest stiffness, so ``coefficient`` 1 doubles
the tangent's bending diagonal. This is implicit-Euler pseudo-time with a
unit step (eta being a viscosity over the step), dynamic relaxation's
friend: where the structure alone has no nearby equilibrium or several (a
fibre resting on two others that spread, rolling off them; a stack
pressed into a column that must buckle sideways), the tangent K + eta I of
each step stays positive far longer, and the state moves through the
instability over a few steps instead of jumping.

The converged answer of a step is NOT the structure's equilibrium: the
drag eta |x - x_n| is a force. So the drag belongs to stages whose path
is artificial anyway (the weaving stage: the interpenetration made up
progressively), followed by a stage without it (``coefficient`` 0 from a
stage's effect options: no residual, no tangent, nothing computed), whose
converged state is an equilibrium of the structure alone. Each step
records the largest drag force relative to the fibres' axial stiffness
E A (``drag_force``): near zero when the state has stopped moving.

With the stage option ``step`` (a load-factor increment h), the drag is a
viscosity instead: eta = coefficient * 12 E I / L^3 * h / (s - s_n), s_n
the load factor of the last accepted step (0 at the stage's start). A step
of the nominal size h drags as ``coefficient`` says; a step the solver cuts
after a failed attempt drags harder, a shorter pseudo-time step. Without it
(the default), a cut step drags as much as the failed one, so where the
state is still moving when the coefficient falls (a fading stage), cutting
cannot slow it down (benchmarks/README.md, "28-fibre bundles: a viscous
fading").

With ``pairs`` (fibres side by side, e.g. neighbours in a yarn's
packing: :meth:`~textile.Fabric.neighbour_fibres`), the drag acts on the
motion of each pair's fibres relative to each other, node by node (node i
of one against node i of the other: the two have as many nodes), and only
``absolute_share`` of it on each node's own motion:

    r_a += eta (d_a - d_b),  r_b -= eta (d_a - d_b),  d = x - x_n,
    r   += absolute_share * eta d   (every node),

the energy eta/2 |d_a - d_b|^2 per pair (a graph Laplacian: a bundle
moving as a whole is not held back by it). Why: the instabilities the drag
is there for are rearrangements within a yarn (a fibre rolling off two
that spread, a stack buckling sideways), while the yarn's own long modes
(straightening under its tension, sliding in at the pulled ends) are
stable and hundreds of times softer than one element's bending. A drag on
the absolute motion holds those back, and once it is taken away the state
must still make that drift, one small step at a time. Measured: fewer
Newton iterations on 3- and 7-fibre bundles, but a bundle's flattening
under a crossing yarn is a relative motion too, and the 28-fibre weave
then stops near the end of its fading where the drag on every node weaves
it; so the lifting weave keeps it as an option (``Weaving(
drag_within_yarns=True)``; benchmarks/README.md, "A drag on the fibres'
motion within their yarn").

Units: those of the model (force, length); ``coefficient``, ``step`` and
``absolute_share`` dimensionless.
"""
from __future__ import annotations

import math
import numbers

import numpy as np

from .. import _cpp
from .base import Effect, State


class ViscousDrag(Effect):
    """Drag of the centre-line points towards the last accepted state.

    ``coefficient`` (>= 0; stage option): eta in units of each fibre's
    12 E I / L^3; 0 switches the drag off. ``pairs`` ((n, 2) fibre
    numbers, optional): drag the relative motion of each pair's fibres,
    node by node, and ``absolute_share`` (in [0, 1]) of the drag on each
    node's own motion (module docstring); without pairs the share is 1."""

    fields = ("beam",)
    symmetric_tangent = True
    constant_tangent = False

    def __init__(self, coefficient: float = 1.0, pairs=None, absolute_share: float = 1.0):
        self.coefficient = _coefficient(coefficient)
        self.step = None        # None: a drag; h > 0: a viscosity (module docstring)
        self._accepted = 0.0    # the load factor of the last accepted step
        self.pairs = _pairs(pairs)
        v = absolute_share
        if isinstance(v, bool) or not isinstance(v, numbers.Real) or not 0 <= v <= 1:
            raise ValueError(f"ViscousDrag: absolute_share is in [0, 1], got {v!r}")
        if not len(self.pairs) and v != 1:
            raise ValueError("ViscousDrag: absolute_share < 1 needs pairs (without them "
                             "nothing else is dragged)")
        self.absolute_share = float(v)
        # the pairs' couplings are outside the beam's node blocks: declared
        # again at every matrix rebuild (the rebuilt pattern is read from
        # tangents, which hold nothing of a drag switched off)
        self.dynamic_sparsity = bool(len(self.pairs))
        self._node_pairs = None   # (n, 2) global nodes of this rank's pairs

    def configure(self, coefficient=None, step=False, **unknown) -> None:
        """Stage options: ``coefficient``, the drag from this stage on (0:
        off), or a callable of the stage's load factor s (e.g. a drag that
        fades to 0 at the stage's end); ``step``, None (a drag, the
        default) or the nominal load-factor step h of a viscous drag (module
        docstring); not given: as before. Each stage starts its steps at
        s = 0."""
        if unknown:
            raise ValueError(f"ViscousDrag.configure: unknown option(s) {sorted(unknown)}; "
                             f"allowed: coefficient, step")
        if coefficient is not None:
            self.coefficient = coefficient if callable(coefficient) \
                else _coefficient(coefficient)
        if step is not False:
            if step is not None and (isinstance(step, bool) or not isinstance(
                    step, numbers.Real) or not 0 < step <= 1):
                raise ValueError(f"ViscousDrag: step is a load-factor increment in (0, 1] "
                                 f"or None, got {step!r}")
            self.step = None if step is None else float(step)
        self._accepted = 0.0

    def configure_resumed(self, **options) -> None:
        """Resumed within a stage: its coefficient and step again (nothing
        of them is saved); the last accepted state and load factor are the
        loaded ones (prepare)."""
        self.configure(**options)

    def _c(self, s: float) -> float:
        c = _coefficient(self.coefficient(s)) if callable(self.coefficient) \
            else self.coefficient
        if self.step is None or c == 0:
            return c
        # a viscosity: the pseudo-time step is this attempt's increment (from
        # 0 where a new stage restarted s; the nominal one at the accepted
        # state itself, where nothing is solved)
        ds = s - self._accepted if s > self._accepted else s
        return c * self.step / ds if ds > 1e-12 else c

    def fibre_ghosts(self, mesh) -> np.ndarray:
        # a pair is assembled by the rank owning its first node
        self._node_pairs = self._pairs_of_nodes(mesh)
        return self._node_pairs[:, 1]

    def _pairs_of_nodes(self, mesh) -> np.ndarray:
        """This rank's (n, 2) global node pairs: node i of one fibre of a
        pair against node i of the other, those whose first node it owns."""
        p = self.pairs
        if not len(p):
            return np.zeros((0, 2), dtype=np.int64)
        nf = len(mesh.fibres)
        if p.max() >= nf:
            raise ValueError(f"ViscousDrag: pairs name fibre {int(p.max())}, the model has {nf}")
        count = np.diff(mesh.first_node)
        bad = np.flatnonzero(count[p[:, 0]] != count[p[:, 1]])
        if len(bad):
            f, g = p[bad[0]]
            raise ValueError(f"ViscousDrag: fibres {f} and {g} of a pair have {count[f]} and "
                             f"{count[g]} nodes; a pair's fibres need as many (node i against "
                             f"node i)")
        n = count[p[:, 0]]
        i = np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)
        nodes = np.column_stack([np.repeat(mesh.first_node[p[:, 0]], n) + i,
                                 np.repeat(mesh.first_node[p[:, 1]], n) + i])
        return nodes[mesh.owns(nodes[:, 0])]

    def setup(self, model) -> None:
        mesh = model.mesh
        self.model = model
        stiffness = np.array([12 * f.material.young * math.pi * f.radius ** 4 / 4
                              / (f.length / ((f.num_nodes - 1) // mesh.order)) ** 3
                              for f in mesh.fibres])
        # eta per local node (its fibre's), position dofs only; the
        # absolute drag acts on the owned ones, pairs may reach ghosts
        nodes = mesh.local_to_global if len(self.pairs) else mesh.local_to_global[: mesh.num_owned]
        node_fibre = np.searchsorted(mesh.first_node, nodes, side="right") - 1
        self._unit = stiffness[node_fibre]                 # 12 E I / L^3 of each node
        self._pos = (9 * np.arange(len(nodes))[:, None] + np.arange(3)).ravel()
        self._owned = mesh.num_owned
        if self._node_pairs is None:
            self._node_pairs = self._pairs_of_nodes(mesh)
        self._pair_local = mesh.global_to_local(self._node_pairs).astype(np.int32)
        assert np.all(self._pair_local >= 0), "pair nodes are local by construction"
        self._pair_unit = self._unit[self._pair_local[:, 0]] if len(self._pair_local) \
            else np.zeros(0)
        self._force_scale = model.force_scale
        self._reference = None
        self.drag_force = 0.0

    def _x(self, state: State) -> np.ndarray:
        return state.u["beam"][self._pos]

    def add_sparsity(self, sparsity) -> None:
        for pair in self._pair_local:
            sparsity.insert("beam", "beam", pair, pair)

    def add_dynamic_pattern(self, model, pattern) -> None:
        if not len(self._node_pairs):
            return
        dofs = model.beam_global_dofs()
        rows = np.ascontiguousarray(dofs[(9 * self._node_pairs[:, :, None]
                                          + np.arange(3)).reshape(-1, 6)], dtype=np.int32)
        for row in rows:
            pattern.add(row, row)

    def prepare(self, model) -> None:
        if self._reference is None:   # a new run, or one resumed from a saved state
            self._reference = self._x(model.state())
            self._accepted = model.load_factor if model.load_factor < 1.0 - 1e-14 else 0.0

    def residual(self, state: State, b) -> None:
        c = self._c(state.load_factor)
        self.drag_force = 0.0
        if c == 0:
            return
        if not len(self.pairs):
            eta = np.repeat(c * self._unit, 3)
            force = eta * (self._x(state) - self._reference)
            b["beam"][self._pos] += force
            self.drag_force = float(np.abs(force).max(initial=0.0))
            return
        d = (self._x(state) - self._reference).reshape(-1, 3)
        force = np.zeros_like(d)
        own = self._owned
        force[:own] = (self.absolute_share * c) * self._unit[:own, None] * d[:own]
        a, g = self._pair_local[:, 0], self._pair_local[:, 1]
        relative = c * self._pair_unit[:, None] * (d[a] - d[g])
        np.add.at(force, a, relative)
        np.add.at(force, g, -relative)
        b["beam"][self._pos] += force.ravel()
        # ghost rows hold part of a sum: the owned ones are the statistic
        self.drag_force = float(np.abs(force[:own]).max(initial=0.0))

    def jacobian(self, state: State, A) -> None:
        c = self._c(state.load_factor)
        if c == 0:
            return
        dofs = state.dofs["beam"][self._pos]
        own = 3 * self._owned
        eta = np.repeat(self.absolute_share * c * self._unit, 3)[:own]
        if self.absolute_share > 0:
            for value in np.unique(eta):
                _cpp.add_diagonal(A, np.ascontiguousarray(dofs[:own][eta == value],
                                                          dtype=np.int32), float(value))
        if not len(self._pair_local):
            return
        node = dofs.reshape(-1, 3)
        a, g = node[self._pair_local[:, 0]].ravel(), node[self._pair_local[:, 1]].ravel()
        w = np.repeat(c * self._pair_unit, 3)
        _cpp.add_entries(A, np.ascontiguousarray(np.concatenate([a, g, a, g]), dtype=np.int32),
                         np.ascontiguousarray(np.concatenate([a, g, g, a]), dtype=np.int32),
                         np.concatenate([w, w, -w, -w]))

    def commit(self, model) -> None:
        self._reference = self._x(model.state())
        self._accepted = model.load_factor

    def statistics(self) -> dict:
        comm = self.model.comm
        largest = comm.allreduce(self.drag_force, op=max)
        return {"drag_force": largest / self._force_scale}


def _pairs(pairs) -> np.ndarray:
    if pairs is None:
        return np.zeros((0, 2), dtype=np.int64)
    try:
        p = np.array(pairs, dtype=float)
    except (TypeError, ValueError) as e:
        raise ValueError(f"ViscousDrag: pairs are (n, 2) fibre numbers, got {pairs!r}") from e
    if p.size == 0:
        return np.zeros((0, 2), dtype=np.int64)
    if p.ndim != 2 or p.shape[1] != 2 or np.any(p != np.round(p)) or np.any(p < 0) \
            or np.any(p[:, 0] == p[:, 1]) or not np.all(np.isfinite(p)):
        raise ValueError(f"ViscousDrag: pairs are (n, 2) numbers of two different fibres, "
                         f"got {pairs!r}")
    return p.astype(np.int64)


def _coefficient(value) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) \
            or not math.isfinite(value) or value < 0:
        raise ValueError(f"ViscousDrag: coefficient must be a finite number >= 0, got {value!r}")
    return float(value)
