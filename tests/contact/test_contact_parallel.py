"""Contact across ranks: the same answer on all ranks as on one."""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import FibreContact


def solve(comm):
    mat = textile.Material(1.0e9, 0.3)
    R, L = 1e-3, 0.1
    # three fibres: A fixed, B crossing on it, C parallel on B (point and line contacts)
    A = textile.straight_fibre([0, -L / 2, 0], [0, L / 2, 0], R, mat, num_elements=8)
    B = textile.straight_fibre([-L / 2, 0, 2 * R], [L / 2, 0, 2 * R], R, mat, num_elements=8)
    C = textile.straight_fibre([-L / 4, 0, 4 * R - 1e-6], [L / 4, 0, 4 * R - 1e-6], R, mat,
                               num_elements=4)
    model = textile.Model([A, B, C], comm=comm)
    for n in range(A.num_nodes):
        model.fix(A, n, "all")
    model.fix(B, 0, ["position", "g1x"], [0, 0, -1e-4, 0])
    model.fix(B, -1, ["y", "z"], [0, -1e-4])
    for n in (0, -1):
        model.fix(C, n, ["x", "y", "g1x"] if n == 0 else ["y"])
    for n in range(C.num_nodes):
        model.add_force(C, n, [0, 0, -1e-3])
    contact = FibreContact(dict(friction=0.2))
    model.add_effect(contact)
    solver = textile.Solver(model, dict(initial_step=0.25, max_step=0.25, verbose=False))
    solver.solve()
    return model.nodal_unknowns(), solver.history[-1].effects, model


@pytest.mark.mpi
def test_contact_parallel_equals_serial():
    q_par, stats_par, model = solve(MPI.COMM_WORLD)
    q_ser, stats_ser, _ = solve(MPI.COMM_SELF)
    # converged to the Newton tolerance in both runs
    assert np.allclose(q_par, q_ser, rtol=0, atol=1e-10 * np.abs(q_ser).max())
    for key in ("contact_zones", "contact_elements", "active_contacts"):
        assert stats_par[key] == stats_ser[key]
    assert stats_par["contact_force_sum"] == pytest.approx(stats_ser["contact_force_sum"],
                                                           rel=1e-8)
    assert stats_ser["active_contacts"] >= 3  # the crossing and C's line contact
