"""Two fibres twisted around each other by one full turn of one end.

Both fibres are clamped at the bottom; the top ends turn together about the
pair's axis (positions and section vectors), free to move axially under a
small tension. Contact must hold them apart at every converged step (gaps
no deeper than twice the target penetration) and, by the 180-degree
symmetry of the problem, the contact forces on the two fibres are images
of each other.
"""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import FibreContact


def rotation(phi):
    c, s = np.cos(phi), np.sin(phi)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def test_twisted_pair_one_turn():
    E, nu, R, L = 1.0e9, 0.3, 5e-4, 0.02
    mat = textile.Material(E, nu)
    fibres = [textile.straight_fibre([s * R, 0, 0], [s * R, 0, L], R, mat, num_elements=24,
                                     section_vector=[1, 0, 0]) for s in (1, -1)]
    model = textile.Model(fibres, comm=MPI.COMM_SELF)
    for f in fibres:
        model.clamp(f, 0)
        X, G1, G2 = f.points[-1], f.g1[-1], f.g2[-1]

        def top(t, X=X, G1=G1, G2=G2):
            Q = rotation(2 * np.pi * t)
            return list((Q @ X - X)[:2]) + list(Q @ G1 - G1) + list(Q @ G2 - G2)

        model.fix(f, -1, ["x", "y", "g1", "g2"], top)
        model.add_force(f, -1, [0, 0, 1.0])
    options = dict(friction=0.0)
    contact = FibreContact(options)
    model.add_effect(contact)
    deepest = []
    solver = textile.Solver(model, dict(initial_step=0.02, max_step=0.05, verbose=False),
                            on_step=lambda s, rec: deepest.append(
                                -contact.elements()["gap"].min()))
    solver.solve()
    assert solver.history[-1].load_factor == pytest.approx(1.0)
    target = contact.options.target_penetration * contact.g_r
    # no pass-through: required gap >= -2 target at every converged step
    # (measured: deepest 1.6 target, at the end of the turn)
    assert max(deepest) <= 2 * target
    stats = solver.history[-1].effects
    assert stats["contact_zones"] == 1 and stats["active_contacts"] > 20  # a line contact
    # symmetry: the force on fibre 0 at node n is the 180-degree image of the
    # force on fibre 1 at node n
    q = model.nodal_unknowns()
    forces = contact.set.nodal_forces(np.ascontiguousarray(q)).reshape(-1, 9)[:, :3]
    n = fibres[0].num_nodes
    f0, f1 = forces[:n], forces[n:]
    scale = np.abs(forces).max()
    assert np.allclose(f0, f1 @ rotation(np.pi).T, atol=1e-6 * scale)
    # action = reaction overall
    assert np.allclose(f0.sum(axis=0), -f1.sum(axis=0), atol=1e-9 * scale)
    # the contact pushes the fibres apart: opposite of the centroid gap
    assert stats["contact_force_sum"] > 0
