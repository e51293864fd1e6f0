"""Factorization choices give the same converged answer and are counted."""
import numpy as np
import pytest
from mpi4py import MPI

import textile

E, NU, R, L = 1.0e9, 0.3, 1e-3, 0.5
EI = E * np.pi * R ** 4 / 4


def cantilevers(n_fibres=3, options=None):
    """Tip-loaded cantilevers, deflection ~0.3 L: a genuinely nonlinear path."""
    fibres = [textile.straight_fibre([0, 0.01 * k, 0], [L, 0.01 * k, 0], R,
                                     textile.Material(E, NU), num_elements=16)
              for k in range(n_fibres)]
    model = textile.Model(fibres, comm=MPI.COMM_SELF)
    for f in fibres:
        model.clamp(f, 0)
        model.add_force(f, -1, [0, 0, -2 * EI / L ** 2])
    solver = textile.Solver(model, dict(initial_step=0.125, max_step=0.125, verbose=False,
                                        **(options or {})))
    solver.solve()
    return model.centreline(fibres[-1])[-1], solver


@pytest.fixture(scope="module")
def reference():
    return cantilevers(options=dict(factorization="lu"))


@pytest.mark.parametrize("options", [dict(factorization="cholesky"),
                                     dict(factorization="lu", scaling="mumps"),
                                     dict(reuse_factorization=3),
                                     dict(low_rank_tolerance=1e-8),
                                     dict(linear_solver="superlu_dist", factorization="lu")])
def test_same_answer_within_the_solver_tolerance(reference, options):
    tip_ref, solver_ref = reference
    tip, solver = cantilevers(options=options)
    # each converged state meets the residual test (rtol 1e-10 of a step's
    # first residual): measured 5e-14 L apart with the same steps, 1.1e-9 L
    # when GMRES with a reused factorization fails and steps get cut
    assert np.allclose(tip, tip_ref, rtol=0, atol=1e-8 * L)
    c = solver.counters
    if options.get("reuse_factorization", 1) > 1:
        # a factorization at each Newton solve's first iteration, then reuse
        assert c["factorizations"] < c["jacobian_evaluations"]
        assert c["matrix_vector_products"] > c["linear_solves"]  # GMRES on the exact tangent


def test_lu_is_scaled_by_the_diagonal_and_mumps_scales_nothing(reference):
    # LU: KSP's diagonal scaling, MUMPS's own off (ICNTL(8) = 0); the answer
    # is LDL^T's unscaled one (test_same_answer_within_the_solver_tolerance)
    _, solver = reference
    factor = solver.linear.snes.getKSP().getPC().getFactorMatrix()
    assert solver.linear.diagonal_scale and factor.getMumpsIcntl(8) == 0
    # LDL^T (the stability check's inverse) and the Krylov paths: unscaled,
    # MUMPS's automatic scaling (77)
    for options in (dict(factorization="cholesky"),
                    dict(factorization="lu", reuse_factorization=3),
                    dict(factorization="lu", scaling="mumps")):
        _, other = cantilevers(n_fibres=1, options=options)
        factor = other.linear.snes.getKSP().getPC().getFactorMatrix()
        assert not other.linear.diagonal_scale and factor.getMumpsIcntl(8) == 77


def test_auto_picks_ldlt_only_for_symmetric_scenes():
    _, solver = cantilevers(n_fibres=1)
    assert solver.linear.kind == "cholesky"
    assert solver.counters["ldlt_factorizations"] == solver.counters["jacobian_evaluations"]
    with pytest.raises(ValueError, match="needs symmetric tangents"):
        fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, NU),
                                     num_elements=2)
        model = textile.Model(fib, comm=MPI.COMM_SELF)
        model.clamp(fib, 0)
        model.add_end_moment(fib, -1, [0, 0, 1e-3])  # follower-like: not symmetric
        textile.Solver(model, dict(factorization="cholesky", verbose=False))


def test_bad_options_are_named():
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, NU), num_elements=2)
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    for bad, match in [(dict(factorization="qr"), "factorization"),
                       (dict(reuse_factorization=0), "reuse_factorization"),
                       (dict(low_rank_tolerance=-1), "low_rank_tolerance"),
                       (dict(scaling="none"), "scaling"),
                       (dict(newton="quasi"), "newton"),
                       (dict(newton_per_pass=-1), "newton_per_pass must be a non-negative"),
                       (dict(newton_per_pass=2.5), "newton_per_pass must be a non-negative")]:
        with pytest.raises(ValueError, match=match):
            textile.Solver(model, bad)


def test_mumps_workspace_grows_when_its_estimate_falls_short(tmp_path_factory):
    """MUMPS sizes its workspace at analysis from an estimate relaxed by
    ICNTL(14) percent; numerical pivoting on a tangent with multiplier rows
    (side bodies on a matrix) and a non-symmetric friction block can need
    more (INFOG(1) = -9, seen on the tests' composite with PETSc's default
    20%). The solver then doubles the relaxation and analyses afresh:
    started from 1%, the composite's release needs one retry (measured) and
    ends where a run with ample workspace (200%) ends."""
    from tests.io.test_state_file import QUIET, composite, fabric
    from tests.woven_states import woven_once
    woven = woven_once(tmp_path_factory, fabric(), QUIET)
    ends = {}
    for relax in (1, 200):
        c, _, stages = composite(woven, MPI.COMM_SELF)
        solver = textile.Solver(c.model, dict(verbose=False,
                                              petsc_options={"mat_mumps_icntl_14": relax}))
        solver.run(stages)
        ends[relax] = (c.model.nodal_unknowns(), solver.counters["linear_solve_retries"],
                       solver.linear.relaxation())
    q1, retries, relaxed = ends[1]
    assert (retries, relaxed) == (1, 40)       # 1% -> 2 x max(1, PETSc's 20)
    assert ends[200][1:] == (0, 200)
    # the same factorizations once they succeed: the same answer exactly
    assert np.array_equal(q1, ends[200][0])
