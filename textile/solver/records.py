"""What a solver run reports: the outcome of one load-step attempt
(:class:`Attempt`) and the record of a converged step (:class:`StepRecord`)."""
from __future__ import annotations

from dataclasses import dataclass, field

from .options import reason_name


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
    #: per group: residual norm at convergence (see textile.solver.convergence)
    residuals: dict = field(default_factory=dict)
    #: negative eigenvalues of the tangent (None: not checked), the
    #: factorization's negative pivots and the zero-energy motions told
    #: apart from them (None: not searched, no negative pivot), and whether
    #: the step was moved to another branch (textile.stability.inertia)
    stability: dict = field(default_factory=dict)
    #: the stage this step belongs to, and the run's time (stage number +
    #: the stage's load factor: continuous over stages)
    stage: str = "load"
    time: float = 0.0
    #: per contact pass of the converged attempt: (Newton iterations, the
    #: largest effect change after it in units of its tolerance)
    passes: list = field(default_factory=list)

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
    #: per contact pass: (its Newton iterations, the largest effect change
    #: after it in units of the effect's tolerance; Effect.update_change)
    passes: list = field(default_factory=list)
    #: per pass after the first, the relaxation factor of its motion
    #: (SolverOptions.loop_relaxation "aitken"; 1: not relaxed)
    relaxation: list = field(default_factory=list)

    def describe(self) -> str:
        text = f"{reason_name(self.reason)} after {self.iterations} Newton iterations"
        return f"{text}: {self.message}" if self.message else text
