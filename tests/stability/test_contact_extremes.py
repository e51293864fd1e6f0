"""Contact with extreme parameters: converge to the known answer.

Crossed fibres pressed at mid-span (docs/references.md §6): B, pinned at both
ends over a span L, lies across a fixed fibre A; its ends are lowered by
delta: delta = f L^3 / (48 E I_B) + p(f), p the law's penetration at the
contact force f. Every case writes an Output directory that the guard
checks, and its Newton count is guarded.
"""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import FibreContact
from tests.contact.test_coplanar_fibres import ROOT_PENETRATION, fan_pair
from tests.contact.test_first_contact import WEIGHT, resting_fibre

from . import guard

E, R, L = 1.0e9, 1e-3, 0.1
MAT = textile.Material(E, 0.3)


def solved(model, out, contact_options=None, step=0.25):
    """Add contact to the scene, solve it in steps of `step` with an Output
    in `out`, check the output; returns (contact, solver)."""
    contact = FibreContact(contact_options)
    model.add_effect(contact)
    solver = textile.Solver(model, dict(initial_step=step, max_step=step, verbose=False),
                            output=textile.Output(out))
    solver.solve()
    guard.clean_output(out, solver)
    return contact, solver


def crossed_pair(out, r_B=R, delta=1e-4, **contact_options):
    A = textile.straight_fibre([0, -L / 2, 0], [0, L / 2, 0], R, MAT, num_elements=8)
    B = textile.straight_fibre([-L / 2, 0, R + r_B], [L / 2, 0, R + r_B], r_B, MAT,
                               num_elements=8)
    model = textile.Model([A, B], comm=MPI.COMM_SELF)
    for n in range(A.num_nodes):
        model.fix(A, n, "all")
    model.fix(B, 0, ["position", "g1x"], [0, 0, -delta, 0])
    model.fix(B, -1, ["y", "z"], [0, -delta])
    contact, solver = solved(model, out, contact_options)
    d = contact.elements()
    f = solver.history[-1].effects["contact_force_sum"]
    I_B = np.pi * r_B ** 4 / 4
    predicted = f * L ** 3 / (48 * E * I_B) + (-d["gap"].min())
    return predicted / delta, contact, solver


def test_penalty_a_million_times_the_transverse_stiffness(out):
    """k = 1e6 x 48 E I / L^3 for the crossing, not adapted: a stiffness
    ratio of 1e6 in one tangent (MUMPS LU, full Newton)."""
    k = 1e6 * 48 * E * (np.pi * R ** 4 / 4) / L ** 3
    ratio, contact, solver = crossed_pair(out, penalty=k / (2 * R), adapt_penalty=False)
    # measured 0.9992: the beam's shear flexibility is not in the reference
    assert ratio == pytest.approx(1.0, abs=2e-3)
    guard.newton_count("contact_penalty_1e6", solver)


def test_regularization_a_millionth_of_the_radius(out):
    """g_r = 1e-6 R, adaptive penalty: the law is a kink at the scale of the
    fibres; the penetration stays at its target (2 g_r)."""
    ratio, contact, solver = crossed_pair(out, regularization=1e-6)
    assert ratio == pytest.approx(1.0, abs=2e-3)  # measured 0.9992 (shear)
    assert -contact.elements()["gap"].min() <= 2 * contact.adaptation.target
    guard.newton_count("contact_regularization_1e-6", solver)


def test_radii_differing_ten_times(out):
    """B ten times thinner than A (r_B = R / 10), lowered by 20 of its radii."""
    ratio, contact, solver = crossed_pair(out, r_B=0.1 * R, delta=2e-3)
    # measured 1.0017: deflection L / 50, beyond small deflections
    assert ratio == pytest.approx(1.0, abs=5e-3)
    assert contact.g_r == pytest.approx(0.02 * 0.1 * R)  # from the smaller radius
    guard.newton_count("contact_radii_10x", solver)


def test_zero_gap_first_contact(out):
    """A fibre under dead forces lying on another it just touches, held by
    nothing else vertically (item 5): one step of the whole load."""
    model, B, contact, solver = resting_fibre("along", 1.0, textile.Output(out))
    guard.clean_output(out, solver)
    (step,) = solver.history
    assert max(step.residual_norms) <= 10 * step.residual_norms[0]  # no blow-up
    assert step.effects["contact_force_sum"] == pytest.approx(WEIGHT * B.num_nodes, rel=1e-3)
    guard.newton_count("contact_zero_gap_first_contact", solver)


def test_coplanar_fan(out):
    """Coplanar fibres 20 degrees apart, touching at their roots (item 7):
    no false penetration, the fibre stays in the plane."""
    A, B = fan_pair(20)
    model = textile.Model([A, B], comm=MPI.COMM_SELF)
    for n in range(A.num_nodes):
        model.fix(A, n, "all")
    model.clamp(B, -1)
    contact, solver = solved(model, out, step=1.0)
    assert np.abs(model.centreline(B)[:, 2]).max() < 1e-9 * R
    assert -contact.elements()["gap"].min() <= max(2 * contact.adaptation.target,
                                                   ROOT_PENETRATION)
    guard.newton_count("contact_coplanar_fan", solver)
