"""Detection among the fibres near a rank's own (detection_view.py).

A grid of five fibres along x crossed by five along y, pressed together, is
partitioned by place: each rank owns half the crossings. A rank detects
among its own fibres and those whose pieces come within the search
distance of its own; the other fibres' nodes are not on it. The contact
elements of both ranks together must be the one-rank elements, grouped in
the same zones.
"""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.detection_view import DetectionView
from textile.effects.fibre_contact import FibreContact

E, R = 1.0e9, 1e-3
GAP = 12 * R       # between parallel fibres: far beyond the search distance
N = 5
L = N * GAP


def run(comm):
    mat = textile.Material(E, 0.3)
    offsets = (np.arange(N) - (N - 1) / 2) * GAP
    along_x = [textile.straight_fibre([-L / 2, y, 0], [L / 2, y, 0], R, mat, num_elements=24)
               for y in offsets]
    along_y = [textile.straight_fibre([x, -L / 2, 2 * R], [x, L / 2, 2 * R], R, mat,
                                      num_elements=24) for x in offsets]
    model = textile.Model(along_x + along_y, comm=comm, partition="place")
    for f in along_x:
        for end in (0, -1):
            model.fix(f, end, "all")
    for f in along_y:   # pressed onto the others
        for end in (0, -1):
            model.fix(f, end, ["x", "y", "z"], lambda t: [0.0, 0.0, -0.1 * R * t])
    contact = FibreContact(dict(adapt_penalty=False, penalty=1e5 / (2 * R), friction=0.2))
    model.add_effect(contact)
    textile.Solver(model, dict(initial_step=0.5, max_step=0.5, verbose=False)).solve()
    return model, contact


def elements(comm, contact) -> np.ndarray:
    d = contact.elements()
    rows = np.column_stack([d["fibre_i"], d["fibre_j"], d["s_i"], d["s_j"], d["zone"],
                            d["normal_force"]])
    rows = np.vstack(comm.allgather(rows))
    return rows[np.lexsort((rows[:, 3], rows[:, 2], rows[:, 1], rows[:, 0]))]


@pytest.mark.mpi
def test_two_ranks_detect_the_one_rank_elements_among_fewer_fibres():
    """The same elements and zones as on one rank: abscissas to 5e-14
    and forces to 1e-12 of the largest (measured 8e-15 and 2.4e-13: the
    same Newton iterates, the residual summed in another order), while
    each rank holds at most 8 of the 10 fibres."""
    comm = MPI.COMM_WORLD
    _, serial = run(MPI.COMM_SELF)
    _, parallel = run(comm)
    contact = parallel
    one, two = elements(MPI.COMM_SELF, serial), elements(comm, parallel)
    assert len(one) == N * N               # every crossing, one element each
    assert len(two) == len(one)
    np.testing.assert_array_equal(two[:, [0, 1]], one[:, [0, 1]])
    # the zones group the elements alike (their numbers are the ranks')
    pairs = np.unique(np.column_stack([one[:, 4], two[:, 4]]), axis=0)
    assert len(np.unique(pairs[:, 0])) == len(np.unique(pairs[:, 1])) == len(pairs)
    np.testing.assert_allclose(two[:, 2:4], one[:, 2:4], rtol=0, atol=5e-14)
    assert np.abs(two[:, 5] - one[:, 5]).max() <= 1e-12 * np.abs(one[:, 5]).max()
    assert parallel.set.num_zones == serial.set.num_zones
    if comm.size == 2:
        # the fibre along y at x = 0 lies on the cut: both ranks hold it
        # and find its crossings (shared zones: one number each);
        # neither rank holds the other half's fibres along y
        held = contact.detection_fibres()
        assert held[N + N // 2]
        assert held.sum() <= 2 * N - 2
        assert np.all(comm.allreduce(held.astype(int)) >= 1)
        assert parallel.assembly_timing()["detection_values"] > 0


def test_a_view_on_one_rank_holds_every_fibre():
    """One rank: every fibre is its own, no ghosts, nothing moved."""
    model, contact = run(MPI.COMM_SELF)
    assert contact.detection_fibres().all()
    view = DetectionView(model.system, contact.radius, contact.options.search_factor)
    flags = view.present(model.state().vector)
    assert flags.all() and view.counts["ghost_fibres"] == 0
    assert view.counts["detection_pieces"] == 0
    q = view.positions(model.state().vector, flags)
    np.testing.assert_array_equal(q, model.beam_positions(model.state()))
    view.destroy()
