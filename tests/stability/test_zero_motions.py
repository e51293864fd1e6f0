"""Zero-energy motions are told from negative eigenvalues by what they are.

A fibre whose sections nothing holds against spinning about its axis has a
singular tangent: its round-off pivot takes either sign. The stability
check finds such motions among each fibre's strain-free candidates
(textile.stability.zero_motions) and leaves their pivots out of the count
(textile.stability.inertia: k - pos(Y^T F^-1 Y) of them are negative), so that the
genuine negative eigenvalues of a buckling column are counted exactly,
whatever sign the spin's pivot took.
"""
import warnings

import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.solver.convergence import EPS
from textile.solver import StabilityWarning
from textile.stability.zero_motions import ZERO_MOTION_TOLERANCE, candidate_energies

from . import guard

NU, L = 0.3, 0.5


def euler_load(young, slenderness, effective_length):
    R = L / slenderness
    return np.pi ** 2 * young * np.pi * R ** 4 / 4 / effective_length ** 2


def tangent_at_solution(model):
    model.newton = "standard"
    model.jacobian(None, model.x, model.A, model.A)
    return model.A


def test_tolerance_lies_between_free_spins_and_held_motions():
    """The energy (scaled metric) of the free spin of a straight fibre pinned
    at both ends is round-off; that of a curved fibre held at every node's
    position is not: its spin bends the sections against the curvature."""
    spins = []
    for slenderness in (10, 1e4):
        for young in (1.0, 1e9):
            fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], L / slenderness,
                                         textile.Material(young, NU), num_elements=32)
            model = textile.Model(fib, comm=MPI.COMM_SELF)
            model.fix(fib, 0, "position")
            model.fix(fib, -1, ["y", "z"])
            model.add_force(fib, -1, [-0.5 * euler_load(young, slenderness, L), 0, 0])
            textile.Solver(model, dict(verbose=False, stability_check="off")).solve()
            energies = candidate_energies(model, tangent_at_solution(model))
            assert list(energies) == [0] and len(energies[0]) == 1  # the spin only
            spins.append(abs(energies[0][0]))
    held = []
    for slenderness in (10, 1e4):
        radius = 0.05 * 1.5 / slenderness
        arc = textile.arc_fibre([0, 0, 0], 0.05, 1.5, radius, textile.Material(1e9, NU),
                                num_elements=16)
        model = textile.Model(arc, comm=MPI.COMM_SELF)
        for n in range(arc.num_nodes):
            model.fix(arc, n, "position")
        model.setup()
        held.append(abs(candidate_energies(model, tangent_at_solution(model))[0][0]))
    # measured 0.0007 to 1.14 eps (the tolerance's comment): round-off
    assert max(spins) <= 5 * EPS < ZERO_MOTION_TOLERANCE
    # measured 1.5e12 eps at L/R = 10 and 1.3e7 eps at 10^4 (as (R/L)^2)
    assert min(held) >= 3e6 * EPS > ZERO_MOTION_TOLERANCE


def spin_free_column(young, slenderness, comm=MPI.COMM_SELF):
    """A clamped-free column whose base holds its position and the
    direction of its section's normal (g1x = g2x = 0) but not the spin of
    its section about the axis; perfectly straight (no lateral force)."""
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], L / slenderness,
                                 textile.Material(young, NU), num_elements=32)
    model = textile.Model(fib, comm=comm)
    model.fix(fib, 0, ["position", "g1x", "g2x"])
    model.add_force(fib, -1, [-1.39 * euler_load(young, slenderness, 2 * L), 0, 0])
    return fib, model


def check_spin_free_column(model, solver, record):
    """Counts and warnings of a spin-free column solved to 1.39 P_cr;
    returns the negative pivots past P_cr."""
    messages = [str(w.message) for w in record]
    assert any("singular" in m and "fibre(s) [0] spin freely" in m for m in messages)
    assert any(m.startswith("stability lost at t=0.75: the tangent has 2 negative")
               for m in messages)
    past = []
    for h in solver.history:
        s = h.stability
        # the straight column buckles in two planes past P_cr (t = 1/1.39)
        assert s["negative_eigenvalues"] == (2 if h.load_factor > 1 / 1.39 else 0)
        # the spin, found whenever there are negative pivots to tell apart
        assert s["zero_energy_motions"] == (None if s["negative_pivots"] == 0 else 1)
        if h.load_factor > 1 / 1.39:
            past.append(s["negative_pivots"])
    return past


def test_free_spin_is_told_from_buckling(tmp_path):
    past = []
    for slenderness in (100, 1e4):
        for young in (1.0, 1e9):
            fib, model = spin_free_column(young, slenderness)
            out = str(tmp_path / f"{slenderness:g}_{young:g}")
            solver = textile.Solver(model, dict(initial_step=0.05, max_step=0.05, verbose=False,
                                                branch_switching=False),
                                    output=textile.Output(out, pictures=False))
            with pytest.warns(StabilityWarning) as record:
                solver.solve()
            guard.clean_output(out, solver)
            guard.newton_count(f"spin_free_column_slenderness{slenderness:g}_E{young:g}", solver)
            past += check_spin_free_column(model, solver, record)
            assert abs(model.centreline(fib)[-1, 1:]).max() < 1e-12 * L  # straight
    # the spin's round-off pivot came out negative at some steps (3 negative
    # pivots) and positive at others (2): 2 eigenvalues either way, which a
    # count of pivots less zero motions would get wrong at the latter
    assert set(past) == {2, 3}


@pytest.mark.mpi
def test_parallel_counts_and_branch_switching():
    """On the model's communicator (the fibre split between the ranks under
    mpirun -n 2): the spin found and left out, and branch switching onto the
    buckled column at L/R = 2000 with the Newton factorization."""
    comm = MPI.COMM_WORLD
    fib, model = spin_free_column(1e9, 2000, comm)
    solver = textile.Solver(model, dict(initial_step=0.05, max_step=0.05, verbose=False,
                                        branch_switching=False))
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always", StabilityWarning)
        solver.solve()
    if comm.rank == 0:  # warnings are issued on rank 0
        check_spin_free_column(model, solver, record)
    assert solver.history[-1].stability["negative_eigenvalues"] == 2

    slenderness = 2000
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], L / slenderness,
                                 textile.Material(1e9, NU), num_elements=32)
    model = textile.Model(fib, comm=comm)
    model.clamp(fib, 0)
    P = euler_load(1e9, slenderness, 2 * L)
    model.add_force(fib, -1, [-1.39 * P, 0, 1e-4 * P])
    solver = textile.Solver(model, dict(initial_step=0.05, max_step=0.05, verbose=False))
    with warnings.catch_warnings():
        warnings.simplefilter("error", StabilityWarning)
        solver.solve()
    assert sum(h.stability["branch_switched"] for h in solver.history) == 1
    assert solver.counters["factorizations"] == solver.counters["jacobian_evaluations"]
    # as on one rank (tests/stability/test_slenderness.py): the tip rotation
    # on the elastica at 1.39 P_cr, 0.76 L off the axis towards +z
    assert model.centreline(fib)[-1, 2] == pytest.approx(0.7617 * L, rel=1e-3)
