"""What a solver run is told: :class:`SolverOptions`; the reasons a step
fails (SNES's own and the solver's, :func:`reason_name`), the solver's
errors and its progress lines (what it reports of each attempt and step:
:mod:`textile.solver.records`)."""
from __future__ import annotations

from dataclasses import dataclass, field

from petsc4py import PETSc

from ..log import get_logger
from ..options import Options

_LOG = get_logger("textile.solver")


class ConvergenceError(RuntimeError):
    """A load step could not be completed even with the smallest step."""


class StabilityWarning(UserWarning):
    """A converged equilibrium is unstable (negative eigenvalues)."""


#: Reasons of a failed attempt that are not SNES's own.
DIVERGED_EFFECTS_UNSETTLED = -200
DIVERGED_NEWTON_CYCLE = -201
DIVERGED_NEWTON_STALL = -202
_OWN_REASONS = {DIVERGED_EFFECTS_UNSETTLED: "DIVERGED_EFFECTS_UNSETTLED",
                DIVERGED_NEWTON_CYCLE: "DIVERGED_NEWTON_CYCLE",
                DIVERGED_NEWTON_STALL: "DIVERGED_NEWTON_STALL"}


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
    grow, cut, easy_iterations, regrow_after:
        Step multiplier after an easy step (<= easy_iterations Newton
        iterations), and after a failed one; after a cut, regrow_after
        steps in a row at one size also grow the next (0, default: never;
        capped contact passes are never easy: the lifting weave uses 3).
    rtol, atol, floor_factor, stol, max_it:
        Newton convergence, tested per group of unknowns (fibre positions,
        fibre section vectors, each other field, constrained rows; see
        :mod:`textile.solver.convergence`): a group has converged when its residual
        norm is below rtol times its value at the start of the Newton solve,
        or below floor_factor * eps * |(|K||q|)_group| (its round-off floor),
        or below atol times its force scale (the largest fibre E*A; times the
        largest radius for section vectors). Or: the Newton update is below
        stol times the solution (relative). max_it: Newton iterations per
        solve; one whose residual repeats itself (``cycling``) stops before,
        as DIVERGED_NEWTON_CYCLE, one that stalls as DIVERGED_NEWTON_STALL.
    path_rtol:
        Newton's tolerance on a stage's path, for stages whose states before
        their end are no answer (a weave's heddles letting go, a drag
        fading): a step before the stage's end (load factor < 1) has
        converged when every group's residual has fallen below path_rtol
        times its value at the step's first Newton iteration (or meets the
        test above); the stage's end to the full test. 0 (default): every step
        to the full test. The lifting weave uses 1e-3
        (:class:`textile.fabric.Weaving`; benchmarks/README.md, "Newton on
        the weave's path to a looser tolerance").
    line_search:
        SNES line search; "basic" (full Newton steps, default): the residual
        norm mixes forces on positions and on section vectors, which misleads
        norm-decrease searches such as "bt" on these beams; failed steps are
        cut instead.
    cycle_line_search:
        A solve whose residual cycles under full steps (or a step's capped
        solves, together) goes on once with this SNES line search ("l2",
        default; "bt", "cp"), within max_it; "none": a cycle fails at once
        (benchmarks/README.md, "A line search after a Newton cycle").
    max_updates:
        Newton solves per step while effects update what Newton holds fixed
        (contact elements, normals, penalties); a step still changing after
        that many, or whose changes' trend or cycle cannot settle in the
        solves left (``convergence.effects_unsettled``), is cut.
    newton_per_pass:
        0 (default): each of those Newton solves runs to convergence before
        the effects update. n > 0: the effects update after at most n Newton
        iterations (the contact passes' frozen normals and elements are a
        fixed point that the solve in between need not settle first); Newton
        then goes on from there. A step is accepted, as with 0, only when a
        solve has converged and no effect changed after it, so the answer
        meets the same tolerances. Only the first half of the max_updates
        solves are capped, and none after the effects settled after a capped
        one or stopped settling (their change not 5% below the pass before:
        ``convergence.capped_passes_stalled``; effects that flip at
        unconverged states, such as stick and slip, settle once the solves
        converge). The lifting weave of bundles
        uses 3
        (:class:`textile.fabric.Weaving`; benchmarks/README.md, "Contact
        passes with capped Newton solves").
    loop_relaxation:
        "none" (default): each contact pass starts where the last Newton
        solve ended. "aitken": the passes' motion is relaxed by Aitken's
        factor (:mod:`textile.solver.loop_relaxation`), which lands a loop
        that contracts linearly on its fixed point in a few passes; the
        effects update at the relaxed state too, and the step still ends
        only after a plain pass at a converged state: the same answer.
    newton:
        "mip" (default; mixed integration point Newton: the beams' geometric
        stiffness uses the stress extrapolated linearly from the previous
        iterate, which keeps Newton from overshooting on large rotations) or
        "standard" (the exact tangent every iteration). The converged answer
        is the same (iteration counts: benchmarks/README.md, "Solver
        options").
    predictor:
        How a step starts. "secant": on the line through the stage's last
        two converged states; "parabola": on the parabola through its last
        three (the secant at its second step); with the MIP Newton their
        first tangent takes the stress extrapolated as the state is. They
        suit smooth paths (large rotations: a roll-up needs 4 iterations a
        step with the parabola) and overshoot contacts coming on. "none":
        from the last converged state with the new loads and prescribed
        values. "auto" (default): the parabola with the MIP Newton when
        every effect of the scene is smooth along the path
        (Effect.smooth_path: no contact); otherwise it evaluates the
        secant's start and the plain one and keeps the one with the smaller
        residual (two residual evaluations a step), its first tangent
        linearized from the converged state (a start chosen step by step
        may sit where the path turns, where the stress's trend misleads).
        Iteration counts: benchmarks/README.md, "Solver options" and "A
        predictor that extrapolates the stress too".
    linear_solver:
        "mumps" (default), "superlu_dist" or "petsc" (serial).
    factorization:
        "auto" (LDL^T in the stages where every effect's tangent is
        symmetric, e.g. friction switched off, else LU), "lu" or "cholesky"
        (LDL^T, symmetric indefinite).
    reuse_factorization:
        1: factorize the tangent every Newton iteration. n > 1: keep a
        factorization for up to n iterations as the preconditioner of GMRES
        on the exact tangent (see :mod:`textile.solver.linear_solver`).
    krylov_rtol, krylov_max_it:
        GMRES tolerance and iteration limit when a factorization is reused
        or approximate.
    scaling:
        How MUMPS's LU factorizations (not LDL^T, not the Krylov paths) see
        the tangent: "diagonal" (default) scaled symmetrically by its
        diagonal; "mumps": unscaled, MUMPS's own scaling at every
        factorization. The same answer (benchmarks/README.md, "MUMPS scaling").
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
        sections free to spin, ...; see :mod:`textile.stability.inertia`); checked
        in the stages whose tangent is symmetric, not otherwise. Recorded per
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
    describe_instability:
        With branch switching off: where a step loses stability, compute its
        critical mode all the same (one SLEPc eigen-solve on the Newton
        factorization) and record what it is (``critical_mode``: eigenvalue,
        share of each group of unknowns, checked with the assembled tangent),
        to tell a physical instability from a numerical one.
    verbose:
        Print one progress line per step on rank 0.
    """

    initial_step: float = 0.1
    min_step: float = 1e-4
    max_step: float = 0.25
    grow: float = 1.5
    cut: float = 0.5
    easy_iterations: int = 4
    regrow_after: int = 0
    rtol: float = 1e-10
    atol: float = 1e-13
    floor_factor: float = 10.0
    stol: float = 1e-10
    max_it: int = 25
    path_rtol: float = 0.0
    line_search: str = "basic"
    cycle_line_search: str = "l2"
    newton: str = "mip"
    predictor: str = "auto"
    max_updates: int = 20
    newton_per_pass: int = 0
    loop_relaxation: str = "none"
    linear_solver: str = "mumps"
    factorization: str = "auto"
    reuse_factorization: int = 1
    krylov_rtol: float = 1e-9
    krylov_max_it: int = 40
    scaling: str = "diagonal"
    low_rank_tolerance: float = 0.0
    petsc_options: dict = field(default_factory=dict)
    stability_check: str = "auto"
    branch_switching: bool = True
    branch_amplitudes: tuple = (0.01, 0.05, 0.2, 0.5, 1.0)
    describe_instability: bool = False
    verbose: bool = True

    kind = "solver"

    def __post_init__(self):
        self.require_positive("initial_step", "min_step", "max_step", "grow", "cut", "rtol",
                              "atol", "floor_factor", "stol", "krylov_rtol")
        if not self.min_step <= self.initial_step <= self.max_step <= 1.0:
            raise ValueError("SolverOptions: need 0 < min_step <= initial_step <= max_step <= 1")
        if not 0 < self.cut < 1 or self.grow < 1:
            raise ValueError("SolverOptions: need 0 < cut < 1 and grow >= 1")
        choices = dict(newton=("standard", "mip"),
                       predictor=("auto", "secant", "parabola", "none"),
                       linear_solver=("mumps", "superlu_dist", "petsc"),
                       factorization=("auto", "lu", "cholesky"),
                       stability_check=("auto", "off"), scaling=("diagonal", "mumps"),
                       cycle_line_search=("none", "l2", "bt", "cp"),
                       loop_relaxation=("none", "aitken"))
        for name, allowed in choices.items():
            if getattr(self, name) not in allowed:
                raise ValueError(f"SolverOptions.{name} must be one of {allowed}, "
                                 f"got {getattr(self, name)!r}")
        for name in ("max_it", "max_updates", "reuse_factorization", "krylov_max_it",
                     "easy_iterations"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or v < 1:
                raise ValueError(f"SolverOptions.{name} must be a positive integer, got {v!r}")
        for name in ("newton_per_pass", "regrow_after"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or v < 0:
                raise ValueError(f"SolverOptions.{name} must be a non-negative integer, "
                                 f"got {v!r}")
        for name in ("branch_switching", "describe_instability", "verbose"):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(f"SolverOptions.{name} must be True or False, "
                                 f"got {getattr(self, name)!r}")
        v = self.path_rtol
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0 <= v < 1:
            raise ValueError(f"SolverOptions.path_rtol must be in [0, 1), got {v!r}")
        if not (isinstance(self.low_rank_tolerance, (int, float))
                and 0 <= self.low_rank_tolerance < 1):
            raise ValueError("SolverOptions.low_rank_tolerance must be in [0, 1)")


def say(options: SolverOptions, comm, msg: str) -> None:
    """One progress line (the ``textile.solver`` logger, INFO) from the
    solver's rank 0 when ``options.verbose``."""
    if options.verbose and comm.rank == 0:
        _LOG.info(msg)
