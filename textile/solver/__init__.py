"""Load stepping with one PETSc SNES over the model's monolithic system.

Each step raises the load factor t (loads and prescribed displacements
scale with it), predicts the new state, and runs Newton (SNES ``newtonls``)
with a direct solver (:mod:`textile.solver.linear_solver`). Convergence is tested
per group of unknowns, each on its own scale (:mod:`textile.solver.convergence`).

A step attempt fails when Newton does not converge (too many iterations, a
failed linear solve), when the residual is not finite, when an iterate
leaves the model's domain (:class:`textile.GeometryError`: a folded
element, ...), or when effects keep changing what Newton holds fixed. A
failed attempt is restored and the step cut; easy steps let the step grow.
A step that cannot be completed ends the run with :class:`ConvergenceError`,
which names the reason in words; every converged step is on disk by then.
Any other exception raised inside an effect is a bug: it propagates with
its traceback.

The parts, each a module of this package:

- :mod:`.options`: :class:`SolverOptions`, the failure reasons and the
  errors; :mod:`.records`: :class:`Attempt` and :class:`StepRecord`;
- :mod:`.newton`: one Newton solve (SNES, linear solver, convergence test,
  cycle detection), :class:`~.newton.Newton`;
- :mod:`.contact_loop`: one load-step attempt (effects prepare, predictor,
  Newton repeated while effects update), :class:`~.contact_loop.ContactLoop`;
- :mod:`.stability_check`: inertia, branch switching, limit points at a
  converged step, :class:`~.stability_check.StabilityCheck`;
- :mod:`.stepping`: step control (:class:`~.stepping.StepControl`), the
  path and the history, :class:`~.stepping.Stepping`;
- :mod:`.stages`: stages one after another and resumed runs,
  :class:`~.stages.Stages`.

The numerics they use: :mod:`.convergence` (the per-group convergence
test) and :mod:`.linear_solver` (the direct solver, MUMPS LU or LDL^T, and
PETSc's event counts), modules of this package; the stability check's
inertia, critical modes and zero-energy motions in :mod:`textile.stability`.

:class:`Solver` composes them.
"""
from __future__ import annotations

import warnings
from typing import TYPE_CHECKING

from petsc4py import PETSc

from .. import _cpp  # noqa: F401 (re-exported: textile.solver's names as before the split)
from ..scene.loading import Stage  # noqa: F401
from ..options import Options  # noqa: F401
from ..stability.inertia import (Inertia, critical_modes, factor_negative_pivots,  # noqa: F401
                                 zero_motion_pivots)
from ..stability.zero_motions import describe, zero_energy_motions  # noqa: F401
from .contact_loop import ContactLoop
from .convergence import GroupTolerances  # noqa: F401
from .linear_solver import LinearSolver, event_counts  # noqa: F401
from .newton import (CYCLE_ITERATIONS, CYCLE_PERIOD, CYCLE_TOLERANCE,  # noqa: F401
                     Newton, NewtonResult, _forget_options, cycling, new_counts)
from .options import (_OWN_REASONS, DIVERGED_EFFECTS_UNSETTLED,  # noqa: F401
                      DIVERGED_NEWTON_CYCLE, DIVERGED_NEWTON_STALL,
                      ConvergenceError, StabilityWarning, SolverOptions, reason_name, say)
from .records import Attempt, StepRecord  # noqa: F401
from .branch_switching import max_op  # noqa: F401
from .stability_check import StabilityCheck  # noqa: F401
from .stages import STAGE_OPTIONS, Stages
from .stepping import StepControl, Stepping  # noqa: F401

if TYPE_CHECKING:  # the model imports .convergence, so this package, first
    from ..scene.model import Model


class Solver:
    """Drive a :class:`~textile.Model` through load steps with one SNES.

    Parameters
    ----------
    model:
        The scene.
    options:
        :class:`SolverOptions` or a dict of its fields.
    output:
        Optional :class:`~textile.io.output.Output` (ParaView files, results.json)
        written after every converged step.
    on_step:
        Optional callable ``(solver, record)`` after each converged step,
        e.g. to record a load curve.

    The parts: ``newton`` (:class:`Newton`: one Newton solve), ``loop``
    (:class:`ContactLoop`: one load-step attempt), ``stability``
    (:class:`StabilityCheck`), ``stepping`` (:class:`Stages`: steps,
    stages, history).
    """

    #: options a stage may change (the linear solver is set once)
    STAGE_OPTIONS = STAGE_OPTIONS

    def __init__(self, model: Model, options=None, output=None, on_step=None):
        self.model = model
        options = options if isinstance(options, SolverOptions) \
            else SolverOptions.from_dict(options)
        self.output = output
        self.on_step = on_step
        system = model.system   # the scene closes here
        system.newton = options.newton
        self.comm = model.comm
        self._counts = new_counts()
        self.newton = Newton(system, options, self._counts)  # starts PETSc's event log
        self._events_at_start = event_counts()
        self.loop = ContactLoop(self.newton)
        self.stability = StabilityCheck(self.loop, self._warn)
        self.stepping = Stages(self, self.loop, self.stability)

    # -- the parts' state, as before the split ---------------------------------
    @property
    def options(self) -> SolverOptions:
        """The options in force (a stage's while it runs)."""
        return self.stepping.options

    @options.setter
    def options(self, options: SolverOptions) -> None:
        self.stepping.options = options

    @property
    def history(self) -> list[StepRecord]:
        """Every converged step of this solver (:class:`StepRecord`)."""
        return self.stepping.history

    @property
    def snes(self) -> PETSc.SNES:
        """The Newton solver's SNES (replaceable by a proxy of it)."""
        return self.newton.snes

    @snes.setter
    def snes(self, snes) -> None:
        self.newton.snes = snes

    @property
    def linear(self):
        """The Newton solver's :class:`~textile.solver.linear_solver.LinearSolver`."""
        return self.newton.linear

    @property
    def prefix(self) -> str:
        """The PETSc options prefix of this solver's SNES/KSP/PC."""
        return self.newton.prefix

    @property
    def tolerances(self) -> GroupTolerances:
        return self.newton.tolerances

    # -- counters --------------------------------------------------------------
    @property
    def counters(self) -> dict:
        """What this solver did so far, failed attempts included: Newton
        solves and iterations, residual and tangent evaluations,
        factorizations (numeric LU or LDL^T, and symbolic), linear solves
        and their wall time (from PETSc's event log), failed attempts,
        accepted steps, the stability check's searches for zero-energy
        motions and eigen-solves for critical modes (SLEPc; both reuse the
        Newton factorization: solves only) and their wall time, the checks
        and their own wall time (``stability_check_seconds``; factorizations
        of the tangent at a converged state where Newton's last one was not
        at it: ``factorizations_at_solution``), branch switches and their
        wall time (critical modes and Newton solves)."""
        now = event_counts()
        out = dict(self._counts)
        for k, v in now.items():
            out[k] = v - self._events_at_start.get(k, 0)
        out["factorizations"] = out["lu_factorizations"] + out["ldlt_factorizations"]
        out["factorization_seconds"] = (out["lu_factorizations_seconds"]
                                        + out["ldlt_factorizations_seconds"])
        out["forced_factorizations"] = self.linear.forced
        return out

    def _log(self, msg: str) -> None:
        say(self.options, self.comm, msg)

    def _warn(self, message: str) -> None:
        if self.comm.rank == 0:
            warnings.warn(message, StabilityWarning, stacklevel=3)
        if self.output is not None:
            self.output.warning(message)

    # -- load steps and stages -------------------------------------------------
    def step_to(self, t: float, predict: bool = True) -> Attempt:
        """One load-step attempt at load factor t from the current state
        (:meth:`ContactLoop.step_to`, with the predictor's earlier
        states)."""
        return self.loop.step_to(t, predict, self.stepping.previous, self.stepping.older)

    def solve(self, t_end: float = 1.0) -> list[StepRecord]:
        """Advance the current stage from its load factor to ``t_end``
        (default 1, the stage's end)."""
        return self.stepping.solve(t_end)

    def run(self, stages, resumed: dict | None = None) -> list[StepRecord]:
        """Run a sequence of :class:`textile.scene.loading.Stage`, each from load
        factor 0 to 1, continuing from the state the previous one left (or,
        with ``resumed``, the attributes load_state returned, from that
        saved state: see :meth:`Stages.run`)."""
        return self.stepping.run(stages, resumed)

    def run_stage(self, stage: Stage, t_end: float = 1.0) -> list[StepRecord]:
        """Start ``stage`` where the current one ended and solve it to its
        load factor ``t_end`` (see :meth:`Stages.run_stage`)."""
        return self.stepping.run_stage(stage, t_end)

    # -- saved states (textile.io.state_file) ---------------------------------
    def position(self) -> dict:
        """Where the run stands, for a saved state (:meth:`Stages.position`)."""
        return self.stepping.position()

    def previous_state(self):
        """The predictor's earlier state (see position), or None."""
        return self.stepping.previous_state()

    def older_state(self):
        """The predictor's state before that (see position), or None."""
        return self.stepping.older_state()

    def resume(self, position: dict, previous, following, matrix_changed: bool = False,
               older=None) -> None:
        """Continue from a saved state (:meth:`Stages.resume`)."""
        self.stepping.resume(position, previous, following, matrix_changed, older)

    def resume_matrix(self) -> None:
        """The model has a new system matrix (a loaded state changed the
        constrained set): solve with it."""
        self.stepping.resume_matrix()
