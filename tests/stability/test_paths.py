"""Equilibrium paths: bifurcations and limit points are seen and named.

Cases 2 and 3 of the stability issue: load control past a bifurcation used
to stay on the unstable straight branch without a word, and limit points
were not named.
"""
import time
import warnings

import numpy as np
import pytest
import scipy.special
from mpi4py import MPI

import textile
from textile.solver import StabilityWarning

from . import guard

E, NU, R, L = 1.0e9, 0.3, 1e-3, 0.5


def column(load=1.6, lateral=1e-4, elements=16, slenderness=L / R):
    """A clamped-free column of L/R = ``slenderness`` (500: R = 1 mm)
    loaded to ``load`` times its Euler load, with a lateral force."""
    radius = L / slenderness
    p_cr = np.pi ** 2 * E * np.pi * radius ** 4 / 4 / (4 * L ** 2)
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], radius, textile.Material(E, NU),
                                 num_elements=elements)
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    model.add_force(fib, -1, [-load * p_cr, 0, lateral * p_cr])
    return fib, model


#: the path cases at the slenderness of the first suite (R = 1 mm) and of
#: fibres (issue 22: the unstable column was once called stable there)
SLENDERNESS = [500, 2000, 10000]


def case(name: str, dt: float, slenderness: float) -> str:
    """Newton-count name (the first suite's names at L/R = 500)."""
    return f"{name}_dt{dt}" + ("" if slenderness == 500 else f"_slenderness{slenderness:g}")


def elastica_load(fib, model) -> float:
    """P/P_cr of the inextensible elastica at the column's tip rotation
    alpha (docs/references.md §4): (2 K(sin(alpha/2)) / pi)^2."""
    x = model.centreline(fib)
    t = x[-1] - x[-2]
    alpha = np.arctan2(abs(t[2]), t[0])
    return (2 * scipy.special.ellipk(np.sin(alpha / 2) ** 2) / np.pi) ** 2


@pytest.mark.parametrize("slenderness", SLENDERNESS)
@pytest.mark.parametrize("dt", [0.05, 0.25])
def test_unstable_branch_is_reported(out, dt, slenderness):
    """Past P_cr with large steps the column stays straight: an unstable
    equilibrium. It must be recorded per step and warned about once."""
    fib, model = column(slenderness=slenderness)
    solver = textile.Solver(model, dict(initial_step=dt, max_step=dt, verbose=False,
                                        branch_switching=False),
                            output=textile.Output(out, pictures=False))
    with pytest.warns(StabilityWarning, match="stability lost at t=.*negative eigenvalue"):
        solver.solve()
    data = guard.clean_output(out, solver)
    neg = [s["negative_eigenvalues"] for s in data["steps"]]
    t = [s["load_factor"] for s in data["steps"]]
    # stable below P_cr (t < 1/1.6), two negative eigenvalues above (the round
    # section buckles in two planes), none unchecked
    assert all(n == 0 for n, ti in zip(neg, t) if ti < 0.6)
    assert all(n == 2 for n, ti in zip(neg, t) if ti > 0.65)
    assert any("stability lost" in w for w in data["meta"]["warnings"])
    assert abs(model.centreline(fib)[-1, 2]) < 1e-3 * L  # still straight
    # counting needs no eigen-solve: a clamped column has no zero-energy
    # motion to tell apart (looked for at every unstable step, counted and
    # timed), and no factorization beyond Newton's (one per tangent)
    assert solver.counters["eigen_solves"] == 0
    unstable = sum(n > 0 for n in neg)
    assert solver.counters["zero_motion_searches"] == unstable > 0
    assert solver.counters["zero_motion_seconds"] > 0
    assert solver.counters["factorizations"] == solver.counters["jacobian_evaluations"]
    guard.newton_count(case("unstable_branch_reported", dt, slenderness), solver)


def test_an_instability_is_described_without_switching(out, monkeypatch):
    """Branch switching off, describe_instability on: the step that loses
    stability records its critical mode (what the 336-fibre composite
    twisting reports, where a switch costs too much), the path stays
    straight, and the eigen-solve is not counted as the check's own time."""
    from textile.solver import stability_check

    class Clock:
        """The check's clock, moved on by 1000 s in each eigen-solve."""
        offset = 0.0

        def perf_counter(self):
            return time.perf_counter() + self.offset

    clock = Clock()

    def slow_critical_modes(*args):
        clock.offset += 1000.0
        return critical_modes(*args)

    critical_modes = stability_check.critical_modes
    monkeypatch.setattr(stability_check, "critical_modes", slow_critical_modes)
    monkeypatch.setattr(stability_check, "time", clock)
    fib, model = column(slenderness=2000)
    solver = textile.Solver(model, dict(initial_step=0.25, max_step=0.25, verbose=False,
                                        branch_switching=False, describe_instability=True),
                            output=textile.Output(out, pictures=False))
    with pytest.warns(StabilityWarning, match="stability lost"):
        solver.solve()
    data = guard.clean_output(out, solver)
    described = [s for s in data["steps"] if "critical_mode" in s]
    # once, at the first unstable step (t = 0.75 > 1/1.6), not at later ones
    assert [s["load_factor"] for s in described] == [0.75]
    mode = described[0]["critical_mode"]
    # the factorization's eigenpair is the assembled tangent's (measured to
    # 1e-7 relative in the switching test: the eigen-solve's tolerance)
    assert mode["eigenvalue"] < 0
    assert mode["rayleigh_with_the_matrix"] == pytest.approx(mode["eigenvalue"], rel=1e-5)
    assert mode["mode_share"]["positions"] + mode["mode_share"]["sections"] == pytest.approx(1)
    assert "moved" not in mode and abs(model.centreline(fib)[-1, 2]) < 1e-3 * L
    c = solver.counters
    assert c["eigen_solves"] == 1 and c["branch_switches"] == c["branch_attempts"] == 0
    # the check's own time (inertia, zero-motion search: milliseconds here)
    # excludes the eigen-solve, 1000 s on the check's clock
    assert c["eigen_solve_seconds"] >= 1000 > c["stability_check_seconds"] > 0


@pytest.mark.parametrize("slenderness", SLENDERNESS)
@pytest.mark.parametrize("dt", [0.05, 0.25])
def test_branch_switching_follows_the_buckled_column(out, dt, slenderness):
    """With branch switching the column leaves the unstable straight branch
    along its critical mode, on the side the lateral force pushes, and ends
    on the elastica."""
    fib, model = column(slenderness=slenderness)
    solver = textile.Solver(model, dict(initial_step=dt, max_step=dt, verbose=False,
                                        branch_switching=True),
                            output=textile.Output(out, pictures=False))
    with warnings.catch_warnings():
        warnings.simplefilter("error", StabilityWarning)  # never unstable
        solver.solve()
    data = guard.clean_output(out, solver)
    assert all(s["negative_eigenvalues"] == 0 for s in data["steps"])
    assert sum(s["branch_switched"] for s in data["steps"]) == 1
    # one eigen-solve: the critical modes, with the Newton factorization
    # (no factorization beyond Newton's: one per tangent)
    assert solver.counters["eigen_solves"] == 1
    assert solver.counters["factorizations"] == solver.counters["jacobian_evaluations"]
    # every Newton solve is a step's or a perturbed state's: the stable
    # equilibrium found is kept as solved, not solved again
    c = solver.counters
    assert c["newton_solves"] == (c["accepted_steps"] + c["failed_attempts"]
                                  + c["branch_attempts"]), c
    assert c["branch_switches"] == 1 and c["stability_checks"] == c["accepted_steps"]
    # the switch is recorded with its critical mode: a negative eigenvalue of
    # the fibre's unknowns (no multiplier here), energy released, the tip moved
    mode = next(s["critical_mode"] for s in data["steps"] if s["branch_switched"])
    assert mode["eigenvalue"] < 0 and mode["energy_released"] > 0
    assert mode["mode_share"]["positions"] + mode["mode_share"]["sections"] == pytest.approx(1)
    assert mode["moved"] > 0.1 * L
    # the factorization's eigenpair is the assembled tangent's (v.Kv = lambda,
    # |Kv| = |lambda|; measured to 1e-7 relative: the eigen-solve's tolerance)
    assert mode["rayleigh_with_the_matrix"] == pytest.approx(mode["eigenvalue"], rel=1e-5)
    assert mode["image_norm_with_the_matrix"] == pytest.approx(-mode["eigenvalue"], rel=1e-5)
    assert model.centreline(fib)[-1, 2] > 0.5 * L  # buckled towards +z, the lateral force
    # 1.6 P_cr on the elastica: measured 0.045% off at L/R = 500, 0.054% at
    # 2000 and 10^4 (extensibility, shear, the discretization, the 1e-4
    # lateral force); the unstable straight branch is 60% off
    assert elastica_load(fib, model) == pytest.approx(1.6, rel=2e-3)
    guard.newton_count(case("branch_switching", dt, slenderness), solver)


def bar(elements=2):
    """A bar held straight (lateral dofs fixed): compression has a limit
    point at stretch 1/sqrt(3), N = -0.19245 E A (docs/references.md §1)."""
    fib = textile.straight_fibre([0, 0, 0], [0.05, 0, 0], R, textile.Material(E, NU),
                                 num_elements=elements, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.fix(fib, 0, ["position", "g1x", "g1z", "g2x", "g2y"])
    for i in range(1, fib.num_nodes):
        model.fix(fib, i, ["y", "z"])
    return fib, model, E * np.pi * R ** 2


def test_force_past_the_limit_point_is_named(out):
    fib, model, EA = bar()
    model.add_force(fib, -1, [-0.3 * EA, 0, 0])
    solver = textile.Solver(model, dict(initial_step=0.25, max_step=0.25, min_step=1e-3,
                                        verbose=False), output=textile.Output(out, pictures=False))
    # past the limit load there is no equilibrium: Newton wanders and stalls
    # (20 iterations) before max_it (25)
    with pytest.raises(textile.ConvergenceError, match="DIVERGED_NEWTON_STALL.*limit point"):
        solver.solve()
    guard.clean_output(out, solver, failed="limit point")
    # the last converged load is below the limit load 0.19245 E A
    assert 0.55 < solver.history[-1].load_factor < 0.19245 / 0.3
    guard.newton_count("limit_point_force", solver)


def test_displacement_past_the_limit_point_is_flagged(out):
    """Displacement-driven, the bar can be squeezed past the limit point;
    each element then has a negative axial stiffness: flagged from the first
    step beyond stretch 1/sqrt(3) = 0.577."""
    fib, model, EA = bar(elements=4)
    model.fix(fib, -1, "x", -0.6 * 0.05)
    solver = textile.Solver(model, dict(initial_step=0.05, max_step=0.05, verbose=False,
                                        branch_switching=False),
                            output=textile.Output(out, pictures=False))
    with pytest.warns(StabilityWarning, match="limit point"):
        solver.solve()
    data = guard.clean_output(out, solver)
    for s in data["steps"]:
        stretch = 1 - 0.6 * s["load_factor"]
        if stretch > 0.6:
            assert s["negative_eigenvalues"] == 0
        elif stretch < 0.56:
            assert s["negative_eigenvalues"] > 0
    guard.newton_count("limit_point_displacement", solver)
