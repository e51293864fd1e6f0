"""Uniaxial tension: exact for this kinematics on any mesh (docs/references.md §1)."""
import numpy as np
import pytest
from mpi4py import MPI

import textile

from .common import QUIET, section


@pytest.mark.parametrize("order,num_elements", [(1, 1), (1, 5), (2, 1), (2, 3)])
@pytest.mark.parametrize("stretch", [1.01, 1.10])
def test_uniaxial_tension_is_exact(order, num_elements, stretch):
    E, nu, R, L = 2.0e9, 0.3, 1e-3, 0.05
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, nu),
                                 num_elements=num_elements, order=order, section_vector=[0, 1, 0])
    model = textile.Model(fib, textile.BeamElement(order=order), comm=MPI.COMM_SELF)
    # node 0: centroid fixed, section vectors free to contract but not to turn
    model.fix(fib, 0, ["position", "g1x", "g1z", "g2x", "g2y"])
    model.fix(fib, -1, "x", (stretch - 1) * L)
    solver = textile.Solver(model, dict(initial_step=1.0, max_step=1.0, **QUIET))
    solver.solve()
    A, _, _, _ = section(E, nu, R)
    N = E * A * stretch * (stretch ** 2 - 1) / 2
    # exact for the model: only round-off and the Newton tolerance remain
    assert model.reaction(fib, -1, "x")[0] == pytest.approx(N, rel=1e-8)
    assert model.reaction(fib, 0, "x")[0] == pytest.approx(-N, rel=1e-8)
    g1, g2 = model.section_vectors(fib)
    expected = np.sqrt(1 - nu * (stretch ** 2 - 1))
    assert np.allclose(np.linalg.norm(g1, axis=1), expected, rtol=1e-8, atol=0)
    assert np.allclose(np.linalg.norm(g2, axis=1), expected, rtol=1e-8, atol=0)
    # the centre line stretches uniformly
    x = model.centreline(fib)[:, 0]
    assert np.allclose(x, stretch * fib.points[:, 0], rtol=1e-10, atol=1e-14)
