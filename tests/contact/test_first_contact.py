"""First contact at zero gap (stability issue item 5).

The regularized penalty law has no stiffness at gap = 0: a fibre pushed by
dead forces onto fibres it just touches, and held by nothing else in that
direction, sees nothing in Newton's first tangent, and the first iterate
went as far as the round-off let it (a residual of 1e13 after 3e-3). Newton's
first tangents now keep a floor of the penalty near gap = 0 that fades
within a few iterations (ContactOptions.tangent_floor); the residual is the
law's, so the converged answer is the same.

Measured (Newton iterations, one load step of the whole force):
B along A: 279 and no converged step without the floor, 11 with it;
B across two fibres: 170 and no converged step, 11 with it.
"""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import FibreContact

E, R, L = 1.0e9, 1e-3, 0.1
MAT = textile.Material(E, 0.3)
WEIGHT = 1e-3  # dead force on each node of B (N), downwards


def resting_scene(kind: str, floor: float):
    """B rests, exactly touching, on fixed fibres: along one ("along") or
    across two parallel ones ("across", a beam on two supports); its nodes
    carry dead forces down, and its supports hold it only horizontally.
    Returns (model, B, contact)."""
    if kind == "along":
        fixed = [textile.straight_fibre([-L / 2, 0, 0], [L / 2, 0, 0], R, MAT, num_elements=8)]
        B = textile.straight_fibre([-L / 4, 0, 2 * R], [L / 4, 0, 2 * R], R, MAT, num_elements=4)
    else:
        fixed = [textile.straight_fibre([-L / 4, y, 0], [L / 4, y, 0], R, MAT, num_elements=4)
                 for y in (-L / 4, L / 4)]
        B = textile.straight_fibre([0, -L / 2, 2 * R], [0, L / 2, 2 * R], R, MAT, num_elements=8)
    model = textile.Model(fixed + [B], comm=MPI.COMM_SELF)
    for A in fixed:
        for n in range(A.num_nodes):
            model.fix(A, n, "all")
    model.fix(B, 0, ["x", "y", "g1x" if kind == "along" else "g1y"])
    model.fix(B, -1, ["x"])
    for n in range(B.num_nodes):
        model.add_force(B, n, [0, 0, -WEIGHT])
    contact = FibreContact(dict(tangent_floor=floor))
    model.add_effect(contact)
    return model, B, contact


def resting_fibre(kind: str, floor: float, output=None):
    """The scene solved in one step of the whole load."""
    model, B, contact = resting_scene(kind, floor)
    solver = textile.Solver(model, dict(initial_step=1.0, max_step=1.0, verbose=False),
                            output=output)
    solver.solve()
    return model, B, contact, solver


@pytest.mark.parametrize("kind", ["along", "across"])
def test_dead_force_onto_a_touching_fibre(kind):
    model, B, contact, solver = resting_fibre(kind, 1.0)
    (step,) = solver.history
    assert step.attempts == 1
    assert solver.counters["newton_iterations"] <= 20  # measured 11 (279 without the floor)
    # no blow-up: the residual stays within 10x its start (measured 1.05x
    # along, 8x across; 1e13 / 3e-3 without the floor)
    assert max(step.residual_norms) <= 10 * step.residual_norms[0]
    # the contacts carry B's weight (the elements' forces are the last
    # detection pass's, within update_tolerance of Newton's)
    assert step.effects["contact_force_sum"] == pytest.approx(WEIGHT * B.num_nodes, rel=1e-3)
    assert np.abs(model.centreline(B)[:, 2] - 2 * R).max() < 0.1 * R  # resting, not gone


@pytest.mark.parametrize("kind", ["along", "across"])
def test_the_floor_does_not_change_the_answer(kind):
    """Half the floor: another Newton path, the same equilibrium (to the
    Newton tolerance)."""
    q = [resting_fibre(kind, floor)[0].nodal_unknowns() for floor in (1.0, 0.5)]
    assert np.allclose(q[0], q[1], rtol=0, atol=1e-12 * np.abs(q[0]).max())
