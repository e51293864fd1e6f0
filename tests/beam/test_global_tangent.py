"""The assembled global tangent equals central differences of the assembled
residual (beam elasticity, dead loads, end moments, constraints together)."""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from tests.finite_differences import assembled_tangent_and_differences


@pytest.mark.parametrize("order", [1, 2])
def test_assembled_tangent_matches_finite_differences(order):
    E, nu, R, L = 1.0e6, 0.3, 1e-2, 0.3
    fibres = [textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, nu),
                                     num_elements=3, order=order),
              textile.arc_fibre([0, 0, 0.1], 0.2, 1.0, 0.5 * R, textile.Material(2 * E, 0.2),
                                num_elements=2, order=order)]
    model = textile.Model(fibres, textile.BeamElement(order=order), comm=MPI.COMM_SELF)
    model.clamp(0, 0)
    model.fix(1, 0, ["position", "g1"])
    model.add_end_moment(0, -1, [0.3, -0.2, 0.5])
    model.add_force(1, -1, [1.0, 2.0, -1.0])
    model.setup()
    model.load_factor = 0.7
    rng = np.random.default_rng(3)
    x = model.x
    # random finite deformation, small enough that no element folds (a
    # folded state, det F <= 0, is a GeometryError; 0.02 folded one here)
    x.setArray(rng.normal(scale=0.01, size=x.getLocalSize()))
    model.apply_constraints(x)
    J, Jfd, free = assembled_tangent_and_differences(model, x, h=1e-6)
    fixed_pos = model.constrained_positions()
    err = np.linalg.norm(J[:, free] - Jfd) / np.linalg.norm(Jfd)
    assert err < 1e-6  # central differences: truncation ~1e-10 relative
    # constrained rows are identity rows
    assert np.allclose(J[fixed_pos][:, fixed_pos], np.eye(len(fixed_pos)))
    assert np.allclose(np.delete(J[fixed_pos], fixed_pos, axis=1), 0.0)
