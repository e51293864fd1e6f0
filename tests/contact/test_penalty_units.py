"""Penalty units: a stiffness per unit length of contact (contact_set.h).

A line contact's elements stand for lengths that sum to the zone's length,
so its stiffness per length does not depend on how finely it is sampled
(``spacing``); a crossing stands for the length r_i + r_j; a zone that
changes kind has its penalty converted so that its force is continuous.
"""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import FibreContact

from .test_parallel_patch import L, Q, R, pressed_parallel_pair

MAT = textile.Material(1.0e9, 0.3)


@pytest.mark.parametrize("finer", [0.25, 0.2])
def test_line_stiffness_per_length_does_not_depend_on_spacing(finer):
    # the patch test, penalty 4e8 N/m per metre, at two spacings
    le = L / 4
    coarse, fine = (pressed_parallel_pair(2, 4, dict(adapt_penalty=False, penalty=4e8,
                                                     regularization=0.02, spacing=f * le))
                    for f in (0.5, finer))
    assert len(fine["gap"]) >= 2 * len(coarse["gap"])  # sampled twice as finely or more
    for d in (coarse, fine):
        # equilibrium: the elements' forces sum to q L (Newton tolerance)
        assert d["normal_force"].sum() == pytest.approx(Q * L, rel=1e-6)
        # lengths, not weights: they add up to the overlap (deformed: 5e-7 longer)
        assert d["length"].sum() == pytest.approx(L, rel=1e-5)
    # the same load gives the same penetration: stiffness per length is
    # unchanged (round-off: measured 9e-14; with per-element weights in units
    # of the spacing it changed by a factor sqrt(2) here)
    p_coarse, p_fine = -coarse["gap"].mean(), -fine["gap"].mean()
    assert p_fine == pytest.approx(p_coarse, rel=1e-12)


def crossing_turned_to_parallel(opts, parallel_angle=10.0):
    """B pressed onto a fixed A by lowering its ends (fixed interference,
    t <= 0.2), then turned about the vertical through the crossing from 14 to
    6 degrees (t = 0.2 -> 1): the zone is a crossing above parallel_angle, a
    line contact below. Returns [(angle, contact force, is a crossing)]."""
    L, delta = 0.06, 5e-5
    th0, th1 = np.radians(14.0), np.radians(6.0)
    A = textile.straight_fibre([0, -L / 2, 0], [0, L / 2, 0], R, MAT, num_elements=12)
    axis0 = np.array([np.sin(th0), np.cos(th0), 0.0])
    c = np.array([0, 0, 2 * R])
    B = textile.straight_fibre(c - L / 2 * axis0, c + L / 2 * axis0, R, MAT, num_elements=12,
                               section_vector=[0, 0, 1])
    model = textile.Model([A, B], comm=MPI.COMM_SELF)
    for n in range(A.num_nodes):
        model.fix(A, n, "all")

    def angle(t):
        return th0 + (th1 - th0) * max(0.0, (t - 0.2) / 0.8)

    def end(sign):
        def displacement(t):
            axis = np.array([np.sin(angle(t)), np.cos(angle(t)), 0.0])
            down = np.array([0, 0, -delta * min(1.0, t / 0.2)])
            return list(sign * L / 2 * (axis - axis0) + down)
        return displacement

    # g1 stays vertical at one end: no free rotation of B about its axis
    model.fix(B, 0, ["position", "g1"], lambda t: end(-1)(t) + [0.0, 0.0, 0.0])
    model.fix(B, -1, ["position"], end(1))
    contact = FibreContact(dict(opts, parallel_angle=parallel_angle))
    model.add_effect(contact)
    rows = []
    textile.Solver(model, dict(initial_step=0.05, max_step=0.05, verbose=False),
                   on_step=lambda s, rec: rows.append(
                       (np.degrees(angle(rec.load_factor)), rec.effects["contact_force_sum"],
                        bool(contact.elements()["crossing"].any()),
                        rec.effects["penalty_conversions"]))).solve()
    return rows


def test_zone_force_continuous_from_crossing_to_line():
    # a contact as compliant as the fibre (crossing stiffness 40 N/m against
    # 48 E I / L^3 ~ 170 N/m), so its stiffness shows in the force
    rows = crossing_turned_to_parallel(dict(adapt_penalty=False, penalty=2e4))
    kinds = [r[2] for r in rows]
    flip = kinds.index(False)
    # one change of kind, after 7.5 degrees: a crossing stays one down to
    # (1 - crossing_bias) parallel_angle (the kinds' hysteresis, detection.h),
    # and a step's passes keep the kind its first pass found (keep_kinds):
    # the step to 7.0 starts from 7.5, so the line contact shows from 6.5
    assert all(kinds[:flip]) and not any(kinds[flip:])
    assert (rows[flip - 1][0], rows[flip][0]) == pytest.approx((7.0, 6.5))  # 0.5 deg a step
    assert rows[flip][3] == 1  # the zone's penalty was converted once
    before = rows[flip - 1][1]
    # the line contact's force grows as the fibres turn parallel (2.2% a
    # step here, the crossing's stays constant): continuous where the line
    # contact's force, extrapolated back to the crossing's last angle, meets
    # the crossing's, within 1.5% (measured 0.53%; without the conversion
    # the force jumps by 76%)
    after = 2.0 * rows[flip][1] - rows[flip + 1][1]
    assert after == pytest.approx(before, rel=1.5e-2)
