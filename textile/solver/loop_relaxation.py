"""Aitken relaxation of the contact loop's passes.

The contact loop (:mod:`textile.solver.contact_loop`) is a fixed point: a
Newton solve with what the effects hold fixed (contact elements, normals,
abscissas) takes a state y to x = G(y), the effects update at x, and so on.
Near its answer it converges linearly; on bundles of fibres the effects'
change falls by only 3-15% a pass (benchmarks/README.md, "A contact loop
judged by its trend"), so a step can take ten passes or more.

Aitken's relaxation (Irons and Tuck's vector form, as fluid-structure
coupling uses it: Kuettler and Wall, 2008) moves the state on along the
pass's motion r_k = G(y_k) - y_k:

    y_{k+1} = y_k + w_k r_k,
    w_k = -w_{k-1} r_{k-1} . (r_k - r_{k-1}) / |r_k - r_{k-1}|^2

(w = 1: the plain loop). For a loop that contracts by rho a pass, w_k =
1 / (1 - rho): the step lands on the fixed point; a loop that swings
(rho < 0: the bundle shear's passes that stand at a change of 2-5, w
0.25-0.55 there) is damped. The effects update again
at y_{k+1} (after the update at x = G(y_k) that judges the pass, so the
loop still ends only at a converged state whose effects did not change).
The converged answer is the plain loop's: only the path to it changes.

Where the motion is not one loop's contraction it starts afresh (w = 1,
no history): at the first pass of an attempt (its motion carries the load
step), when a pass changes from capped Newton solves to full ones (another
map), after an update that changed nothing (the next solve has the same
map), or made new contact forces or retuned penalties (change inf). The
contact loop judges a relaxed loop's trend (convergence.effects_unsettled)
from its first relaxed pass on (:attr:`AitkenRelaxation.waiting`).
"""
from __future__ import annotations

import math

from petsc4py import PETSc

#: Bounds on the relaxation factor w: a loop contracting by 0.9 a pass needs
#: w = 10 to land; beyond that the motion is a standing loop's (rate near 1,
#: w unbounded), not a contraction worth following. Below 1: a loop that
#: overshoots (rate < 0) is damped, but not to a standstill.
RELAXATION_BOUNDS = (0.25, 10.0)


class AitkenRelaxation:
    """The relaxation factors of one load-step attempt's passes."""

    def __init__(self):
        self._last: PETSc.Vec | None = None   # the last pass's motion r_{k-1}
        self._factor = 1.0                    # its factor w_{k-1}
        self._capped: bool | None = None
        #: every relaxation factor applied in the attempt (1 included)
        self.factors: list[float] = []
        #: how many of the attempt's passes were moved (a factor other than 1)
        self.relaxed_passes = 0

    @property
    def started(self) -> bool:
        """Has a pass of the attempt been relaxed (restarts keep it)?"""
        return self.relaxed_passes > 0

    @property
    def waiting(self) -> bool:
        """Has no pass been relaxed yet, with fewer than two motions seen
        (the fewest a factor needs)?"""
        return not self.started and len(self.factors) < 2

    def restart(self) -> None:
        """Forget the passes so far (the next motion has another map)."""
        if self._last is not None:
            self._last.destroy()
        self._last, self._factor, self._capped = None, 1.0, None

    def relax(self, origin: PETSc.Vec, x: PETSc.Vec, capped: bool) -> float:
        """``x``: the state a Newton solve reached from ``origin``, where the
        effects were last updated (``capped``: at most newton_per_pass
        iterations). Moves x to origin + w (x - origin) and returns w
        (collective)."""
        if capped != self._capped:
            self.restart()
        motion = x - origin
        w = 1.0
        if self._last is not None:
            d = motion - self._last
            dd = d.dot(d)
            if dd > 0:
                w = -self._factor * self._last.dot(d) / dd
            d.destroy()
            self._last.destroy()
            if not math.isfinite(w):
                w = 1.0
            w = min(max(w, RELAXATION_BOUNDS[0]), RELAXATION_BOUNDS[1])
        self._last, self._factor, self._capped = motion, w, capped
        if w != 1.0:
            x.axpy(w - 1.0, motion)   # x = origin + w * motion
            self.relaxed_passes += 1
        self.factors.append(w)
        return w

    def destroy(self) -> None:
        self.restart()
