"""Coplanar fibres at an angle (stability issue item 7).

Two fibres lying in one plane and diverging at a modest angle touch along a
line near their roots; t_i x t_j is out of that plane, and a gap measured
along it reads -(r_i + r_j), a penetration that is not there. The crossing
normal applies only where the centre lines really cross (a crossing zone,
or an out-of-plane separation of the order of the radii); side by side in a
plane, the normal is the centroid-to-centroid direction.
"""
import math

import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import FibreContact
from tests.contact.test_weaving_mode import flat_fabric

E, R = 1.0e9, 1e-3
MAT = textile.Material(E, 0.3)
ROOT_PENETRATION = 0.5 * R  # the real one, at the roots


def fan_pair(angle, L=0.03, ne=8):
    """A along x; B from a root 2R - ROOT_PENETRATION beside A's, at `angle`
    degrees to it in the plane z = 0."""
    A = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, MAT, num_elements=ne,
                               section_vector=[0, 0, 1])
    th = math.radians(angle)
    root = np.array([0.0, 2 * R - ROOT_PENETRATION, 0.0])
    B = textile.straight_fibre(root, root + L * np.array([math.cos(th), math.sin(th), 0]), R,
                               MAT, num_elements=ne, section_vector=[0, 0, 1])
    return A, B


def real_penetration(d):
    """Largest real penetration of the elements: r_i + r_j minus the
    distance of their centroids (both fibres of radius R)."""
    return np.max(2 * R - np.linalg.norm(d["position_i"] - d["position_j"], axis=1), initial=0)


@pytest.mark.parametrize("angle", [5, 10, 15, 20, 30])
def test_fan_reads_no_false_penetration(angle):
    """No element is deeper than the roots' real penetration, and the fibre
    pushed away at its root stays in the plane: before the fix (angles above
    parallel_angle, then 10 degrees) every element read -2R along z and pushed B
    out of the plane."""
    A, B = fan_pair(angle)
    model = textile.Model([A, B], comm=MPI.COMM_SELF)
    for n in range(A.num_nodes):
        model.fix(A, n, "all")
    model.clamp(B, -1)  # B's root is free: contact pushes it away
    contact = FibreContact()
    model.add_effect(contact)
    model.setup()
    contact.prepare(model)
    d = contact.elements()
    assert len(d["gap"]) > 0
    # elements sit between the roots: none is deeper than the roots (round-off)
    assert -d["gap"].min() <= ROOT_PENETRATION * (1 + 1e-9)
    assert np.all(np.abs(d["normal"][:, 2]) < 1e-12)  # in the fibres' plane
    history = textile.Solver(model, dict(verbose=False, initial_step=1.0, max_step=1.0)).solve()
    assert history[-1].load_factor == pytest.approx(1.0)
    assert history[0].attempts == 1  # the first step converges at once
    # in-plane problem, symmetric about z = 0: B never leaves the plane
    assert np.abs(model.centreline(B)[:, 2]).max() < 1e-9 * R
    assert model.centreline(B)[0, 1] > 2 * R - ROOT_PENETRATION  # pushed away, in y
    d = contact.elements()
    # the converged penetration is the law's (below the band's top), not 2R
    assert -d["gap"].min() <= 2 * contact.adaptation.target


def test_flat_weave_start_converges_its_first_step():
    """The weaving start with flat yarns (3 fibres side by side): all fibres
    in the plane z = 0, warps and wefts interpenetrating at the crossings.
    Ordinary contact separates them in one step (the crossing normals are
    vertical), and no element reads more than the real penetration of its
    centroids (the fibres of a yarn that fan out around a crossing are
    coplanar pairs at an angle)."""
    fab, model, contact = flat_fabric(2, "plain")
    fibres = fab.fibres()
    history = textile.Solver(model, dict(verbose=False, initial_step=1.0, max_step=1.0)).solve()
    assert len(history) == 1 and history[0].attempts == 1
    d = contact.elements()
    active = d["normal_force"] > 0
    assert -d["gap"][active].min() <= 2 * contact.adaptation.target
    # warps (fibres 0-5) and wefts (6-11) separated vertically at the crossings
    z = [model.centreline(f)[len(f.points) // 2, 2] for f in fibres]
    gaps = [abs(z[i] - z[j]) for i in range(6) for j in range(6, 12)]
    assert min(gaps) > 2 * R - 2 * contact.adaptation.target
