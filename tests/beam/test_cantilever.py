"""Small-deflection cantilever (docs/references.md §5), shear term with factor 1."""
import numpy as np
import pytest
from mpi4py import MPI

import textile

from .common import QUIET, section


@pytest.mark.parametrize("num_elements", [2, 8])
def test_tip_deflection(num_elements):
    E, nu, R, L, P = 1.0e9, 0.3, 1e-3, 0.2, 1e-4
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, nu),
                                 num_elements=num_elements)
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    model.add_force(fib, -1, [0, 0, -P])
    solver = textile.Solver(model, dict(initial_step=1.0, max_step=1.0, **QUIET))
    solver.solve()
    A, I, _, G = section(E, nu, R)
    ref = P * L ** 3 / (3 * E * I) + P * L / (G * A)
    tip = -model.centreline(fib)[-1, 2]
    # the quadratic element with 2 Gauss points is exact up to geometric
    # nonlinearity (w/L ~ 2e-3): measured 3.2e-6 (2 elements) and 3.0e-6
    # (8) below the linear answer; tolerance 3x
    assert tip == pytest.approx(ref, rel=1e-5)
    assert model.reaction(fib, 0, "z")[0] == pytest.approx(P, rel=1e-9)  # equilibrium
    # regression: a nearly linear problem converges in few Newton iterations
    assert solver.history[-1].newton_iterations <= 4


def test_full_integration_locks_and_converges():
    """Quadratic elements with 3 Gauss points lock (O(h^2)); with 2 they do not."""
    E, nu, R, L, P = 1.0e9, 0.3, 1e-3, 0.2, 1e-4
    A, I, _, G = section(E, nu, R)
    ref = P * L ** 3 / (3 * E * I) + P * L / (G * A)
    errors = {}
    for points in (2, 3):
        for n in (4, 8, 16):
            fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, nu),
                                         num_elements=n)
            model = textile.Model(fib, textile.BeamElement(order=2, axial_points=points),
                                  comm=MPI.COMM_SELF)
            model.clamp(fib, 0)
            model.add_force(fib, -1, [0, 0, -P])
            textile.Solver(model, dict(initial_step=1.0, max_step=1.0, **QUIET)).solve()
            errors[points, n] = abs(-model.centreline(fib)[-1, 2] / ref - 1)
    for n in (4, 8, 16):
        assert errors[2, n] < 1e-5  # no locking at any mesh (geometric nonlinearity ~3e-6)
    # locking of the fully integrated element decays at order 2: measured
    # 1.54e-2 on 4 elements (README), 3.7e-3 on 8, 7.8e-4 on 16
    assert errors[3, 4] == pytest.approx(1.54e-2, rel=0.05)
    for a, b in ((4, 8), (8, 16)):
        rate = np.log2(errors[3, a] / errors[3, b])
        assert rate > 1.8


def test_curved_cantilever_converges_without_membrane_locking():
    """Quarter-circle cantilever (radius a) under an out-of-plane tip load:
    delta = P a^3 [pi/(4 E I) + (3 pi/4 - 2)/(G J)] (Roark, bending + torsion)."""
    E, nu, R, a, P = 1.0e9, 0.3, 1e-3, 0.2, 1e-4
    A, I, J, G = section(E, nu, R)
    ref = P * a ** 3 * (np.pi / (4 * E * I) + (3 * np.pi / 4 - 2) / (G * J))
    errors = []
    for n in (2, 4, 8, 16):
        fib = textile.arc_fibre([0, 0, 0], a, np.pi / 2, R, textile.Material(E, nu),
                                num_elements=n)
        model = textile.Model(fib, comm=MPI.COMM_SELF)
        model.clamp(fib, 0)
        model.add_force(fib, -1, [0, 0, -P])
        textile.Solver(model, dict(initial_step=1.0, max_step=1.0, **QUIET)).solve()
        errors.append(abs(-model.centreline(fib)[-1, 2] / ref - 1))
    # measured: 5.1e-3, 7.5e-4, 1.4e-4, 1.8e-5 (the arc is itself interpolated)
    assert all(e1 > e2 for e1, e2 in zip(errors, errors[1:]))  # monotone convergence
    assert errors[-1] < 1e-4
