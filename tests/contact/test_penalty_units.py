"""Penalty units: a stiffness per unit length of contact (contact_set.h).

A line contact's elements stand for lengths that sum to the zone's length,
so its stiffness per length does not depend on how finely it is sampled
(``spacing``); a crossing stands for the length r_i + r_j.
"""
import pytest
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import FibreContact

E, NU, R = 1.0e9, 0.3, 1e-3
MAT = textile.Material(E, NU)


def pressed_parallel_pair(spacing, L=0.02, ne=4, q=10.0):
    """The line-contact patch test (REFERENCES.md 7): B pressed on a fixed,
    parallel A by a uniform line load q, penalty 4e8 N/m per metre."""
    A = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, MAT, num_elements=ne,
                               section_vector=[0, 1, 0])
    B = textile.straight_fibre([0, 0, 2 * R - 1e-6], [L, 0, 2 * R - 1e-6], R, MAT,
                               num_elements=ne, section_vector=[0, 1, 0])
    model = textile.Model([A, B], comm=MPI.COMM_SELF)
    for n in range(A.num_nodes):
        model.fix(A, n, "all")
    for n in range(B.num_nodes):
        model.fix(B, n, "y")
    model.fix(B, 0, ["x", "g1z"])
    le = L / ne
    for e in range(ne):
        for a, w in enumerate([1 / 6, 2 / 3, 1 / 6]):
            model.add_force(B, 2 * e + a, [0, 0, -q * le * w])
    contact = FibreContact(dict(adapt_penalty=False, penalty=4e8, regularization=0.02,
                                spacing=spacing))
    model.add_effect(contact)
    textile.Solver(model, dict(initial_step=0.5, max_step=0.5, verbose=False)).solve()
    return contact.elements(), q * L


@pytest.mark.parametrize("finer", [0.25, 0.2])
def test_line_stiffness_per_length_does_not_depend_on_spacing(finer):
    le = 0.02 / 4
    coarse, total = pressed_parallel_pair(0.5 * le)
    fine, _ = pressed_parallel_pair(finer * le)
    assert len(fine["gap"]) > len(coarse["gap"])  # sampled more finely
    for d in (coarse, fine):
        # equilibrium: the elements' forces sum to q L (Newton tolerance)
        assert d["normal_force"].sum() == pytest.approx(total, rel=1e-6)
        # lengths, not weights: they add up to the overlap (deformed: 5e-7 longer)
        assert d["length"].sum() == pytest.approx(0.02, rel=1e-5)
    # the same load gives the same penetration: stiffness per length is
    # unchanged (round-off: measured 9e-14; with per-element weights in units
    # of the spacing it changed by a factor sqrt(2) here)
    p_coarse, p_fine = -coarse["gap"].mean(), -fine["gap"].mean()
    assert p_fine == pytest.approx(p_coarse, rel=1e-12)
