"""One Newton solve: SNES ``newtonls`` over the model's monolithic system,
its linear solver (:mod:`textile.solver.linear_solver`), the per-group convergence
test (:mod:`textile.solver.convergence`) and cycle detection.

:class:`Newton` solves the model at its current load factor from the
current iterate, nothing else: no prediction, no effects' updates, no step
control (:mod:`textile.solver.contact_loop`, :mod:`textile.solver.stepping`).
"""
from __future__ import annotations

import itertools
import weakref
from dataclasses import dataclass, field

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from .convergence import (CYCLE_ITERATIONS, CYCLE_PERIOD, CYCLE_TOLERANCE,  # noqa: F401
                          STALL_MESSAGE, GroupTolerances, cycling, stalled)
from .kept_residual import KeptResidual
from .linear_solver import LinearSolver
from .options import DIVERGED_NEWTON_CYCLE, DIVERGED_NEWTON_STALL, SolverOptions, say


def _forget_options(prefix: str) -> None:
    """Remove every option of the PETSc database that starts with prefix."""
    opts = PETSc.Options()
    for name in [n for n in opts.getAll() if n.startswith(prefix)]:
        opts.delValue(name)


#: numbers the PETSc option prefixes of the solvers (textile1_, textile2_, ...)
_prefixes = itertools.count(1)


def new_counts() -> dict:
    """The counters a solver keeps itself (the rest: PETSc's event log)."""
    return dict(newton_solves=0, newton_iterations=0, failed_attempts=0,
                accepted_steps=0, residual_evaluations=0, jacobian_evaluations=0,
                linear_solve_retries=0, matrix_rebuilds_in_newton=0, cycle_line_searches=0,
                eigen_solves=0, eigen_solve_seconds=0.0, zero_motion_searches=0,
                zero_motion_seconds=0.0, stability_checks=0, stability_check_seconds=0.0,
                branch_switches=0, branch_attempts=0, branch_switch_seconds=0.0,
                factorizations_at_solution=0)


@dataclass
class NewtonResult:
    """What one Newton solve did (its linear-solve retries included)."""

    reason: int = 0
    iterations: int = 0
    residual_norms: list = field(default_factory=list)
    message: str = ""
    #: stopped unconverged by its iteration cap (Newton.solve's cap), not failed
    capped: bool = False


class Newton:
    """One SNES with the model's residual, tangent and convergence test.

    ``system`` is a scene's assembled System (``model.system``, its ``newton`` set);
    ``options`` is a :class:`SolverOptions` (its Newton, linear-solver and
    PETSc fields; ``max_it``, ``stol`` and ``verbose`` are read at every
    solve: a stage may change them). ``counts``: the dict of counters to
    add to (:func:`new_counts` by default)."""

    def __init__(self, system, options: SolverOptions, counts: dict | None = None):
        self.system = system
        self.options = options
        self.comm = system.comm
        self.tolerances = GroupTolerances(options.rtol, options.atol, options.floor_factor)
        groups = system.residual_groups
        self.scales = np.array([groups.scale[n] for n in groups.names])
        self.prefix = f"textile{next(_prefixes)}_"
        # PETSc's options database is bounded (error 55 once full): ours go with the solver
        weakref.finalize(self, _forget_options, self.prefix)
        self.counts = counts if counts is not None else new_counts()
        #: was the last factorization the exact tangent of a state close to
        #: the last iterate? (see converged; textile.solver.stability_check)
        self.factor_near = False
        # the last solve cycled, stalled; its residual norms after the first
        self.cycled, self.stalled, self._solve_norms = False, False, []
        #: did the solve stop because the matrix has no room for the
        #: iterate's couplings (system.matrix_stale, see _converged)?
        self.outgrown = False
        #: Newton iterations allowed in the current solve (0: max_it; see solve)
        self.cap = 0
        #: the last residual evaluation, when residual_norm made it (see
        #: KeptResidual); any other evaluation forgets it
        self._kept_residual = None
        self.snes = self._create_snes()  # starts PETSc's event log

    def _create_snes(self) -> PETSc.SNES:
        o, m = self.options, self.system
        snes = PETSc.SNES().create(self.comm)
        snes.setOptionsPrefix(self.prefix)
        snes.setType("newtonls")
        snes.setFunction(self._residual, m.b)
        symmetric = all(e.symmetric_tangent for e in m.effects)
        self.linear = LinearSolver(snes, o, self.prefix, symmetric, self.comm)
        snes.setJacobian(self._jacobian, *self.linear.operators(m.A))
        snes.setTolerances(max_it=o.max_it)
        snes.setConvergenceTest(self._converged)
        snes.setConvergenceHistory(reset=True)
        opts = PETSc.Options()
        # petsc4py 3.18 has no SNESLineSearch binding: set it as an option
        opts[self.prefix + "snes_linesearch_type"] = o.line_search
        # the first Newton iterate of a finite rotation can raise the residual
        # norm by orders of magnitude (section vectors stretch to first
        # order): no divergence-by-growth test, failures are caught by max_it
        opts[self.prefix + "snes_divergence_tolerance"] = -1
        for k, v in o.petsc_options.items():
            opts[self.prefix + k.lstrip("-")] = v
        snes.setFromOptions()
        # generic command-line options (-snes_monitor, ...) without our prefix
        snes.setOptionsPrefix(None)
        snes.setFromOptions()
        snes.setOptionsPrefix(self.prefix)
        return snes

    def stage_began(self) -> None:
        """A stage has begun (its effect options set): the factorization
        follows its tangent's symmetry (LinearSolver.stage_symmetry)."""
        self.linear.stage_symmetry(all(e.symmetric_tangent for e in self.system.effects))

    def _residual(self, snes, x, b) -> None:
        kept, self._kept_residual = self._kept_residual, None
        reuse = kept is not None and kept.matches(self.system, x)
        if self.comm.size > 1:
            # every rank or none: the evaluation is collective
            reuse = self.comm.allreduce(reuse, op=MPI.LAND)
        if reuse:
            # the predictor's last residual_norm was at this very iterate:
            # the same residual, not evaluated again
            kept.restore(self.system, b)
            return
        self.counts["residual_evaluations"] += 1
        self.system.residual(snes, x, b)

    def _jacobian(self, snes, x, J, P) -> None:
        self.counts["jacobian_evaluations"] += 1
        self.system.jacobian(snes, x, J, P)
        self.linear.refresh(snes)

    def _converged(self, snes, it, norms):
        """Per-group residual test (textile.solver.convergence) or a negligible
        Newton update; domain errors and non-finite residuals stop SNES."""
        m, o = self.system, self.options
        xnorm, ynorm, fnorm = norms
        if m.domain_error is not None:
            return PETSc.SNES.ConvergedReason.DIVERGED_FUNCTION_DOMAIN
        if not np.isfinite(fnorm):
            return PETSc.SNES.ConvergedReason.DIVERGED_FNORM_NAN
        g = m.residual_norms
        if it == 0:
            # the size of the unknowns as the kernels see them (positions):
            # the scale of a negligible Newton update and of the constraint rows
            self._q_norm = m.x.norm() + m.reference_norm()
        settled = it > 0 and ynorm <= self.tolerances.floor_update * self._q_norm
        # was the last factorization the exact tangent of a state close to
        # this one? (the inertia of the stability check is read from it; a
        # MIP tangent is exact only for a small extrapolation)
        self.factor_near = (it > 0 and ynorm <= 1e-6 * self._q_norm
                            and m.last_tangent_update <= 1e-6 * self._q_norm)
        reference = m.force_reference.copy()
        reference[m.residual_groups.names.index("constraints")] = self._q_norm
        floors = lambda: m.floors(snes.getSolution())  # noqa: E731 (collective, on demand)
        if np.all(self.tolerances.converged(g, reference, floors, self.scales, settled,
                                            on_path=m.load_factor < 1.0 - 1e-14)):
            return PETSc.SNES.ConvergedReason.CONVERGED_FNORM_ABS
        if it == 0:
            self._f0 = fnorm
            self._fnorms = []
        self._fnorms.append(fnorm)
        self._solve_norms += [fnorm] if it > 0 else []  # (a restart's first: the last again)
        # a negligible update converges, unless the iterate blew up (a tiny
        # step relative to a huge solution must not accept |r| = 1e29)
        if it > 0 and ynorm <= o.stol * xnorm and fnorm <= self._f0:
            return PETSc.SNES.ConvergedReason.CONVERGED_SNORM_RELATIVE
        if it >= (min(o.max_it, self.cap) if self.cap else o.max_it):
            return PETSc.SNES.ConvergedReason.DIVERGED_MAX_IT
        if self.comm.allreduce(m.matrix_stale, op=MPI.LOR):
            # the iterate couples unknowns the matrix has no room for (a
            # contact closing on new fibre elements): PETSc would reallocate
            # the matrix entry by entry, seconds on a fabric; solve goes on
            # from this iterate with a rebuilt matrix instead
            self.outgrown = True
            return PETSc.SNES.ConvergedReason.DIVERGED_MAX_IT
        if stalled(self._solve_norms):
            self.stalled = True  # as a cycle: solve names it
            return PETSc.SNES.ConvergedReason.DIVERGED_DTOL
        if cycling(self._fnorms):
            self.cycled = True  # solve names it (SNES knows no such reason)
            return PETSc.SNES.ConvergedReason.DIVERGED_DTOL
        return PETSc.SNES.ConvergedReason.CONVERGED_ITERATING

    # -- one solve -----------------------------------------------------------------
    def set_operators(self, A: PETSc.Mat) -> None:
        """Solve with the model's new system matrix A (new couplings, a new
        constrained set)."""
        self._kept_residual = None
        self.snes.setJacobian(self._jacobian, *self.linear.operators(A))

    def solve(self, x: PETSc.Vec, cap: int = 0, search: bool = False,
              path: bool = True, same_step: bool = False) -> NewtonResult:
        """Newton from x (changed in place) at the model's load factor; a
        failed linear solve is retried with more MUMPS workspace or, after
        GMRES on a reused or approximate factorization, a fresh one.
        ``cap`` > 0: stop after at most that many iterations (unconverged:
        ``NewtonResult.capped``; SolverOptions.newton_per_pass). ``search``:
        with the cycle line search from the start (the solves before this
        one cycled). ``path``, ``same_step``: GroupTolerances.begin_solve."""
        m, o = self.system, self.options
        result, self._solve_norms = NewtonResult(), []  # over the solve's restarts (stalled)
        self.tolerances.begin_solve(o.path_rtol if path else 0.0, same_step)
        capped = 0 < cap < o.max_it
        budget = cap if capped else o.max_it
        spent = 0  # by SNES solves stopped for a matrix rebuild or a cycle
        # SolverOptions.cycle_line_search: after a cycle
        searching = search and o.cycle_line_search != "none"
        if searching:
            self.counts["cycle_line_searches"] += 1
            self._line_search(o.cycle_line_search)
        for retry in range(o.max_it):
            self.counts["newton_solves"] += 1
            self.cycled = self.outgrown = self.stalled = False
            self.cap = budget - spent if capped or spent else 0  # read by _converged
            try:
                self.snes.solve(None, x)
            finally:
                if searching:
                    self._line_search(o.line_search)
            result.reason = self.snes.getConvergedReason()
            its = self.snes.getIterationNumber()
            self.counts["newton_iterations"] += its
            result.iterations += its
            result.residual_norms += [float(r) for r in
                                      self.snes.getConvergenceHistory()[0][: its + 1]]
            if self.cycled and o.cycle_line_search != "none" and not searching \
                    and spent + its < budget:
                # full steps land where they started: on from this iterate
                # with a line search along the same Newton directions
                spent, searching = spent + its, True
                self.counts["cycle_line_searches"] += 1
                self._line_search(o.cycle_line_search)
                continue
            if self.cycled:
                result.reason = DIVERGED_NEWTON_CYCLE
                result.message = ("the residual repeats itself (contact or "
                                  "stick-slip switches flipping, or stuck)")
            if self.stalled:
                result.reason, result.message = DIVERGED_NEWTON_STALL, STALL_MESSAGE
            if self.outgrown and spent + its < budget:
                spent += its
                self.counts["matrix_rebuilds_in_newton"] += 1
                self.set_operators(m.rebuild_matrix())
                continue
            if not (result.reason == PETSc.SNES.ConvergedReason.DIVERGED_LINEAR_SOLVE
                    and m.domain_error is None):
                break
            if self.linear.grow_workspace(self.snes):
                # MUMPS out of its workspace estimate: again with more
                self.counts["linear_solve_retries"] += 1
                say(o, self.comm, f"  MUMPS's workspace estimate was too small: relaxed to "
                                  f"{self.linear.relaxation()}%, solving again")
                continue
            if not self.linear.krylov:
                break
            # GMRES with a reused or approximate factorization failed:
            # go on from this iterate with a fresh, exact one
            self.counts["linear_solve_retries"] += 1
            self.linear.force_refactorization()
        result.capped = capped and \
            result.reason == PETSc.SNES.ConvergedReason.DIVERGED_MAX_IT
        return result

    def _line_search(self, kind: str) -> None:
        PETSc.Options()[self.prefix + "snes_linesearch_type"] = kind
        self.snes.setFromOptions()

    def residual_norm(self, x: PETSc.Vec) -> float:
        """Norm of the residual at x with the constraints of the current
        load factor applied (inf outside the domain); x is not changed."""
        m = self.system
        y = x.copy()
        m.apply_constraints(y)
        r = m.b.duplicate()
        self._residual(None, y, r)
        clean = m.domain_error is None
        m.domain_error = None
        norm = r.norm()
        if clean and np.isfinite(norm):
            # SNES's first residual is this one when the step starts here
            self._kept_residual = KeptResidual(m, y, r)
        y.destroy()
        r.destroy()
        return norm if np.isfinite(norm) else np.inf
