"""Crossed fibres pressed at mid-span (docs/references.md §6).

Fibre B, simply supported with span L (one end pinned, the other on a
roller), lies across a fixed fibre A at mid-span; its ends are lowered by
delta. Small deflections: delta = f L^3 / (48 E I) + p(f), with p the
penetration of the regularized penalty law at the contact force f.
"""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import FibreContact


def penetration(force, k, g_r):
    """Inverse of the regularized penalty law (docs/method.md §4.3)."""
    if force < 0.5 * k * g_r:
        return np.sqrt(2 * g_r * force / k)
    return force / k + g_r / 2


E, NU, R, L = 1.0e9, 0.3, 1e-3, 0.1
DELTA, K, REG = 2e-4, 1e5, 0.05


def pressed(num_elements, comm=MPI.COMM_SELF):
    """B's ends lowered by DELTA onto A in 8 steps; returns (model, A, B,
    [(end displacement, step statistics)])."""
    mat = textile.Material(E, NU)
    A = textile.straight_fibre([0, -L / 2, 0], [0, L / 2, 0], R, mat, num_elements=num_elements)
    B = textile.straight_fibre([-L / 2, 0, 2 * R], [L / 2, 0, 2 * R], R, mat,
                               num_elements=num_elements)
    model = textile.Model([A, B], comm=comm)
    for n in range(A.num_nodes):
        model.fix(A, n, "all")
    delta, k, reg = DELTA, K, REG
    model.fix(B, 0, ["position", "g1x"], [0, 0, -delta, 0])
    model.fix(B, -1, ["y", "z"], [0, -delta])
    # penalty per unit length: a crossing stands for r_i + r_j = 2R of
    # contact, so its stiffness (force/length) is k
    contact = FibreContact(dict(adapt_penalty=False, penalty=k / (2 * R), regularization=reg))
    model.add_effect(contact)
    curve = []
    solver = textile.Solver(model, dict(initial_step=0.125, max_step=0.125, verbose=False),
                            on_step=lambda s, rec: curve.append(
                                (s.model.load_factor * delta, rec.effects)))
    solver.solve()
    return model, A, B, curve


@pytest.mark.parametrize("num_elements", [8, 16])
def test_force_displacement(num_elements):
    I = np.pi * R ** 4 / 4
    k, reg = K, REG
    model, A, B, curve = pressed(num_elements)
    assert len(curve) == 8
    for d, stats in curve:
        f = stats["contact_force_sum"]
        n = stats["active_contacts"]
        assert n == 1  # a crossing is a point contact: one element
        predicted = f * L ** 3 / (48 * E * I) + penetration(f / n, k, reg * R)
        # the beam's shear flexibility (absent from the reference) accounts
        # for the measured 0.08%; tolerance 2.5 times that
        assert predicted == pytest.approx(d, rel=2e-3)
    # the supports pull B down as hard as the contact pushes it up
    # (equilibrium to the Newton tolerance)
    supports = model.reaction(B, 0, "z")[0] + model.reaction(B, -1, "z")[0]
    assert -supports == pytest.approx(curve[-1][1]["contact_force_sum"], rel=1e-6)
    # fibre A is held at every node: its supports take the whole contact
    # force (the contact's share of constrained rows counts as reaction)
    held = sum(model.reaction(A, n, "z")[0] for n in range(A.num_nodes))
    assert held == pytest.approx(curve[-1][1]["contact_force_sum"], rel=1e-6)


def supports(model, A, B) -> np.ndarray:
    """(A's held nodes' z reactions summed, B's two supports' z)."""
    held = sum(model.reaction(A, n, "z")[0] for n in range(A.num_nodes))
    return np.array([held, model.reaction(B, 0, "z")[0], model.reaction(B, -1, "z")[0]])


@pytest.mark.mpi
def test_contact_reactions_on_two_ranks():
    """The contact's share of the prescribed rows counts as reaction on any
    partition: A (held at every node) on one rank, B on the other, the
    crossing between them; the reactions are the serial ones (measured
    5e-12: the penalty's stiff forces summed in another order) and A's
    supports take the whole contact force."""
    serial, parallel = pressed(8), pressed(8, MPI.COMM_WORLD)
    rs, rp = supports(*serial[:3]), supports(*parallel[:3])
    force = parallel[3][-1][1]["contact_force_sum"]
    assert rp[0] == pytest.approx(force, rel=1e-6)   # equilibrium, to the Newton tolerance
    assert np.abs(rp - rs).max() < 2e-11 * np.abs(rs).max()
