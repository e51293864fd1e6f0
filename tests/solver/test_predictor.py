"""The predictor: a step starts from the polynomial through the stage's last
converged states (SolverOptions.predictor "secant" or "parabola"), and the
MIP Newton's first tangent there takes the stress extrapolated alike
(System.set_predicted_stress).

The roll-up of tests/beam/test_rollup.py in 16 steps of pi/8: from the
extrapolated state, a tangent whose stress is the linear extrapolation from
the last converged state sees the rotation's chord as a stretch; its
geometric stiffness stiffens bending, Newton first removes the stretch and
only then the bending error (6.9 iterations a step with the secant; the
plain start's 5.6). With the stress extrapolated as the state is, the
parabola needs 4 (benchmarks/README.md, "A predictor that extrapolates the
stress too").
"""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from tests.beam.common import QUIET, section

E, NU, R, L = 1.0e9, 0.3, 1e-3, 1.0


def rollup(comm=MPI.COMM_SELF, **options):
    """The cantilever of test_rollup.py (16 elements) and its solver in
    steps of 1/16 of the end moment that closes the ring."""
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, NU),
                                 num_elements=16, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=comm)
    model.clamp(fib, 0)
    _, I, _, _ = section(E, NU, R)
    model.add_end_moment(fib, -1, [0, 0, 2 * np.pi * E * I / L])
    return model, textile.Solver(model, dict(initial_step=1 / 16, max_step=1 / 16,
                                             **options, **QUIET))


def test_the_parabola_with_its_stress_rolls_up_in_four_iterations_a_step():
    model, solver = rollup(predictor="parabola")
    solver.solve(1.0)
    its = [h.newton_iterations for h in solver.history]
    # Newton regression (measured): the first step has no earlier state
    # (the plain start: 5), the second a secant (4), then the parabola (4)
    assert its == [5] + [4] * 15
    # the same ring as every other start: the tip back at the clamp
    # (6.08974e-6 L for every predictor, benchmarks/newton_iterations.py)
    assert np.linalg.norm(model.centreline(0)[-1]) == pytest.approx(6.08974e-6 * L, rel=1e-4)


def test_the_secant_alone_needs_five():
    """The secant, with its stress: 4 to 5 a step, measured 78 in
    all; without the stress extrapolated the secant needs 110."""
    _, solver = rollup(predictor="secant")
    solver.solve(1.0)
    its = [h.newton_iterations for h in solver.history]
    assert sum(its) == 78 and max(its) == 5


def test_a_run_resumed_within_a_stage_takes_the_same_steps(tmp_path):
    """Saved after the 4th step: the file holds both earlier states, and the
    resumed run extrapolates as the continuous one (same iterations, the
    same state to round-off). Without the older state its first step would
    be a secant's."""
    model, solver = rollup(predictor="parabola")
    path = str(tmp_path / "rolled.h5")
    solver.on_step = lambda s, rec: textile.save_state(model, path, s) if rec.step == 4 else None
    solver.solve(0.5)
    end = model.nodal_unknowns()
    continuous = [h.newton_iterations for h in solver.history][4:]

    model, solver = rollup(predictor="parabola")
    attrs = textile.load_state(model, path, solver)
    assert attrs["previous_load_factor"] == pytest.approx(3 / 16)
    assert attrs["older_load_factor"] == pytest.approx(2 / 16)
    solver.solve(0.5)
    assert [h.newton_iterations for h in solver.history] == continuous
    # round-off (the same operations in the same order: measured 0)
    assert np.abs(model.nodal_unknowns() - end).max() < 1e-12 * L


@pytest.mark.mpi
def test_two_ranks_take_the_same_steps():
    """The fibre split over two ranks: the same iterations, the same ring
    (round-off of sums in another order: measured 0)."""
    serial, serial_solver = rollup(predictor="parabola")
    parallel, parallel_solver = rollup(MPI.COMM_WORLD, predictor="parabola")
    serial_solver.solve(0.5)
    parallel_solver.solve(0.5)
    assert [h.newton_iterations for h in parallel_solver.history] == \
        [h.newton_iterations for h in serial_solver.history]
    assert np.abs(parallel.nodal_unknowns() - serial.nodal_unknowns()).max() < 1e-12 * L


def test_an_unknown_predictor_is_named():
    with pytest.raises(ValueError, match="SolverOptions.predictor must be one of"):
        textile.SolverOptions(predictor="quadratic")
