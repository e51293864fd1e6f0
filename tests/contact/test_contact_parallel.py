"""Contact across ranks: the same answer on all ranks as on one."""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import FibreContact


def solve(comm, c_start=-0.25):
    mat = textile.Material(1.0e9, 0.3)
    R, L = 1e-3, 0.1
    # three fibres: A fixed, B crossing on it, C parallel on B (point and line contacts)
    A = textile.straight_fibre([0, -L / 2, 0], [0, L / 2, 0], R, mat, num_elements=8)
    B = textile.straight_fibre([-L / 2, 0, 2 * R], [L / 2, 0, 2 * R], R, mat, num_elements=8)
    C = textile.straight_fibre([c_start * L, 0, 4 * R - 1e-6], [L / 4, 0, 4 * R - 1e-6], R, mat,
                               num_elements=4)
    model = textile.Model([A, B, C], comm=comm)
    for n in range(A.num_nodes):
        model.fix(A, n, "all")
    model.fix(B, 0, ["position", "g1x"], [0, 0, -1e-4, 0])
    model.fix(B, -1, ["y", "z"], [0, -1e-4])
    for n in (0, -1):
        model.fix(C, n, ["x", "y", "g1x"] if n == 0 else ["y"])
    for n in range(C.num_nodes):
        model.add_force(C, n, [0, 0, -1e-3])
    contact = FibreContact(dict(friction=0.2))
    model.add_effect(contact)
    solver = textile.Solver(model, dict(initial_step=0.25, max_step=0.25, verbose=False))
    solver.solve()
    model.contact = contact
    return model.nodal_unknowns(), solver.history[-1].effects, model


@pytest.mark.mpi
def test_contact_parallel_equals_serial():
    q_par, stats_par, model = solve(MPI.COMM_WORLD)
    q_ser, stats_ser, _ = solve(MPI.COMM_SELF)
    # converged to the Newton tolerance in both runs
    assert np.allclose(q_par, q_ser, rtol=0, atol=1e-10 * np.abs(q_ser).max())
    for key in ("contact_zones", "contact_elements", "active_contacts"):
        assert stats_par[key] == stats_ser[key]
    assert stats_par["contact_force_sum"] == pytest.approx(stats_ser["contact_force_sum"],
                                                           rel=1e-8)
    assert stats_ser["active_contacts"] >= 3  # the crossing and C's line contact


def tangent_times(model, v):
    """(A v) per global beam unknown (all ranks) for the tangent at the
    model's current state, and the contact's off-rank block counts of
    that one assembly (summed over ranks)."""
    comm = model.comm
    dofs = model.beam_global_dofs()
    before = model.contact.assembly_timing()
    model.jacobian(None, model.x, model.A, model.A)
    after = model.contact.assembly_timing()
    x, y = model.A.createVecs()
    r0, r1 = x.getOwnershipRange()
    mine = (dofs >= r0) & (dofs < r1)
    x.setValues(dofs[mine], v[mine])
    x.assemble()
    model.A.mult(x, y)
    out = np.zeros(dofs.size)
    out[mine] = y.getArray()[dofs[mine] - r0]
    counts = [comm.allreduce(after[k] - before[k]) for k in ("off_rank_sent", "off_rank_stashed")]
    return comm.allreduce(out), counts


@pytest.mark.mpi
def test_off_rank_blocks_reach_their_owners():
    """The contact tangent's blocks of other ranks' rows go to their owners
    and are added in place there (assembly/off_rank_blocks.h), none through
    PETSc's stash, and the tangent is the serial one."""
    comm = MPI.COMM_WORLD
    v = np.random.default_rng(5).normal(size=9 * 43)  # the same on all ranks
    # C's line contact on B reaches over the cut between the ranks (B's
    # node 4 of 17, x = -L/4)
    _, _, par = solve(comm, c_start=-0.375)
    _, _, ser = solve(MPI.COMM_SELF, c_start=-0.375)
    assert par.beam_global_dofs().size == v.size
    Av_par, (sent, stashed) = tangent_times(par, v)
    Av_ser, _ = tangent_times(ser, v)
    scale = np.abs(Av_ser).max()
    # the two states agree to the Newton tolerance (1e-10 of the positions,
    # test above); the penalty tangent amplifies that to ~1e-9 at most
    assert np.allclose(Av_par, Av_ser, rtol=0, atol=1e-8 * scale)
    assert stashed == 0
    if comm.size > 1:
        assert sent > 0
    # the rebuilt matrix had room for them: the rows declared for another
    # rank reached it (cpp/textile/assembly/sparsity_pattern.h); a missed
    # entry would have been allocated on insertion
    assert comm.allreduce(par.A.getInfo()["mallocs"]) == 0
