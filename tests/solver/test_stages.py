"""Runs in stages: ramp, hold, release; continuous numbering and tags."""
import json

import numpy as np
import pytest
from mpi4py import MPI

import textile

E, NU, R, L = 1.0e9, 0.3, 1e-3, 0.2
EI = E * np.pi * R ** 4 / 4
F = 0.5 * EI / L ** 2  # a moderate lateral tip force


def cantilever():
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, NU),
                                 num_elements=8, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    force = model.add_force(fib, -1, [0, 0, F])
    return fib, model, force


def test_hold_a_force_while_a_displacement_ramps_then_release(tmp_path):
    fib, model, force = cantilever()
    pull = model.fix(fib, -1, "x", 1e-4)  # a stretch, reached in the first stage
    out = textile.Output(str(tmp_path), pictures=False)
    solver = textile.Solver(model, dict(initial_step=0.25, max_step=0.5, verbose=False),
                            output=out)
    tension = []

    def check(solver, rec):
        # global equilibrium at every step: the clamp and the tip's support
        # balance the lateral force, whatever the stage
        clamp = model.reaction(fib, 0)
        if rec.stage != "release":
            tip = model.reaction(fib, -1, "x")
            tension.append(-tip[0])
            # to the convergence test's rtol 1e-10 of the reactions
            assert clamp[0] + tip[0] == pytest.approx(0, abs=1e-9 * abs(tip[0]))
        assert clamp[2] == pytest.approx(-F if rec.stage != "load" else -rec.load_factor * F,
                                         rel=1e-9)

    solver.on_step = check
    solver.run([textile.Stage("load"),
                textile.Stage("stretch", ramp={pull: 3e-4}),   # the force is held
                textile.Stage("release", release=[pull])])
    stages = [h.stage for h in solver.history]
    assert stages[0] == "load" and stages[-1] == "release" and "stretch" in stages
    # the stretch stage raised the tension (3x the end displacement)
    assert max(tension) > 2.5 * tension[0]
    # released: the same state as a cantilever that was never pulled (elastic)
    fib2, model2, _ = cantilever()
    textile.Solver(model2, dict(verbose=False)).solve()
    assert np.abs(model.nodal_unknowns() - model2.nodal_unknowns()).max() < 1e-10 * L
    # results.json: steps numbered continuously, tagged with their stage,
    # time = stage number + load factor, increasing
    steps = json.loads((tmp_path / "results.json").read_text())["steps"]
    assert [s["step"] for s in steps] == list(range(1, len(steps) + 1))
    assert [s["stage"] for s in steps] == stages
    times = [s["time"] for s in steps]
    assert np.all(np.diff(times) > 0) and times[-1] == pytest.approx(3.0)


def bent_in_a_stage(path_rtol: float):
    """The cantilever, its tip force 10 times the moderate one (the tip
    rises to 0.71 L), in one stage of 4 steps."""
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, NU),
                                 num_elements=8, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    model.add_force(fib, -1, [0, 0, 10 * F])
    solver = textile.Solver(model, dict(initial_step=0.25, max_step=0.25, verbose=False,
                                        path_rtol=path_rtol))
    solver.run([textile.Stage("load")])
    return model, solver


def test_a_stage_path_to_a_looser_tolerance_ends_on_the_full_one():
    """SolverOptions.path_rtol: a stage's steps before its end stop once
    each group's residual has fallen that much within the Newton solve; the
    stage's end meets the full test. Elastic, so the end state is the same."""
    full, full_solver = bent_in_a_stage(0.0)
    loose, loose_solver = bent_in_a_stage(1e-3)
    its = lambda s: [h.newton_iterations for h in s.history]  # noqa: E731
    # measured [5, 5, 4, 4] and [5, 3, 3, 4]: the middle steps stop 2
    # iterations earlier, the first (its residual falls from a straight
    # fibre's) and the last as before
    assert its(full_solver) == [5, 5, 4, 4]
    assert its(loose_solver) == [5, 3, 3, 4]
    # the same end state to the full test's accuracy (measured 1e-16 L)
    assert np.abs(loose.nodal_unknowns() - full.nodal_unknowns()).max() < 1e-10 * L
    # the end's residuals as small as the full run's (to the test's rtol)
    end = loose_solver.history[-1].residuals["positions"]
    assert end <= 1e-10 * 10 * F + 1e-13 * E * np.pi * R ** 2


def test_a_stage_needs_the_previous_one_finished():
    fib, model, force = cantilever()
    solver = textile.Solver(model, dict(verbose=False))
    solver.solve(0.5)
    with pytest.raises(RuntimeError, match="stage 'load' stopped at load factor 0.5"):
        solver.run_stage(textile.Stage("next"))


def test_stage_errors_are_named():
    fib, model, force = cantilever()
    solver = textile.Solver(model, dict(verbose=False))
    with pytest.raises(ValueError, match="cannot change between stages"):
        solver.run_stage(textile.Stage("s", solver={"linear_solver": "petsc"}))
    with pytest.raises(TypeError, match="ramp keys must be handles"):
        solver.run_stage(textile.Stage("s", ramp={"force": 1.0}))


def pull_and_bend_scene(on_step=None):
    """A rigid body pulls a fibre (force), then turns it about y
    (prescribed) while the force is held: (model, solver, [pull, turn])."""
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, NU),
                                 num_elements=8, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.add_rigid_body(textile.RigidBody("clamp", sections=[(fib, 0)]).fix())
    end = textile.RigidBody("end", sections=[(fib, -1)])
    turn = end.prescribe(["y", "z", "rx", "ry", "rz"], 0.0)
    end.add_force([1e-3 * E * np.pi * R ** 2, 0, 0])
    model.add_rigid_body(end)
    solver = textile.Solver(model, dict(verbose=False, max_step=0.5), on_step=on_step)
    return model, solver, [textile.Stage("pull"),
                           textile.Stage("turn", ramp={turn: [0, 0, 0, 0.3, 0]})]


def pulled_and_bent(path=None, resume_from=None):
    """The two stages of pull_and_bend_scene; optionally save after the
    first stage, or resume the second from a saved file."""
    model, solver, (first, second) = pull_and_bend_scene()
    if resume_from is None:
        solver.run_stage(first)
        if path is not None:
            textile.save_state(model, path, solver, fibre_data={"yarn": [3]})
    else:
        attrs = textile.load_state(model, resume_from, solver)
        assert attrs["fibre_data"]["yarn"].tolist() == [3]  # labels come back
    solver.run_stage(second)
    return model


def test_saved_and_resumed_run_equals_the_continuous_one(tmp_path):
    path = str(tmp_path / "pulled.h5")
    continuous = pulled_and_bent(path=path)
    resumed = pulled_and_bent(resume_from=path)
    # same converged state (elastic, path-independent) to the solver tolerance
    assert np.abs(continuous.nodal_unknowns() - resumed.nodal_unknowns()).max() < 1e-10 * L
    rc, rr = continuous.rigid_bodies.reactions(), resumed.rigid_bodies.reactions()
    assert np.abs(rc - rr).max() <= 1e-8 * np.abs(rc).max()
    assert resumed.rigid_bodies.turned[1] == pytest.approx([0, 0.3, 0], abs=1e-14)


def test_a_run_of_stages_goes_on_from_a_state_saved_at_any_step(tmp_path):
    """Solver.run(stages, resumed=attrs): a state saved at a stage's end goes
    on with the next stage, one saved within a stage goes on in it, one
    saved at the run's end runs nothing; each ends where the whole run did."""
    saved = []

    def save(solver, rec):
        path = str(tmp_path / f"step{rec.step}.h5")
        textile.save_state(solver.model, path, solver)
        saved.append((rec.stage, rec.load_factor, rec.step, path))

    whole, solver, stages = pull_and_bend_scene(save)
    solver.run(stages)
    steps = len(solver.history)
    kinds = {"pull": [], "turn": []}
    for stage, t, step, path in saved:
        kinds[stage].append((t, step, path))
    end_of_pull = [p for t, _, p in kinds["pull"] if t == 1.0][0]
    within_turn = [(step, p) for t, step, p in kinds["turn"] if t < 1.0][0]
    end_of_run = kinds["turn"][-1][2]
    for path, left in ((end_of_pull, len(kinds["turn"])),
                       (within_turn[1], steps - within_turn[0]), (end_of_run, 0)):
        model, solver, stages = pull_and_bend_scene()
        attrs = textile.load_state(model, path, solver)
        solver.run(stages, resumed=attrs)
        assert len(solver.history) == left  # only the steps the saved run had left
        assert np.abs(whole.nodal_unknowns() - model.nodal_unknowns()).max() < 1e-10 * L
        assert model.rigid_bodies.turned[1] == pytest.approx([0, 0.3, 0], abs=1e-14)


def test_fibre_labels_must_match_the_fibres(tmp_path):
    fib, model, force = cantilever()
    with pytest.raises(ValueError, match="fibre_data.'yarn'. has .2,. values"):
        textile.save_state(model, str(tmp_path / "s.h5"), fibre_data={"yarn": [0, 1]})


def pushed_then_freed(comm):
    """A fibre clamped at one end, its other end pushed sideways by a
    prescription (stage 1) that is then released under a force (stage 2):
    on 2 ranks only rank 0 holds the released unknown."""
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, NU),
                                 num_elements=8, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=comm)
    model.clamp(fib, -1)
    push = model.fix(fib, 0, "y", 1e-3 * L)
    model.add_force(fib, 0, [0, F, 0])
    textile.Solver(model, dict(verbose=False)).run(
        [textile.Stage("push"), textile.Stage("free", release=[push])])
    return model.nodal_unknowns()


@pytest.mark.mpi
def test_a_release_held_by_one_rank():
    """Every rank takes the new system matrix when one rank's prescribed
    unknowns are released (the other rank saw no change and did not: the
    run hung), and the answer is the serial one (measured 2e-14)."""
    serial, parallel = pushed_then_freed(MPI.COMM_SELF), pushed_then_freed(MPI.COMM_WORLD)
    assert np.abs(parallel - serial).max() < 1e-12 * np.abs(serial).max()
    assert serial[0, 1] > 1e-3 * L   # the force took the end further once released


def bad_stages(model, force, pull):
    """(stage arguments, error, message) of stages refused when made."""
    from textile.effects.fibre_contact import FibreContact
    contact = FibreContact()
    return [
        (dict(name="both", ramp={pull: 2e-4}, release=[pull]), ValueError,
         "is both ramped and released"),
        (dict(name="nan", ramp={force: float("nan")}), ValueError, "must be finite numbers"),
        (dict(name="shape", ramp={force: [1.0, 2.0]}), ValueError, "one per component: 3"),
        (dict(name="text", ramp={force: "up"}), ValueError, "must be finite numbers"),
        (dict(name="release", release=pull), TypeError, "release must be a list of handles"),
        (dict(name="release item", release=["pull"]), TypeError,
         "release items must be handles"),
        (dict(name="", ramp={}), ValueError, "name must be a non-empty string"),
        (dict(name="options", effects={contact: dict(mode="weaving", speed=2)}), ValueError,
         r"unknown stage option\(s\) \['speed'\] of FibreContact; allowed: "
         r"\['fibre_yarn', 'friction', 'make_up_penetrations', 'mode', 'update_tolerance', "
         r"'yarn_above'\]"),
        (dict(name="no options", effects={model.beam: dict(stiff=True)}), ValueError,
         r"unknown stage option\(s\) \['stiff'\] of .*; allowed: none"),
        (dict(name="effect", effects={"contact": {}}), TypeError, "effects keys must be "
                                                                  "effects"),
        (dict(name="effect options", effects={contact: "weaving"}), TypeError,
         "must be a dict"),
        (dict(name="solver", solver=[("max_step", 0.1)]), TypeError, "solver must be a dict"),
        # solver options: a bad value found when the stage started left it
        # begun, and the run could go on with no stage after it
        (dict(name="step", solver=dict(max_step=-0.1)), ValueError,
         r"Stage 'step': solver option max_step must be a load-factor increment in \(0, 1\], "
         r"got -0.1"),
        (dict(name="steps", solver=dict(initial_step=0.5, max_step=0.1)), ValueError,
         "need min_step <= initial_step <= max_step"),
        (dict(name="step kind", solver=dict(initial_step="0.1")), ValueError,
         "solver option initial_step must be a load-factor increment"),
        (dict(name="iterations", solver=dict(max_it=2.5)), ValueError,
         "Stage 'iterations': SolverOptions.max_it must be a positive integer, got 2.5"),
        (dict(name="newton", solver=dict(newton="fast")), ValueError,
         "SolverOptions.newton must be one of"),
        (dict(name="switch", solver=dict(branch_switching="yes")), ValueError,
         "solver option branch_switching must be True or False, got 'yes'"),
        (dict(name="linear", solver=dict(linear_solver="petsc")), ValueError,
         r"solver options \['linear_solver'\] cannot change between stages"),
    ]


def test_bad_stages_are_refused_when_made(tmp_path):
    """Every bad stage definition is a named error when the Stage is made:
    after a first stage it leaves the run as it was (nothing computed is
    lost, nothing half applied), and the run goes on with a good stage."""
    fib, model, force = cantilever()
    pull = model.fix(fib, -1, "x", 0.0)
    out = textile.Output(str(tmp_path), pictures=False)
    solver = textile.Solver(model, dict(initial_step=0.5, max_step=0.5, verbose=False),
                            output=out)
    solver.run([textile.Stage("load")])
    before = (len(solver.history), model.nodal_unknowns().copy(),
              (tmp_path / "results.json").read_text())
    for kwargs, error, message in bad_stages(model, force, pull):
        with pytest.raises(error, match=message):
            textile.Stage(**kwargs)
    assert len(solver.history) == before[0]
    assert np.array_equal(model.nodal_unknowns(), before[1])
    assert (tmp_path / "results.json").read_text() == before[2]
    solver.run_stage(textile.Stage("more", ramp={force: [0, 0, 2 * F]}, release=[pull]))
    assert solver.history[-1].stage == "more"
    assert model.reaction(fib, 0)[2] == pytest.approx(-2 * F, rel=1e-9)


def test_stage_step_sizes_conflicting_with_the_run_are_refused_before_it_begins():
    """A stage's step sizes are checked alone when it is made, and against
    the run's when it starts: a conflict is refused before the stage
    begins (it used to leave the stage begun, so no stage could follow),
    and a good stage then runs."""
    fib, model, force = cantilever()
    solver = textile.Solver(model, dict(initial_step=0.5, max_step=0.5, verbose=False))
    solver.run([textile.Stage("load")])
    steps = len(solver.history)
    with pytest.raises(ValueError, match="need 0 < min_step <= initial_step <= max_step"):
        solver.run_stage(textile.Stage("coarse", ramp={force: [0, 0, 2 * F]},
                                       solver=dict(min_step=0.7)))
    assert len(solver.history) == steps
    solver.run_stage(textile.Stage("more", ramp={force: [0, 0, 2 * F]}))
    assert solver.history[-1].stage == "more"
    assert model.reaction(fib, 0)[2] == pytest.approx(-2 * F, rel=1e-9)


@pytest.mark.parametrize("name", ["verbose", "branch_switching"])
def test_solver_switches_are_true_or_false(name):
    """A switch given as text or a number is a named error, not truthy."""
    with pytest.raises(ValueError, match=f"SolverOptions.{name} must be True or False"):
        textile.SolverOptions(**{name: "no"})
