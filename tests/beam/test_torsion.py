"""Torsion of a round fibre: G J exact (docs/references.md §3)."""
import numpy as np
import pytest
from mpi4py import MPI

import textile

from .common import QUIET, section


@pytest.mark.parametrize("nu", [0.0, 0.3])
def test_torsional_stiffness(nu):
    E, R, L = 1.0e9, 1e-3, 0.2
    _, _, J, G = section(E, nu, R)
    tau = 1e-3 / R            # twist rate with tau R = 1e-3: linear regime
    T = G * J * tau
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, nu),
                                 num_elements=8, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    model.add_end_moment(fib, -1, [T, 0, 0])
    solver = textile.Solver(model, dict(initial_step=0.5, max_step=0.5, **QUIET))
    solver.solve()
    g1, _ = model.section_vectors(fib)
    phi = np.arctan2(g1[-1, 2], g1[-1, 1])  # rotation of g1 about x at the tip
    # 0.5% required; expected error ~(tau R)^2 from finite strain
    assert phi / (tau * L) == pytest.approx(1.0, rel=5e-3)
    assert phi / (tau * L) == pytest.approx(1.0, rel=1e-4)  # measured tighter
    # the twist is uniform: rotation grows linearly along the fibre
    ang = np.arctan2(g1[:, 2], g1[:, 1])
    assert np.allclose(ang, tau * fib.points[:, 0], rtol=1e-3, atol=1e-9)
