"""The solver's parts (textile/solver/) each on its own: one Newton solve,
one load-step attempt, the stability check, the step-size rule; and the
package's modules stay small."""
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

import textile
from textile.solver import (DIVERGED_EFFECTS_UNSETTLED, DIVERGED_NEWTON_CYCLE,  # noqa: F401
                            DIVERGED_NEWTON_STALL, Attempt, ConvergenceError, Solver,
                            SolverOptions,
                            StabilityWarning, StepRecord, cycling, reason_name)
from textile.effects.base import Effect
from textile.solver.contact_loop import ContactLoop
from textile.solver.newton import Newton, new_counts
from textile.solver.stability_check import StabilityCheck
from textile.solver.stepping import StepControl

E, NU, R, L = 1.0e9, 0.3, 1e-3, 0.2
EI = E * np.pi * R ** 4 / 4
QUIET = dict(verbose=False)
#: Newton iterations of the cantilever's one step (MIP Newton, no predictor)
CANTILEVER_ITERATIONS = 6


def cantilever():
    """A cantilever under a lateral tip force of moderate rotation."""
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, NU),
                                 num_elements=8, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    model.add_force(fib, -1, [0, 0, 2.0 * EI / L ** 2])
    return fib, model


def set_up(model, options):
    """What Solver does to a model before its parts use it."""
    model.setup()
    model.newton = options.newton
    return Newton(model, options)


def one_step_with_solver():
    fib, model = cantilever()
    solver = Solver(model, dict(initial_step=1.0, max_step=1.0, **QUIET))
    solver.solve()
    assert len(solver.history) == 1 and solver.history[0].attempts == 1
    return solver, model


def _newton_at_full_load(options):
    fib, model = cantilever()
    newton = set_up(model, options)
    model.domain_error = None
    for e in model.effects:
        e.prepare(model)
    model.start_newton()
    model.set_linearization_point()
    model.load_factor = 1.0
    model.apply_constraints(model.x)
    return model, newton


def test_one_newton_solve_alone():
    """Newton alone, from the reference state at load factor 1, converges
    as the Solver's one step does: same iterations, residuals, state."""
    solver, reference = one_step_with_solver()
    model, newton = _newton_at_full_load(SolverOptions(**QUIET))
    result = newton.solve(model.x)
    step = solver.history[0]
    assert result.reason > 0, reason_name(result.reason)
    assert result.iterations == step.newton_iterations
    assert result.residual_norms == step.residual_norms
    assert newton.counts["newton_solves"] == 1
    assert newton.counts["newton_iterations"] == result.iterations
    assert np.array_equal(model.x.getArray(), reference.x.getArray())
    assert newton.prefix.startswith("textile") and newton.prefix != solver.prefix


@pytest.mark.parametrize("line_search", ["l2", "none"])
def test_a_cycling_solve_goes_on_with_a_line_search(monkeypatch, line_search):
    """SolverOptions.cycle_line_search: a solve taken for cycling after its
    second iteration goes on from that iterate with the l2 line search (and
    converges: the cantilever has no cycle), once, then the line search is
    the plain one again; with "none" the solve fails at once."""
    import textile.solver.newton as newton_module
    calls = []

    def cycles_once(norms):
        calls.append(len(norms))
        return len(calls) == 3
    monkeypatch.setattr(newton_module, "cycling", cycles_once)
    model, newton = _newton_at_full_load(SolverOptions(cycle_line_search=line_search, **QUIET))
    result = newton.solve(model.x)
    kind = PETSc.Options().getString(newton.prefix + "snes_linesearch_type")
    assert kind == "basic"
    if line_search == "none":
        assert result.reason == DIVERGED_NEWTON_CYCLE and result.iterations == 2
        assert newton.counts["cycle_line_searches"] == 0
        return
    assert result.reason > 0, reason_name(result.reason)
    assert newton.counts["cycle_line_searches"] == 1
    assert newton.counts["newton_solves"] == 2
    # the two solves' iterations together; the cantilever's count, give or
    # take the line search's shorter steps
    assert newton.counts["newton_iterations"] == result.iterations
    assert CANTILEVER_ITERATIONS - 1 <= result.iterations <= CANTILEVER_ITERATIONS + 3
    assert len(result.residual_norms) == result.iterations + 2  # each solve's initial norm


def test_a_stalled_solve_fails_at_once(monkeypatch):
    """A solve that has stalled (convergence.stalled, given the residuals
    after the first) fails there, with no line search, and says so."""
    import textile.solver.newton as newton_module
    histories = []

    def stalls_at_the_third(norms):
        histories.append(list(norms))
        return len(histories) == 3
    monkeypatch.setattr(newton_module, "stalled", stalls_at_the_third)
    model, newton = _newton_at_full_load(SolverOptions(**QUIET))
    result = newton.solve(model.x)
    assert result.reason == DIVERGED_NEWTON_STALL, reason_name(result.reason)
    assert reason_name(result.reason) == "DIVERGED_NEWTON_STALL"
    assert result.iterations == 2 and "have not gone below" in result.message
    assert newton.counts["cycle_line_searches"] == 0
    assert histories == [[], result.residual_norms[1:2], result.residual_norms[1:3]]


class _Unsettled(Effect):
    """An effect that changes by ``changes[k]`` (in units of its tolerance)
    at its k-th update of an attempt, the last value ever after."""

    fields = ("beam",)

    def __init__(self, changes):
        self.changes, self.k = list(changes), 0

    def prepare(self, model):
        self.k = 0

    def update(self, model):
        self.k += 1
        return self.update_change() > 1

    def update_change(self):
        return self.changes[min(self.k, len(self.changes)) - 1]


def _attempt(changes, **options):
    """One attempt of the cantilever at full load with an effect whose
    updates change by ``changes`` (_Unsettled)."""
    fib, model = cantilever()
    model.add_effect(_Unsettled(changes))
    return ContactLoop(set_up(model, SolverOptions(**QUIET, **options))).step_to(1.0)


def test_a_contact_loop_that_cycles_fails_at_once():
    """Passes whose changes repeat with a period (the effects alternating
    between states: the 6 x 6 sample of 28-fibre bundles spent 137 Newton
    iterations in 20 passes of 11.3, 14.8, 11.3, ...) fail the attempt at
    the first trend over TREND_SOLVES solves that stands (a rate of 1 to
    1 + CYCLE_TOLERANCE; faster rises are transients); a cycle
    through new contacts (inf: no trend) fails when the Newton cycle test
    sees its period; changes that fall fast enough to settle in the solves
    left run on and settle."""
    from textile.solver.convergence import TREND_SOLVES
    assert TREND_SOLVES == 3
    attempt = _attempt([20, 16, 13] + [11.3, 14.8] * 20)
    assert attempt.reason == DIVERGED_EFFECTS_UNSETTLED and not attempt.converged
    # 13, 11.3, 14.8 rises 6.7% a solve (a transient, not judged); 11.3,
    # 14.8, 11.3 stands: not falling, at pass 6 (11 before the trend test)
    assert attempt.updates == 6 and "not falling after 6 Newton solves" in attempt.message
    assert "11.3, 14.8, 11.3" in attempt.message
    # rising fast, then settling (a rod pushed through a cantilever in one
    # step: its contact held, its zone stiffened; test_tunnelling.py)
    attempt = _attempt([51, 111, 180, 315, 8.2, 5.4, 0.03])
    assert attempt.converged and attempt.updates == 7
    attempt = _attempt([np.inf, 5.0] * 20)
    # the cycle test's shortest history of period 2 (6 + 2 + 2 changes; an
    # infinite change matches only another): pass 10
    assert attempt.updates == 10 and "cycling after 10 Newton solves" in attempt.message
    # 30% a solve from 40: below 1 at pass 12
    attempt = _attempt([40 * 0.7 ** k for k in range(40)])
    assert attempt.converged and attempt.updates == 12


def test_a_contact_loop_that_falls_slowly_goes_on_while_it_can_settle():
    """Changes falling steadily go on while their rate brings them to 1
    within max_updates (the bundle shear's 1.13, 1.1, 1.07, 1.04, 1.01 was
    once cut one solve before it settled), and fail as soon as their trend
    over TREND_SOLVES solves cannot: the 6 x 6 shear of 7-fibre bundles
    failed attempts whose changes fell 1-4% a solve only after 9 of them."""
    # 3% a solve from 1.3: below 1 at the 10th of them, pass 13
    attempt = _attempt([5, 3, 2] + [1.3 * 0.97 ** k for k in range(30)])
    assert attempt.converged and attempt.updates == 13
    # 4% a solve from 2.4: 1.2 after the 17 solves left at pass 3
    attempt = _attempt([2.4 * 0.96 ** k for k in range(30)])
    assert attempt.reason == DIVERGED_EFFECTS_UNSETTLED and attempt.updates == 3
    assert "falling by 4% a Newton solve, too slowly to settle in the 17 solves left, " \
           "after 3 Newton solves" in attempt.message
    # 10% a solve from 40 cannot settle in 20 solves: said at pass 3, not 20
    attempt = _attempt([40 * 0.9 ** k for k in range(40)])
    assert attempt.updates == 3 and "falling by 10% a Newton solve" in attempt.message


def test_capped_solves_stop_once_the_effects_settle_after_one():
    """newton_per_pass: once the effects did not change after a capped
    solve, the next solves run to convergence (two settle the step), where
    the first half of max_updates solves used to be capped whatever the
    effects did (the bundle shear: 10 capped solves a step)."""
    attempt = _attempt([5.0] + [0.5] * 40, newton_per_pass=1)
    assert attempt.converged
    # pass 1 capped (changed), pass 2 capped (settled), passes 3 and 4 to
    # convergence: the effects set at a converged state did not change
    assert attempt.updates == 4, attempt.passes


def test_capped_solves_stop_once_they_stop_settling_the_effects():
    """newton_per_pass: capped solves whose effects' change no longer falls
    by CYCLE_TOLERANCE (5%) a pass give way to solves run to convergence
    (capped_passes_stalled; the 6 x 6 shear of 7-fibre bundles: 10 capped
    passes a step whose changes stood at 1-6, then one or two full solves
    settled it)."""
    from textile.solver.convergence import capped_passes_stalled
    assert not capped_passes_stalled([8.0]) and not capped_passes_stalled([8.0, 4.0])
    assert capped_passes_stalled([8.0, 4.0, 3.9]) and capped_passes_stalled([2.0, 2.2])
    assert not capped_passes_stalled([np.inf, 5.0]) and not capped_passes_stalled([5.0, np.inf])
    # passes 1-3 capped (8, 4, 3.9: stalled), 4 and 5 to convergence (0.5:
    # settled at a converged state); capped until the effects settled, it
    # took 6 passes
    attempt = _attempt([8.0, 4.0, 3.9] + [0.5] * 40, newton_per_pass=1)
    assert attempt.converged and attempt.updates == 5, attempt.passes
    assert [i for i, _ in attempt.passes[:3]] == [1, 1, 1] and attempt.passes[3][0] > 1


def test_capped_solves_that_cycle_together_go_on_with_a_line_search(monkeypatch):
    """Capped solves (newton_per_pass) are too short to show a cycle each:
    the contact loop tests the attempt's whole residual history, and a
    solve after a history taken for cycling starts with the line search."""
    import textile.solver.contact_loop as loop_module
    monkeypatch.setattr(loop_module, "cycling", lambda norms: len(norms) > 0)
    fib, model = cantilever()
    loop = ContactLoop(set_up(model, SolverOptions(newton_per_pass=2, **QUIET)))
    attempt = loop.step_to(1.0)
    assert attempt.converged and attempt.updates > 1
    assert loop.newton.counts["cycle_line_searches"] == attempt.updates - 1


def test_newton_iterations_of_the_cantilever():
    """The known count (a change of the Newton solver shows here first)."""
    solver, _ = one_step_with_solver()
    assert solver.history[0].newton_iterations == CANTILEVER_ITERATIONS


def test_one_load_step_attempt_alone():
    """ContactLoop.step_to: one attempt, the model left at the new state;
    Solver.step_to is the same attempt."""
    fib, model = cantilever()
    loop = ContactLoop(set_up(model, SolverOptions(**QUIET)))
    attempt = loop.step_to(0.5)
    assert isinstance(attempt, Attempt) and attempt.converged
    assert attempt.updates == 1 and model.load_factor == 0.5
    fib2, model2 = cantilever()
    solver = Solver(model2, QUIET)
    again = solver.step_to(0.5)
    assert again == attempt
    assert np.array_equal(model.x.getArray(), model2.x.getArray())


def test_stability_check_alone():
    """A straight column of round section past its buckling load: two
    negative eigenvalues (it buckles in either lateral plane), read from the
    Newton factorization by StabilityCheck alone."""
    length = 0.5
    load = np.pi ** 2 * EI / (4 * length ** 2)
    fib = textile.straight_fibre([0, 0, 0], [length, 0, 0], R, textile.Material(E, NU),
                                 num_elements=8)
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    model.add_force(fib, -1, [-1.3 * load, 0, 0])
    loop = ContactLoop(set_up(model, SolverOptions(**QUIET)))
    assert loop.step_to(1.0).converged
    check = StabilityCheck(loop)
    assert check.inertia().negative == 2
    assert check.counts["zero_motion_searches"] == 1


def test_step_control_alone():
    """The cut/grow rule on a scripted sequence of attempt outcomes: the
    steps Stepping.solve would take, without a model."""
    o = SolverOptions(initial_step=0.1, max_step=0.25, min_step=0.01, grow=1.5, cut=0.5,
                      easy_iterations=4, **QUIET)
    control = StepControl(o)
    # (converged, Newton iterations) of each attempt, in turn
    outcomes = iter([(True, 3), (True, 6), (False, 25), (True, 4), (True, 2), (True, 1),
                     (True, 1), (True, 1)])
    t, dt, taken = 0.0, control.first(), []
    while t < 1.0 - 1e-14:
        step = control.clip(dt, t, 1.0)
        converged, iterations = next(outcomes)
        if not converged:
            dt = control.failed(step)
            assert not control.gives_up(dt)
            taken.append(("cut", step))
            continue
        t += step
        dt = control.converged(step, iterations)
        taken.append(("ok", step))
    assert [k for k, _ in taken] == ["ok", "ok", "cut", "ok", "ok", "ok", "ok", "ok"]
    assert [s for _, s in taken] == pytest.approx([0.1, 0.15, 0.15, 0.075, 0.1125, 0.16875,
                                                   0.25, 1.0 - 0.85625], rel=1e-14)
    assert StepControl(SolverOptions(initial_step=0.5, max_step=0.5, **QUIET)).first() == 0.5
    small = StepControl(SolverOptions(min_step=0.01, initial_step=0.015, **QUIET))
    assert small.gives_up(small.failed(0.015))


def scripted_steps(control, outcomes):
    """The steps (kind, size) StepControl gives a scripted sequence of
    (converged, Newton iterations) outcomes, until they run out."""
    t, dt, taken = 0.0, control.first(), []
    for converged, iterations in outcomes:
        step = control.clip(dt, t, 1.0)
        if converged:
            t += step
            dt = control.converged(step, iterations)
        else:
            dt = control.failed(step)
        taken.append(("ok" if converged else "cut", step))
    return taken


def test_steps_grow_again_after_a_cut():
    """Hard steps (more than easy_iterations) keep their size, except after
    a cut: regrow_after of them in a row at one size let the next grow.
    Without the rule a stage whose steps all take 10 iterations (capped
    contact passes) crept on at its hardest step's size."""
    hard = [(True, 10)] * 4 + [(False, 30)] + [(True, 10)] * 7
    o = SolverOptions(initial_step=0.1, max_step=0.1, cut=0.5, grow=1.5, easy_iterations=4,
                      regrow_after=3, **QUIET)
    sizes = [s for _, s in scripted_steps(StepControl(o), hard)]
    assert sizes == pytest.approx([0.1] * 5 + [0.05] * 3 + [0.075] * 3 + [0.1], rel=1e-14)
    never = SolverOptions(initial_step=0.1, max_step=0.1, regrow_after=0, **QUIET)
    assert [s for _, s in scripted_steps(StepControl(never), hard)][5:] == \
        pytest.approx([0.05] * 7, rel=1e-14)
    # no cut yet: hard steps keep the initial size below max_step
    grows = SolverOptions(initial_step=0.1, max_step=0.25, regrow_after=1, **QUIET)
    assert [s for _, s in scripted_steps(StepControl(grows), [(True, 10)] * 4)] == \
        pytest.approx([0.1] * 4, rel=1e-14)
    # a resumed stage counts on from its saved count
    control = StepControl(o, since_cut=2)
    assert control.converged(0.05, 10) == pytest.approx(0.075, rel=1e-14)
    with pytest.raises(ValueError, match="regrow_after must be a non-negative integer"):
        SolverOptions(regrow_after=-1)


def test_a_run_resumed_after_a_cut_grows_its_steps_as_the_continuous_one(tmp_path):
    """The count of steps since the last cut is part of a saved state: the
    cantilever's first attempts are cut three times (max_it 4), its steps
    grow every second one after that, saved and resumed between two."""
    options = dict(initial_step=1.0, max_step=1.0, max_it=4, easy_iterations=1,
                   regrow_after=2, **QUIET)
    path = str(tmp_path / "cut.h5")
    fib, model = cantilever()
    solver = Solver(model, options)
    solver.on_step = lambda s, rec: textile.save_state(model, path, s) \
        if rec.step == 3 else None
    solver.solve()
    continuous = [h.load_factor for h in solver.history]
    assert continuous[:3] == pytest.approx([0.125, 0.25, 0.4375], rel=1e-14)
    fib, model = cantilever()
    solver = Solver(model, options)
    assert textile.load_state(model, path, solver)["steps_since_cut"] == 1
    solver.solve()
    assert [h.load_factor for h in solver.history] == pytest.approx(continuous[3:], rel=1e-14)


def test_counters_are_shared_by_the_parts():
    """The Solver's counters are its parts' (one dict)."""
    fib, model = cantilever()
    solver = Solver(model, dict(initial_step=0.5, max_step=0.5, **QUIET))
    solver.solve()
    assert solver.newton.counts is solver._counts is solver.stability.counts
    assert solver.counters["newton_iterations"] == sum(
        h.newton_iterations for h in solver.history)
    assert solver.counters["accepted_steps"] == len(solver.history) == 2
    assert set(new_counts()) <= set(solver.counters)


def test_stage_options_reach_every_part():
    fib, model = cantilever()
    solver = Solver(model, QUIET)
    seen = []
    solver.on_step = lambda s, rec: seen.append(
        {s.options.max_it, s.newton.options.max_it, s.loop.options.max_it,
         s.stability.options.max_it})
    solver.run_stage(textile.Stage("load", solver=dict(max_it=17, initial_step=0.5,
                                                       max_step=0.5)))
    assert seen and all(v == {17} for v in seen)
    assert solver.newton.options.max_it == solver.options.max_it == 25


def test_modules_stay_small():
    """Each part of the solver is read in one sitting."""
    package = Path(textile.__file__).parent / "solver"
    sizes = {p.name: len(p.read_text().splitlines()) for p in package.glob("*.py")}
    assert {"__init__.py", "options.py", "newton.py", "contact_loop.py", "stepping.py",
            "stages.py", "stability_check.py"} <= set(sizes)
    assert all(n < 300 for n in sizes.values()), sizes
    assert not (package.parent / "solver.py").exists()


def test_the_solver_api_is_kept():
    """What textile/, the tests, demos and benchmarks use of the one-class
    Solver and of the textile.solver module, there after the split."""
    import textile.solver as module
    for name in ("Solver", "SolverOptions", "StepRecord", "Attempt", "ConvergenceError",
                 "StabilityWarning", "DIVERGED_EFFECTS_UNSETTLED", "DIVERGED_NEWTON_CYCLE",
                 "reason_name", "cycling", "CYCLE_ITERATIONS", "CYCLE_PERIOD",
                 "CYCLE_TOLERANCE", "max_op", "factor_negative_pivots", "zero_energy_motions",
                 "critical_modes", "Inertia"):
        assert hasattr(module, name), name
    assert textile.Solver is Solver and textile.SolverOptions is SolverOptions
    fib, model = cantilever()
    solver = Solver(model, QUIET)
    for name in ("model", "options", "output", "on_step", "history", "comm", "tolerances",
                 "prefix", "snes", "linear", "counters", "step_to", "solve", "run",
                 "run_stage", "position", "previous_state", "resume", "resume_matrix",
                 "STAGE_OPTIONS", "_counts"):
        assert hasattr(solver, name), name
    assert Solver.STAGE_OPTIONS >= {"initial_step", "max_it", "newton", "verbose"}
    # the SNES can be replaced by a proxy of it (benchmarks/contact_costs.py)
    snes = solver.snes
    solver.snes = snes
    assert solver.newton.snes is snes
