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


E, NU, R, L = 1.0e9, 0.3, 5e-4, 0.02


def rotation(phi):
    c, s = np.cos(phi), np.sin(phi)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def twisted_pair(elements: int = 24, order: int = 2, element=None, contact=None,
                 comm=MPI.COMM_SELF):
    """The scene (module docstring), to be solved from load factor 0 to 1
    (one turn); returns (model, fibres, contact). ``elements`` and ``order``:
    each fibre's; ``element``: the BeamElement, ``contact``: ContactOptions
    as a dict (frictionless unless it says otherwise), both default
    textile's (benchmarks/accuracy_cost.py sweeps them)."""
    mat = textile.Material(E, NU)
    fibres = [textile.straight_fibre([s * R, 0, 0], [s * R, 0, L], R, mat,
                                     num_elements=elements, order=order,
                                     section_vector=[1, 0, 0]) for s in (1, -1)]
    model = textile.Model(fibres, element=element, comm=comm)
    for f in fibres:
        model.clamp(f, 0)
        X, G1, G2 = f.points[-1], f.g1[-1], f.g2[-1]

        def top(t, X=X, G1=G1, G2=G2):
            Q = rotation(2 * np.pi * t)
            return list((Q @ X - X)[:2]) + list(Q @ G1 - G1) + list(Q @ G2 - G2)

        model.fix(f, -1, ["x", "y", "g1", "g2"], top)
        model.add_force(f, -1, [0, 0, 1.0])
    contact = FibreContact(dict(dict(friction=0.0), **(contact or {})))
    model.add_effect(contact)
    return model, fibres, contact


def contact_forces(model, fibres, contact):
    """(f0, f1): the nodal contact forces (positions) on each fibre."""
    q = model.nodal_unknowns()
    forces = contact.set.nodal_forces(np.ascontiguousarray(q)).reshape(-1, 9)[:, :3]
    n = fibres[0].num_nodes
    return forces[:n], forces[n:]


def symmetry_error(model, fibres, contact) -> float:
    """max |f0 - Q f1| / max |f|: the force on fibre 0 at node n against the
    180-degree image of the force on fibre 1 at node n (zero by symmetry)."""
    f0, f1 = contact_forces(model, fibres, contact)
    scale = max(np.abs(f0).max(), np.abs(f1).max())
    return float(np.abs(f0 - f1 @ rotation(np.pi).T).max() / scale)


def test_twisted_pair_one_turn():
    model, fibres, contact = twisted_pair()
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
    # force on fibre 1 at node n: to round-off (measured 1.1e-14 of the
    # largest force; 100x for another BLAS's round-off)
    assert symmetry_error(model, fibres, contact) < 1e-12
    f0, f1 = contact_forces(model, fibres, contact)
    scale = max(np.abs(f0).max(), np.abs(f1).max())
    # action = reaction overall
    assert np.allclose(f0.sum(axis=0), -f1.sum(axis=0), atol=1e-9 * scale)
    # the contact pushes the fibres apart: opposite of the centroid gap
    assert stats["contact_force_sum"] > 0
