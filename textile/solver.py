"""Load stepping with one PETSc SNES over the model's monolithic system.

Each step raises the load factor t (loads and prescribed displacements
scale with it), predicts the prescribed values, and runs Newton with line
search (SNES ``newtonls``) with a direct solver (MUMPS LU by default). A
step that fails (divergence, NaN, too many iterations, an error in a
kernel) is restored and cut; easy steps let the step grow. A step that
cannot be completed ends the run with :class:`ConvergenceError`; every
converged step is already on disk by then.
"""
from __future__ import annotations

import math
import os
import sys
import time
from dataclasses import dataclass, field

import numpy as np
from petsc4py import PETSc

from .model import Model
from .options import Options


class ConvergenceError(RuntimeError):
    """A load step could not be completed even with the smallest step."""


@dataclass
class SolverOptions(Options):
    """Options of :class:`Solver` (unknown names raise ValueError).

    Attributes
    ----------
    initial_step, min_step, max_step:
        Load-factor increments (0 < min <= initial <= max <= 1).
    grow, cut:
        Step multiplier after an easy step (<= easy_iterations Newton
        iterations) and after a failed one.
    easy_iterations:
        Newton iterations at or below which a step counts as easy.
    rtol, atol, stol, max_it:
        SNES tolerances: residual norm relative to the step's first one;
        absolute residual norm as a fraction of the model's force scale
        (the largest fibre's E*A: round-off in the internal forces sits
        near 1e-15 of it); relative step norm; Newton iterations per attempt.
    stagnation_update, stagnation_reduction:
        Round-off floor test: converged when the Newton update is below
        stagnation_update of the solution, the residual no longer halves and
        is below stagnation_reduction of the step's first residual.
    line_search:
        SNES line search; "basic" (full Newton steps, default): the residual
        norm mixes forces on positions and on section vectors, which misleads
        norm-decrease searches such as "bt" on these beams; failed steps are
        cut instead.
    max_updates:
        Newton solves per step while effects update what Newton holds fixed
        (contact elements, normals, penalties); a step still changing after
        that many is cut.
    newton:
        "standard" (exact tangent every iteration) or "mip" (mixed
        integration point Newton: the beams' geometric stiffness uses the
        stress extrapolated linearly from the previous iterate, which keeps
        Newton from overshooting on large rotations; the converged answer is
        the same).
    predictor:
        Initial guess of a step: "secant" extrapolates the last converged
        increment (fewer Newton iterations on smooth paths), "none" starts
        from the last converged state.
    linear_solver:
        "mumps" (LU, default), "superlu_dist" or "petsc" (serial LU).
    petsc_options:
        Extra PETSc options for this solver's SNES/KSP/PC, e.g.
        {"snes_linesearch_type": "basic"} (applied with the solver's prefix);
        command-line -snes_*, -ksp_*, -pc_* options also apply.
    verbose:
        Print one progress line per step on rank 0.
    """

    initial_step: float = 0.1
    min_step: float = 1e-4
    max_step: float = 0.25
    grow: float = 1.5
    cut: float = 0.5
    easy_iterations: int = 4
    rtol: float = 1e-10
    atol: float = 1e-13
    stol: float = 1e-10
    max_it: int = 25
    stagnation_update: float = 1e-6
    stagnation_reduction: float = 1e-3
    line_search: str = "basic"
    newton: str = "standard"
    predictor: str = "secant"
    max_updates: int = 20
    linear_solver: str = "mumps"
    petsc_options: dict = field(default_factory=dict)
    verbose: bool = True

    kind = "solver"

    def __post_init__(self):
        self.require_positive("initial_step", "min_step", "max_step", "grow", "cut", "rtol",
                              "atol", "stol", "stagnation_update", "stagnation_reduction")
        if not self.min_step <= self.initial_step <= self.max_step <= 1.0:
            raise ValueError("SolverOptions: need 0 < min_step <= initial_step <= max_step <= 1")
        if not 0 < self.cut < 1 or self.grow < 1:
            raise ValueError("SolverOptions: need 0 < cut < 1 and grow >= 1")
        if self.predictor not in ("secant", "none"):
            raise ValueError(f"SolverOptions.predictor must be 'secant' or 'none', "
                             f"got {self.predictor!r}")
        if self.newton not in ("standard", "mip"):
            raise ValueError(f"SolverOptions.newton must be 'standard' or 'mip', "
                             f"got {self.newton!r}")
        if self.linear_solver not in ("mumps", "superlu_dist", "petsc"):
            raise ValueError(f"SolverOptions.linear_solver must be 'mumps', 'superlu_dist' or "
                             f"'petsc', got {self.linear_solver!r}")


@dataclass
class StepRecord:
    """Statistics of one converged load step."""

    step: int
    load_factor: float
    newton_iterations: int
    attempts: int
    residual_norms: list
    wall_time: float
    converged_reason: int
    energy: float
    updates: int = 1
    effects: dict = field(default_factory=dict)


class Solver:
    """Drive a :class:`~textile.Model` through load steps with one SNES.

    Parameters
    ----------
    model:
        The scene.
    options:
        :class:`SolverOptions` or a dict of its fields.
    output:
        Optional :class:`~textile.output.Output` (ParaView files, results.json)
        written after every converged step.
    on_step:
        Optional callable ``(solver, record)`` after each converged step,
        e.g. to record a load curve.
    """

    _count = 0

    def __init__(self, model: Model, options=None, output=None, on_step=None):
        self.model = model
        self.options = options if isinstance(options, SolverOptions) \
            else SolverOptions.from_dict(options)
        self.output = output
        self.on_step = on_step
        self.history: list[StepRecord] = []
        self._previous = None  # (load factor, state) of the step before the last
        model.setup()
        model.newton = self.options.newton
        self.comm = model.comm
        Solver._count += 1
        self.prefix = f"textile{Solver._count}_"
        self.snes = self._create_snes()

    def _create_snes(self) -> PETSc.SNES:
        o, m = self.options, self.model
        snes = PETSc.SNES().create(self.comm)
        snes.setOptionsPrefix(self.prefix)
        snes.setType("newtonls")
        snes.setFunction(m.residual, m.b)
        snes.setJacobian(m.jacobian, m.A)
        snes.setTolerances(rtol=o.rtol, atol=o.atol * m.force_scale, stol=o.stol, max_it=o.max_it)
        snes.setConvergenceTest(self._converged)
        snes.setConvergenceHistory(reset=True)
        ksp = snes.getKSP()
        ksp.setType("preonly")
        pc = ksp.getPC()
        pc.setType("lu")
        if o.linear_solver != "petsc":
            pc.setFactorSolverType(o.linear_solver)
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

    def _converged(self, snes, it, norms):
        """SNES convergence test: PETSc's tests (residual relative/absolute,
        step relative) plus one for the round-off floor. The floor of the
        residual norm grows with the stiffness of the discretization (about
        E A / element length), so no fixed absolute tolerance fits every mesh:
        a Newton update below stagnation_update of the solution that no longer
        halves a residual already reduced by stagnation_reduction means the
        floor is reached and the solution is converged to round-off."""
        xnorm, ynorm, fnorm = norms
        o = self.options
        if not np.isfinite(fnorm):
            return PETSc.SNES.ConvergedReason.DIVERGED_FNORM_NAN
        if it == 0:
            self._fnorms = [fnorm]
            return 2 if fnorm <= o.atol * self.model.force_scale else 0
        self._fnorms.append(fnorm)
        f0 = self._fnorms[0]
        if fnorm <= o.atol * self.model.force_scale:
            return PETSc.SNES.ConvergedReason.CONVERGED_FNORM_ABS
        if fnorm <= o.rtol * f0:
            return PETSc.SNES.ConvergedReason.CONVERGED_FNORM_RELATIVE
        if ynorm <= o.stol * xnorm:
            return PETSc.SNES.ConvergedReason.CONVERGED_SNORM_RELATIVE
        if (it >= 2 and ynorm <= o.stagnation_update * xnorm
                and fnorm > 0.5 * self._fnorms[-2] and fnorm <= o.stagnation_reduction * f0):
            return PETSc.SNES.ConvergedReason.CONVERGED_SNORM_RELATIVE
        if it >= o.max_it:
            return PETSc.SNES.ConvergedReason.DIVERGED_MAX_IT
        return PETSc.SNES.ConvergedReason.CONVERGED_ITERATING

    def _log(self, msg: str) -> None:
        if self.options.verbose and self.comm.rank == 0:
            print(msg, flush=True)

    def step_to(self, t: float) -> tuple[bool, int, list, int, int]:
        """One load-step attempt at load factor t from the current state:
        effects prepare (at the converged state), predictor, then Newton (loop 3) repeated while an effect updates what
        Newton held fixed (loops 1-2: contact elements, normals, penalties).
        Returns (converged, Newton iterations, residual history, SNES reason,
        outer iterations)."""
        m, o = self.model, self.options
        error = None
        try:
            # at the last converged state: history (e.g. friction stick
            # points) carries over to re-detected elements without the
            # step's increment
            for e in m.effects:
                e.prepare(m)
        except (PETSc.Error, RuntimeError, ValueError) as exc:
            error = exc
        # collective: a rank that failed alone must not leave the others
        # waiting in the next collective call
        if self.comm.allreduce(error is not None):
            self._log(f"    error preparing t={t:.6g}: {error}")
            return False, 0, [], -100, 0
        # the converged state is the linearization point of the predictor
        m.set_linearization_point()
        prev = self._previous
        if o.predictor == "secant" and prev is not None and prev[0] < m.load_factor:
            t_prev, x_prev = prev
            # x += (t - t_n) / (t_n - t_prev) * (x_n - x_prev)
            m.x.axpy((t - m.load_factor) / (m.load_factor - t_prev), m.x - x_prev)
        m.load_factor = t
        m.apply_constraints(m.x)
        total, hist, reason = 0, [], 0
        try:
            for outer in range(1, o.max_updates + 1):
                if self.comm.allreduce(m.matrix_stale):
                    # new couplings (contact): a matrix preallocated for them
                    self.snes.setJacobian(m.jacobian, m.rebuild_matrix())
                self.snes.solve(None, m.x)
                reason = self.snes.getConvergedReason()
                its = self.snes.getIterationNumber()
                total += its
                hist += [float(r) for r in self.snes.getConvergenceHistory()[0][: its + 1]]
                if reason <= 0 or not np.isfinite(m.x.norm()):
                    return False, total, hist, reason, outer
                error, changed = None, False
                try:
                    changed = any([e.update(m) for e in m.effects])
                except (RuntimeError, ValueError) as exc:
                    error = exc
                if self.comm.allreduce(error is not None):  # collective, see prepare
                    self._log(f"    error updating effects at t={t:.6g}: {error}")
                    return False, total, hist, -100, outer
                if not self.comm.allreduce(changed):
                    return True, total, hist, reason, outer
            self._log(f"    effects still changing after {o.max_updates} updates at t={t:.6g}")
            return False, total, hist, -200, o.max_updates
        except (PETSc.Error, RuntimeError, ValueError) as e:
            # an exception inside a callback or a kernel (e.g. a degenerate
            # geometry): the attempt fails and the step is cut
            self._log(f"    error at t={t:.6g}: {e}")
            return False, total, hist, -100, 0

    def solve(self, t_end: float = 1.0) -> list[StepRecord]:
        """Advance from the current load factor to ``t_end`` (default 1)."""
        o, m = self.options, self.model
        if not (isinstance(t_end, (int, float)) and math.isfinite(t_end)):
            raise ValueError(f"t_end must be a finite number, got {t_end!r}")
        t = m.load_factor
        dt = min(o.initial_step, o.max_step)
        x_saved = m.x.copy()
        attempts = 0
        while t < t_end - 1e-14:
            step = min(dt, t_end - t)
            t0 = time.perf_counter()
            ok, its, hist, reason, outer = self.step_to(t + step)
            attempts += 1
            if not ok:
                x_saved.copy(m.x)
                m.load_factor = t
                for e in m.effects:
                    e.restore(m)
                dt = step * o.cut
                self._log(f"  step to t={t + step:.6g} failed (reason {reason}, {its} its): "
                          f"cutting to dt={dt:.3g}")
                if dt < o.min_step:
                    msg = (f"load step from t={t:.6g} did not converge even with dt < "
                           f"min_step={o.min_step:g} (last SNES reason {reason}); "
                           f"{len(self.history)} converged steps are kept")
                    if self.output is not None:
                        self.output.failure(msg)
                    raise ConvergenceError(msg)
                continue
            for e in m.effects:
                e.commit(m)
            self._previous = (t, x_saved.copy())
            t += step
            m.x.copy(x_saved)
            stats = {}
            for e in m.effects:
                stats.update(e.statistics())
            rec = StepRecord(len(self.history) + 1, t, its, attempts, hist,
                             time.perf_counter() - t0, reason,
                             self.comm.allreduce(m.beam.energy), outer, stats)
            self.history.append(rec)
            attempts = 0
            self._log(f"step {rec.step:3d}  t={t:.4f}  newton={its:2d}  "
                      f"|r|={hist[-1] if hist else float('nan'):.2e}  {rec.wall_time:.2f}s")
            if self.output is not None:
                self.output.write_step(self, rec)
            if self.on_step is not None:
                self.on_step(self, rec)
            if its <= o.easy_iterations:
                dt = min(step * o.grow, o.max_step)
            else:
                dt = step
        return self.history
