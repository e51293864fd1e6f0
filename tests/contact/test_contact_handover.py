"""Contact history across a partition cut (history_handover.h).

Fibre B crosses fibre A at right angles, is pressed onto it and then slides
along its own axis by one and a half elements, with friction. Partitioned
by place, B is cut between two ranks at the crossing: the crossing's
element is evaluated by the rank owning B's element there
(evaluated_here), which changes as B slides. The successor on the other
rank must take over the element's stick point: with the reversible slip
larger than a step's slide, losing it would restart the friction force
from zero.
"""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import FibreContact

E, R, L = 1.0e9, 1e-3, 0.1
ELEMENTS = 8
SLIDE = 1.5 * L / ELEMENTS      # more than an element


def run(comm, partition="place"):
    """The supports' tangential force on B after every step, the model
    and its contact."""
    mat = textile.Material(E, 0.3)
    A = textile.straight_fibre([0, -L / 2, 0], [0, L / 2, 0], R, mat, num_elements=ELEMENTS)
    B = textile.straight_fibre([-L / 2, 0, 2 * R], [L / 2, 0, 2 * R], R, mat,
                               num_elements=ELEMENTS)
    model = textile.Model([A, B], comm=comm, partition=partition)
    for n in range(A.num_nodes):
        model.fix(A, n, "all")
    press = 2e-4

    def ends(t):   # pressed (0 -> 0.2), then slid along x (0.2 -> 1)
        return [SLIDE * max(t - 0.2, 0) / 0.8, 0.0, -press * min(t / 0.2, 1.0)]

    model.fix(B, 0, ["x", "y", "z", "g1x"], lambda t: ends(t) + [0.0])
    model.fix(B, -1, ["x", "y", "z"], ends)
    # the reversible slip (3 R) spans several steps' slide (0.78 R a step):
    # the stick point carries the friction force from step to step
    contact = FibreContact(dict(adapt_penalty=False, penalty=1e5 / (2 * R), regularization=0.05,
                                friction=0.3, reversible_slip=3.0))
    model.add_effect(contact)
    rows = []

    def record(solver, rec):
        support = model.reaction(B, 0, "position") + model.reaction(B, -1, "position")
        rows.append((rec.load_factor, support[0]))

    textile.Solver(model, dict(initial_step=0.05, max_step=0.05, verbose=False),
                   on_step=record).solve()
    return np.array(rows), model, contact


@pytest.mark.mpi
def test_the_crossing_keeps_its_stick_point_on_the_other_rank():
    """Two ranks give the one-rank friction force at every step (measured
    3.7e-9 of its largest value: each Newton solve stops within its
    tolerance, and the stick force mu N |slip| / u_rev magnifies position
    round-off; without the handover 0.28)."""
    serial, _, _ = run(MPI.COMM_SELF)
    parallel, model, contact = run(MPI.COMM_WORLD)
    comm = MPI.COMM_WORLD
    if comm.size == 2:
        # the case meant: B's elements at the crossing before (4) and after
        # (2) the slide belong to different ranks, and history did travel
        mesh = model.mesh
        b = mesh.first_node[1]
        assert mesh.node_owner[b + 2 * 4] != mesh.node_owner[b + 2 * 2]
        d = contact.elements()
        assert comm.allreduce(len(d["s_j"])) == 1
        s_j = np.concatenate(comm.allgather(d["s_j"]))
        assert s_j[0] == pytest.approx(4 - 1.5, abs=1e-2)
        assert comm.allreduce(contact.assembly_timing()["history_bytes_received"]) > 0
    np.testing.assert_array_equal(parallel[:, 0], serial[:, 0])      # the same steps
    force = np.abs(serial[:, 1]).max()
    assert force > 1e-3   # friction acts (measured 3.1e-3 N)
    assert np.abs(parallel[:, 1] - serial[:, 1]).max() < 2e-8 * force
