"""A scene contact cannot resolve stops cleanly: a specific message, the
last converged state on disk, no NaN.

Two crossing fibres are moved rigidly through each other (every node
prescribed, A up and B down by 3 radii each): no equilibrium keeps them
apart. The penalty is raised to the top of its range, then the step is
refused as a pass-through, cut, and the run ends with a ConvergenceError
that names the fibres.
"""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import FibreContact

from . import guard

E, R, L = 1.0e9, 1e-3, 0.06


def test_forced_pass_through_stops_with_a_message(out):
    mat = textile.Material(E, 0.3)
    A = textile.straight_fibre([-L / 2, 0, 0], [L / 2, 0, 0], R, mat, num_elements=8)
    B = textile.straight_fibre([0, -L / 2, 2 * R], [0, L / 2, 2 * R], R, mat, num_elements=8)
    model = textile.Model([A, B], comm=MPI.COMM_SELF)
    for f, dz in ((A, 3 * R), (B, -3 * R)):
        for n in range(f.num_nodes):
            model.fix(f, n, "all", [0, 0, dz, 0, 0, 0, 0, 0, 0])
    contact = FibreContact()
    model.add_effect(contact)
    solver = textile.Solver(model, dict(initial_step=0.25, max_step=0.25, verbose=False),
                            output=textile.Output(out))
    message = "fibres 0 and 1 have passed through each other"
    with pytest.raises(textile.ConvergenceError, match=message):
        solver.solve()
    data = guard.clean_output(out, solver, failed=message)
    assert "penalty_range" in data["meta"]["failure"]
    # the last converged state is the one on disk, before the pass-through
    assert 0 < len(solver.history) and solver.history[-1].load_factor < 0.5
    assert solver.history[-1].effects["crossed_contacts"] == 0
    assert np.all(np.isfinite(model.nodal_unknowns()))
    # no Newton-count guard: every unknown is prescribed, so no step takes
    # a Newton iteration (a guard of 0 could not tell anything)
    assert solver.counters["newton_iterations"] == 0
