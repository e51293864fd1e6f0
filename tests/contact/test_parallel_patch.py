"""Parallel fibres, line-contact patch test (docs/references.md §7).

Fibre A is fixed; fibre B, parallel and touching it, is pressed by a
uniform line load q. The penetration must be uniform along the overlap and
the contact forces must sum to q L.
"""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import FibreContact


E, NU, R, L, Q = 1.0e9, 0.3, 1e-3, 0.02, 10.0


def pressed_parallel_pair(order: int, num_elements: int, contact_options: dict) -> dict:
    """A fixed; B parallel on it, pressed by the line load Q (consistent
    nodal forces); the contact elements at equilibrium."""
    mat = textile.Material(E, NU)
    A = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, mat, num_elements=num_elements,
                               order=order, section_vector=[0, 1, 0])
    # B starts with a tiny interpenetration so the contact has stiffness at once
    B = textile.straight_fibre([0, 0, 2 * R - 1e-6], [L, 0, 2 * R - 1e-6], R, mat,
                               num_elements=num_elements, order=order, section_vector=[0, 1, 0])
    model = textile.Model([A, B], textile.BeamElement(order=order), comm=MPI.COMM_SELF)
    for n in range(A.num_nodes):
        model.fix(A, n, "all")
    for n in range(B.num_nodes):
        model.fix(B, n, "y")
    model.fix(B, 0, ["x", "g1z"])
    # consistent nodal forces of the uniform line load
    le = L / num_elements
    weights = [1 / 6, 2 / 3, 1 / 6] if order == 2 else [1 / 2, 1 / 2]
    for e in range(num_elements):
        for a, w in enumerate(weights):
            model.add_force(B, order * e + a, [0, 0, -Q * le * w])
    contact = FibreContact(contact_options)
    model.add_effect(contact)
    textile.Solver(model, dict(initial_step=0.5, max_step=0.5, verbose=False)).solve()
    return contact.elements()


@pytest.mark.parametrize("order,num_elements", [(2, 4), (2, 7), (1, 6)])
def test_uniform_penetration_and_total_force(order, num_elements):
    # per unit length: 1e6 N/m for each element of the default spacing (le / 2)
    le = L / num_elements
    data = pressed_parallel_pair(order, num_elements, dict(
        adapt_penalty=False, penalty=1e6 / (0.5 * le), regularization=0.02))
    penetration = -data["gap"]
    assert len(penetration) >= 2 * num_elements  # a line contact, not a point
    assert np.all(penetration > 0)
    spread = (penetration.max() - penetration.min()) / penetration.mean()
    # required < 1e-3; measured ~3e-6 (section deformation under the contact)
    assert spread < 1e-4
    # equilibrium: Newton tolerance only
    assert data["normal_force"].sum() == pytest.approx(Q * L, rel=1e-6)
