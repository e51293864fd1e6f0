"""The same fibre problem on all ranks and on one rank gives the same answer.

Run under ``mpirun -n 2``: the fibre's nodes are then split between the
ranks (ghost nodes at the cut), and the result is compared with a solve of
the same problem on MPI.COMM_SELF on each rank.
"""
import numpy as np
import pytest
from mpi4py import MPI

import textile

from .common import QUIET, section


def solve_bent_fibre(comm):
    E, nu, R, L = 1.0e9, 0.3, 1e-3, 1.0
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, nu),
                                 num_elements=16, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=comm)
    model.clamp(fib, 0)
    _, I, _, _ = section(E, nu, R)
    # finite rotations in two planes plus twist: a genuinely 3D nonlinear path
    model.add_end_moment(fib, -1, [0.3 * E * I / L, 0.2 * E * I / L, 0.5 * E * I / L])
    model.add_force(fib, 8, [0, 0, -2 * E * I / L ** 2])
    solver = textile.Solver(model, dict(initial_step=0.25, max_step=0.25, **QUIET))
    solver.solve()
    return (model.nodal_unknowns(), model.reaction(fib, 0, "all"),
            [h.newton_iterations for h in solver.history], model)


@pytest.mark.mpi
def test_parallel_equals_serial():
    q_par, r_par, its_par, model = solve_bent_fibre(MPI.COMM_WORLD)
    q_ser, r_ser, its_ser, _ = solve_bent_fibre(MPI.COMM_SELF)
    if MPI.COMM_WORLD.size > 1:
        # the fibre really is distributed: each rank owns part of its nodes
        assert 0 < model.mesh.num_owned < model.mesh.num_nodes_global
        assert len(model.mesh.ghosts) > 0 or MPI.COMM_WORLD.rank == MPI.COMM_WORLD.size - 1
    # Newton converges to round-off in both runs: 1e-10 relative
    assert np.allclose(q_par, q_ser, rtol=0, atol=1e-10 * np.abs(q_ser).max())
    # reactions are internal forces: their round-off floor is ~1e-15 E A
    # (the solver's absolute tolerance is 1e-13 E A), not 1e-10 of the reaction
    assert np.allclose(r_par, r_ser, rtol=1e-10, atol=1e-13 * model.force_scale)
    assert its_par == its_ser
    # the displacement is not trivial
    assert np.abs(q_ser[:, :3] - model.mesh.X_global[:, :3]).max() > 0.1


def solve_short_fibre(comm):
    """One element (3 nodes), a tip force: on 2 ranks one rank owns no
    node and no element (its sparsity blocks stay empty)."""
    E, R, L = 1.0e9, 1e-3, 0.1
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, 0.3),
                                 num_elements=1)
    model = textile.Model(fib, comm=comm)
    model.clamp(fib, 0)
    model.add_force(fib, -1, [0, 1e-3, 0])
    textile.Solver(model, dict(QUIET)).solve()
    return model.centreline(fib)[-1], model


@pytest.mark.mpi
def test_a_rank_without_elements():
    tip, model = solve_short_fibre(MPI.COMM_WORLD)
    if model.comm.size > 1:
        assert min(model.mesh.owned_counts) == 0  # the case meant: a rank owns nothing
    tip_serial, _ = solve_short_fibre(MPI.COMM_SELF)
    # the same Newton path on both: equal to round-off
    assert np.allclose(tip, tip_serial, rtol=0, atol=1e-12 * np.abs(tip_serial).max())
    assert tip_serial[1] > 0  # it did bend
