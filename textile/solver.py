"""Load stepping with one PETSc SNES over the model's monolithic system.

Each step raises the load factor t (loads and prescribed displacements
scale with it), predicts the new state, and runs Newton (SNES ``newtonls``)
with a direct solver (:mod:`textile.linear_solver`). Convergence is tested
per group of unknowns, each on its own scale (:mod:`textile.convergence`).

A step attempt fails when Newton does not converge (too many iterations, a
failed linear solve), when the residual is not finite, when an iterate
leaves the model's domain (:class:`textile.GeometryError`: a folded
element, ...), or when effects keep changing what Newton holds fixed. A
failed attempt is restored and the step cut; easy steps let the step grow.
A step that cannot be completed ends the run with :class:`ConvergenceError`,
which names the reason in words; every converged step is on disk by then.
Any other exception raised inside an effect is a bug: it propagates with
its traceback.
"""
from __future__ import annotations

import dataclasses
import math
import time
import warnings
import weakref
from dataclasses import dataclass, field

import numpy as np
from petsc4py import PETSc

from . import _cpp
from .convergence import GroupTolerances
from .linear_solver import LinearSolver, event_counts
from .loading import Stage
from .model import Model
from .options import Options
from .stability import Inertia, critical_modes, factor_negative_pivots, zero_motion_pivots
from .zero_motions import describe, zero_energy_motions


class ConvergenceError(RuntimeError):
    """A load step could not be completed even with the smallest step."""


class StabilityWarning(UserWarning):
    """A converged equilibrium is unstable (negative eigenvalues)."""


def max_op():
    from mpi4py import MPI

    return MPI.MAX


#: Reasons of a failed attempt that are not SNES's own.
DIVERGED_EFFECTS_UNSETTLED = -200
DIVERGED_NEWTON_CYCLE = -201
_OWN_REASONS = {DIVERGED_EFFECTS_UNSETTLED: "DIVERGED_EFFECTS_UNSETTLED",
                DIVERGED_NEWTON_CYCLE: "DIVERGED_NEWTON_CYCLE"}

#: A Newton solve whose residual norm repeats itself with a period of 1 to
#: CYCLE_PERIOD iterations (each of the last max(CYCLE_ITERATIONS, 2 period)
#: values within CYCLE_TOLERANCE of the one a period before) is cycling
#: (stick-slip or contact switches flipping in turn) or stuck: it would not
#: converge within max_it, so the attempt fails at once and the step is cut.
#: A residual falling by 5% a period needs 45 periods per decade: none of
#: that converges anyway.
CYCLE_ITERATIONS, CYCLE_PERIOD, CYCLE_TOLERANCE = 6, 4, 0.05


def cycling(norms: list[float]) -> bool:
    """Does this Newton residual history (norm per iteration) cycle?"""
    for period in range(1, CYCLE_PERIOD + 1):
        n = max(CYCLE_ITERATIONS, 2 * period)
        if len(norms) < n + period + 2:  # the first two iterations never count
            continue
        h = norms[-n - period:]
        if all(abs(a - b) <= CYCLE_TOLERANCE * max(a, b)
               for a, b in zip(h[period:], h[:-period])):
            return True
    return False


def reason_name(reason: int) -> str:
    """Name of an SNES converged reason (or of the solver's own reasons)."""
    if reason in _OWN_REASONS:
        return _OWN_REASONS[reason]
    for name in dir(PETSc.SNES.ConvergedReason):
        if name.isupper() and name != "ITERATING" \
                and getattr(PETSc.SNES.ConvergedReason, name) == reason:
            return name
    return f"reason {reason}"


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
    rtol, atol, floor_factor, stol, max_it:
        Newton convergence, tested per group of unknowns (fibre positions,
        fibre section vectors, each other field, constrained rows; see
        :mod:`textile.convergence`): a group has converged when its residual
        norm is below rtol times its value at the start of the Newton solve,
        or below floor_factor * eps * |(|K||q|)_group| (its round-off floor),
        or below atol times its force scale (the largest fibre E*A; times the
        largest radius for section vectors). Or: the Newton update is below
        stol times the solution (relative). max_it: Newton iterations per
        solve; a solve whose residual repeats itself (``cycling``) stops
        before, as DIVERGED_NEWTON_CYCLE.
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
        "mip" (default; mixed integration point Newton: the beams' geometric
        stiffness uses the stress extrapolated linearly from the previous
        iterate, which keeps Newton from overshooting on large rotations) or
        "standard" (the exact tangent every iteration). The converged answer
        is the same (iteration counts: benchmarks/README.md, "Solver
        options").
    predictor:
        How a step starts: "secant" extrapolates the last converged
        increment, which helps on smooth paths and overshoots large
        rotations and contacts coming on; "none" starts from the last
        converged state with the new loads and prescribed values; "auto"
        (default) evaluates both starts and keeps the one with the smaller
        residual (two residual evaluations a step). Iteration counts:
        benchmarks/README.md, "Solver options".
    linear_solver:
        "mumps" (default), "superlu_dist" or "petsc" (serial).
    factorization:
        "auto" (LDL^T when every effect's tangent is symmetric, else LU),
        "lu" or "cholesky" (LDL^T, symmetric indefinite).
    reuse_factorization:
        1: factorize the tangent every Newton iteration. n > 1: keep a
        factorization for up to n iterations as the preconditioner of GMRES
        on the exact tangent (see :mod:`textile.linear_solver`).
    krylov_rtol, krylov_max_it:
        GMRES tolerance and iteration limit when a factorization is reused
        or approximate.
    low_rank_tolerance:
        > 0: MUMPS block low-rank factorization with this compression
        tolerance (an approximate factorization preconditioning GMRES).
    petsc_options:
        Extra PETSc options for this solver's SNES/KSP/PC, e.g.
        {"snes_linesearch_type": "basic"} (applied with the solver's prefix);
        command-line -snes_*, -ksp_*, -pc_* options also apply.
    stability_check:
        "auto": after every converged step, count the negative eigenvalues of
        the tangent from the Newton solver's LDL^T factorization (its
        negative pivots, less those of zero-energy motions: a fibre's
        sections free to spin, ...; see :mod:`textile.stability`); checked
        when the scene's tangent is symmetric, not otherwise. Recorded per
        step (``StepRecord.stability``, results.json) with a warning the
        first time stability is lost. "off": no check.
    branch_switching:
        When a converged step is found unstable (more negative eigenvalues
        than the step before: a bifurcation was passed), perturb it along the
        critical modes (SLEPc) and solve again at the same load, so that
        Newton settles on the stable branch (e.g. the buckled column instead
        of the straight one). Tried with amplitudes ``branch_amplitudes``
        (fractions of the longest fibre) and both signs. On by default: an
        unstable equilibrium is a wrong answer for a fabric; False keeps the
        unstable path (recorded and warned about).
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
    floor_factor: float = 10.0
    stol: float = 1e-10
    max_it: int = 25
    line_search: str = "basic"
    newton: str = "mip"
    predictor: str = "auto"
    max_updates: int = 20
    linear_solver: str = "mumps"
    factorization: str = "auto"
    reuse_factorization: int = 1
    krylov_rtol: float = 1e-9
    krylov_max_it: int = 40
    low_rank_tolerance: float = 0.0
    petsc_options: dict = field(default_factory=dict)
    stability_check: str = "auto"
    branch_switching: bool = True
    branch_amplitudes: tuple = (0.01, 0.05, 0.2, 0.5, 1.0)
    verbose: bool = True

    kind = "solver"

    def __post_init__(self):
        self.require_positive("initial_step", "min_step", "max_step", "grow", "cut", "rtol",
                              "atol", "floor_factor", "stol", "krylov_rtol")
        if not self.min_step <= self.initial_step <= self.max_step <= 1.0:
            raise ValueError("SolverOptions: need 0 < min_step <= initial_step <= max_step <= 1")
        if not 0 < self.cut < 1 or self.grow < 1:
            raise ValueError("SolverOptions: need 0 < cut < 1 and grow >= 1")
        choices = dict(newton=("standard", "mip"), predictor=("auto", "secant", "none"),
                       linear_solver=("mumps", "superlu_dist", "petsc"),
                       factorization=("auto", "lu", "cholesky"),
                       stability_check=("auto", "off"))
        for name, allowed in choices.items():
            if getattr(self, name) not in allowed:
                raise ValueError(f"SolverOptions.{name} must be one of {allowed}, "
                                 f"got {getattr(self, name)!r}")
        for name in ("max_it", "max_updates", "reuse_factorization", "krylov_max_it",
                     "easy_iterations"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or v < 1:
                raise ValueError(f"SolverOptions.{name} must be a positive integer, got {v!r}")
        for name in ("branch_switching", "verbose"):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(f"SolverOptions.{name} must be True or False, "
                                 f"got {getattr(self, name)!r}")
        if not (isinstance(self.low_rank_tolerance, (int, float))
                and 0 <= self.low_rank_tolerance < 1):
            raise ValueError("SolverOptions.low_rank_tolerance must be in [0, 1)")


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
    #: per group: residual norm at convergence (see textile.convergence)
    residuals: dict = field(default_factory=dict)
    #: negative eigenvalues of the tangent (None: not checked), the
    #: factorization's negative pivots and the zero-energy motions told
    #: apart from them (None: not searched, no negative pivot), and whether
    #: the step was moved to another branch (textile.stability)
    stability: dict = field(default_factory=dict)
    #: the stage this step belongs to, and the run's time (stage number +
    #: the stage's load factor: continuous over stages)
    stage: str = "load"
    time: float = 0.0

    @property
    def reason(self) -> str:
        """The SNES converged reason in words."""
        return reason_name(self.converged_reason)


@dataclass
class Attempt:
    """What one attempt at a load step did."""

    converged: bool
    iterations: int = 0
    residual_norms: list = field(default_factory=list)
    reason: int = 0
    updates: int = 0
    message: str = ""

    def describe(self) -> str:
        text = f"{reason_name(self.reason)} after {self.iterations} Newton iterations"
        return f"{text}: {self.message}" if self.message else text


def _forget_options(prefix: str) -> None:
    """Remove every option of the PETSc database that starts with prefix."""
    opts = PETSc.Options()
    for name in list(opts.getAll()):
        if name.startswith(prefix):
            opts.delValue(name)


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
        self._negative = 0     # negative eigenvalues at the last converged step
        self._first_increment = None  # (dt, du) of the first converged step
        self._base_options = self.options
        self._stage = Stage("load")   # the implicit first stage
        self._stage_index = 0
        self._stage_started = False
        #: the step size the next step of the stage takes (after a converged step)
        self._next_step: float | None = None
        #: steps converged before this solver (a run resumed from a saved state)
        self._steps_before = 0
        #: a stage resumed from a saved state in its middle: what its first
        #: solve needs (see resume)
        self._resuming: dict | None = None
        self._warned_unstable = False
        self._warned_singular = False
        model.setup()
        model.newton = self.options.newton
        self.comm = model.comm
        o = self.options
        self.tolerances = GroupTolerances(o.rtol, o.atol, o.floor_factor)
        groups = model.residual_groups
        self._scales = np.array([groups.scale[n] for n in groups.names])
        Solver._count += 1
        self.prefix = f"textile{Solver._count}_"
        # PETSc's options database is global and bounded (error 55 once
        # full): a solver's prefixed options go with it
        weakref.finalize(self, _forget_options, self.prefix)
        self._counts = dict(newton_solves=0, newton_iterations=0, failed_attempts=0,
                            accepted_steps=0, residual_evaluations=0, jacobian_evaluations=0,
                            linear_solve_retries=0, eigen_solves=0, eigen_solve_seconds=0.0,
                            zero_motion_searches=0, zero_motion_seconds=0.0)
        self.snes = self._create_snes()  # starts PETSc's event log
        self._events_at_start = event_counts()

    # -- SNES ------------------------------------------------------------------
    def _create_snes(self) -> PETSc.SNES:
        o, m = self.options, self.model
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

    def _residual(self, snes, x, b) -> None:
        self._counts["residual_evaluations"] += 1
        self.model.residual(snes, x, b)

    def _jacobian(self, snes, x, J, P) -> None:
        self._counts["jacobian_evaluations"] += 1
        self.model.jacobian(snes, x, J, P)
        self.linear.refresh(snes)

    def _converged(self, snes, it, norms):
        """Per-group residual test (textile.convergence) or a negligible
        Newton update; domain errors and non-finite residuals stop SNES."""
        m, o = self.model, self.options
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
        self._factor_near = (it > 0 and ynorm <= 1e-6 * self._q_norm
                             and m.last_tangent_update <= 1e-6 * self._q_norm)
        reference = m.force_reference.copy()
        reference[m.residual_groups.names.index("constraints")] = self._q_norm
        floors = lambda: m.floors(snes.getSolution())  # noqa: E731 (collective, on demand)
        if np.all(self.tolerances.converged(g, reference, floors, self._scales,
                                            settled)):
            return PETSc.SNES.ConvergedReason.CONVERGED_FNORM_ABS
        if it == 0:
            self._f0 = fnorm
            self._fnorms = []
        self._fnorms.append(fnorm)
        # a negligible update converges, unless the iterate blew up (a tiny
        # step relative to a huge solution must not accept |r| = 1e29)
        if it > 0 and ynorm <= o.stol * xnorm and fnorm <= self._f0:
            return PETSc.SNES.ConvergedReason.CONVERGED_SNORM_RELATIVE
        if it >= o.max_it:
            return PETSc.SNES.ConvergedReason.DIVERGED_MAX_IT
        if cycling(self._fnorms):
            self._cycled = True  # step_to names it (SNES knows no such reason)
            return PETSc.SNES.ConvergedReason.DIVERGED_DTOL
        return PETSc.SNES.ConvergedReason.CONVERGED_ITERATING

    def _log(self, msg: str) -> None:
        if self.options.verbose and self.comm.rank == 0:
            print(msg, flush=True)

    # -- counters --------------------------------------------------------------
    @property
    def counters(self) -> dict:
        """What this solver did so far, failed attempts included: Newton
        solves and iterations, residual and tangent evaluations,
        factorizations (numeric LU or LDL^T, and symbolic), linear solves
        and their wall time (from PETSc's event log), failed attempts,
        accepted steps, the stability check's searches for zero-energy
        motions and eigen-solves for critical modes (SLEPc; both reuse the
        Newton factorization: solves only) and their wall time."""
        now = event_counts()
        out = dict(self._counts)
        for k, v in now.items():
            out[k] = v - self._events_at_start.get(k, 0)
        out["factorizations"] = out["lu_factorizations"] + out["ldlt_factorizations"]
        out["factorization_seconds"] = (out["lu_factorizations_seconds"]
                                        + out["ldlt_factorizations_seconds"])
        out["forced_factorizations"] = self.linear.forced
        return out

    # -- load steps ------------------------------------------------------------
    def _effects_step(self, method: str) -> tuple[bool, str]:
        """Call ``method`` of every effect (prepare, update); GeometryError
        on any rank makes the attempt fail. Returns (changed, error)."""
        m = self.model
        error, changed = "", False
        try:
            results = [getattr(e, method)(m) for e in m.effects]
            changed = any(bool(r) for r in results)
        except _cpp.GeometryError as exc:
            error = str(exc)
        m.start_newton()  # the tangents of the Newton solve that follows count from 0
        errors = [e for e in self.comm.allgather(error) if e]
        return self.comm.allreduce(changed), (errors[0] if errors else "")

    def step_to(self, t: float, predict: bool = True) -> Attempt:
        """One load-step attempt at load factor t from the current state:
        effects prepare (at the converged state), predictor, then Newton
        (loop 3) repeated while an effect updates what Newton held fixed
        (loops 1-2: contact elements, normals, penalties)."""
        m, o = self.model, self.options
        m.domain_error = None
        # at the last converged state: history (e.g. friction stick points)
        # carries over to re-detected elements without the step's increment
        _, error = self._effects_step("prepare")
        if error:
            return Attempt(False, reason=PETSc.SNES.ConvergedReason.DIVERGED_FUNCTION_DOMAIN,
                           message=f"preparing effects: {error}")
        # the converged state is the linearization point of the predictor
        m.set_linearization_point()
        prev = self._previous
        t_n = m.load_factor
        m.load_factor = t
        if predict and o.predictor != "none" and prev is not None and prev[0] < t_n:
            t_prev, x_prev = prev
            plain = m.x.copy()
            # x += (t - t_n) / (t_n - t_prev) * (x_n - x_prev)
            m.x.axpy((t - t_n) / (t_n - t_prev), m.x - x_prev)
            if o.predictor == "auto" and self._residual_norm(m.x) > self._residual_norm(plain):
                plain.copy(m.x)  # the extrapolation is worse than none
            plain.destroy()
        m.apply_constraints(m.x)
        attempt = Attempt(False)
        for outer in range(1, o.max_updates + 1):
            attempt.updates = outer
            if self.comm.allreduce(m.matrix_stale):
                # new couplings (contact): a matrix preallocated for them
                self.snes.setJacobian(self._jacobian, *self.linear.operators(m.rebuild_matrix()))
            for retry in range(o.max_it):
                self._counts["newton_solves"] += 1
                self._cycled = False
                self.snes.solve(None, m.x)
                attempt.reason = self.snes.getConvergedReason()
                if self._cycled:
                    attempt.reason = DIVERGED_NEWTON_CYCLE
                    attempt.message = ("the residual repeats itself (contact or "
                                       "stick-slip switches flipping, or stuck)")
                its = self.snes.getIterationNumber()
                self._counts["newton_iterations"] += its
                attempt.iterations += its
                attempt.residual_norms += [float(r) for r in
                                           self.snes.getConvergenceHistory()[0][: its + 1]]
                if not (attempt.reason == PETSc.SNES.ConvergedReason.DIVERGED_LINEAR_SOLVE
                        and m.domain_error is None):
                    break
                if self.linear.grow_workspace(self.snes):
                    # MUMPS out of its workspace estimate: again with more
                    self._counts["linear_solve_retries"] += 1
                    self._log(f"  MUMPS's workspace estimate was too small: relaxed to "
                              f"{self.linear.relaxation()}%, solving again")
                    continue
                if not self.linear.krylov:
                    break
                # GMRES with a reused or approximate factorization failed:
                # go on from this iterate with a fresh, exact one
                self._counts["linear_solve_retries"] += 1
                self.linear.force_refactorization()
            if m.domain_error is not None:
                # (PETSc may have stopped on the infinite residual first)
                attempt.reason = PETSc.SNES.ConvergedReason.DIVERGED_FUNCTION_DOMAIN
                attempt.message = str(m.domain_error)
                return attempt
            if attempt.reason <= 0 or not np.isfinite(m.x.norm()):
                return attempt
            changed, error = self._effects_step("update")
            if error:
                attempt.reason = PETSc.SNES.ConvergedReason.DIVERGED_FUNCTION_DOMAIN
                attempt.message = f"updating effects: {error}"
                return attempt
            if not changed:
                attempt.converged = True
                return attempt
        attempt.reason = DIVERGED_EFFECTS_UNSETTLED
        attempt.message = (f"effects (contact elements, normals, penalties) still changing "
                           f"after {o.max_updates} Newton solves")
        return attempt

    # -- stability ---------------------------------------------------------------
    def _inertia(self) -> Inertia:
        """Negative eigenvalues of the tangent at the converged state, from
        the Newton factorization (textile.stability): its negative pivots,
        less the multipliers' and the zero-energy motions'."""
        if self.options.stability_check == "off":
            return Inertia(None)
        if not getattr(self, "_factor_near", False) and self.linear.kind == "cholesky":
            self._factorize_at_solution()
        ksp = self.snes.getKSP()
        negative = factor_negative_pivots(ksp)
        if negative is None:
            return Inertia(None)
        # a saddle point (multipliers) has one negative eigenvalue per
        # constraint row by construction (Sylvester)
        pivots = negative - self.model.saddle_point_rows
        if pivots <= 0:
            return Inertia(pivots, pivots)
        # some negative pivots may be round-off of zero-energy motions
        t0 = time.perf_counter()
        try:
            motions = zero_energy_motions(self.model, self.model.A)
            negative = pivots - zero_motion_pivots(ksp.getPC(), [z.vector for z in motions])
        finally:
            self._counts["zero_motion_searches"] += 1
            self._counts["zero_motion_seconds"] += time.perf_counter() - t0
        return Inertia(negative, pivots, motions)

    def _factorize_at_solution(self) -> None:
        """Factorize the exact tangent at the converged state (the Newton
        solve ended without a factorization close enough to it)."""
        m = self.model
        newton, m.newton = m.newton, "standard"
        try:
            self._counts["jacobian_evaluations"] += 1
            m.jacobian(None, m.x, m.A, m.A)
        finally:
            m.newton = newton
        ksp = self.snes.getKSP()
        ksp.setOperators(m.A, m.A)
        ksp.setUp()
        self._factor_near = True

    def _check_stability(self, t: float) -> dict:
        """At a converged step: count negative eigenvalues, warn the first
        time stability is lost, switch branch if asked."""
        o = self.options
        inertia = self._inertia()
        out = dict(negative_eigenvalues=inertia.negative, negative_pivots=inertia.pivots,
                   zero_energy_motions=inertia.zero, branch_switched=False)
        if not inertia.checked:
            return out
        if inertia.motions and not self._warned_singular:
            self._warned_singular = True
            self._warn(f"the tangent is singular at t={t:.6g}: {inertia.zero} zero-energy "
                       f"motion(s): {describe(inertia.motions)}; their round-off pivots are "
                       f"not counted as negative eigenvalues (hold them if they should be)")
        before = self._negative
        if inertia.negative > before and o.branch_switching:
            switched = self._switch_branch(t, inertia, before)
            if switched is not None:
                inertia = switched
                out.update(negative_eigenvalues=inertia.negative, negative_pivots=inertia.pivots,
                           zero_energy_motions=inertia.zero, branch_switched=True)
        if inertia.negative > 0 and not self._warned_unstable:
            self._warned_unstable = True
            hint = ("" if o.branch_switching else
                    "; SolverOptions(branch_switching=True) follows the stable branch")
            self._warn(f"stability lost at t={t:.6g}: the tangent has {inertia.negative} "
                       f"negative eigenvalue(s), the equilibrium followed is unstable (a "
                       f"bifurcation or limit point was passed){hint}")
        self._negative = inertia.negative
        return out

    def _critical_modes(self, count: int, deflate):
        """critical_modes of the current factorization, counted and timed."""
        t0 = time.perf_counter()
        try:
            return critical_modes(self.snes.getKSP(), self.model.constrained_positions(), count,
                                  self.comm, deflate)
        finally:
            self._counts["eigen_solves"] += 1
            self._counts["eigen_solve_seconds"] += time.perf_counter() - t0

    def _load_pattern(self, t: float) -> PETSc.Vec:
        """d(external load)/dt at the current state: minus the residual's
        derivative in the load factor (a finite difference; exact for dead
        loads), zero on constrained rows."""
        m = self.model
        h = 1e-6 * max(abs(t), 1.0)
        r0, r1 = m.b.duplicate(), m.b.duplicate()
        m.residual(None, m.x, r0)
        m.load_factor = t + h
        m.invalidate_constraints()
        m.residual(None, m.x, r1)
        m.load_factor = t
        m.invalidate_constraints()
        m.residual(None, m.x, m.b)  # leave the model's residual at t
        f = r0
        f.axpy(-1.0, r1)
        f.scale(1.0 / h)
        f.getArray()[m.residual_groups.rows["constraints"]] = 0.0
        r1.destroy()
        return f

    def _switch_branch(self, t: float, found: Inertia, before: int) -> Inertia | None:
        """Perturb the unstable converged state along its critical modes and
        solve again at the same load; the first stable answer is kept.

        The direction is the part of the load pattern f along the critical
        modes, d = sum_i (phi_i . f) phi_i, oriented so that the load does
        positive work along it: an imperfection (a small lateral force)
        picks its own branch, as the physical structure would; a perfect
        structure falls back to the first mode, both signs."""
        m, o = self.model, self.options
        self._log(f"  t={t:.6g}: unstable ({found.negative} negative eigenvalue(s)): branch "
                  f"switching along the critical modes (SLEPc)")
        values, modes = self._critical_modes(found.negative - before,
                                             [z.vector for z in found.motions or []])
        if not modes:
            return None
        f = self._load_pattern(t)
        d = modes[0].duplicate()
        d.set(0.0)
        for mode in modes:
            d.axpy(mode.dot(f), mode)
        work = d.dot(f)
        directions = [d, -d] if work > 1e-12 * f.norm() * d.norm() \
            else [modes[0], -modes[0]]
        unstable = m.x.copy()
        length = max(f_.length for f_ in m.mesh.fibres)
        positions = m.residual_groups.rows["positions"]
        stable = []  # (state, inertia) of stable equilibria found
        for amplitude in o.branch_amplitudes:
            for direction in directions:
                scale = self.comm.allreduce(
                    float(np.abs(direction.getArray(readonly=True)[positions]).max(initial=0.0)),
                    op=max_op())
                if scale == 0:
                    continue
                unstable.copy(m.x)
                m.x.axpy(amplitude * length / scale, direction)
                for e in m.effects:
                    e.restore(m)
                attempt = self.step_to(t, predict=False)
                inertia = self._inertia()
                if attempt.converged and inertia.checked and inertia.negative <= before:
                    stable.append((m.x.copy(), inertia))
            if stable:
                break
        if not stable:
            unstable.copy(m.x)
            for e in m.effects:
                e.restore(m)
            self.step_to(t, predict=False)  # effects, residual and tangent at it again
            self._warn(f"branch switching at t={t:.6g} found no stable equilibrium near the "
                       f"unstable one (amplitudes {o.branch_amplitudes} of the fibre length)")
            return None
        # of several stable equilibria, the one of least potential energy
        best, inertia = stable[0]
        for x, i in stable[1:]:
            if self._energy_difference(best, x) < 0:
                best, inertia = x, i
        best.copy(m.x)
        for e in m.effects:
            e.restore(m)
        attempt = self.step_to(t, predict=False)  # effects and tangent at the chosen state
        self._log(f"    branch switched at t={t:.6g} along the critical mode(s) "
                  f"(eigenvalue {values[0]:.3g})")
        return self._inertia() if attempt.converged else inertia

    def _energy_difference(self, xa: PETSc.Vec, xb: PETSc.Vec) -> float:
        """Potential energy of state b minus state a (same load factor):
        the residual integrated along the straight path between them (4-point
        Gauss), over the free unknowns (exact for conservative effects)."""
        m = self.model
        dx = xb.copy()
        dx.axpy(-1.0, xa)
        free = np.ones(len(dx.getArray()), dtype=bool)
        free[m.residual_groups.rows["constraints"]] = False
        x = xa.duplicate()
        r = m.b.duplicate()
        total = 0.0
        points, weights = np.polynomial.legendre.leggauss(4)
        for p, w in zip(points, weights):
            xa.copy(x)
            x.axpy(0.5 * (p + 1.0), dx)
            m.residual(None, x, r)
            total += 0.5 * w * float(np.dot(r.getArray(readonly=True)[free],
                                            dx.getArray(readonly=True)[free]))
        return self.comm.allreduce(total)

    def _diagnose(self, t: float) -> str:
        """Why the path may have ended, from the converged steps: the
        current stiffness parameter (Bergan) S = (f.du_1/dt_1) / (f.du_n/dt_n),
        the stiffness along the load pattern f relative to the first step's,
        falls to 0 at a limit point; and the last state's stability."""
        notes = []
        if self._negative:
            notes.append(f"the last converged state is unstable ({self._negative} negative "
                         f"eigenvalue(s) of the tangent)")
        if self._first_increment is not None and self._previous is not None:
            dt1, du1 = self._first_increment
            t_prev, x_prev = self._previous
            dun = self.model.x - x_prev
            f = self._load_pattern(t)
            c1, cn = f.dot(du1) / dt1, f.dot(dun) / (t - t_prev)
            if c1 > 0 and cn != 0 and c1 / cn < 0.2:
                notes.append(f"the stiffness along the load has fallen to {100 * c1 / cn:.1f}% "
                             f"of its initial value (current stiffness parameter): a limit point "
                             f"(the largest load this structure carries) is near; load control "
                             f"cannot pass it: prescribe displacements instead")
        return "".join(f"; {n}" for n in notes)

    def _warn(self, message: str) -> None:
        if self.comm.rank == 0:
            warnings.warn(message, StabilityWarning, stacklevel=3)
        if self.output is not None:
            self.output.warning(message)

    # -- stages ------------------------------------------------------------------
    #: options a stage may change (the linear solver is set once)
    STAGE_OPTIONS = {"initial_step", "min_step", "max_step", "grow", "cut", "easy_iterations",
                     "max_it", "max_updates", "newton", "predictor", "branch_switching",
                     "branch_amplitudes", "verbose"}

    def run(self, stages) -> list[StepRecord]:
        """Run a sequence of :class:`textile.loading.Stage`, each from load
        factor 0 to 1, continuing from the state the previous one left."""
        stages = list(stages)
        for k, stage in enumerate(stages):
            if self.output is not None:  # pictures of the final state only
                self.output.hold_pictures = k < len(stages) - 1
            self.run_stage(stage)
        return self.history

    def run_stage(self, stage: Stage, t_end: float = 1.0) -> list[StepRecord]:
        """Start ``stage`` where the current one ended and solve it to its
        load factor ``t_end`` (default 1, its end; :meth:`solve` goes on
        from there, with the solver's own options). The current stage must
        be complete (load factor 1), unless nothing has been solved yet."""
        if not isinstance(stage, Stage):
            raise TypeError(f"expected a textile.Stage, got {type(stage).__name__}")
        m = self.model
        unknown = set(stage.solver) - self.STAGE_OPTIONS
        if unknown:
            raise ValueError(f"Stage {stage.name!r}: solver options {sorted(unknown)} cannot "
                             f"change between stages; allowed: {sorted(self.STAGE_OPTIONS)}")
        # combined with the run's options before anything changes: a stage
        # whose step sizes conflict with the run's is refused, not left begun
        options = dataclasses.replace(self._base_options, **stage.solver)
        if self._stage_started:
            if m.load_factor < 1.0 - 1e-14:
                if self._resuming is not None and stage.name == self._stage.name:
                    return self._resume_stage(stage)
                raise RuntimeError(f"stage {self._stage.name!r} stopped at load factor "
                                   f"{m.load_factor:.6g}: finish it (run_stage with that "
                                   f"stage) before starting {stage.name!r}")
            m.finish_stage()
            self._stage_index += 1
        self._stage = stage
        if m.begin_stage(stage):
            # the prescribed set changed: a new matrix for the new rows
            self.snes.setJacobian(self._jacobian, *self.linear.operators(m.A))
        self.options = options
        self._previous = None  # no secant predictor across stages
        self._log(f"stage {self._stage_index}: {stage.name}")
        try:
            return self.solve(t_end)
        finally:
            self.options = self._base_options

    def _resume_stage(self, stage: Stage) -> list[StepRecord]:
        """Go on with the stage a saved state stopped in (see resume): its
        handles again (the callables of s are not saved), not its effect
        options (the effects saved theirs), its solver options."""
        m = self.model
        before = [s.snapshot() for s in m.schedules()]
        stage.apply(effects=False)
        try:
            self._check_following(self._resuming["following"], stage.name)
        except ValueError:
            for s, snap in zip(m.schedules(), before):
                s.restore(snap)
            raise
        self._stage = stage
        if m.update_constraints():   # the saved releases again: the same set, as a rule
            self.snes.setJacobian(self._jacobian, *self.linear.operators(m.A))
        self.options = dataclasses.replace(self._base_options, **stage.solver)
        self._log(f"stage {self._stage_index}: {stage.name} resumed at s={m.load_factor:.6g}")
        try:
            return self.solve(1.0)
        finally:
            self.options = self._base_options

    # -- saved states (textile.io.state_file) -------------------------------------
    def position(self) -> dict:
        """Where the run stands, for a saved state: the stage (name, index),
        the run's time, the steps converged so far, the step size the next
        step takes (0 once the stage is complete), the load factor of the
        secant predictor's earlier state (-1: none) and the negative
        eigenvalues at the last step; stage_started is 0 before any solve
        (the next stage starts from the saved state)."""
        m = self.model
        within = self._stage_started and m.load_factor < 1.0 - 1e-14
        return dict(stage=self._stage.name, stage_index=self._stage_index,
                    stage_started=int(self._stage_started),
                    time=self._stage_index + m.load_factor,
                    steps=self._steps_before + len(self.history),
                    next_step=float(self._next_step or 0.0) if within else 0.0,
                    previous_load_factor=float(self._previous[0])
                    if within and self._previous is not None else -1.0,
                    negative_eigenvalues=self._negative)

    def previous_state(self) -> PETSc.Vec | None:
        """The secant predictor's earlier state (see position), or None."""
        m = self.model
        within = self._stage_started and m.load_factor < 1.0 - 1e-14
        return self._previous[1] if within and self._previous is not None else None

    def resume(self, position: dict, previous: PETSc.Vec | None,
               following: list[np.ndarray], matrix_changed: bool = False) -> None:
        """Continue from a saved state (:func:`textile.load_state`, which has
        set the model): ``position`` as :meth:`position` gave it,
        ``previous`` the predictor's earlier state, ``following`` per
        schedule of the model the components that followed a callable of s
        when saved. A state saved within a stage goes on in it with the
        saved step size and predictor, as the saving run would have:
        :meth:`run_stage` with that stage (or :meth:`solve` for a scene's
        first, implicit stage). ``matrix_changed``: loading changed the
        constrained set, so the model has a new system matrix."""
        m = self.model
        if matrix_changed:
            self.resume_matrix()
        self._stage = Stage(str(position["stage"]))
        self._stage_index = int(position["stage_index"])
        self._stage_started = bool(position.get("stage_started", True))
        self._steps_before = int(position.get("steps", 0))
        self._negative = int(position.get("negative_eigenvalues", 0))
        self._previous = None
        self._resuming = None
        if self._stage_started and m.load_factor < 1.0 - 1e-14:
            if previous is not None:
                self._previous = (float(position["previous_load_factor"]), previous)
            step = float(position.get("next_step", 0.0))
            self._resuming = dict(next_step=step if step > 0 else None, following=following)

    def resume_matrix(self) -> None:
        """The model has a new system matrix (a loaded state changed the
        constrained set): solve with it."""
        self.snes.setJacobian(self._jacobian, *self.linear.operators(self.model.A))

    def _check_following(self, saved: list[np.ndarray], stage: str) -> None:
        """A resumed stage: the components that followed a callable of s
        when the state was saved must follow one again (the Stage given to
        run_stage, or the scene's own for its first stage)."""
        for sched, mask in zip(self.model.schedules(), saved):
            now = sched.following()
            if now.shape != mask.shape or np.any(now != mask):
                differ = np.flatnonzero(now != mask) if now.shape == mask.shape \
                    else np.arange(len(mask))
                raise ValueError(
                    f"resuming stage {stage!r}: components {differ[:5].tolist()} of "
                    f"schedule {sched.name!r} followed a callable of s when the state was "
                    f"saved and do not now, or the other way round: resume with the Stage "
                    f"that gives them (solver.run_stage(stage)), on the scene built as it was")

    def _residual_norm(self, x: PETSc.Vec) -> float:
        """Norm of the residual at x with the constraints of the current
        load factor applied (inf outside the domain); x is not changed."""
        m = self.model
        y = x.copy()
        m.apply_constraints(y)
        r = m.b.duplicate()
        self._residual(None, y, r)
        m.domain_error = None
        norm = r.norm()
        y.destroy()
        r.destroy()
        return norm if np.isfinite(norm) else np.inf

    def solve(self, t_end: float = 1.0) -> list[StepRecord]:
        """Advance the current stage from its load factor to ``t_end``
        (default 1, the stage's end)."""
        self._stage_started = True
        if not hasattr(self, "_t0"):
            self._t0 = time.perf_counter()
        o, m = self.options, self.model
        if not (isinstance(t_end, (int, float)) and math.isfinite(t_end)):
            raise ValueError(f"t_end must be a finite number, got {t_end!r}")
        t = m.load_factor
        dt = min(o.initial_step, o.max_step)
        if self._resuming is not None:
            # a stage resumed from a saved state: its step size and callables
            self._check_following(self._resuming["following"], self._stage.name)
            resuming, self._resuming = self._resuming, None
            if resuming["next_step"] is not None:
                dt = resuming["next_step"]
        x_saved = m.x.copy()
        attempts = 0
        while t < t_end - 1e-14:
            step = min(dt, t_end - t)
            t0 = time.perf_counter()
            attempt = self.step_to(t + step)
            attempts += 1
            if not attempt.converged:
                self._counts["failed_attempts"] += 1
                x_saved.copy(m.x)
                m.load_factor = t
                for e in m.effects:
                    e.restore(m)
                dt = step * o.cut
                self._log(f"  step to t={t + step:.6g} failed ({attempt.describe()}): "
                          f"cutting to dt={dt:.3g}")
                if dt < o.min_step:
                    msg = (f"load step from t={t:.6g} did not converge even with dt < "
                           f"min_step={o.min_step:g}; last attempt: {attempt.describe()}"
                           f"{self._diagnose(t)}; "
                           f"{len(self.history)} converged steps are kept")
                    if self.output is not None:
                        self.output.failure(msg)
                    raise ConvergenceError(msg)
                continue
            stability = self._check_stability(t + step)
            for e in m.effects:
                e.commit(m)
            # no secant predictor across a jump to another branch
            self._previous = None if stability["branch_switched"] else (t, x_saved.copy())
            if self._first_increment is None:
                self._first_increment = (step, m.x - x_saved)
            t += step
            m.x.copy(x_saved)
            stats = {}
            for e in m.effects:
                stats.update(e.statistics())
            # the next step's size (known before on_step: a state saved there
            # goes on as this run does)
            if attempt.iterations <= o.easy_iterations:
                dt = min(step * o.grow, o.max_step)
            else:
                dt = step
            self._next_step = dt
            rec = StepRecord(self._steps_before + len(self.history) + 1, t, attempt.iterations,
                             attempts, attempt.residual_norms, time.perf_counter() - t0,
                             attempt.reason, self.comm.allreduce(m.beam.energy),
                             attempt.updates, stats,
                             m.residual_groups.as_dict(m.residual_norms), stability,
                             self._stage.name, self._stage_index + t)
            self.history.append(rec)
            self._counts["accepted_steps"] += 1
            # petsc4py keeps dropped parallel objects (old vectors, a
            # replaced matrix) until a collective clean-up: here, every step
            PETSc.garbage_cleanup(self.comm)
            attempts = 0
            self._log(f"step {rec.step:4d}  {self._stage.name} s={t:.4f}  "
                      f"newton {attempt.iterations:2d}  solves {attempt.updates:2d}  "
                      f"|r| {rec.residual_norms[-1] if rec.residual_norms else float('nan'):.1e}"
                      f"  {rec.wall_time:6.2f} s  (total {time.perf_counter() - self._t0:.1f} s)")
            if self.output is not None:
                self.output.write_step(self, rec)
            if self.on_step is not None:
                self.on_step(self, rec)
        return self.history
