"""MIP Newton (SolverOptions(newton="mip")) reaches the same equilibria as
standard Newton in fewer iterations.

The MIP tangent differs from the exact one only in the stress of its
geometric stiffness (linearly extrapolated from the previous iterate,
cpp/textile/beam/beam_element.h), so the converged states are the same;
the roll-up, whose standard Newton zig-zags for ~11 iterations a step,
converges quadratically.
"""
import numpy as np
import pytest
import scipy.special
from mpi4py import MPI

import textile

from .common import QUIET, section


def rolled_fibre(comm, num_elements, newton, predictor="secant"):
    """The roll-up of test_rollup.py: a cantilever, its end moment
    M = 2 pi E I / L closes it into a ring at load factor 1, steps of 0.05
    (18 degrees). Returns the model and its solver."""
    E, nu, R, L = 1.0e9, 0.3, 1e-3, 1.0
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, nu),
                                 num_elements=num_elements, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=comm)
    model.clamp(fib, 0)
    _, I, _, _ = section(E, nu, R)
    model.add_end_moment(fib, -1, [0, 0, 2 * np.pi * E * I / L])
    return model, textile.Solver(model, dict(initial_step=0.05, max_step=0.05, newton=newton,
                                             predictor=predictor, **QUIET))


# how far apart the two runs may end a step: with predictor "none" both
# converge to round-off (measured 1e-10); with "secant" the solver's rtol,
# relative to the predicted state's large residual (1e3 against 3e-4 for the
# load increment), accepts standard Newton's iterate at a residual of ~1e-7,
# 2e-5 away from the equilibrium (measured)
SAME_STATE = {"none": 1e-9, "secant": 1e-4}


@pytest.mark.parametrize("predictor", ["secant", "none"])
def test_rollup_with_mip_newton_reaches_the_standard_states(predictor):
    """test_rollup.py checks standard Newton against the exact ring; MIP
    Newton must pass through the same equilibria."""
    std, std_solver = rolled_fibre(MPI.COMM_SELF, 32, "standard", predictor)
    mip, mip_solver = rolled_fibre(MPI.COMM_SELF, 32, "mip", predictor)
    for t in (0.25, 0.5, 1.0):
        std_solver.solve(t)
        mip_solver.solve(t)
        assert np.allclose(mip.nodal_unknowns(), std.nodal_unknowns(), rtol=0,
                           atol=SAME_STATE[predictor])
    assert np.linalg.norm(mip.centreline(0)[-1]) < 1e-3  # the ring closed (measured 3e-5)
    # 20 steps of 18 degrees: measured 5-6 iterations a step (standard
    # Newton: 9-12, zig-zagging); quadratic convergence from the first
    # linearized iterate, whose stretch of the fibre is O(step^2)
    its = [h.newton_iterations for h in mip_solver.history]
    assert len(its) == 20 and max(its) <= 7


def post_buckling(newton):
    """Clamped-free column (demos/demo_buckled_column.py on 8 elements)
    loaded to 1.2 Euler loads with a lateral perturbation of 1e-4; returns
    (P/P_e, tip rotation in degrees) along the path, and the solver."""
    E, nu, R, L = 1.0e9, 0.3, 1e-3, 0.5
    _, I, _, _ = section(E, nu, R)
    P_e = np.pi ** 2 * E * I / (4 * L ** 2)
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, nu),
                                 num_elements=8, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    model.add_force(fib, -1, [-1.2 * P_e, 0, 1e-4 * P_e])
    path = []

    def record(solver, rec):
        _, g2 = solver.model.section_vectors(fib)
        path.append((1.2 * rec.load_factor, np.degrees(np.arctan2(-g2[-1, 0], g2[-1, 2]))))

    # steps of 0.005: with 0.01 MIP Newton converges, right past P_e, to the
    # unstable near-straight equilibrium on the other side (load control
    # cannot tell the branches apart; standard Newton failed there, was cut
    # and happened to land on the stable branch)
    solver = textile.Solver(model, dict(initial_step=0.005, max_step=0.005, newton=newton,
                                        **QUIET), on_step=record)
    solver.solve(1.0)
    return np.array(path), solver


def test_post_buckling_path_with_mip_newton():
    mip, solver_mip = post_buckling("mip")
    std, solver_std = post_buckling("standard")
    load, alpha = mip[:, 0], mip[:, 1]
    assert np.all(np.diff(alpha) > -1e-9)  # the stable branch, not the mirror one
    # the inextensible elastica: P/P_cr = (2 K(sin(alpha/2)) / pi)^2;
    # measured 2e-4 (20 deg) and 3e-4 (60 deg) from it on 8 elements
    for a in (20.0, 60.0):
        ref = (2 * scipy.special.ellipk(np.sin(np.radians(a) / 2) ** 2) / np.pi) ** 2
        assert np.interp(a, alpha, load) == pytest.approx(ref, rel=1e-3)
    # the same end state as standard Newton: both converged to 1e-10
    assert mip[-1, 1] == pytest.approx(std[-1, 1], rel=1e-8)
    # past the critical load: measured 4.7 iterations a step on average
    # (at most 7) against 6.8 (at most 23) for standard Newton
    post = [h.newton_iterations for h, (p, _) in zip(solver_mip.history, mip) if p > 1.0]
    post_std = [h.newton_iterations for h, (p, _) in zip(solver_std.history, std) if p > 1.0]
    assert np.mean(post) < 0.8 * np.mean(post_std) and max(post) <= 9


def rollup_quarter(comm):
    """A quarter of the roll-up on 16 elements with MIP Newton."""
    model, solver = rolled_fibre(comm, 16, "mip")
    solver.solve(0.25)
    return model.nodal_unknowns(), [h.newton_iterations for h in solver.history], model


@pytest.mark.mpi
def test_mip_newton_parallel_equals_serial():
    """The updates du of ghost nodes reach the element kernels: the
    iterations and the answer do not depend on the partition."""
    q_par, its_par, model = rollup_quarter(MPI.COMM_WORLD)
    q_ser, its_ser, _ = rollup_quarter(MPI.COMM_SELF)
    if MPI.COMM_WORLD.size > 1:
        assert 0 < model.mesh.num_owned < model.mesh.num_nodes_global
    assert its_par == its_ser
    # Newton converges to round-off in both runs: 1e-10 relative
    assert np.allclose(q_par, q_ser, rtol=0, atol=1e-10 * np.abs(q_ser).max())
