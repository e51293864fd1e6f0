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
import numpy as np
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


def pressed_crossing(push=PUSH, max_it=25, side=None, max_step=1.0):
    """Fibre B across fixed fibre A, GAP above it; B's ends clamped and
    lowered by ``push`` in one load step, so B bends over A (``push``
    callable: s -> B's ends' nine displacements). ``side``: a fixed fibre C
    along A, that far from it. Returns (model, contact, solver)."""
    A = textile.straight_fibre([-L / 2, 0, 0], [L / 2, 0, 0], R, MAT, num_elements=8)
    B = textile.straight_fibre([0, -L / 2, 2 * R + GAP], [0, L / 2, 2 * R + GAP], R, MAT,
                               num_elements=8)
    fibres = [A, B]
    if side is not None:
        # beside A's half away from B
        fibres.append(textile.straight_fibre([L / 10, 2 * R + side, 0],
                                             [L / 2, 2 * R + side, 0], R, MAT, num_elements=4))
    model = textile.Model(fibres, comm=MPI.COMM_SELF)
    # with C, A is held at its ends only: the pattern's A rows and columns
    # are unknowns
    for n in range(A.num_nodes) if side is None else (0, A.num_nodes - 1):
        model.fix(A, n, "all")
    for f in fibres[2:]:
        for n in (0, f.num_nodes - 1):   # free between its ends: its rows are unknowns
            model.fix(f, n, "all")
    for n in (0, B.num_nodes - 1):
        model.fix(B, n, "all", value=push if callable(push) else [0, 0, -push] + [0] * 6)
    contact = WatchedContact()
    contact.fibres_for_test = fibres
    model.add_effect(contact)
    solver = textile.Solver(model, dict(initial_step=max_step, max_step=max_step,
                                        max_it=max_it, verbose=False))
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


def _stored_between(model, fibre_a, fibre_b, fibres) -> int:
    """Stored entries of the system matrix in fibre_a's rows and fibre_b's
    columns (one rank)."""
    first = np.cumsum([0] + [f.num_nodes for f in fibres])
    dofs = model.beam_global_dofs(constrained=True).reshape(-1, 9)
    rows = dofs[first[fibre_a]:first[fibre_a + 1]].ravel()
    cols = set(dofs[first[fibre_b]:first[fibre_b + 1]].ravel().tolist())
    ai, aj, _ = model.A.getValuesCSR()
    return sum(int(np.isin(aj[ai[r]:ai[r + 1]], list(cols)).sum()) for r in rows if r >= 0)


def test_the_pattern_holds_only_contacts_that_carry_force():
    # C lies 0.3 R beside A: detected, open, beyond the penalty's
    # regularization. Preallocated while it was within 0.5 R, such pairs
    # left 45% of a bundle weave's stored entries zero and its
    # factorizations did 2.7 times the work (benchmarks/README.md, "A
    # contact pattern of the contacts that carry force")
    model, contact, solver = pressed_crossing(side=0.3 * R)
    solver.solve()
    assert abs(model.load_factor - 1.0) < 1e-12
    fibres = contact.fibres_for_test
    assert _stored_between(model, 1, 0, fibres) > 0   # B's rows: the pressed crossing A-B
    assert _stored_between(model, 2, 0, fibres) == 0  # C's rows: the open neighbour A-C
    assert model.A.getInfo()["mallocs"] == 0


def test_a_contact_released_leaves_the_pattern():
    # B pressed onto A at s = 1/2 and lifted back to its start (0.6 R above
    # A) at s = 1: the converged state has no A-B contact, and the matrix
    # no room for it (couplings used to be kept for the whole run)
    def there_and_back(s):
        return [0, 0, -PUSH * (1 - abs(2 * s - 1))] + [0] * 6
    model, contact, solver = pressed_crossing(push=there_and_back, max_step=0.5)
    solver.solve()
    assert abs(model.load_factor - 1.0) < 1e-12
    assert len(contact.events) == 2 and contact.events[0][1] > 0, contact.events
    assert contact.events[1] == ("commit", 0), contact.events
    assert _stored_between(model, 1, 0, contact.fibres_for_test) == 0
