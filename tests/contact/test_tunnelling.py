"""Fibres must not tunnel through each other silently (stability issue item 9).

Detection keeps centre lines closer than search_factor (r_i + r_j); a fibre
pushed through another faster than a soft penalty holds it used to end a
Newton solve beyond that distance on the wrong side, where a fresh
detection found nothing. Contacts whose fibres have crossed are now held
(with their normal) until pushed back, zones are stiffened in the step, and
when the penalty cannot grow the step is refused with a message naming the
fibres.
"""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import FibreContact

E, R, L = 1.0e9, 1e-3, 0.1
MAT = textile.Material(E, 0.3)
PUSH = 0.155 * L   # 15.5 radii
XC = 0.75 * L      # where the rod crosses the cantilever


def cantilever_and_rod(rigid_rod: bool, penalty: float, adapt: bool, **contact_options):
    """A cantilever A along x (clamped at x = 0); a rod B along y lying on it
    at x = XC, pushed down by PUSH: all its nodes (a rigid indenter), or
    its two ends (pinned)."""
    A = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, MAT, num_elements=8)
    half = L / 8 if rigid_rod else L / 4
    B = textile.straight_fibre([XC, -half, 2 * R], [XC, half, 2 * R], R, MAT,
                               num_elements=4 if rigid_rod else 8)
    model = textile.Model([A, B], comm=MPI.COMM_SELF)
    model.clamp(A, 0)
    if rigid_rod:
        for n in range(B.num_nodes):
            model.fix(B, n, "all", [0, 0, -PUSH, 0, 0, 0, 0, 0, 0])
    else:
        model.fix(B, 0, ["position", "g1x"], [0, 0, -PUSH, 0])
        model.fix(B, -1, "position", [0, 0, -PUSH])
    contact = FibreContact(dict(penalty=penalty * E / 8, adapt_penalty=adapt, **contact_options))
    model.add_effect(contact)
    return model, A, B, contact


def height_of_a_under_the_rod(model, A):
    x, z = model.centreline(A)[:, 0], model.centreline(A)[:, 2]
    return np.interp(XC, x, z)


def test_indenter_pushed_through_in_one_step_is_held():
    """A rigid rod pushed 15.5 radii down in one step onto a cantilever,
    with a penalty a million times too soft: the first Newton solve ends
    with the rod's centre line 5.8 radii below the cantilever's (beyond the
    search distance of 4), the contact is held along its normal, the zone
    stiffened, and the cantilever pushed down under the rod. Before, the
    contact was lost and the rod went through (A back at z = 0)."""
    model, A, B, contact = cantilever_and_rod(True, 1e-6, True)
    history = textile.Solver(model, dict(initial_step=1.0, max_step=1.0, verbose=False)).solve()
    assert history[-1].load_factor == pytest.approx(1.0)
    assert sum(h.effects["held_contacts"] for h in history) > 0  # the mechanism acted
    assert all(h.effects["crossed_contacts"] == 0 for h in history)
    z_rod = model.centreline(B)[B.num_nodes // 2, 2]
    assert z_rod == pytest.approx(2 * R - PUSH, abs=1e-12)
    # the cantilever is under the rod (nodal heights interpolated: it is
    # about a diameter down); the zone's penalty went to the top of its range
    # (1e3 x the initial one, still 1e3 x too soft), so the penetration is
    # the law's at that penalty: a third of a radius, not a pass-through
    assert z_rod - height_of_a_under_the_rod(model, A) > 1.5 * R
    d = contact.elements()
    assert len(d["gap"]) == 1
    assert d["penalty"][0] == pytest.approx(contact.adaptation.k_max)
    k = d["penalty"][0] * d["length"][0]
    assert -d["gap"][0] == pytest.approx(d["normal_force"][0] / k + contact.g_r / 2, rel=1e-9)
    assert d["separation"][0] > 1.5 * R
    # forces balance: the clamp holds the cantilever against the contact
    # force (a reaction is minus the force applied). The element's force is
    # R_N times its gap's gradient (its point moves along the bent
    # cantilever: the force is normal to the cantilever there, not exactly
    # along the pass's normal N), so the balance is checked on the
    # contact's nodal forces on A: those of the last detection pass, within
    # update_tolerance (1e-3) of Newton's (measured 1.3e-7)
    f_contact = contact.nodal_forces()[: A.num_nodes, 2].sum()  # internal force: minus the push
    assert model.reaction(A, 0, "z")[0] == pytest.approx(f_contact, rel=1e-3)


def test_a_lagging_loop_still_pushes_back_fibres_that_crossed():
    """The same indenter with a contact loop that lags (update_tolerance
    inf, Weaving's lagged_path): a step is accepted after its first
    converged solve, except where fibres crossed: those zones are retuned
    within the step and solved again (FibreContact.update), so the step
    ends with the rod on its side of the cantilever, not through it."""
    import math
    model, A, B, contact = cantilever_and_rod(True, 1e-6, True, update_tolerance=math.inf)
    history = textile.Solver(model, dict(initial_step=1.0, max_step=1.0, verbose=False)).solve()
    assert history[-1].load_factor == pytest.approx(1.0)
    assert all(h.effects["crossed_contacts"] == 0 for h in history)
    # the retunes of the crossed zone, each followed by a Newton solve
    retunes = sum(h.effects["emergency_retunes"] for h in history)
    assert retunes > 0
    assert sum(h.updates for h in history) >= 1 + retunes
    # the rod's centre line above the cantilever's (measured 0.83 R), not
    # through it; the penetration (1.17 R) is the lag's: the retunes of a
    # zone that did not cross act from the next step (a loop that does not
    # lag holds the rod 1.5 R up in this one, the test above)
    z_rod = model.centreline(B)[B.num_nodes // 2, 2]
    assert 0.4 * R < z_rod - height_of_a_under_the_rod(model, A) < 1.5 * R
    assert np.all(contact.elements()["separation"] > 0)


def test_fixed_soft_penalty_stops_with_a_message():
    """The rod's ends pushed 15.5 radii in 5 steps against a fixed penalty
    too soft to hold it: the run stops, naming the fibres that passed
    through each other, instead of letting the rod through silently (before:
    it finished with the rod below the cantilever and A unloaded)."""
    model, A, B, contact = cantilever_and_rod(False, 1e-4, False)
    solver = textile.Solver(model, dict(initial_step=0.2, max_step=0.2, verbose=False))
    with pytest.raises(textile.ConvergenceError, match="fibres 0 and 1 have passed through "
                                                       "each other.*adapt_penalty is off"):
        solver.solve()
    # every accepted step has the rod above the cantilever
    assert all(h.effects["crossed_contacts"] == 0 for h in solver.history)
    d = contact.elements()
    assert np.all(d["separation"] > 0)


def test_rod_pushed_across_a_cantilever():
    """The scene of the issue: the rod's ends pushed 0.155 L in 5 steps with
    a soft starting penalty, adapted: the contact holds at every step (the
    cantilever follows the rod) and the run finishes (the first step is cut
    once: prescribed at once, the ends' 3 radii fold the rod's end elements
    before any contact acts).
    Before, the crossing sat on the kink of the rod under the force and
    jumped across it from one pass to the next (effects still changing
    after 20 updates at t = 0.6)."""
    model, A, B, contact = cantilever_and_rod(False, 1e-3, True)
    gaps = []

    def record(solver, rec):
        z_rod = model.centreline(B)[B.num_nodes // 2, 2]
        gaps.append(z_rod - height_of_a_under_the_rod(model, A))

    history = textile.Solver(model, dict(initial_step=0.2, max_step=0.2, verbose=False),
                             on_step=record).solve()
    target = contact.adaptation.target
    assert history[-1].load_factor == pytest.approx(1.0)
    assert sum(h.attempts - 1 for h in history) <= 1
    for h in history:
        assert h.effects["active_contacts"] == 1 and h.effects["crossed_contacts"] == 0
        assert h.effects["max_penetration_over_radius"] * R <= 2 * target
    # the cantilever stays under the rod at every step
    assert min(gaps) > 1.5 * R
    supports = model.reaction(B, 0, "z")[0] + model.reaction(B, -1, "z")[0]
    assert model.reaction(A, 0, "z")[0] == pytest.approx(-supports, rel=1e-6)
