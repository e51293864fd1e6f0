"""The system matrix has room for every contact coupling Newton assembles.

The matrix is preallocated for the fibre-element pairs of the contact
elements near closing (``CouplingPattern``, gap below
``FibreContact.pattern_margin``). An element that closes only within a
Newton solve, on a pair not recorded, used to be inserted by PETSc
reallocating the matrix entry by entry: measured on the main demo's 7-fibre
weave (session 14), 3024 reallocations in one tangent, 3-9 s a tangent
instead of 0.03 s, and 19 s of a 58 s run in two failed attempts. Now
Newton stops at that iterate, the matrix is rebuilt with the new
couplings, and Newton goes on from the same iterate (the iterations count
against the same cap). And the couplings a failed attempt's iterates
recorded are forgotten when the attempt is undone: they doubled the
pattern of that run (617 -> 1170 fibre-element pairs) and each later
factorization took twice as long.
"""
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import FibreContact

R, L = 1e-3, 0.1
MAT = textile.Material(1.0e9, 0.3)
GAP = 0.6 * R   # the start: detected (centre lines within 4 R), beyond the pattern's margin
PUSH = 1.0 * R  # B's ends go down by this: B closes on A within the step's Newton solve


class WatchedContact(FibreContact):
    """FibreContact recording its pattern's size at each commit and
    restore (a failed attempt undone)."""

    def __init__(self):
        super().__init__()
        self.events = []

    def commit(self, model):
        super().commit(model)
        self.events.append(("commit", self.coverage.size))

    def restore(self, model):
        before = self.coverage.size
        super().restore(model)
        self.events.append(("restore", before, self.coverage.size))


def pressed_crossing(push=PUSH, max_it=25):
    """Fibre B across fixed fibre A, GAP above it; B's ends clamped and
    lowered by ``push`` in one load step, so B bends over A. Returns
    (model, contact, solver)."""
    A = textile.straight_fibre([-L / 2, 0, 0], [L / 2, 0, 0], R, MAT, num_elements=8)
    B = textile.straight_fibre([0, -L / 2, 2 * R + GAP], [0, L / 2, 2 * R + GAP], R, MAT,
                               num_elements=8)
    model = textile.Model([A, B], comm=MPI.COMM_SELF)
    for n in range(A.num_nodes):
        model.fix(A, n, "all")
    for n in (0, B.num_nodes - 1):
        model.fix(B, n, "all", value=[0, 0, -push, 0, 0, 0, 0, 0, 0])
    contact = WatchedContact()
    model.add_effect(contact)
    solver = textile.Solver(model, dict(initial_step=1.0, max_step=1.0, max_it=max_it,
                                        verbose=False))
    return model, contact, solver


def test_a_contact_closing_within_newton_gets_a_rebuilt_matrix():
    model, contact, solver = pressed_crossing()
    solver.solve()
    assert abs(model.load_factor - 1.0) < 1e-12
    # the element closed within Newton, on a pair the matrix had no room for
    assert solver.counters["matrix_rebuilds_in_newton"] >= 1
    # and nothing was inserted outside the matrix's pattern (before: one
    # reallocation per new nonzero)
    assert model.A.getInfo()["mallocs"] == 0
    assert solver.counters["failed_attempts"] == 0


def test_a_failed_attempt_forgets_its_couplings():
    model, contact, solver = pressed_crossing(push=2 * R, max_it=6)
    solver.solve()
    assert abs(model.load_factor - 1.0) < 1e-12
    assert solver.counters["failed_attempts"] >= 1
    committed, grown = 0, 0
    for event in contact.events:
        if event[0] == "commit":
            committed = event[1]
        else:
            # undone: the pattern is the last converged state's again
            _, before, after = event
            assert after == committed, contact.events
            grown += before > after
    assert grown >= 1, contact.events   # an attempt did record couplings
    assert model.A.getInfo()["mallocs"] == 0
