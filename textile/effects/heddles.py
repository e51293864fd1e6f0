"""Heddles: soft vertical springs that lift each yarn over, and press it
under, the yarns it crosses (the lifting weave, docs/method.md §6.4).

On a loom, heddles lift the warps that pass over a weft and leave down the
others. Here every node of a fibre near a crossing of its yarn is pushed
vertically towards the height its yarn takes there, by a one-sided spring
(a shelf: it pushes a node that is on the wrong side of it, never pulls):

    r_z += -sigma k w(t) g(p),   p = sigma (lift sigma A - u_z),

g(p) = 0 for p <= 0, p^2 / (2 delta) up to delta = 0.05 A, then
p - delta / 2 (the contact's regularized penalty law, so the push starts
smoothly and Newton does not cycle on it); with

- u_z the node's vertical displacement (so a bundle keeps its shape: each
  fibre is lifted from its own starting height);
- t the node's current coordinate along its yarn's axis (x for a warp, y
  for a weft): the heddles stay where the crossings are while the yarn's
  material slides through them as it crimps;
- w(t) = cos^2(pi (t - c) / (2 h)) within a reach h of the crossing at
  c, 0 elsewhere (h a fraction of the spacing of the crossings along the
  yarn, so the yarn between crossings and near its ends is free);
- sigma = +1 where the yarn passes over the yarn it crosses, -1 under
  (the fabric's weave pattern); A the amplitude, lift in [0, 1] its
  share at the stage's load factor (a stage option); p > 0: the node is
  below the shelf of a yarn passing over (above it, under);
- k = stiffness x 12 E I / L^3, E I the fibre's bending stiffness and L its
  element length: in units of the fibre's own softest stiffness, as
  :class:`~textile.effects.viscous_drag.ViscousDrag`'s.

The force is vertical only, like a frictionless heddle eye's: it does not
derive from a potential (its tangent has the term -sigma k w'(t) g(p) in
the row of u_z and the column of the node's axial coordinate; the tangent
is not symmetric). The heddles belong to the weaving's artificial path:
the stage after them fades ``stiffness`` to 0, and the converged state of
the stage that ends with stiffness 0 is an equilibrium of the fabric alone.

Units: those of the model; ``stiffness`` and ``lift`` dimensionless,
``amplitude`` a length.
"""
from __future__ import annotations

import math
import numbers

import numpy as np

from .. import _cpp
from .base import Effect, State


def _fraction(value, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) \
            or not math.isfinite(value) or value < 0:
        raise ValueError(f"Heddles: {name} must be a finite number >= 0, got {value!r}")
    return float(value)


class Heddles(Effect):
    """Vertical springs at a fabric's crossings (module docstring).

    Parameters
    ----------
    fabric:
        The :class:`~textile.fabric.Fabric` whose fibres the model holds (in
        the order of ``fabric.fibres()``).
    amplitude:
        Height A each yarn is lifted by (or pressed down by) at a crossing,
        from its starting plane; > 0.
    stiffness:
        Spring per node, in units of its fibre's 12 E I / L^3 (stage
        option: a number, or a callable of the stage's load factor s).
    lift:
        Share of the amplitude (stage option: a number in [0, 1] or a
        callable of s).
    reach:
        Half-width h of a heddle along the yarn, as a fraction of the
        spacing of the crossings along it; in (0, 0.5].
    """

    fields = ("beam",)
    symmetric_tangent = False
    constant_tangent = False

    def __init__(self, fabric, amplitude: float, stiffness=30.0, lift=0.0,
                 reach: float = 0.3):
        from ..fabric.fabric import Fabric
        if not isinstance(fabric, Fabric):
            raise TypeError(f"Heddles: fabric must be a textile.fabric.Fabric, got "
                            f"{type(fabric).__name__}")
        if _fraction(amplitude, "amplitude") == 0:
            raise ValueError("Heddles: amplitude must be > 0")
        reach = _fraction(reach, "reach")
        if not 0 < reach <= 0.5:
            raise ValueError(f"Heddles: reach must be in (0, 0.5] (a fraction of the crossings' "
                             f"spacing; beyond 0.5 two heddles overlap), got {reach!r}")
        self.fabric, self.amplitude, self.reach = fabric, float(amplitude), reach
        self.regularization = 0.05 * self.amplitude
        self.stiffness = stiffness
        self.lift = lift
        self.configure(stiffness=stiffness, lift=lift)

    def configure(self, stiffness=None, lift=None, **unknown) -> None:
        """Stage options ``stiffness`` and ``lift`` (numbers or callables of
        the stage's load factor s)."""
        if unknown:
            raise ValueError(f"Heddles.configure: unknown option(s) {sorted(unknown)}; "
                             f"allowed: stiffness, lift")
        if stiffness is not None:
            self.stiffness = stiffness if callable(stiffness) \
                else _fraction(stiffness, "stiffness")
        if lift is not None:
            if not callable(lift) and not 0 <= _fraction(lift, "lift") <= 1:
                raise ValueError(f"Heddles: lift must be in [0, 1], got {lift!r}")
            self.lift = lift if callable(lift) else float(lift)

    def configure_resumed(self, **options) -> None:
        """Resumed within a stage: its stiffness and lift again (nothing of
        them is saved; they hold no history)."""
        self.configure(**options)

    def _value(self, v, s: float, name: str) -> float:
        if not callable(v):
            return v
        value = _fraction(v(s), name)
        if name == "lift" and value > 1:
            raise ValueError(f"Heddles: lift must be in [0, 1], got {value!r}")
        return value

    # -- set-up --------------------------------------------------------------
    def setup(self, model) -> None:
        mesh, fabric = model.mesh, self.fabric
        if len(mesh.fibres) != len(fabric.fibre_yarn):
            raise ValueError(f"Heddles: the fabric has {len(fabric.fibre_yarn)} fibres, the "
                             f"model {len(mesh.fibres)}")
        n = mesh.num_owned
        owned = mesh.local_to_global[:n]
        node_fibre = np.searchsorted(mesh.first_node, owned, side="right") - 1
        unit = np.array([12 * f.material.young * math.pi * f.radius ** 4 / 4
                         / (f.length / ((f.num_nodes - 1) // mesh.order)) ** 3
                         for f in mesh.fibres])
        self._unit = unit[node_fibre]
        yarn = np.asarray(fabric.fibre_yarn)[node_fibre]
        # per node: the axis it runs along, its reference coordinate there,
        # and its yarn's crossings (position, over/under) along that axis
        self._axis = np.where(yarn < fabric.num_warp, 0, 1)
        self._t0 = mesh.X_local[np.arange(n), self._axis]
        self._crossings = []
        for k in range(fabric.num_yarns):
            if k < fabric.num_warp:
                at = [fabric.yarn_axis(fabric.num_warp + i)[0][0] for i in range(fabric.num_weft)]
                over = np.asarray(fabric.order)[:, k]
            else:
                at = [fabric.yarn_axis(j)[0][1] for j in range(fabric.num_warp)]
                over = ~np.asarray(fabric.order, dtype=bool)[k - fabric.num_warp, :]
            spacing = fabric.spacing[1] if k < fabric.num_warp else fabric.spacing[0]
            self._crossings.append((np.asarray(at, dtype=float), np.where(over, 1.0, -1.0),
                                    self.reach * spacing))
        self._yarn = yarn
        self._z = 9 * np.arange(n) + 2
        self._t = 9 * np.arange(n) + self._axis
        self._force_scale = model.force_scale
        self.model = model
        self.heddle_force = 0.0

    def _springs(self, u: np.ndarray, lift: float):
        """Per owned node: heddle weight w, dw/dt, its side sigma (+1 lifts,
        -1 presses down, 0 no heddle) and how far the node is on the wrong
        side of its heddle, p = sigma (lift sigma A - u_z) (> 0: pushed)."""
        t = self._t0 + u[self._t]
        w, dw, side = (np.zeros_like(t) for _ in range(3))
        for k, (at, sign, h) in enumerate(self._crossings):
            mine = np.flatnonzero(self._yarn == k)
            d = (t[mine, None] - at[None, :]) / h               # (nodes, crossings)
            near = np.abs(d) < 1
            c, s = np.cos(0.5 * np.pi * d), np.sin(0.5 * np.pi * d)
            w[mine] = np.sum(np.where(near, c * c, 0.0), axis=1)
            dw[mine] = np.sum(np.where(near, -np.pi / h * c * s, 0.0), axis=1)
            # heddles do not overlap (reach <= 0.5): at most one is near
            side[mine] = np.sum(np.where(near, sign[None, :], 0.0), axis=1)
        p = side * (lift * side * self.amplitude - u[self._z])
        return w, dw, side, p

    def _law(self, p: np.ndarray):
        """The heddle's push g(p) / k and its slope g'(p): 0 for p <= 0,
        p^2 / (2 delta) up to delta, then p - delta / 2 (the contact's
        regularized penalty, docs/method.md §3.3, so the push starts
        smoothly and Newton does not cycle on it)."""
        delta = self.regularization
        g = np.where(p <= 0, 0.0, np.where(p < delta, p * p / (2 * delta), p - 0.5 * delta))
        dg = np.where(p <= 0, 0.0, np.where(p < delta, p / delta, 1.0))
        return g, dg

    # -- system --------------------------------------------------------------
    def residual(self, state: State, b) -> None:
        k = self._value(self.stiffness, state.load_factor, "stiffness")
        self.heddle_force = 0.0
        if k == 0:
            return
        u = state.u["beam"]
        lift = self._value(self.lift, state.load_factor, "lift")
        w, _, side, p = self._springs(u, lift)
        g, _ = self._law(p)
        force = -side * k * self._unit * w * g
        b["beam"][self._z] += force
        self.heddle_force = float(np.abs(force).max(initial=0.0))

    def jacobian(self, state: State, A) -> None:
        k = self._value(self.stiffness, state.load_factor, "stiffness")
        if k == 0:
            return
        u, dofs = state.u["beam"], state.dofs["beam"]
        lift = self._value(self.lift, state.load_factor, "lift")
        w, dw, side, p = self._springs(u, lift)
        g, dg = self._law(p)
        on = (w > 0) & (p > 0)
        rows = np.ascontiguousarray(dofs[self._z][on], dtype=np.int32)
        cols = np.ascontiguousarray(dofs[self._t][on], dtype=np.int32)
        ku = (k * self._unit)[on]
        _cpp.add_entries(A, rows, rows, np.ascontiguousarray(ku * w[on] * dg[on]))
        _cpp.add_entries(A, rows, cols, np.ascontiguousarray(-side[on] * ku * dw[on] * g[on]))

    def statistics(self) -> dict:
        comm = self.model.comm
        return {"heddle_force": comm.allreduce(self.heddle_force, op=max) / self._force_scale}
