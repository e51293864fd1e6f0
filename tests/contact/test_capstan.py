"""A thin fibre wrapped over a thick fixed one: the capstan (stability issue
item 6).

B (radius r = R / 100) lies on A (radius R, fixed, along y) over a quarter
turn, straight legs leaving tangentially (its reference shape is the
wrapped one, so nothing bends it but the contact). End 1 carries a dead
tension T; end 2 is held, then pulled along its leg until B slides.
Before, the wrap was one crossing element that jumped between the two ends
of the wrap from one pass to the next ("effects still changing after 20
updates"); now the contact is spread along the wrap, each element's normal
radial from A's axis.

Reference (moment balance about A's axis of a slice of B: the tensions act
at B's centre line, radius R + r, friction at its surface, radius R):
T2 / T1 = exp(mu theta R / (R + r)) when B slides towards end 2 and
exp(-mu theta R / (R + r)) when it slides towards end 1, the capstan
equation exp(mu theta) in the limit r << R; 1 without friction.
"""
import math

import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import FibreContact

E, R = 1.0e9, 1e-3
MAT = textile.Material(E, 0.3)
r = 0.01 * R
RHO = R + r          # radius of B's centre line around A's axis
THETA = math.pi / 2  # wrap angle
T = 1e-2 * E * math.pi * r * r  # a strain of 1%


def capstan(mu: float, arc_elements: int = 16, leg_elements: int = 8, comm=MPI.COMM_SELF,
            contact=None, element=None):
    """The scene; returns (model, B, contact, handle of end 2's displacement,
    unit direction of leg 2 away from the wrap). ``contact``: ContactOptions
    as a dict (friction is ``mu``), ``element``: the BeamElement (both
    default textile's; benchmarks/accuracy_cost.py sweeps them)."""
    leg = 2 * R
    pts = [[-leg + leg * k / (2 * leg_elements), 0, RHO] for k in range(2 * leg_elements)]
    pts += [[RHO * math.cos(a), 0, RHO * math.sin(a)]
            for a in math.pi / 2 - THETA * np.arange(2 * arc_elements) / (2 * arc_elements)]
    a1 = math.pi / 2 - THETA
    out = np.array([math.sin(a1), 0, -math.cos(a1)])
    start = RHO * np.array([math.cos(a1), 0, math.sin(a1)])
    pts += [start + out * leg * k / (2 * leg_elements) for k in range(2 * leg_elements + 1)]
    B = textile.Fibre(np.array(pts), r, MAT, [0, 1, 0])
    A = textile.straight_fibre([0, -2 * R, 0], [0, 2 * R, 0], R, MAT, num_elements=4,
                               section_vector=[1, 0, 0])
    model = textile.Model([A, B], element=element, comm=comm)
    for n in range(A.num_nodes):
        model.fix(A, n, "all")
    model.add_force(B, 0, [-T, 0, 0])
    model.fix(B, 0, ["y", "z", "g1x", "g1z"])
    end = model.fix(B, -1, ["position", "g1x", "g1z"], [0.0] * 5)
    contact = FibreContact(dict(contact or {}, friction=mu))
    model.add_effect(contact)
    return model, B, contact, end, out


def tension_ratio(model, B, out) -> float:
    """Tension at end 2 (the support's pull along leg 2) over T."""
    return float(model.reaction(B, -1, "position") @ out) / T


def test_frictionless_wrap_is_spread_and_transmits_the_tension():
    model, B, contact, end, out = capstan(0.0)
    textile.Solver(model, dict(initial_step=0.25, max_step=0.25, verbose=False)).solve()
    d = contact.elements()
    active = d["normal_force"] > 0
    # spread along the wrap (16 elements of B over the quarter turn)
    assert active.sum() >= 16 and not np.any(d["crossing"][active])
    # each normal radial from A's axis (y), pointing from B (j) to A (i)
    p = d["position_j"][active]
    radial = p * [1, 0, 1] / np.linalg.norm(p * [1, 0, 1], axis=1)[:, None]
    assert np.allclose(np.einsum("ij,ij->i", d["normal"][active], radial), -1, atol=1e-9)
    # no friction: the same tension at both ends (measured 0.07% apart)
    assert tension_ratio(model, B, out) == pytest.approx(1.0, abs=1e-2)
    # the contact carries the tensions' resultant, T sqrt(2) for a quarter turn
    resultant = (d["normal_force"][active, None] * d["normal"][active]).sum(axis=0)
    assert np.linalg.norm(resultant) == pytest.approx(math.sqrt(2) * T, rel=1e-2)


def tension_then_pull(mu: float, arc_elements: int, comm=MPI.COMM_SELF):
    """B slides under T (end 2 held), then end 2 is pulled by 4 r along its
    leg; returns (model, B, contact, the tension ratio after every step)."""
    model, B, contact, end, out = capstan(mu, arc_elements, comm=comm)
    ratios = []
    solver = textile.Solver(model, dict(initial_step=0.25, max_step=0.25, verbose=False),
                            on_step=lambda s, rec: ratios.append(tension_ratio(model, B, out)))
    solver.run([textile.Stage("tension"),
                textile.Stage("pull", ramp={end: list(4 * r * out) + [0.0, 0.0]},
                              solver=dict(initial_step=0.1, max_step=0.1))])
    return model, B, contact, np.array(ratios)


@pytest.mark.parametrize("arc_elements", [8, 16])
def test_capstan_ratio_with_friction(arc_elements):
    """mu = 0.3: B first slides towards end 1 under T (end 2 held), then
    towards end 2 once end 2 is pulled by 4 r."""
    mu = 0.3
    model, B, contact, ratios = tension_then_pull(mu, arc_elements)
    thick = math.exp(mu * THETA * R / RHO)
    # end of the tension stage: sliding towards end 1 (measured +0.03%)
    assert ratios[3] == pytest.approx(1 / thick, rel=2e-3)
    # pulled: every element slides, at the capstan ratio (measured -0.03%;
    # the thin-fibre exp(mu theta) = 1.602 is 0.5% above: r / (R + r))
    d = contact.elements()
    active = d["normal_force"] > 0
    assert np.all(d["slip"][active])
    assert ratios[-1] == pytest.approx(thick, rel=2e-3)
    assert ratios[-1] == pytest.approx(math.exp(mu * THETA), rel=1e-2)


@pytest.mark.mpi
def test_capstan_on_two_ranks_equals_one():
    """The sliding wrap, split between the ranks, gives the one-rank
    positions (measured 9e-16 R and 4e-16 R, round-off) and tension ratios.
    The ratios agree to the Newton tolerance: each solve stops once its
    residual is within tolerance, and the sums in another order can stop
    it an iteration earlier. Measured 2e-11 (2026-12-01, both took the same
    iterations) and 1.4e-8 (2026-12-03, an AMD EPYC VM: at the first pull
    step one rank took 5 iterations to a residual of 8.6e-13 N, two ranks
    3 to 7.6e-11 N); 3.5x the larger."""
    serial, parallel = (tension_then_pull(0.3, 8, comm) for comm in (MPI.COMM_SELF,
                                                                     MPI.COMM_WORLD))
    assert np.abs(parallel[3] - serial[3]).max() < 5e-8 * np.abs(serial[3]).max()
    qs, qp = serial[0].nodal_unknowns(), parallel[0].nodal_unknowns()
    assert np.abs(qp[:, 0:3] - qs[:, 0:3]).max() < 1e-13 * R
