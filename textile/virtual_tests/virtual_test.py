"""What every virtual test shares: a woven sample driven by side bodies
through a release stage and a loading stage, a load curve recorded at
every step, the balance of the side bodies' reactions checked, and the
results written for a person to look at.

A concrete test (tension, shear, ...) says which sides get a body and how
they are held (:meth:`VirtualTest.hold`), what it ramps
(:meth:`VirtualTest.drive`) and what it measures at a step
(:meth:`VirtualTest.measure`).

The curve is the side's reaction as computed, not tared: its first point
is the released (settled) sample's, which holds the woven state's own
stresses (the crimped yarns' bending, the contact forces between them)
and is not zero on a finite sample; the load then moves from it alike
both ways (benchmarks/README.md, "The shear curve's start"). Stiffnesses
are slopes, so the start does not enter them; the figures give it under
``START_FIGURE`` (a test machine's preload, which an experiment tares).
"""
from __future__ import annotations

import json
import os
import time
from dataclasses import dataclass, field

import numpy as np
from mpi4py import MPI

from .. import presets
from ..composite.composite import Composite
from ..beam.fibre_loads import FIGURES, fibre_loads, ranked_table
from ..fabric.fabric import Fabric
from ..scene.loading import Stage
from ..beam.material import Material
from ..fabric.sample import Sample
from ..io.state_file import SceneMismatchError, StateFileError, load_state, save_state
from ..solver import ConvergenceError, Solver
from .load_curve import LoadCurve

#: the figure holding the curve's first point: the released sample's
#: reaction (module docstring)
START_FIGURE = "load at the start (the released sample's reaction)"


@dataclass
class VirtualTestResult:
    """What a virtual test gives back (every rank gets the same).

    Attributes
    ----------
    name:
        The test ("tension", "shear", ...).
    curve:
        The :class:`~textile.virtual_tests.load_curve.LoadCurve` (first point:
        the released sample, not tared: module docstring).
    steps:
        Per loading step: step number, load factor, Newton iterations,
        attempts (failed ones included), wall seconds, the reactions'
        balance (:meth:`VirtualTest.balance`) and the test's own figures.
    figures:
        The test's summary (e.g. a membrane stiffness, a locking angle).
    wall_seconds:
        The whole run (release and loading), construction excluded.
    counters:
        The solver's counters (factorizations, Newton solves, ...).
    """

    name: str
    curve: LoadCurve
    steps: list = field(default_factory=list)
    figures: dict = field(default_factory=dict)
    wall_seconds: float = 0.0
    counters: dict = field(default_factory=dict)
    #: per fibre at the last step (:func:`textile.beam.fibre_loads.fibre_loads`)
    fibre_loads: dict = field(default_factory=dict)
    #: each fibre's yarn, for tables
    fibre_yarn: np.ndarray | None = None

    def ranked_table(self, count: int = 10) -> str:
        """The most loaded fibres at the last step (a line saying there is
        none when the test stopped before its first loading step)."""
        if not self.fibre_loads:
            return "no loading step: no fibre loads"
        return ranked_table(self.fibre_loads, count=count, yarn=self.fibre_yarn)

    @property
    def force_balance(self) -> float:
        """The largest force imbalance over the loading steps
        (:meth:`VirtualTest.balance`)."""
        return max((s["force_balance"] for s in self.steps), default=0.0)

    @property
    def moment_balance(self) -> float:
        """The largest moment imbalance over the loading steps."""
        return max((s["moment_balance"] for s in self.steps), default=0.0)

    def write(self, directory: str) -> list[str]:
        """``<name>.csv``, ``<name>.png`` and ``<name>.json`` (the steps and
        figures) and ``<name>_fibres.txt`` in ``directory`` (call on one
        rank); the paths of the first three (no PNG when the test stopped
        before its first loading step: LoadCurve.write)."""
        paths = self.curve.write(directory, self.name)
        with open(os.path.join(directory, f"{self.name}_fibres.txt"), "w") as f:
            f.write(self.ranked_table(count=20) + "\n")
        path = os.path.join(directory, f"{self.name}.json")
        with open(path, "w") as f:
            json.dump(dict(name=self.name, figures=self.figures, wall_seconds=self.wall_seconds,
                           curve=dict(x=self.curve.x, y=self.curve.y, xlabel=self.curve.xlabel,
                                      ylabel=self.curve.ylabel),
                           steps=self.steps, counters=self.counters,
                           most_loaded_fibres=[int(i) for i in
                                               self.fibre_loads.get("most_loaded", [])[:20]]),
                      f, indent=1, default=float)
        return paths + [path]


class IncompleteTest(ConvergenceError):
    """A virtual test stopped before its last load step (a step failed even
    with the smallest increment). ``result`` holds what the converged steps
    gave (curve, steps, figures of that range, counters), already written to
    the test's output directory if it has one: nothing computed is lost,
    and nothing passes for a finished test."""

    def __init__(self, message: str, result: "VirtualTestResult"):
        super().__init__(message)
        self.result = result


def figures_table(results: dict) -> str:
    """A printable table of the figures of several results ({label:
    VirtualTestResult}): one row per label and figure, e.g. the membrane
    stiffnesses of tension and shear tests side by side."""
    rows = [(label, name, value) for label, r in results.items()
            for name, value in r.figures.items()
            if name not in ("width", "gauge length")]
    w1 = max([len(r[0]) for r in rows] + [4])
    w2 = max([len(r[1]) for r in rows] + [6])
    lines = [f"{'test':<{w1}}  {'figure':<{w2}}  value"]
    for label, name, value in rows:
        text = "not reached" if value is None else f"{value:.4g}"
        lines.append(f"{label:<{w1}}  {name:<{w2}}  {text}")
    return "\n".join(lines)


class VirtualTest:
    """A virtual test on a woven sample (module docstring).

    Parameters
    ----------
    fabric, woven:
        The :class:`~textile.fabric.Fabric` and the path of its saved woven
        state (:func:`textile.save_state` after a weaving run).
    steps:
        Load steps of the loading stage.
    matrix:
        None (the fabric alone) or the matrix :class:`~textile.beam.material.Material`
        (a :class:`~textile.composite.Composite`); ``composite`` holds more
        of its options (size, degree, ...).
    contact:
        Fibre-fibre contact options. A fabric alone needs friction (its yarns
        would slide freely over each other otherwise): default friction 0.2.
    release_steps:
        Steps of the first stage, which lets the free yarn ends go; 0: no
        such stage, the free yarn ends keep, as dead loads, the forces that
        held them in the woven state (the yarns' weaving tension): a small
        sample's yarns with free ends rest on a few crossings only and can
        slide away once let go. Default (None): 2 with a matrix (the matrix
        takes the yarns' weaving tension over), 0 without.
    settle_drag:
        A fabric alone: 0 (default) or the coefficient of a drag on the
        fibres' centre lines through the first stage, faded out to none at
        its end (:class:`~textile.fabric.sample.Sample`'s ``settle_drag``):
        bundles whose friction starts afresh settle with it.
    turning_ends:
        A fabric alone: may the bodies at the free yarn ends turn
        (:class:`~textile.fabric.sample.Sample`'s ``turning_ends``; None,
        default: not at bundles' ends, which keep their woven orientation).
    solver_options:
        :class:`~textile.solver.SolverOptions` entries (tolerances, linear
        solver, verbose).
    output:
        Directory for the ParaView series, results.json and pictures of
        every step (None: nothing written during the run).
    checkpoint:
        None, or the path stem of a checkpoint written after every converged
        step: ``<checkpoint>.h5`` (the state, :func:`textile.save_state`)
        and ``<checkpoint>.json`` (the result so far: curve, steps, fibre
        loads, counters, wall time). ``run(resume=True)`` goes on from it:
        a run of hours stopped (a session's end, a killed process) loses at
        most the step it was in.
    preset:
        Accuracy preset (:mod:`textile.presets`; None: "standard"): the
        contact options (under the friction default above), the matrix's
        ``size`` and ``degree`` and the solver options are its, except those
        given (``contact``, ``composite`` and ``solver_options`` entries).
    comm:
        MPI communicator.
    """

    name = "virtual test"
    xlabel = ""
    ylabel = ""
    #: sides with a body, and those of them pinned (not clamped)
    sides: tuple = ("xmin", "xmax")
    pins: tuple = ()
    split: tuple = ()
    #: after a cut, loading steps grow again once this many converged in a
    #: row at one size (SolverOptions.regrow_after): no loading step is
    #: "easy" on a bundle sample, and without it a test goes on at its
    #: hardest step's size. The picture frame's 63 deg: 477 Newton
    #: iterations against 881; the 6 x 6 shear of 7-fibre bundles: the
    #: same 63-64 min, its failed attempts at regrown steps (65 iterations
    #: each) taking what the fewer steps save (benchmarks/README.md,
    #: "Loading steps that grow again after a cut")
    REGROW_AFTER = 3
    #: Newton iterations between contact updates in the loading of a fabric
    #: of bundles (SolverOptions.newton_per_pass): the contact loop between
    #: bundles converges linearly over 5-13 passes a step, which capped
    #: solves need not each settle. The 3-fibre bundle sample's shear,
    #: tension, bending, twisting: 35, 37, 43, 43 Newton iterations against
    #: 43, 51, 55, 59; the 6 x 6 sample of 7-fibre bundles sheared to the
    #: end in 64 min, where solves to convergence reached 0.80 of the load
    #: in 51 min (benchmarks/README.md, "The bundle shear's contact loop",
    #: "Capped solves in a bundle sample's loading"). Not on monofilaments
    #: or flat rows, whose loop settles in 1-2 passes: the tests' 2 x 2
    #: monofilament shear took 54 against 38.
    NEWTON_PER_PASS_BUNDLES = 2
    #: the contact loop's passes relaxed in the loading of a fabric of
    #: bundles (SolverOptions.loop_relaxation): its slow passes swing
    #: between contact states, which Aitken's factor (0.25-0.55 there)
    #: damps (benchmarks/README.md, "Aitken relaxation of the contact loop")
    LOOP_RELAXATION_BUNDLES = "aitken"
    #: called as on_step(solver, step record) after every converged step
    #: (progress reports, partial results of long runs)
    on_step = None

    def __init__(self, fabric: Fabric, woven: str, steps: int = 10, matrix: Material | None = None,
                 composite: dict | None = None, contact=None, release_steps: int | None = None,
                 settle_drag: float = 0.0, turning_ends: bool | None = None,
                 solver_options: dict | None = None, output: str | None = None,
                 checkpoint: str | None = None, preset: str | None = None,
                 comm=MPI.COMM_WORLD):
        if woven is None or not isinstance(woven, (str, os.PathLike)):
            raise TypeError(f"{type(self).__name__}: woven must be the path of a saved woven "
                            f"state (textile.save_state after a Weaving run), got {woven!r}")
        if not (composite is None or isinstance(composite, dict)):
            raise TypeError(f"{type(self).__name__}: composite must be a dict of Composite "
                            f"options or None, got {composite!r}")
        if not (output is None or isinstance(output, (str, os.PathLike))):
            raise TypeError(f"{type(self).__name__}: output must be the path of a directory "
                            f"or None (nothing written), got {output!r}")
        if not (checkpoint is None or isinstance(checkpoint, (str, os.PathLike))):
            raise TypeError(f"{type(self).__name__}: checkpoint must be a path stem (for "
                            f"<stem>.h5 and <stem>.json) or None, got {checkpoint!r}")
        preset = presets.checked(preset, type(self).__name__)
        if release_steps is None:
            release_steps = 2 if matrix is not None else 0
        for label, v, low in (("steps", steps, 1), ("release_steps", release_steps, 0)):
            if isinstance(v, bool) or not isinstance(v, int) or v < low:
                raise ValueError(f"{type(self).__name__}: {label} must be an integer >= {low}, "
                                 f"got {v!r}")
        if contact is None:
            contact = dict(friction=0.0 if matrix is not None else 0.2)
        if matrix is None:
            if composite:
                raise ValueError(f"{type(self).__name__}: composite options {composite!r} "
                                 f"without a matrix")
            self.sample = Sample(fabric, str(woven), sides=self.sides, pins=self.pins,
                                 split=self.split, contact=contact, preset=preset,
                                 settle_drag=settle_drag, turning_ends=turning_ends,
                                 comm=comm)
        else:
            if settle_drag:
                raise ValueError(f"{type(self).__name__}: settle_drag is for a fabric alone "
                                 f"(the matrix holds a composite's fibres)")
            if turning_ends is not None:
                raise ValueError(f"{type(self).__name__}: turning_ends is for a fabric alone "
                                 f"(a composite's free fibre ends have no end bodies)")
            if self.pins:
                raise ValueError(f"{type(self).__name__}: pinned sides are not available with "
                                 f"a matrix (a matrix face follows its body fully)")
            self.sample = Composite(fabric, str(woven), matrix, sides=self.sides,
                                    contact=contact, preset=preset, comm=comm,
                                    **(composite or {}))
        self.steps, self.release_steps = steps, release_steps
        self.preset = preset
        self.solver_options = presets.solver(preset, dict(verbose=False)
                                             | dict(solver_options or {}))
        self.output_dir = output
        self.checkpoint = None if checkpoint is None else str(checkpoint)
        #: what an earlier run resumed from the checkpoint did (counters, wall time)
        self._earlier: dict = {}
        self.comm = comm
        self.gauge = self.sample.side_distance("x")

    # -- what a concrete test says ---------------------------------------------
    def drive(self) -> dict:
        """Hold the side bodies; return {handle: target at the stage end} of
        the loading stage (before the model is solved)."""
        raise NotImplementedError

    def measure(self, s: float) -> tuple[float, float, dict]:
        """(abscissa, ordinate, figures) at the loading stage's load factor
        ``s`` (collective)."""
        raise NotImplementedError

    def summarize(self, result: VirtualTestResult) -> dict:
        """The test's figures from its curve."""
        return {}

    # -- shared ----------------------------------------------------------------
    def balance(self) -> tuple[float, float]:
        """(force imbalance, moment imbalance) of the loads on the sample
        (:meth:`~textile.fabric.sample.Sample.reaction_balance`): |sum of the
        forces| over the largest body force, and |sum of the moments about
        the origin| over the largest body moment about the origin (forces
        at the body centres included). The forces balance to the Newton
        tolerance; the moments only up to the couples of friction and
        woven contacts, which the contact formulation applies on the centre
        lines (collective)."""
        total = self.sample.reaction_balance()
        bodies = self.sample.model.rigid_bodies
        r, c = bodies.reactions(), bodies.positions()
        f = np.linalg.norm(r[:, 0:3], axis=1).max()
        m = np.linalg.norm(r[:, 3:6] + np.cross(c, r[:, 0:3]), axis=1).max()
        return (float(np.linalg.norm(total[0:3]) / f) if f > 0 else 0.0,
                float(np.linalg.norm(total[3:6]) / m) if m > 0 else 0.0)

    def first_stage(self) -> Stage:
        """The stage before the loading: it lets the free yarn ends go
        (``release_steps`` > 0), or only settles the loaded woven state with
        this test's contact options; over it, the woven state's friction
        forces and the side bodies' free components are released
        (:class:`~textile.fabric.sample.Sample`), and a ``settle_drag``
        fades out. The curve starts where it ends."""
        if self.release_steps:
            stage = self.sample.release_stage(self.release_steps)
            steps = self.release_steps
        else:
            steps = self.sample.SETTLE_DRAG_STEPS if self.sample.drag is not None else 1
            stage = Stage("settle", solver=dict(initial_step=1.0 / steps, max_step=1.0 / steps))
        stage.effects.update(self.sample.settle_drag_effects(steps))
        return stage

    def loading_stage(self, targets: dict) -> Stage:
        """The test's loading, to ``targets`` ({handle: target at its end},
        :meth:`drive`'s) in ``steps`` steps: a step cut after a failed
        attempt grows back after ``REGROW_AFTER`` steps converged in a row
        at its size; on a fabric of bundles its Newton solves are capped at
        ``NEWTON_PER_PASS_BUNDLES`` iterations between contact updates and
        the passes relaxed (``LOOP_RELAXATION_BUNDLES``; the
        ``solver_options``' ``regrow_after``, ``newton_per_pass`` and
        ``loop_relaxation`` win)."""
        bundles = self.sample.fabric.has_bundles
        passes = self.solver_options.get("newton_per_pass",
                                         self.NEWTON_PER_PASS_BUNDLES if bundles else 0)
        relaxation = self.solver_options.get("loop_relaxation",
                                             self.LOOP_RELAXATION_BUNDLES if bundles else "none")
        regrow = self.solver_options.get("regrow_after", self.REGROW_AFTER)
        return Stage(self.name, ramp=targets, effects=self.sample.drag_off_effects(),
                     solver=dict(initial_step=1.0 / self.steps, max_step=1.0 / self.steps,
                                 regrow_after=regrow, newton_per_pass=passes,
                                 loop_relaxation=relaxation))

    def run(self, resume: bool = False) -> VirtualTestResult:
        """Release (or settle), then load step by step; the result
        (collective). A step that fails even with the smallest increment
        raises :class:`IncompleteTest`, whose ``result`` holds the steps
        done (written out like a finished test's). ``resume``: go on from
        the ``checkpoint`` an earlier run of the same test wrote (its steps,
        counters and wall time count in the result)."""
        if resume and self.checkpoint is None:
            raise ValueError(f"{type(self).__name__}.run(resume=True) needs the checkpoint "
                             f"the earlier run wrote (checkpoint=...)")
        targets = self.drive()
        # what the side bodies leave free lets the woven state go over the
        # first stage, not at once
        self.sample.hold_side_reactions()
        stages = [self.first_stage(), self.loading_stage(targets)]
        what = "composite" if isinstance(self.sample, Composite) else "woven sample"
        curve = LoadCurve(self.xlabel, self.ylabel, title=f"{self.name} of the {what}")
        result = VirtualTestResult(self.name, curve,
                                   fibre_yarn=np.asarray(self.sample.fabric.fibre_yarn))

        def add_point(rec):
            s = rec.load_factor if rec.stage == self.name else 0.0
            x, y, figures = self.measure(s)
            curve.add(x, y)
            if rec.stage == self.name:
                force_balance, moment_balance = self.balance()
                loads = fibre_loads(self.sample.model)
                top = int(loads["most_loaded"][0])
                result.steps.append(dict(
                    step=rec.step, load_factor=s, newton_iterations=rec.newton_iterations,
                    attempts=rec.attempts, wall_seconds=rec.wall_time,
                    force_balance=force_balance, moment_balance=moment_balance, x=x, y=y,
                    most_loaded_fibre=top,
                    **{k: float(loads[k][top]) for k in FIGURES}, **figures))
                result.fibre_loads = loads

        def record(solver, rec):
            # the curve starts where the release (or settling) ends
            if rec.stage == self.name or rec.load_factor >= 1.0:
                add_point(rec)
            if self.checkpoint is not None:
                self._save_checkpoint(solver, result, t0)
            if self.on_step is not None:
                self.on_step(solver, rec)

        output = self.sample.output(self.output_dir) if self.output_dir else None
        solver = Solver(self.sample.model, self.solver_options, output=output, on_step=record)
        resumed = self._load_checkpoint(solver, result) if resume else None
        t0 = time.perf_counter()
        try:
            solver.run(stages, resumed=resumed)
        except ConvergenceError as error:
            # keep what the converged steps gave, flagged as incomplete
            self._finish(result, solver, t0)
            raise IncompleteTest(
                f"{self.name} stopped at load factor "
                f"{result.steps[-1]['load_factor'] if result.steps else 0.0:.6g} of 1 after "
                f"{len(result.steps)} loading steps"
                f"{'; what it did is in ' + self.output_dir if self.output_dir else ''}: "
                f"{error}", result) from error
        self._finish(result, solver, t0)
        return result

    # -- checkpoint -----------------------------------------------------------
    def _so_far(self, solver: Solver, t0: float) -> tuple[float, dict]:
        """(wall seconds, counters) of the run so far, an earlier run's
        (resumed from its checkpoint) included."""
        counters = dict(self._earlier.get("counters", {}))
        for k, v in solver.counters.items():
            counters[k] = counters.get(k, 0) + v
        return self._earlier.get("wall_seconds", 0.0) + time.perf_counter() - t0, counters

    def _save_checkpoint(self, solver: Solver, result: VirtualTestResult, t0: float) -> None:
        """The state and the result so far (class docstring's ``checkpoint``;
        collective). Each file is replaced whole; both carry the count of
        converged steps, so a run killed between the two writes leaves a
        pair that :meth:`_load_checkpoint` refuses, never a curve with a
        step missing."""
        save_state(self.sample.model, self.checkpoint + ".h5", solver,
                   fibre_data={"yarn": self.sample.fabric.fibre_yarn})
        converged = solver.position()["steps"]
        wall, counters = self._so_far(solver, t0)
        if self.comm.rank == 0:
            loads = {k: np.asarray(v).tolist() for k, v in result.fibre_loads.items()}
            tmp = self.checkpoint + ".json.tmp"
            with open(tmp, "w") as f:
                json.dump(dict(test=self.name, steps_asked=self.steps,
                               converged_steps=converged,
                               curve=dict(x=result.curve.x, y=result.curve.y),
                               steps=result.steps, fibre_loads=loads, counters=counters,
                               wall_seconds=wall), f, default=float)
            os.replace(tmp, self.checkpoint + ".json")

    def _load_checkpoint(self, solver: Solver, result: VirtualTestResult) -> dict:
        """Set the model and the solver to the checkpoint's state and
        ``result`` to its rows; returns what load_state returned (for
        :meth:`Solver.run`'s ``resumed``). Collective. A missing or
        unreadable checkpoint, or a state and rows that disagree, raise
        StateFileError; a checkpoint of another test SceneMismatchError
        (both ValueErrors)."""
        saved = None
        if self.comm.rank == 0:
            try:
                with open(self.checkpoint + ".json") as f:
                    saved = json.load(f)
            except (OSError, ValueError) as e:
                saved = f"{self.checkpoint}.json: {e}"
        saved = self.comm.bcast(saved)
        name = type(self).__name__
        if isinstance(saved, str):
            raise StateFileError(f"{name}: no checkpoint to resume from: {saved}")
        if (saved.get("test"), saved.get("steps_asked")) != (self.name, self.steps):
            raise SceneMismatchError(f"{name}: {self.checkpoint}.json is a checkpoint of "
                                     f"{saved.get('test')!r} in {saved.get('steps_asked')} "
                                     f"steps, not of {self.name!r} in {self.steps}")
        attrs = load_state(self.sample.model, self.checkpoint + ".h5", solver)
        if int(attrs["steps"]) != saved["converged_steps"]:
            raise StateFileError(f"{name}: {self.checkpoint}.h5 holds the state after "
                                 f"{int(attrs['steps'])} steps, its .json the rows of "
                                 f"{saved['converged_steps']} (the run was stopped between "
                                 f"the two writes): run the test again from the start")
        result.curve.x[:], result.curve.y[:] = saved["curve"]["x"], saved["curve"]["y"]
        result.steps[:] = saved["steps"]
        result.fibre_loads = {k: np.asarray(v) for k, v in saved["fibre_loads"].items()}
        self._earlier = dict(counters=saved["counters"], wall_seconds=saved["wall_seconds"])
        return attrs

    def _finish(self, result: VirtualTestResult, solver: Solver, t0: float) -> None:
        """Wall time, counters and figures of the steps done (an earlier
        run's, resumed from its checkpoint, included); written out."""
        result.wall_seconds, result.counters = self._so_far(solver, t0)
        # a curve needs the released state and a loading step
        result.figures = self.summarize(result) if result.steps else {}
        if result.steps:
            result.figures[START_FIGURE] = float(result.curve.y[0])
        if self.output_dir and self.comm.rank == 0 and result.curve.x:
            result.write(self.output_dir)
