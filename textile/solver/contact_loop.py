"""One load-step attempt: the effects prepare, the predictor, then Newton
repeated while an effect updates what Newton held fixed (contact elements,
normals, penalties: loops 1-2 around Newton's loop 3); each Newton solve
runs to convergence, or at most SolverOptions.newton_per_pass iterations.

:class:`ContactLoop` takes the model from its last converged state to a
load factor t, or reports why not (:class:`textile.solver.Attempt`); it
does not restore a failed attempt nor choose t
(:mod:`textile.solver.stepping`).
"""
from __future__ import annotations

import numpy as np
from petsc4py import PETSc

from .. import _cpp
from .convergence import capped_passes_stalled, cycling, effects_unsettled
from .loop_relaxation import AitkenRelaxation
from .newton import Newton
from .options import DIVERGED_EFFECTS_UNSETTLED
from .records import Attempt


class ContactLoop:
    """Load-step attempts with one :class:`Newton` (its model, options and
    counters)."""

    def __init__(self, newton: Newton):
        self.newton = newton
        self.system = newton.system
        self.comm = newton.comm
        self.options = newton.options
        #: did the predictor keep the extrapolated state at the last step?
        self.extrapolation_won = False

    def effects_step(self, method: str) -> tuple[bool, str]:
        """Call ``method`` of every effect (prepare, update); GeometryError
        on any rank makes the attempt fail. Returns (changed, error)."""
        m = self.system
        error, changed = "", False
        try:
            results = [getattr(e, method)(m) for e in m.effects]
            changed = any(bool(r) for r in results)
        except _cpp.GeometryError as exc:
            error = str(exc)
        m.start_newton()  # the tangents of the Newton solve that follows count from 0
        errors = [e for e in self.comm.allgather(error) if e]
        return self.comm.allreduce(changed), (errors[0] if errors else "")

    def extrapolate(self, points: list, t: float, stress: bool) -> list:
        """Set the system's state to the polynomial through ``points``
        [(load factor, state)] (the current state first, the system's state
        now, then earlier converged ones), evaluated at t: x = sum_i w_i x_i with Lagrange
        weights w_i (sum w_i = 1). Returns (if ``stress``, else []) what the
        MIP tangent at that state needs for a stress extrapolated with the
        same weights (System.set_predicted_stress): the strain is quadratic
        in the state, so sum_i w_i E(x_i) = E(x) + sum_{i<j} w_i w_j 1/2 h(x_i -
        x_j)^T h(x_i - x_j), i.e. the pairs (-w_i w_j, x_i - x_j). Without
        it the tangent's stress would be the linear extrapolation from the
        current state to the predicted one, whose spurious stretch (a
        rotation's chord) stiffens bending until Newton has removed it
        (benchmarks/README.md, "A predictor that extrapolates the stress
        too")."""
        m = self.system
        w = [float(np.prod([(t - tj) / (ti - tj) for j, (tj, _) in enumerate(points) if j != i]))
             for i, (ti, _) in enumerate(points)]
        # x = x_0 + sum_{i>0} w_i (x_i - x_0): increments, not sums of states
        for wi, (_, xi) in zip(w[1:], points[1:]):
            d = xi - points[0][1]
            m.x.axpy(wi, d)
            d.destroy()
        return [(-w[i] * w[j], points[i][1] - points[j][1])
                for i in range(len(points)) for j in range(i + 1, len(points)) if stress]

    def step_to(self, t: float, predict: bool = True, previous=None, older=None) -> Attempt:
        """One load-step attempt at load factor t from the current state:
        effects prepare (at the converged state), predictor, then Newton
        (loop 3) repeated while an effect updates what Newton held fixed
        (loops 1-2: contact elements, normals, penalties). ``previous`` and
        ``older``: (load factor, state) of the converged steps before the
        current one, most recent first, for the predictor (None: none)."""
        m, o = self.system, self.options
        m.domain_error = None
        # at the last converged state: history (e.g. friction stick points)
        # carries over to re-detected elements without the step's increment
        _, error = self.effects_step("prepare")
        if error:
            return Attempt(False, reason=PETSc.SNES.ConvergedReason.DIVERGED_FUNCTION_DOMAIN,
                           message=f"preparing effects: {error}")
        # the converged state is the linearization point of the predictor
        m.set_linearization_point()
        t_n = m.load_factor
        m.load_factor = t
        # "auto" with the MIP Newton on a scene whose every effect is smooth
        # along the path: the parabola (its stress extrapolated too)
        predictor = o.predictor
        if predictor == "auto" and m.newton == "mip" and all(e.smooth_path for e in m.effects):
            predictor = "parabola"
        order = 2 if predictor == "parabola" else 1
        earlier = [p for p in (previous, older)[:order] if p is not None]
        # only states before the current one, in order (none after a gap)
        for k, p in enumerate(earlier):
            if p[0] >= (t_n if k == 0 else earlier[k - 1][0]):
                earlier = earlier[:k]
                break
        if predict and predictor != "none" and earlier:
            plain = m.x.copy()
            # the stress extrapolated alike: for a chosen predictor (auto's
            # first tangent is linearized from the converged state)
            stress = self.extrapolate([(t_n, plain)] + earlier, t,
                                      predictor != "auto" and m.newton == "mip")
            norm = self.newton.residual_norm
            if predictor == "auto":
                # the state the last step chose is evaluated last: when it
                # wins again, its residual is Newton's first (kept by
                # Newton.residual_norm, not evaluated again)
                if self.extrapolation_won:
                    plain_norm = norm(plain)
                    extrapolated_norm = norm(m.x)
                else:
                    extrapolated_norm = norm(m.x)
                    plain_norm = norm(plain)
                self.extrapolation_won = not extrapolated_norm > plain_norm
                if not self.extrapolation_won:
                    plain.copy(m.x)  # the extrapolation is worse than none
            if stress:
                m.set_predicted_stress(stress)
            for _, d in stress:
                d.destroy()
            plain.destroy()
        m.apply_constraints(m.x)
        return self._passes()

    def _passes(self) -> Attempt:
        """The contact loop of :meth:`step_to` (loops 1-2 around Newton's
        loop 3) from the predicted state."""
        m, o = self.system, self.options
        attempt = Attempt(False)
        # were the effects last updated at a converged state? (the step's
        # start is one; a capped solve's iterate is not: an answer is taken
        # only from effects set at a converged state, which keeps it to
        # round-off on any number of ranks)
        set_at_converged = True
        # the effects' change after each solve run to convergence: a loop
        # that cycles between effect states (contact sets) fails at once
        settled_changes = []
        # Newton to SolverOptions.path_rtol (before a stage's end) until the
        # loop cycles: the changes a loose solve leaves can keep the loop
        # just above its tolerance; full solves settled that on the 28-fibre
        # weave (a cycle they do not settle costs twice: benchmarks/README.md)
        path = o.path_rtol > 0
        # the effects settled after a capped solve, or capped solves stopped
        # bringing them closer (capped_passes_stalled): the rest run to
        # convergence (capped on, the passes kept the solve's iterations
        # short: the bundle shear's steps took 10 capped solves where two
        # full ones settle; benchmarks/README.md, "The bundle shear's
        # contact loop")
        capped_done, capped_changes = False, []
        # the passes' motion relaxed (SolverOptions.loop_relaxation) from
        # ``origin``, the state where the effects were last updated (none
        # before the first update: the first solve's motion carries the
        # load step)
        relaxation = AitkenRelaxation() if o.loop_relaxation == "aitken" else None
        origin = None
        try:
            for outer in range(1, o.max_updates + 1):
                attempt.updates = outer
                if self.comm.allreduce(m.matrix_stale):
                    # new couplings (contact): a matrix preallocated for them
                    self.newton.set_operators(m.rebuild_matrix())
                # capped solves between effect updates (newton_per_pass) for the
                # first half of the passes or until the effects settle after one
                # or stop settling;
                # then (effects that do not settle at unconverged states:
                # stick-slip flips) to convergence
                capped = outer <= o.max_updates // 2 and not capped_done
                # capped solves too short to show a cycle may make one together
                result = self.newton.solve(m.x, o.newton_per_pass if capped else 0,
                                           search=cycling(attempt.residual_norms), path=path,
                                           same_step=outer > 1)
                attempt.reason = result.reason
                if result.message:
                    attempt.message = result.message
                attempt.iterations += result.iterations
                attempt.residual_norms += result.residual_norms
                if m.domain_error is not None:
                    # (PETSc may have stopped on the infinite residual first)
                    attempt.reason = PETSc.SNES.ConvergedReason.DIVERGED_FUNCTION_DOMAIN
                    attempt.message = str(m.domain_error)
                    return attempt
                if (attempt.reason <= 0 and not result.capped) or not np.isfinite(m.x.norm()):
                    return attempt
                changed, error = self.effects_step("update")
                if error:
                    attempt.reason = PETSc.SNES.ConvergedReason.DIVERGED_FUNCTION_DOMAIN
                    attempt.message = f"updating effects: {error}"
                    return attempt
                change = max((e.update_change() for e in m.effects), default=0.0)
                attempt.passes.append((result.iterations, change))
                if not changed and not result.capped and set_at_converged:
                    attempt.converged = True
                    return attempt
                set_at_converged = not result.capped
                if result.capped:
                    capped_changes.append(change)
                    capped_done = not changed or capped_passes_stalled(capped_changes)
                if not result.capped:
                    settled_changes.append(change)
                    # a relaxed loop is judged by its own trend: not while
                    # the relaxation waits for the two motions it needs (the
                    # plain passes' slow fall is what it speeds up)
                    why = "" if relaxation is not None and relaxation.waiting else \
                        effects_unsettled(settled_changes, o.max_updates - outer)
                    if why:
                        if path:  # on with full solves (another map: no relaxation across)
                            path, settled_changes = False, []
                            if relaxation is not None:
                                relaxation.restart()
                            origin = self._keep(origin)
                            continue
                        attempt.reason = DIVERGED_EFFECTS_UNSETTLED
                        attempt.message = self._unsettled(attempt,
                                                          f"{why} after {outer} Newton solves")
                        return attempt
                if relaxation is not None:
                    if origin is None or not changed or not np.isfinite(change):
                        relaxation.restart()
                    elif relaxation.relax(origin, m.x, result.capped) != 1.0:
                        if relaxation.relaxed_passes == 1:
                            settled_changes = []  # the relaxed loop's trend from here
                        # the effects again, at the relaxed state (not a
                        # converged one: a plain pass must follow before the end)
                        m.apply_constraints(m.x)
                        set_at_converged = False
                        _, error = self.effects_step("update")
                        if error:
                            attempt.reason = PETSc.SNES.ConvergedReason.DIVERGED_FUNCTION_DOMAIN
                            attempt.message = f"updating effects at a relaxed state: {error}"
                            return attempt
                    origin = self._keep(origin)
            attempt.reason = DIVERGED_EFFECTS_UNSETTLED
            attempt.message = self._unsettled(attempt, f"still changing after {o.max_updates} "
                                                       f"Newton solves")
            return attempt
        finally:
            if relaxation is not None:
                attempt.relaxation = relaxation.factors
                relaxation.destroy()
            if origin is not None:
                origin.destroy()

    def _keep(self, origin):
        """The system's state copied into ``origin`` (made if None)."""
        if origin is None:
            return self.system.x.copy()
        self.system.x.copy(origin)
        return origin

    @staticmethod
    def _unsettled(attempt: Attempt, how: str) -> str:
        changes = ", ".join(f"{c:.3g}" for _, c in attempt.passes[-5:])
        return (f"effects (contact elements, normals, penalties) {how} (the last changes, "
                f"in units of their tolerance: {changes})")
