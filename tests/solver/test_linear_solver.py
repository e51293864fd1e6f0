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
                       (dict(newton="quasi"), "newton")]:
        with pytest.raises(ValueError, match=match):
            textile.Solver(model, bad)
