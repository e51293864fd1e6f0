"""FibreContact's stage option make_up_penetrations: penetrations found at a
stage's start are made up over the stage, its end being the structure's
own equilibrium."""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import FibreContact

E, R, L = 1.0e9, 1e-3, 0.03
MAT = textile.Material(E, 0.3)
START = 0.6 * R    # B starts this deep in A, ends clamped: far beyond the penalty's depth


def pushed_through(steps, make_up):
    """A along x, held; B along y across it, its ends clamped START lower
    than touching: contact pushes B's middle up by about START."""
    A = textile.straight_fibre([-L / 2, 0, 0], [L / 2, 0, 0], R, MAT, num_elements=8)
    B = textile.straight_fibre([0, -L / 2, 2 * R - START], [0, L / 2, 2 * R - START], R, MAT,
                               num_elements=8)
    model = textile.Model([A, B], comm=MPI.COMM_SELF)
    for n in range(A.num_nodes):
        model.fix(A, n, "all")
    model.clamp(B, 0)
    model.clamp(B, -1)
    # penalty adaptation off: the penalty then has no history, and the end
    # state none of the path
    contact = FibreContact(dict(friction=0.0, adapt_penalty=False))
    model.add_effect(contact)
    solver = textile.Solver(model, dict(initial_step=1.0 / steps, max_step=1.0 / steps,
                                        verbose=False))
    heights = []   # of B's middle
    solver.on_step = lambda s, rec: heights.append(
        model.centreline(1)[model.centreline(1).shape[0] // 2, 2])
    effects = {contact: dict(make_up_penetrations=True)} if make_up else {}
    solver.run([textile.Stage("push", effects=effects)])
    return model, contact, solver, heights


def test_the_stage_ends_at_the_equilibrium_without_it():
    """Frictionless: the end state is the one the stage reaches without the
    option (to the Newton tolerance), whatever the path."""
    made_up, contact, solver, steps = pushed_through(4, True)
    direct, _, _, _ = pushed_through(1, False)
    x, y = made_up.nodal_unknowns(), direct.nodal_unknowns()
    assert np.abs(x - y).max() < 1e-9 * R, np.abs(x - y).max()
    # B's middle rises step by step: after the first (which also settles B
    # on the law's working depth, measured 1.17 times the others), by the
    # nearly the same share each (measured within 0.5%; B stiffens as it bends)
    rise = np.diff([2 * R - START] + steps)
    assert np.all(rise > 0), steps
    assert rise[1:] == pytest.approx(np.full(3, rise[1]), rel=1.5e-2), rise / rise[1]


def test_only_its_stage_makes_up():
    """The option holds for its stage: a next stage starts with nothing to
    make up (the depth scale back to 0)."""
    model, contact, solver, _ = pushed_through(2, True)
    assert contact._depth_scale() == 0.0
    solver.run_stage(textile.Stage("hold"))
    assert contact._depth_scale() == 0.0


@pytest.mark.parametrize("options, message", [
    (dict(make_up_penetrations="yes"), "make_up_penetrations must be True or False"),
    (dict(mode="weaving", fibre_yarn=[0, 1], yarn_above=[[0, 1], [-1, 0]],
          make_up_penetrations=True), "make_up_penetrations goes with the ordinary mode"),
])
def test_bad_values_are_named_errors(options, message):
    with pytest.raises(ValueError, match=message):
        FibreContact().configure(**options)
