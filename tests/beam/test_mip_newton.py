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


@pytest.mark.parametrize("predictor", ["secant", "none"])
def test_rollup_closes_the_ring_with_mip_newton(predictor):
    # the set-up and tolerances of test_rollup.py
    E, nu, R, L = 1.0e9, 0.3, 1e-3, 1.0
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, nu),
                                 num_elements=32, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    _, I, _, _ = section(E, nu, R)
    model.add_end_moment(fib, -1, [0, 0, 2 * np.pi * E * I / L])
    solver = textile.Solver(model, dict(initial_step=0.05, max_step=0.05, newton="mip",
                                        predictor=predictor, **QUIET))
    for t in (0.25, 0.5):
        solver.solve(t)
        theta = 2 * np.pi * t
        ref = np.array([L * np.sin(theta) / theta, L * (1 - np.cos(theta)) / theta, 0.0])
        tip = model.centreline(fib)[-1]
        assert np.linalg.norm(tip - ref) < 5e-3 * L  # required 0.5% of L (measured ~1e-5)
    solver.solve(1.0)
    tip = model.centreline(fib)[-1]
    assert np.linalg.norm(tip) < 1e-3 * L  # back at the clamp (measured ~3e-5 L)
    c = np.array([0.0, L / (2 * np.pi), 0.0])
    r = np.linalg.norm(model.centreline(fib) - c, axis=1)
    assert np.allclose(r, L / (2 * np.pi), rtol=1e-3)
    # 20 steps of 18 degrees: measured 5-6 iterations a step (standard
    # Newton: 9-12, zig-zagging); quadratic convergence from the first
    # linearized iterate, whose stretch of the fibre is O(step^2)
    its = [h.newton_iterations for h in solver.history]
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
    """A quarter of the roll-up (16 elements, 5 steps) with MIP Newton."""
    E, nu, R, L = 1.0e9, 0.3, 1e-3, 1.0
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, nu),
                                 num_elements=16, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=comm)
    model.clamp(fib, 0)
    _, I, _, _ = section(E, nu, R)
    model.add_end_moment(fib, -1, [0, 0, 2 * np.pi * E * I / L])
    solver = textile.Solver(model, dict(initial_step=0.05, max_step=0.05, newton="mip",
                                        **QUIET))
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
