"""Step control: the load factor of a stage driven from where it stands to
its end in steps that are cut when an attempt fails and grow when Newton
has it easy (stages and saved states: :mod:`textile.solver.stages`).

:class:`StepControl` is the step-size rule alone; :class:`Stepping` drives
a :class:`~textile.solver.contact_loop.ContactLoop` with it and keeps the
path (the secant predictor's earlier state, the first increment), the
stage and the history of converged steps.
"""
from __future__ import annotations

import math
import time

import numpy as np
from petsc4py import PETSc

from ..scene.loading import Stage
from .contact_loop import ContactLoop
from .options import ConvergenceError, SolverOptions, say
from .records import StepRecord
from .stability_check import StabilityCheck


class StepControl:
    """The step-size rule of :class:`SolverOptions`: the first step
    ``min(initial_step, max_step)``; a failed attempt of size ``step`` is
    tried again with ``step * cut``, and the stage gives up once that is
    below ``min_step``; a converged step in at most ``easy_iterations``
    Newton iterations lets the next grow by ``grow`` (up to ``max_step``),
    otherwise it keeps its size, except after a cut: ``regrow_after``
    steps converged in a row at one size let it grow again. A step never
    passes the stage's end.

    ``since_cut``: steps converged at the current size since the stage's
    last cut (None: no cut yet; a resumed stage passes its saved count)."""

    def __init__(self, options: SolverOptions, since_cut: int | None = None):
        self.options = options
        self.since_cut = since_cut

    def first(self) -> float:
        return min(self.options.initial_step, self.options.max_step)

    @staticmethod
    def clip(dt: float, t: float, t_end: float) -> float:
        """The step taken from t with step size dt."""
        return min(dt, t_end - t)

    def failed(self, step: float) -> float:
        """The step size after a failed attempt of size step."""
        self.since_cut = 0
        return step * self.options.cut

    def gives_up(self, dt: float) -> bool:
        return dt < self.options.min_step

    def converged(self, step: float, iterations: int) -> float:
        """The next step size after a step converged in ``iterations``."""
        o = self.options
        if self.since_cut is not None:
            self.since_cut += 1
        if iterations <= o.easy_iterations or (
                o.regrow_after and self.since_cut is not None
                and self.since_cut >= o.regrow_after):
            if self.since_cut is not None:
                self.since_cut = 0
            return min(step * o.grow, o.max_step)
        return step


class Stepping:
    """Load steps and stages of ``loop`` (a ContactLoop) with ``stability``
    checked at every converged step; ``owner`` (the Solver) is what the
    output and the on_step callback are given."""

    def __init__(self, owner, loop: ContactLoop, stability: StabilityCheck):
        self.owner = owner
        self.loop = loop
        self.newton = loop.newton
        self.stability = stability
        #: the scene (schedules, stages) and its assembled system (the numerics)
        self.model = owner.model
        self.system = loop.system
        self.comm = loop.comm
        self.counts = loop.newton.counts
        self._options = loop.options
        self.base_options = loop.options
        self.history: list[StepRecord] = []
        self.previous = None  # (load factor, state) of the step before the last
        self.older = None  # the same one step earlier (the quadratic predictor)
        self.first_increment = None  # (dt, du) of the first converged step
        self.stage = Stage("load")   # the implicit first stage
        self.stage_index = 0
        self.stage_started = False
        #: the step size the next step of the stage takes (after a converged step)
        self.next_step: float | None = None
        #: the step-size rule of the stage being solved (its state is saved)
        self.control: StepControl | None = None
        #: steps converged before this solver (a run resumed from a saved state)
        self.steps_before = 0
        #: a stage resumed from a saved state in its middle: what its first
        #: solve needs (see resume)
        self.resuming: dict | None = None
        self.t0 = None  # the first solve's start (wall time in the log)

    @property
    def options(self) -> SolverOptions:
        return self._options

    @options.setter
    def options(self, options: SolverOptions) -> None:
        """A stage's options, for every part."""
        self._options = options
        for part in (self.newton, self.loop, self.stability):
            part.options = options

    def log(self, msg: str) -> None:
        say(self.options, self.comm, msg)

    def check_following(self, saved: list[np.ndarray], stage: str) -> None:
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

    def solve(self, t_end: float = 1.0) -> list[StepRecord]:
        """Advance the current stage from its load factor to ``t_end``
        (default 1, the stage's end)."""
        self.stage_started = True
        if self.t0 is None:
            self.t0 = time.perf_counter()
        o, m = self.options, self.system
        if not (isinstance(t_end, (int, float)) and math.isfinite(t_end)):
            raise ValueError(f"t_end must be a finite number, got {t_end!r}")
        t = m.load_factor
        control = self.control = StepControl(o)
        dt = control.first()
        if self.resuming is not None:
            # a stage resumed from a saved state: its step size and callables
            self.check_following(self.resuming["following"], self.stage.name)
            resuming, self.resuming = self.resuming, None
            if resuming["next_step"] is not None:
                dt = resuming["next_step"]
            control.since_cut = resuming["since_cut"]
        x_saved = m.x.copy()
        attempts = 0
        while t < t_end - 1e-14:
            step = control.clip(dt, t, t_end)
            t0 = time.perf_counter()
            attempt = self.loop.step_to(t + step, True, self.previous, self.older)
            attempts += 1
            if not attempt.converged:
                self.counts["failed_attempts"] += 1
                x_saved.copy(m.x)
                m.load_factor = t
                for e in m.effects:
                    e.restore(m)
                dt = control.failed(step)
                self.log(f"  step to t={t + step:.6g} failed ({attempt.describe()}): "
                         f"cutting to dt={dt:.3g}")
                if control.gives_up(dt):
                    msg = (f"load step from t={t:.6g} did not converge even with dt < "
                           f"min_step={o.min_step:g}; last attempt: {attempt.describe()}"
                           f"{self.stability.diagnose(t, self.previous, self.first_increment)}; "
                           f"{len(self.history)} converged steps are kept")
                    if self.owner.output is not None:
                        self.owner.output.failure(msg)
                    raise ConvergenceError(msg)
                continue
            stability = self.stability.check(t + step)
            for e in m.effects:
                e.commit(m)
            # no predictor across a jump to another branch
            switched = stability["branch_switched"]
            self.older = None if switched else self.previous
            self.previous = None if switched else (t, x_saved.copy())
            if self.first_increment is None:
                self.first_increment = (step, m.x - x_saved)
            t += step
            m.x.copy(x_saved)
            stats = {}
            for e in m.effects:
                stats.update(e.statistics())
            # the next step's size (known before on_step: a state saved there
            # goes on as this run does)
            dt = control.converged(step, attempt.iterations)
            self.next_step = dt
            rec = StepRecord(self.steps_before + len(self.history) + 1, t, attempt.iterations,
                             attempts, attempt.residual_norms, time.perf_counter() - t0,
                             attempt.reason, self.comm.allreduce(m.beam.energy),
                             attempt.updates, stats,
                             m.residual_groups.as_dict(m.residual_norms), stability,
                             self.stage.name, self.stage_index + t, attempt.passes)
            self.history.append(rec)
            self.counts["accepted_steps"] += 1
            # petsc4py keeps dropped parallel objects (old vectors, a
            # replaced matrix) until a collective clean-up: here, every step
            PETSc.garbage_cleanup(self.comm)
            attempts = 0
            self.log(f"step {rec.step:4d}  {self.stage.name} s={t:.4f}  "
                     f"newton {attempt.iterations:2d}  solves {attempt.updates:2d}  "
                     f"|r| {rec.residual_norms[-1] if rec.residual_norms else float('nan'):.1e}"
                     f"  {rec.wall_time:6.2f} s  (total {time.perf_counter() - self.t0:.1f} s)")
            if self.owner.output is not None:
                self.owner.output.write_step(self.owner, rec)
            if self.owner.on_step is not None:
                self.owner.on_step(self.owner, rec)
        return self.history
