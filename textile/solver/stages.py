"""Stages and saved states: stages run one after another, each from load
factor 0 to 1 from the state the previous one left, with its own solver
options (:data:`STAGE_OPTIONS`) and the scene's changes of
:class:`textile.scene.loading.Stage`; a run saved within a stage
(:mod:`textile.io.state_file`) goes on as the saving run would have.
"""
from __future__ import annotations

import dataclasses

import numpy as np
from petsc4py import PETSc

from ..scene.loading import Stage
from .records import StepRecord
from .stepping import Stepping

#: options a stage may change (the linear solver is set once)
STAGE_OPTIONS = {"initial_step", "min_step", "max_step", "grow", "cut", "easy_iterations",
                 "regrow_after",
                 "max_it", "path_rtol", "max_updates", "newton_per_pass", "loop_relaxation",
                 "newton", "predictor",
                 "branch_switching", "branch_amplitudes", "verbose"}


def stopped_within_stage(resumed: dict) -> bool:
    """Did the run a saved state's attributes (load_state's) describe stop
    inside a begun stage (not at its end)?"""
    return bool(int(resumed.get("stage_started", 1))) \
        and float(resumed["load_factor"]) < 1.0 - 1e-14


class Stages(Stepping):
    """:class:`Stepping` over a sequence of stages, resumable."""

    STAGE_OPTIONS = STAGE_OPTIONS

    def run(self, stages, resumed: dict | None = None) -> list[StepRecord]:
        """Run a sequence of :class:`textile.scene.loading.Stage`, each from load
        factor 0 to 1, continuing from the state the previous one left.
        ``resumed``: the attributes ``load_state(model, path, solver)``
        returned for a state saved during a run of the same stages; the run
        goes on from there (the stage it stopped in, or the next one)."""
        stages = list(stages)
        start = 0
        if resumed is not None:
            index = int(resumed.get("stage_index", 0))
            started = bool(int(resumed.get("stage_started", 1)))
            start = index if (stopped_within_stage(resumed) or not started) else index + 1
        for k in range(start, len(stages)):
            stage = stages[k]
            if self.owner.output is not None:  # pictures of the final state only
                self.owner.output.hold_pictures = k < len(stages) - 1
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
        options = dataclasses.replace(self.base_options, **stage.solver)
        if self.stage_started:
            if m.load_factor < 1.0 - 1e-14:
                if self.resuming is not None and stage.name == self.stage.name:
                    return self.resume_stage(stage)
                raise RuntimeError(f"stage {self.stage.name!r} stopped at load factor "
                                   f"{m.load_factor:.6g}: finish it (run_stage with that "
                                   f"stage) before starting {stage.name!r}")
            m.finish_stage()
            self.stage_index += 1
        self.stage = stage
        if m.begin_stage(stage):
            # the prescribed set changed: a new matrix for the new rows
            self.newton.set_operators(self.system.A)
        self.newton.stage_began()
        self.options = options
        self.previous = self.older = None  # no predictor across stages
        self.log(f"stage {self.stage_index}: {stage.name}")
        try:
            return self.solve(t_end)
        finally:
            self.options = self.base_options

    def resume_stage(self, stage: Stage) -> list[StepRecord]:
        """Go on with the stage a saved state stopped in (see resume): its
        handles again (the callables of s are not saved), its effect options
        through ``Effect.configure_resumed`` (what an effect saved stays),
        its solver options."""
        m = self.model
        before = [s.snapshot() for s in m.schedules()]
        stage.apply(effects=False)
        try:
            self.check_following(self.resuming["following"], stage.name)
        except ValueError:
            for s, snap in zip(m.schedules(), before):
                s.restore(snap)
            raise
        self.stage = stage
        if m.update_constraints():   # the saved releases again: the same set, as a rule
            self.newton.set_operators(self.system.A)
        self.newton.stage_began()
        self.options = dataclasses.replace(self.base_options, **stage.solver)
        self.log(f"stage {self.stage_index}: {stage.name} resumed at s={m.load_factor:.6g}")
        try:
            return self.solve(1.0)
        finally:
            self.options = self.base_options

    # -- saved states (textile.io.state_file) -------------------------------------
    def position(self) -> dict:
        """Where the run stands, for a saved state: the stage (name, index),
        the run's time, the steps converged so far, the step size the next
        step takes (0 once the stage is complete), the load factors of the
        predictor's earlier states (-1: none), the steps converged at the
        current size since the stage's last cut (-1: none; StepControl)
        and the negative
        eigenvalues at the last step; stage_started is 0 before any solve
        (the next stage starts from the saved state)."""
        m = self.model
        within = self.stage_started and m.load_factor < 1.0 - 1e-14
        return dict(stage=self.stage.name, stage_index=self.stage_index,
                    stage_started=int(self.stage_started),
                    time=self.stage_index + m.load_factor,
                    steps=self.steps_before + len(self.history),
                    next_step=float(self.next_step or 0.0) if within else 0.0,
                    steps_since_cut=self.control.since_cut if within and self.control
                    and self.control.since_cut is not None else -1,
                    previous_load_factor=float(self.previous[0])
                    if within and self.previous is not None else -1.0,
                    older_load_factor=float(self.older[0])
                    if within and self.older is not None else -1.0,
                    negative_eigenvalues=self.stability.negative)

    def _kept(self, earlier) -> PETSc.Vec | None:
        """An earlier state's vector while its stage goes on, else None."""
        within = self.stage_started and self.model.load_factor < 1.0 - 1e-14
        return earlier[1] if within and earlier is not None else None

    def previous_state(self) -> PETSc.Vec | None:
        """The predictor's earlier state (see position), or None."""
        return self._kept(self.previous)

    def older_state(self) -> PETSc.Vec | None:
        """The predictor's state before that (see position), or None."""
        return self._kept(self.older)

    def resume(self, position: dict, previous: PETSc.Vec | None,
               following: list[np.ndarray], matrix_changed: bool = False,
               older: PETSc.Vec | None = None) -> None:
        """Continue from a saved state (:func:`textile.load_state`, which has
        set the model): ``position`` as :meth:`position` gave it,
        ``previous`` and ``older`` the predictor's earlier states, ``following`` per
        schedule of the model the components that followed a callable of s
        when saved. A state saved within a stage goes on in it with the
        saved step size and predictor, as the saving run would have:
        :meth:`run_stage` with that stage (or :meth:`solve` for a scene's
        first, implicit stage). ``matrix_changed``: loading changed the
        constrained set, so the model has a new system matrix."""
        m = self.model
        if matrix_changed:
            self.resume_matrix()
        self.stage = Stage(str(position["stage"]))
        self.stage_index = int(position["stage_index"])
        self.stage_started = bool(position.get("stage_started", True))
        self.steps_before = int(position.get("steps", 0))
        self.stability.negative = int(position.get("negative_eigenvalues", 0))
        self.previous = self.older = None
        self.resuming = None
        if self.stage_started and m.load_factor < 1.0 - 1e-14:
            if previous is not None:
                self.previous = (float(position["previous_load_factor"]), previous)
                if older is not None and float(position.get("older_load_factor", -1.0)) >= 0:
                    self.older = (float(position["older_load_factor"]), older)
            step = float(position.get("next_step", 0.0))
            since = int(position.get("steps_since_cut", -1))
            self.resuming = dict(next_step=step if step > 0 else None, following=following,
                                 since_cut=since if since >= 0 else None)

    def resume_matrix(self) -> None:
        """The model has a new system matrix (a loaded state changed the
        constrained set): solve with it."""
        self.newton.set_operators(self.system.A)
