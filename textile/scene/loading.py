"""How loads and prescribed values evolve over a run made of stages.

A run is a sequence of *stages* (weave, release, load, ...). Within a stage
the load factor s goes from 0 to 1. Every loading quantity of a scene (a
prescribed displacement, a dead force, a moment, a rigid body's prescribed
component or load) lives in a :class:`Schedule` and, during a stage, is

- **ramped**: from its value at the stage start to a target, linearly in s;
- **held**: at its value at the stage start (everything not ramped);
- given by a callable of s (absolute values), or
- **released** (prescriptions only): no longer prescribed from the stage
  start on (the unknowns become free).

Before any stage is declared, a scene's quantities ramp from zero to the
values they were defined with: a plain ``Solver.solve()`` is one stage that
applies every load, as before stages existed.

A :class:`Handle` names some components of a schedule (what ``Model.fix``,
``Model.add_force``, ``RigidBody.prescribe``, ... return); a
:class:`Stage` says what happens to handles, effects and solver options.
"""
from __future__ import annotations

import inspect
import numbers
from dataclasses import dataclass, field

import numpy as np

from ..effects.base import Effect


class Handle:
    """Components ``index`` of ``schedule``: a quantity a stage can ramp,
    hold or release."""

    def __init__(self, schedule: "Schedule", index: np.ndarray, label: str):
        self.schedule = schedule
        self.index = np.asarray(index, dtype=np.int64)
        self.label = label

    @property
    def value(self) -> np.ndarray:
        """Value at the end of the last completed stage (or the start)."""
        return self.schedule.start[self.index].copy()

    def __repr__(self) -> str:
        return f"Handle({self.label!r}, {len(self.index)} component(s))"


class Schedule:
    """Scalar components that follow the stages (see the module docstring).

    ``target`` is where each component goes in the current stage, ``start``
    where it was at the stage start; ``active`` is False for released
    prescriptions.
    """

    def __init__(self, name: str):
        self.name = name
        self.start = np.zeros(0)
        self.target = np.zeros(0)
        self.active = np.zeros(0, dtype=bool)
        self._callables: list[tuple] = []  # (fun, positions, component of fun's output)

    def __len__(self) -> int:
        return len(self.start)

    def add(self, values, label: str) -> Handle:
        """New components ramping from 0 to ``values`` in the first stage;
        ``values`` may be a callable of s returning them all."""
        if callable(values):
            raise TypeError("use add_callable for callables")
        v = np.atleast_1d(np.asarray(values, dtype=float)).ravel()
        if not np.all(np.isfinite(v)):
            raise ValueError(f"{label}: values must be finite, got {values!r}")
        idx = np.arange(len(self.start), len(self.start) + len(v))
        self.start = np.concatenate([self.start, np.zeros(len(v))])
        self.target = np.concatenate([self.target, v])
        self.active = np.concatenate([self.active, np.ones(len(v), dtype=bool)])
        return Handle(self, idx, label)

    def add_callable(self, fun, size: int, label: str) -> Handle:
        """New components given by ``fun(s)`` (``size`` values) in the first
        stage; held at their final value afterwards."""
        h = self.add(np.zeros(size), label)
        self._callables.append((fun, h.index, np.arange(size)))
        return h

    # -- evaluation ------------------------------------------------------------
    def values(self, s: float) -> np.ndarray:
        """All components at stage load factor s."""
        v = self.start + s * (self.target - self.start)
        for fun, pos, comp in self._callables:
            out = np.atleast_1d(np.asarray(fun(s), dtype=float)).ravel()
            if not np.all(np.isfinite(out)):
                raise ValueError(f"{self.name}: a callable returned {out!r} at s={s}")
            v[pos] = out[comp]
        return v

    # -- stages ------------------------------------------------------------------
    def finish_stage(self) -> None:
        """The stage is complete: its end values become the next start, held
        unless the next stage says otherwise."""
        self.start = self.values(1.0)
        self.target = self.start.copy()
        self._callables = []

    def ramp(self, handle: Handle, target) -> None:
        t = np.broadcast_to(np.asarray(target, dtype=float), (len(handle.index),))
        if not np.all(np.isfinite(t)):
            raise ValueError(f"{handle.label}: ramp target must be finite")
        self.target[handle.index] = t
        self._callables = [c for c in self._callables if not np.isin(c[1], handle.index).any()]

    def follow(self, handle: Handle, fun) -> None:
        """Components given by ``fun(s)`` during this stage."""
        self._callables.append((fun, handle.index, np.arange(len(handle.index))))

    def following(self) -> np.ndarray:
        """True for the components given by a callable of s in this stage."""
        out = np.zeros(len(self.start), dtype=bool)
        for _, pos, _ in self._callables:
            out[pos] = True
        return out

    def has_callables(self) -> bool:
        """True if some components are given by a callable of s in this stage."""
        return bool(self._callables)

    def snapshot(self) -> tuple:
        """Everything a stage may change, for :meth:`restore`."""
        return self.start.copy(), self.target.copy(), self.active.copy(), list(self._callables)

    def restore(self, snapshot: tuple) -> None:
        self.start, self.target, self.active, self._callables = (
            snapshot[0].copy(), snapshot[1].copy(), snapshot[2].copy(), list(snapshot[3]))

    def load_saved(self, start, target, active, done=None) -> None:
        """Take the values a saved state holds (textile.io.state_file):
        each entry's stage start, target and whether it is active; ``done``
        (a mask, the current values): entries of a finished stage whose
        callables' end values stand for them from now on."""
        self.start = np.array(start, dtype=float)
        self.target = np.array(target, dtype=float)
        self.active = np.array(active, dtype=bool)
        if done is not None:
            mask, current = done
            self.start[mask] = self.target[mask] = np.asarray(current)[mask]

    def forget_callables(self) -> None:
        """Drop every callable: the components keep ``start`` and ``target``
        (a saved state sets them: :func:`textile.load_state`)."""
        self._callables = []

    def release(self, handle: Handle) -> None:
        self.active[handle.index] = False


def stage_options(effect) -> set[str]:
    """The options ``effect.configure`` declares: its named parameters (a
    catch-all ``**options`` declares none; configure refuses what it does
    not know)."""
    kinds = (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)
    return {p.name for p in inspect.signature(effect.configure).parameters.values()
            if p.kind in kinds}


#: the step sizes, which the solver's options order min <= initial <= max
_STEPS = ("min_step", "initial_step", "max_step")


def _check_solver_options(label: str, options: dict) -> None:
    """A stage's solver options checked when the stage is made: names a
    stage may change, each value as SolverOptions checks it, the switches
    True or False, and the step sizes given ordered among themselves (their
    order against the run's own step sizes is checked when the stage
    starts). A bad value found only then stopped the run for good: the
    stage was already begun."""
    from ..solver import Solver, SolverOptions   # the solver imports this module
    unknown = sorted(set(options) - Solver.STAGE_OPTIONS)
    if unknown:
        raise ValueError(f"{label}: solver options {unknown} cannot change between stages; "
                         f"allowed: {sorted(Solver.STAGE_OPTIONS)}")
    for name, v in options.items():
        if name in _STEPS:
            if isinstance(v, bool) or not isinstance(v, numbers.Real) or not 0 < v <= 1:
                raise ValueError(f"{label}: solver option {name} must be a load-factor "
                                 f"increment in (0, 1], got {v!r}")
        elif name in ("branch_switching", "verbose"):
            if not isinstance(v, bool):
                raise ValueError(f"{label}: solver option {name} must be True or False, got "
                                 f"{v!r}")
        else:
            try:
                SolverOptions(**{name: v})
            except (TypeError, ValueError) as error:
                raise ValueError(f"{label}: {error}") from None
    given = [(name, options[name]) for name in _STEPS if name in options]
    if [v for _, v in given] != sorted(v for _, v in given):
        raise ValueError(f"{label}: solver options need min_step <= initial_step <= max_step, "
                         f"got {dict(given)}")


def _numeric(value) -> bool:
    try:
        np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return False
    return True


@dataclass
class Stage:
    """One stage of a run.

    Attributes
    ----------
    name:
        Label in outputs (results.json, ParaView field data).
    ramp:
        Handle -> target value at the stage end (or a callable of s giving
        the value during the stage); every other quantity is held.
    release:
        Prescription handles no longer prescribed from the stage start.
    effects:
        Effect -> options set at the stage start (``effect.configure``), e.g.
        the weaving contact mode in one stage, ordinary contact in the next.
    solver:
        Solver options for this stage (initial_step, max_step, ...).
    """

    name: str
    ramp: dict = field(default_factory=dict)
    release: list = field(default_factory=list)
    effects: dict = field(default_factory=dict)
    solver: dict = field(default_factory=dict)

    def __post_init__(self):
        """Every check that needs no model, when the stage is made: a bad
        stage is refused before a run starts (or, made between stages of a
        run, without touching it), never half applied."""
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"Stage: name must be a non-empty string, got {self.name!r}")
        label = f"Stage {self.name!r}"
        for attribute in ("ramp", "effects", "solver"):
            if not isinstance(getattr(self, attribute), dict):
                raise TypeError(f"{label}: {attribute} must be a dict, got "
                                f"{type(getattr(self, attribute)).__name__}")
        _check_solver_options(label, self.solver)
        if isinstance(self.release, (str, bytes, dict)) or not hasattr(self.release, "__iter__"):
            raise TypeError(f"{label}: release must be a list of handles, got "
                            f"{type(self.release).__name__}")
        self.release = list(self.release)
        for h, target in self.ramp.items():
            if not isinstance(h, Handle):
                raise TypeError(f"{label}: ramp keys must be handles (what Model.fix, "
                                f"Model.add_force, ... return), got {h!r}")
            if not callable(target):
                t = np.asarray(target, dtype=float) if _numeric(target) else None
                if t is None or t.ndim > 1 or t.size not in (1, len(h.index)) \
                        or not np.all(np.isfinite(t)):
                    raise ValueError(f"{label}: the ramp target of {h.label} must be finite "
                                     f"numbers (one, or one per component: {len(h.index)}) "
                                     f"or a callable of the stage's load factor, got "
                                     f"{target!r}")
        for h in self.release:
            if not isinstance(h, Handle):
                raise TypeError(f"{label}: release items must be handles, got {h!r}")
            for r in self.ramp:
                if r.schedule is h.schedule and np.isin(r.index, h.index).any():
                    raise ValueError(f"{label}: {h.label} is both ramped and released; a "
                                     f"released prescription no longer has a value to ramp "
                                     f"(ramp it in one stage, release it in the next)")
        for effect, options in self.effects.items():
            if not isinstance(effect, Effect):
                raise TypeError(f"{label}: effects keys must be effects (with configure), got "
                                f"{effect!r}")
            if not isinstance(options, dict):
                raise TypeError(f"{label}: the options of {type(effect).__name__} must be a "
                                f"dict, got {options!r}")
            unknown = sorted(set(options) - stage_options(effect))
            if unknown:
                allowed = sorted(stage_options(effect))
                raise ValueError(f"{label}: unknown stage option(s) {unknown} of "
                                 f"{type(effect).__name__}; allowed: "
                                 f"{allowed if allowed else 'none'}")

    def apply(self, effects: bool = True) -> bool:
        """Set the targets and releases of the stage's handles, and the
        effects' options; returns True when a release changes the set of
        prescribed unknowns. ``effects=False``: a stage resumed from a
        saved state within it applies its handles again (the callables of
        s are not saved) and gives the effects its options through
        ``Effect.configure_resumed`` (they keep what they saved)."""
        for h, target in self.ramp.items():
            if not isinstance(h, Handle):
                raise TypeError(f"Stage {self.name!r}: ramp keys must be handles (what "
                                f"Model.fix, Model.add_force, ... return), got {h!r}")
            if callable(target):
                h.schedule.follow(h, target)
            else:
                h.schedule.ramp(h, target)
        for h in self.release:
            if not isinstance(h, Handle):
                raise TypeError(f"Stage {self.name!r}: release items must be handles, got {h!r}")
            h.schedule.release(h)
        for effect, options in self.effects.items():
            (effect.configure if effects else effect.configure_resumed)(**options)
        return bool(self.release)
