"""Contact along sliding and wrapped fibres: converge with the physics right.

Every case writes an Output directory that the guard checks, and its
Newton count is guarded.
"""
import math

import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import FibreContact
from tests.contact.test_capstan import RHO, THETA, capstan, tension_ratio
from tests.contact.test_capstan import R as R_DRUM
from tests.contact.test_capstan import r as r_capstan
from tests.contact.test_frictionless_drag import slide_over_an_arc
from tests.contact.test_tunnelling import PUSH, cantilever_and_rod

from . import guard
from .test_contact_extremes import solved

E, R = 1.0e9, 1e-3
MAT = textile.Material(E, 0.3)


def test_near_parallel_sliding_with_mu_one(out):
    """B, 3 degrees off A and pressed on it, slides 10 radii along its axis
    with mu = 1: the line contact slips everywhere, the supports pull with
    mu times the force pressing B down, and B stays on A."""
    L, mu = 0.06, 1.0
    A = textile.straight_fibre([-L / 2, 0, 0], [L / 2, 0, 0], R, MAT, num_elements=12)
    axis = np.array([math.cos(math.radians(3)), math.sin(math.radians(3)), 0])
    centre = np.array([0, 0, 2 * R])
    B = textile.straight_fibre(centre - L / 2 * axis, centre + L / 2 * axis, R, MAT,
                               num_elements=12)
    model = textile.Model([A, B], comm=MPI.COMM_SELF)
    for n in range(A.num_nodes):
        model.fix(A, n, "all")
    press, slide = 5e-5, 10 * R
    b0 = model.fix(B, 0, ["position", "g1x"], [0, 0, -press, 0])
    b1 = model.fix(B, -1, "position", [0, 0, -press])
    contact = FibreContact(dict(friction=mu))
    model.add_effect(contact)
    solver = textile.Solver(model, dict(initial_step=0.25, max_step=0.25, verbose=False),
                            output=textile.Output(out))
    end = list(slide * axis + [0, 0, -press])
    solver.run([textile.Stage("press"),
                textile.Stage("slide", ramp={b0: end + [0.0], b1: end},
                              solver=dict(initial_step=0.05, max_step=0.1))])
    guard.clean_output(out, solver)
    supports = model.reaction(B, 0, "position") + model.reaction(B, -1, "position")
    # the Coulomb limit at full slip (measured 1.0032: the line contact's
    # normals follow the 3-degree angle)
    assert abs(supports @ axis) / -supports[2] == pytest.approx(mu, rel=1e-2)
    d = contact.elements()
    active = d["normal_force"] > 0
    assert np.all(d["slip"][active]) and active.sum() >= 8
    assert all(h.effects["crossed_contacts"] == 0 for h in solver.history)
    assert -d["gap"].min() <= 2 * contact.adaptation.target
    guard.newton_count("contact_near_parallel_mu1", solver)


def test_capstan(out):
    """A thin fibre over a thick fixed one through 90 degrees (item 6),
    mu = 0.3, pulled until it slides: the thick-fibre capstan ratio."""
    mu = 0.3
    model, B, contact, end, leg = capstan(mu)
    ratios = []
    solver = textile.Solver(model, dict(initial_step=0.25, max_step=0.25, verbose=False),
                            on_step=lambda s, rec: ratios.append(tension_ratio(model, B, leg)),
                            output=textile.Output(out))
    solver.run([textile.Stage("tension"),
                textile.Stage("pull", ramp={end: list(4 * r_capstan * leg) + [0.0, 0.0]},
                              solver=dict(initial_step=0.1, max_step=0.1))])
    guard.clean_output(out, solver)
    # measured -0.03%
    assert ratios[-1] == pytest.approx(math.exp(mu * THETA * R_DRUM / RHO), rel=2e-3)
    guard.newton_count("contact_capstan", solver)


def test_frictionless_drag(out):
    """A fibre slid over a curved one without friction (item 8): no drag."""
    model, contact, solver, drags = slide_over_an_arc(textile.Output(out))
    guard.clean_output(out, solver)
    assert max(drags) < 1e-3  # measured 4.5e-5
    guard.newton_count("contact_frictionless_drag", solver)


def test_tunnelling_rod(out):
    """A rigid rod pushed 15.5 radii in one step through a penalty a
    million times too soft (item 9): held, stiffened, the cantilever
    ends under the rod."""
    model, A, B, contact = cantilever_and_rod(True, 1e-6, True)
    solver = textile.Solver(model, dict(initial_step=1.0, max_step=1.0, verbose=False),
                            output=textile.Output(out))
    solver.solve()
    guard.clean_output(out, solver)
    assert sum(h.effects["held_contacts"] for h in solver.history) > 0
    d = contact.elements()
    assert len(d["gap"]) == 1 and d["separation"][0] > 1.5 * R
    assert model.centreline(B)[B.num_nodes // 2, 2] == pytest.approx(2 * R - PUSH, abs=1e-12)
    guard.newton_count("contact_tunnelling_rod", solver)


def test_fibre_folded_onto_itself(out):
    """A hairpin: two legs of one fibre, 4 radii apart, joined by a half
    turn held at its apex; a line load pinches the legs towards each other,
    so they press on each other along their length (self-contact). Its
    legs run against each other: before the zones knew it
    (ProximityZone.reversed), every element of the zone sat at one place
    (its intermediate geometry folded onto a point), and the old version of
    this scene, whose clamped ends were pushed onto each other, passed
    only because of that."""
    n_leg, n_bend, leg, bend = 8, 6, 0.03, 2 * R
    pts = [[leg - leg * k / (2 * n_leg), -bend, 0] for k in range(2 * n_leg)]
    pts += [[bend * math.cos(a), bend * math.sin(a), 0]
            for a in -math.pi / 2 - math.pi * np.arange(2 * n_bend) / (2 * n_bend)]
    pts += [[leg * k / (2 * n_leg), bend, 0] for k in range(2 * n_leg + 1)]
    F = textile.Fibre(np.array(pts), R, MAT, [0, 0, 1])
    model = textile.Model([F], comm=MPI.COMM_SELF)
    apex = len(pts) // 2
    model.fix(F, apex, "all")
    for k in range(len(pts)):
        if k != apex:
            model.fix(F, k, "z")  # in its plane: pressed legs would roll over each other
    # 20 times the tip force that closes the legs' gap of 2 R, spread along them
    force = 20 * 3 * E * math.pi * R ** 4 / 4 * 2 * R / leg ** 3
    legs = 2 * n_leg
    for k in range(legs):
        model.add_force(F, k, [0, force / legs, 0])
        model.add_force(F, len(pts) - 1 - k, [0, -force / legs, 0])
    contact, solver = solved(model, out, step=0.0625)
    d = contact.elements()
    active = d["normal_force"] > 0
    assert active.sum() >= 10 and np.all(d["fibre_i"][active] == 0)  # a self-contact line
    # spread along the legs (11 elements over 2.5 elements of each leg)
    assert np.ptp(d["s_i"][active]) > 2.0
    assert all(h.effects["crossed_contacts"] == 0 for h in solver.history)
    assert -d["gap"].min() <= 2 * contact.adaptation.target
    # mirror symmetry about y = 0 (measured to round-off)
    x = model.centreline(F)
    assert np.abs(x[::-1, 1] + x[:, 1]).max() < 1e-9 * R
    guard.newton_count("contact_self_fold", solver)
