"""Contact history in saved states: a run resumed from a saved state equals
the continuous one, with friction (stick points), whatever the partition.

A is fixed along y; B crosses it (a crossing) and C lies along B (a line
contact), each pressed down; then B's ends and C's far end are pulled along
x: the contacts slide with friction (mu = 0.3). The state is saved there;
then they move back by half the reversible slip: the contacts stick, and
their tangential forces come from the stick points carried in the state.
"""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import FibreContact

E, R, L = 1.0e9, 1e-3, 0.1
MAT = textile.Material(E, 0.3)


def scene(comm, friction=0.3):
    A = textile.straight_fibre([0, -L / 2, 0], [0, L / 2, 0], R, MAT, num_elements=8)
    B = textile.straight_fibre([-L / 2, 0, 2 * R], [L / 2, 0, 2 * R], R, MAT, num_elements=8)
    C = textile.straight_fibre([-L / 4, 0, 4 * R - 1e-6], [L / 4, 0, 4 * R - 1e-6], R, MAT,
                               num_elements=4)
    model = textile.Model([A, B, C], comm=comm)
    for n in range(A.num_nodes):
        model.fix(A, n, "all")
    b0 = model.fix(B, 0, ["position", "g1x"], [0, 0, -1e-4, 0])
    b1 = model.fix(B, -1, ["position"], [0, 0, -1e-4])
    c1 = model.fix(C, -1, ["x", "y", "g1x"], [0, 0, 0])
    model.fix(C, 0, "y")
    for n in range(C.num_nodes):
        model.add_force(C, n, [0, 0, -2e-2])
    contact = FibreContact(dict(friction=friction))
    model.add_effect(contact)
    solver = textile.Solver(model, dict(initial_step=0.25, max_step=0.25, verbose=False))

    def slide(name, dx):
        return textile.Stage(name, ramp={b0: [dx, 0, -1e-4, 0], b1: [dx, 0, -1e-4],
                                         c1: [2 * dx, 0, 0]})

    # back by half the reversible slip: the contacts stick, and their
    # tangential forces are the elastic slips carried by the stick points
    u_rev = contact.options.reversible_slip * R
    return model, contact, solver, [textile.Stage("press"), slide("slide", 2 * R),
                                    slide("back", 2 * R - 0.5 * u_rev)]


def run(comm, path, resume: bool):
    model, contact, solver, (press, slide1, slide2) = scene(comm)
    if resume:
        textile.load_state(model, path, solver)
    else:
        solver.run([press, slide1])
        textile.save_state(model, path, solver)
    solver.run_stage(slide2)
    return model.nodal_unknowns(), contact, solver


def compare(continuous, resumed):
    (qc, _, sc), (qr, _, sr) = continuous, resumed
    assert np.abs(qc - qr).max() < 1e-10 * L  # the same path, to round-off
    # the same contact history: statistics of the last step
    for key in ("contact_elements", "active_contacts", "slipping_contacts", "contact_zones"):
        assert sc.history[-1].effects[key] > 0 or key == "slipping_contacts"
        assert sc.history[-1].effects[key] == sr.history[-1].effects[key]
    assert sr.history[-1].effects["contact_force_sum"] == pytest.approx(
        sc.history[-1].effects["contact_force_sum"], rel=1e-10)


def test_resumed_run_equals_the_continuous_one(tmp_path):
    path = str(tmp_path / "slid.h5")
    continuous = run(MPI.COMM_SELF, path, resume=False)
    # the first sliding stage slips, the last one sticks
    history = continuous[2].history
    assert max(h.effects["slipping_contacts"] for h in history if h.stage == "slide") > 0
    assert history[-1].stage == "back" and history[-1].effects["slipping_contacts"] == 0
    compare(continuous, run(MPI.COMM_SELF, path, resume=True))


def test_the_saved_history_decides_the_resumed_run(tmp_path):
    """Control: a resumed run that loses the stick points (reset to the
    particles' current relative positions: no elastic slip) ends elsewhere
    (its sticking contacts pull the other way): the comparison above can
    fail."""
    path = str(tmp_path / "slid.h5")
    continuous = run(MPI.COMM_SELF, path, resume=False)
    model, contact, solver, (_, _, slide2) = scene(MPI.COMM_SELF)
    original = contact.load_state

    def forgetful(model, data):
        data = dict(data)
        d = {k: np.asarray(v) for k, v in data.items()}
        original(model, d)
        saved = contact.set.data()
        d["stick"] = saved["position_i"] - saved["position_j"]  # no elastic slip
        original(model, d)

    contact.load_state = forgetful
    textile.load_state(model, path, solver)
    solver.run_stage(slide2)
    assert np.abs(continuous[0] - model.nodal_unknowns()).max() > 1e-8 * L


@pytest.mark.mpi
def test_saved_on_two_ranks_resumed_on_one():
    """Saved by a run on every rank, resumed on each rank alone: the file
    does not depend on the partition."""
    comm = MPI.COMM_WORLD
    path = comm.bcast(__import__("tempfile").mkdtemp() if comm.rank == 0 else None) + "/s.h5"
    continuous = run(comm, path, resume=False)
    comm.barrier()
    compare(continuous, run(MPI.COMM_SELF, path, resume=True))


def test_weaving_mode_and_order_are_saved(tmp_path):
    """A state saved in the weaving stage resumes in it (same mode, same
    crossing order) and goes on as the continuous run does."""
    from tests.contact.test_weaving_mode import two_yarns
    from textile.effects.weaving_contact import weaving_mode

    path = str(tmp_path / "woven.h5")
    runs = []
    for resume in (False, True):
        fab, model, contact = two_yarns(warp_on_top=True)
        solver = textile.Solver(model, dict(initial_step=0.2, max_step=0.2, verbose=False))
        weave = textile.Stage("weave", effects={contact: weaving_mode(fab)})
        relax = textile.Stage("relax", effects={contact: dict(mode="ordinary")})
        if resume:
            textile.load_state(model, path, solver)
            assert contact.mode == "weaving"
            assert contact._order.sign(0, 3) == 1  # warp (yarn 0) above weft (yarn 1)
        else:
            solver.run_stage(weave)
            textile.save_state(model, path, solver)
        solver.run_stage(relax)
        runs.append(model.nodal_unknowns())
    assert np.abs(runs[0] - runs[1]).max() < 1e-10 * L


def test_a_frictionless_contact_keeps_no_stick_memory():
    """Frictionless, the crossing and the line contact slide 2 R: their
    stick points follow them, so friction switched on later (a scene with
    friction reading this state) starts from zero elastic slip. Before, a
    frictionless element's stick point stayed where it was made, and read
    with friction the 2 R slid became tangential forces at the friction
    limit: in a woven 3-fibre bundle fabric, 3.6 N of spurious force (its
    fibres' forces are ~7 N)."""
    model, contact, solver, (press, slide, _) = scene(MPI.COMM_SELF, friction=0.0)
    solver.run([press, slide])
    d = contact.set.data()
    assert np.count_nonzero(d["normal_force"] > 0) >= 2     # both contacts pressed
    # exactly zero: the stick point is the converged Delta itself
    assert np.abs(np.asarray(d["elastic_slip"])).max() == 0.0
