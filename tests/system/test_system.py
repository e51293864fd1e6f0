"""The scene and its assembled system (textile.system.system.System;
docs/solver_parts.md): the solver's parts work on the model's System, a
Newton solve runs on a System alone, and a closed scene refuses additions."""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.solver import SolverOptions
from textile.solver.newton import Newton

E, R, L, P = 1.0e9, 1e-3, 1.0, 1e-6   # P L^2 / (E I) = 1.3e-3: the linear regime


def cantilever():
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, 0.0),
                                 num_elements=8)
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    model.add_force(fib, -1, [0, 0, P])
    return fib, model


def test_the_solver_parts_work_on_the_models_system():
    fib, model = cantilever()
    solver = textile.Solver(model, dict(verbose=False))
    system = model.system
    assert solver.newton.system is system and solver.loop.system is system
    assert solver.stability.system is system and solver.stepping.system is system
    assert solver.stepping.model is model           # the scene: schedules, stages
    solver.solve()
    deflection = model.centreline(fib)[-1, 2]
    # P L^3 / (3 E I); measured 1.3e-6 relative (geometric nonlinearity,
    # shear): tolerance 4x
    assert deflection == pytest.approx(P * L ** 3 / (3 * E * np.pi * R ** 4 / 4), rel=5e-6)
    # the support reaction balances the load (read through the scene)
    assert model.reaction(fib, 0)[2] == pytest.approx(-P, rel=1e-8)


def test_a_newton_solve_runs_on_a_system_alone():
    """Newton needs the System only: the same answer as the Solver's."""
    fib, model = cantilever()
    textile.Solver(model, dict(verbose=False)).solve()
    expected = model.centreline(fib)

    fib2, scene = cantilever()
    system = scene.system
    system.newton = "standard"
    system.load_factor = 1.0
    system.apply_constraints(system.x)
    result = Newton(system, SolverOptions(verbose=False)).solve(system.x)
    assert result.reason > 0
    # one load step against the Solver's steps: equal to the tolerance of
    # the convergence test (measured 3.0e-13 of L: the Solver's last step
    # starts on the parabola, whose residual, 2.8e-11, the test accepts
    # at once; 8.8e-15 from the plain start)
    assert np.allclose(scene.centreline(fib2), expected, rtol=0, atol=1e-12 * L)


def test_a_closed_scene_refuses_additions():
    fib, model = cantilever()
    model.system   # built: the scene closes
    with pytest.raises(RuntimeError, match="already assembled"):
        model.add_force(fib, 3, [1.0, 0, 0])
    assert model.system is model.system   # built once
