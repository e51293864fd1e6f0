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

Units: those of the model (force, length); ``coefficient`` and ``step``
dimensionless.
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
    12 E I / L^3; 0 switches the drag off."""

    fields = ("beam",)
    symmetric_tangent = True
    constant_tangent = False

    def __init__(self, coefficient: float = 1.0):
        self.coefficient = _coefficient(coefficient)
        self.step = None        # None: a drag; h > 0: a viscosity (module docstring)
        self._accepted = 0.0    # the load factor of the last accepted step

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

    def setup(self, model) -> None:
        mesh = model.mesh
        self.model = model
        # eta per owned node (its fibre's), position dofs only
        owned = mesh.local_to_global[: mesh.num_owned]
        node_fibre = np.searchsorted(mesh.first_node, owned, side="right") - 1
        stiffness = np.array([12 * f.material.young * math.pi * f.radius ** 4 / 4
                              / (f.length / ((f.num_nodes - 1) // mesh.order)) ** 3
                              for f in mesh.fibres])
        self._unit = stiffness[node_fibre]                 # 12 E I / L^3 of each owned node
        self._pos = (9 * np.arange(mesh.num_owned)[:, None] + np.arange(3)).ravel()
        self._force_scale = model.force_scale
        self._reference = None
        self.drag_force = 0.0

    def _x(self, state: State) -> np.ndarray:
        return state.u["beam"][self._pos]

    def prepare(self, model) -> None:
        if self._reference is None:   # a new run, or one resumed from a saved state
            self._reference = self._x(model.state())
            self._accepted = model.load_factor if model.load_factor < 1.0 - 1e-14 else 0.0

    def residual(self, state: State, b) -> None:
        c = self._c(state.load_factor)
        self.drag_force = 0.0
        if c == 0:
            return
        eta = np.repeat(c * self._unit, 3)
        force = eta * (self._x(state) - self._reference)
        b["beam"][self._pos] += force
        self.drag_force = float(np.abs(force).max(initial=0.0))

    def jacobian(self, state: State, A) -> None:
        c = self._c(state.load_factor)
        if c == 0:
            return
        dofs = state.dofs["beam"][self._pos]
        eta = np.repeat(c * self._unit, 3)
        for value in np.unique(eta):
            _cpp.add_diagonal(A, np.ascontiguousarray(dofs[eta == value], dtype=np.int32),
                              float(value))

    def commit(self, model) -> None:
        self._reference = self._x(model.state())
        self._accepted = model.load_factor

    def statistics(self) -> dict:
        comm = self.model.comm
        largest = comm.allreduce(self.drag_force, op=max)
        return {"drag_force": largest / self._force_scale}


def _coefficient(value) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) \
            or not math.isfinite(value) or value < 0:
        raise ValueError(f"ViscousDrag: coefficient must be a finite number >= 0, got {value!r}")
    return float(value)
