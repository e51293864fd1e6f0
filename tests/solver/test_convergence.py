"""Newton convergence per group of unknowns, and failures named in words."""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.solver.convergence import EPS
from textile.effects import Effect

E, NU, R, L = 1.0e9, 0.3, 1e-3, 0.5
P_CR = np.pi ** 2 * E * (np.pi * R ** 4 / 4) / (4 * L ** 2)  # clamped-free column


def column(n, lateral=1e-4):
    """Clamped-free column under P_cr (reached at t = 1) plus a lateral
    perturbation ``lateral`` P_cr at its tip."""
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, NU),
                                 num_elements=n)
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    model.add_force(fib, -1, [-P_CR, lateral * P_CR, 0])
    return fib, model


@pytest.mark.parametrize("n,dt,t_end", [(40, 0.01, 0.1), (128, 0.1, 0.5)])
def test_steps_at_the_round_off_floor_converge(n, dt, t_end):
    """A nearly exact predictor leaves the first residual on its round-off
    floor; the old single-norm test (1e-13 E A) then failed every step to
    min_step (40 elements at steps of 0.01 stopped at step 2; 128 elements
    at 0.5 P_cr). The floor test accepts them in one or two iterations."""
    fib, model = column(n, lateral=0.0)
    solver = textile.Solver(model, dict(initial_step=dt, max_step=dt, verbose=False))
    solver.solve(t_end)
    assert all(h.attempts == 1 for h in solver.history)
    assert max(h.newton_iterations for h in solver.history) <= 3
    # converged means at most floor_factor (10) times eps |K||q| per group;
    # measured: 0.2-0.35 eps |K||q| on positions and section vectors
    floors = EPS * model.floors(model.x)
    assert np.all(model.residual_norms <= 10 * floors + 1e-300)
    # and the answer is the straight column's (docs/references.md §1): the stretch
    # solves lambda (lambda^2 - 1) / 2 = -t P / (E A)
    lam = np.roots([0.5, 0.0, -0.5, t_end * P_CR / (E * np.pi * R ** 2)])
    lam = lam[np.argmin(np.abs(lam - 1))].real
    # (measured 1.3e-4: the clamp blocks the Poisson contraction over ~R, R/L = 2e-3)
    shortening = L - model.centreline(fib)[-1, 0]
    assert shortening == pytest.approx((1 - lam) * L, rel=5e-4)


def test_groups_are_reported_per_step(tmp_path):
    fib, model = column(8)
    out = textile.Output(str(tmp_path), pictures=False)
    solver = textile.Solver(model, dict(verbose=False), output=out)
    solver.solve(0.2)
    rec = solver.history[-1]
    assert set(rec.residuals) == {"positions", "sections", "constraints"}
    assert rec.reason == "CONVERGED_FNORM_ABS"
    import json
    step = json.loads((tmp_path / "results.json").read_text())["steps"][-1]
    assert step["residual_positions"] == pytest.approx(rec.residuals["positions"])


def test_failure_names_the_snes_reason():
    """DIVERGED_MAX_IT in words, never a bare number."""
    fib, model = column(8)
    solver = textile.Solver(model, dict(initial_step=1.0, max_step=1.0, min_step=0.5,
                                        max_it=1, verbose=False))
    with pytest.raises(textile.ConvergenceError, match="DIVERGED_MAX_IT after 1 Newton"):
        solver.solve(1.0)


class _Raises(Effect):
    """An effect whose residual raises ``error`` once t exceeds 0.3."""

    fields = ("beam",)

    def __init__(self, error):
        self.error = error

    def residual(self, state, b):
        if state.load_factor > 0.3:
            raise self.error


def test_a_bug_inside_an_effect_propagates():
    """A programming error is not a convergence failure: it reaches the
    caller with its own type and traceback instead of ten step cuts."""
    fib, model = column(4)
    model.add_effect(_Raises(KeyError("bug in an effect")))
    solver = textile.Solver(model, dict(verbose=False))
    with pytest.raises(KeyError, match="bug in an effect"):
        solver.solve()
    assert solver.counters["failed_attempts"] == 0


def test_a_domain_error_cuts_the_step_and_is_named():
    """GeometryError (e.g. a folded element) rejects the iterate: the step
    is cut, and when it persists the message says why."""
    fib, model = column(4)
    model.add_effect(_Raises(textile.GeometryError("folded element 3 of fibre 0")))
    solver = textile.Solver(model, dict(initial_step=0.25, min_step=0.01, verbose=False))
    with pytest.raises(textile.ConvergenceError,
                       match="DIVERGED_FUNCTION_DOMAIN.*folded element 3 of fibre 0"):
        solver.solve()
    assert solver.history[-1].load_factor <= 0.3
    assert solver.counters["failed_attempts"] >= 5


def test_counters_count_every_factorization():
    fib, model = column(8)
    solver = textile.Solver(model, dict(initial_step=0.25, verbose=False))
    solver.solve(0.5)
    c = solver.counters
    # a tangent per Newton iteration, plus the exact ones the stability check
    # factorizes at converged states it has no close factorization of
    assert c["jacobian_evaluations"] >= c["newton_iterations"]
    # one factorization per tangent (no reuse), symbolic once per matrix
    assert c["factorizations"] == c["jacobian_evaluations"]
    assert c["symbolic_factorizations"] == 1
    assert c["accepted_steps"] == len(solver.history) == 2


def test_cycling_newton_is_recognised():
    """Residual histories that repeat themselves with a period of 1 to 4
    iterations (stick-slip flipping, stuck at a floor) are cycling; a
    converging history, even a slow one, and a short one are not."""
    from textile.solver import cycling
    base = [1e-2, 1e-3]
    assert cycling(base + [5e-4, 8.7e-4] * 5)                       # period 2 (capstan)
    assert cycling(base + [4.96e-4, 9.86e-4, 4.99e-4, 7.71e-4] * 3)  # period 4
    assert cycling(base + [1.97e-8] * 8)                             # stuck
    assert not cycling(base + [5e-4, 8.7e-4] * 2)                    # too short to tell
    assert not cycling([10.0 ** -k for k in range(12)])              # converging
    assert not cycling([0.9 ** k for k in range(20)])                # slow, but 10% a step
    inf = float("inf")                    # inf - x passes any relative tolerance: inf = inf only
    assert not cycling(base + [inf, 3e-4, inf, 7e-4, inf, 2e-4, inf, 9e-4, inf, 1e-4])
    assert cycling(base + [inf, 5e-4] * 5)


#: residual norms of Newton solves (restarts on a rebuilt matrix merged,
#: each solve's first residual left out): the 6 x 6 sample of 28-fibre
#: bundles at its settling's s = 0.836 (2 ranks), the step doubled to
#: 0.0066, whose solve wandered for 50 iterations and 15 rebuilds; the same
#: load reached in two halves, whose second solve 2-cycled until the
#: cycle's line search; a column pushed off its unstable branch
#: (tests/stability/test_paths.py), which jumps 1e7-fold and then settles
#: on the buckled one; a step 100 times too large with the standard Newton
#: (tests/stability/test_extremes.py), 1e8 times its start, then falling
#: 3-fold an iteration
WANDERING = [3.2, 0.28, 0.28, 0.32, 0.41, 0.38, 0.75, 0.88, 1.8, 1.8, 2.3, 1.3, 0.65,
             3.1, 2.3, 0.74, 5.7, 0.91, 2.4, 2.0, 1.4, 2.0, 4.0, 4.2, 3.4, 2.9, 3.2, 4.1, 3.2,
             3.7, 4.4, 3.0, 4.8, 3.5, 2.6, 9.2, 4.4, 7.3, 3.0, 7.6, 6.6, 2.6, 3.6, 14, 6.2, 28,
             9.6, 20, 34, 470]
TWO_CYCLE = [1.9, 0.15, 0.18, 0.14, 0.18, 0.14, 0.18, 0.14, 0.18, 0.14]
OFF_THE_BRANCH = [27.9, 2.21, 0.0171, 0.0298, 1.33e5, 1.69e4, 2.26e3, 335, 50, 3.77, 0.0339,
                  6e-4, 2e-7, 1e-11]
TOO_LARGE = [3.86e8 / 3.4 ** k for k in range(25)]


def test_a_stalled_newton_is_recognised():
    """A Newton solve whose last STALL_ITERATIONS iterates have not gone
    below the lowest of the STALL_ITERATIONS before them has stalled: the
    28-fibre sample's wandering solve after 16 of its 50 iterations; not a
    converging history, nor one that jumps and then falls, however slowly,
    nor the 2-cycle that the cycle test finds first."""
    from textile.solver import cycling
    from textile.solver.convergence import CYCLE_PERIOD, STALL_ITERATIONS, stalled
    assert STALL_ITERATIONS == 2 * CYCLE_PERIOD

    def first_stall(norms):
        return next((k for k in range(len(norms) + 1) if stalled(norms[:k])), None)
    assert first_stall(WANDERING) == 2 * STALL_ITERATIONS
    for converging in (OFF_THE_BRANCH, TOO_LARGE, [10.0 ** -k for k in range(12)],
                       [0.97 ** k for k in range(60)], TWO_CYCLE):
        assert first_stall(converging) is None
    assert cycling([1.7] + TWO_CYCLE)


def test_the_path_tolerance_is_relative_to_the_steps_start():
    """SolverOptions.path_rtol: a step's solves after a contact update
    converge relative to the step's first residuals, not to their own
    start; relative to each solve's own start, the 1.5-width 7-fibre weave's
    capped passes ran out the contact loop's first half (a settling step of
    43 Newton iterations in 12 solves at path_rtol 0.05: each pass fell
    below the last but never by path_rtol of its own start)."""
    from textile.solver.convergence import GroupTolerances
    tol = GroupTolerances()
    reference, scales = np.array([1.0, 1.0]), np.array([1.0, 1.0])

    def converged(norms, on_path=True):
        return bool(np.all(tol.converged(np.array(norms), reference, None, scales,
                                         on_path=on_path)))
    tol.begin_solve(0.05)
    assert not converged([1.0, 2.0])            # the step's first residuals
    assert not converged([0.2, 0.2])
    tol.begin_solve(0.05, same_step=True)       # after a contact update
    assert converged([0.04, 0.09])              # below 0.05 x (1, 2)
    tol.begin_solve(0.05)                       # the next step: its own start
    assert not converged([0.04, 0.09])
    assert converged([0.001, 0.004])
    # a stage's end (on_path False): the full test only
    tol.begin_solve(0.05)
    assert not converged([1.0, 2.0], on_path=False)
    assert not converged([0.04, 0.09], on_path=False)
