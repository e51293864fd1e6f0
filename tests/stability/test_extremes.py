"""Extreme parameters and careless steps: converge to the known answer.

A cantilever under a dead tip force P orthogonal to it follows Euler's
elastica; its tip is computed here independently (scipy's BVP solver on
EI theta'' + P cos(theta) = 0, theta(0) = 0, theta'(L) = 0).
"""
import numpy as np
import pytest
import scipy.integrate
from mpi4py import MPI

import textile

from . import guard

E = 1.0e9


def elastica_tip(k: float) -> tuple[float, float]:
    """Tip of the inextensible elastica with k = P L^2 / (E I): (horizontal
    shortening, vertical deflection) / L."""
    def rhs(s, y):  # y = (theta, theta', x, z)
        return np.vstack([y[1], -k * np.cos(y[0]), np.cos(y[0]), np.sin(y[0])])

    def bc(a, b):
        return np.array([a[0], b[1], a[2], a[3]])

    s = np.linspace(0, 1, 201)
    guess = np.vstack([0.5 * s, 0.5 * np.ones_like(s), s, 0 * s])
    sol = scipy.integrate.solve_bvp(rhs, bc, s, guess, tol=1e-10, max_nodes=100000)
    assert sol.success
    return 1 - sol.y[2, -1], sol.y[3, -1]


def cantilever(k, slenderness, nu, elements, options, out):
    R = 1e-3
    L = slenderness * R
    EI = E * np.pi * R ** 4 / 4
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, nu),
                                 num_elements=elements, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    model.add_force(fib, -1, [0, 0, k * EI / L ** 2])  # dead: stays along z
    solver = textile.Solver(model, dict(verbose=False, **options),
                            output=textile.Output(out, pictures=False))
    solver.solve()
    guard.clean_output(out, solver)
    tip = model.centreline(fib)[-1]
    return (L - tip[0]) / L, tip[2] / L, solver


def test_reference_elastica_values():
    """The independent reference reproduces Bisshopp & Drucker's table."""
    assert elastica_tip(1.0) == pytest.approx((0.05643, 0.30172), abs=2e-5)


@pytest.mark.parametrize("newton", ["standard", "mip"])
def test_step_100_times_too_large(out, newton):
    """k = 100 (the tip swings to 0.94 L) is comfortable in steps of ~0.01
    of the load. One step of the whole load: standard Newton cannot take it
    and the step is cut automatically; MIP Newton takes it at once. Both
    finish on the elastica."""
    dx, dz, solver = cantilever(100.0, 200, 0.3, 16,
                                dict(initial_step=1.0, max_step=1.0, newton=newton), out)
    ex, ez = elastica_tip(100.0)
    # measured 7.5e-4: the fibre stretches by P / (E A) = 6e-4 (the elastica
    # is inextensible)
    assert (dx, dz) == pytest.approx((ex, ez), abs=2e-3)
    if newton == "standard":
        assert solver.history[0].attempts > 1  # the first step was cut
    guard.newton_count(f"step_100x_too_large_{newton}", solver)


def test_slenderness_ten_thousand(out):
    """L/R = 1e4: axial stiffness 4e8 times the bending one; the
    round-off floor of the residual grows accordingly and must not stop
    Newton."""
    dx, dz, solver = cantilever(1.0, 1e4, 0.3, 64, dict(initial_step=0.25, max_step=0.25),
                                out)
    ex, ez = elastica_tip(1.0)
    # measured 7.6e-7 (64 elements; O(h^4), 6.6e-6 on 32): at L/R = 1e4 the
    # beam is the inextensible elastica. Before the force scale of the
    # convergence test was the applied load (not the first residual), steps
    # of 0.25 stopped 2.5e-5 off (a Newton zig-zag accepted midway)
    assert (dx, dz) == pytest.approx((ex, ez), abs=3e-6)
    guard.newton_count("slenderness_1e4", solver)


def test_nearly_incompressible_fibre(out):
    """nu = 0.49: the 3D law of the section average is nearly
    incompressible (lambda = 25 mu); bending must still see E I (the
    Poisson cure), on the elastica."""
    dx, dz, solver = cantilever(2.0, 200, 0.49, 16, dict(initial_step=0.25, max_step=0.25),
                                out)
    ex, ez = elastica_tip(2.0)
    # measured 1e-4; without the cure E I would be 4.4x too stiff here
    assert (dx, dz) == pytest.approx((ex, ez), abs=1e-3)
    guard.newton_count("poisson_0.49", solver)
