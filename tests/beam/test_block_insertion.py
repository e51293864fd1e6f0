"""Element blocks added at precomputed matrix positions equal PETSc's own
insertion (BlockInsertion, cpp/textile/assembly/petsc_insert.h).

A model's first tangent goes through MatSetValuesLocal (the matrix has no
final pattern yet); later ones add at positions found once. Both must give
the same matrix, serial and with a fibre cut between ranks (rows of the
other rank go through PETSc's stash).
"""
import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

import textile


def model(comm):
    E, nu, R = 1.0e6, 0.3, 1e-2
    # 8 + 4 elements: on 2 ranks the cut falls inside the first fibre
    fibres = [textile.straight_fibre([0, 0, 0], [0.3, 0, 0], R, textile.Material(E, nu),
                                     num_elements=8),
              textile.arc_fibre([0, 0, 0.1], 0.2, 1.0, 0.5 * R, textile.Material(2 * E, 0.2),
                                num_elements=4)]
    m = textile.Model(fibres, comm=comm)
    m.clamp(0, 0)
    m.fix(1, 0, ["position", "g1"])
    m.setup()
    return m


def tangent(m, scale, seed):
    """Local rows of the tangent at a random state, as a dense array."""
    rng = np.random.default_rng(seed + m.comm.rank)
    m.x.setArray(rng.normal(scale=scale, size=m.x.getLocalSize()))
    m.apply_constraints(m.x)
    m.jacobian(None, m.x, m.A, m.A)
    return m.A.convert("dense", PETSc.Mat()).getDenseArray().copy(), m.x.copy()


@pytest.mark.mpi
def test_direct_insertion_equals_petsc_insertion():
    comm = MPI.COMM_WORLD
    m = model(comm)
    if comm.size > 1:
        # a fibre is cut between the ranks: ghost rows and columns exist
        assert comm.allreduce(len(m.mesh.ghosts)) > 0
    tangent(m, 0.005, 1)                       # first: MatSetValuesLocal
    K_direct, x = tangent(m, 0.005, 2)         # second: precomputed positions
    fresh = model(comm)
    x.copy(fresh.x)
    fresh.jacobian(None, fresh.x, fresh.A, fresh.A)
    K_petsc = fresh.A.convert("dense", PETSc.Mat()).getDenseArray()
    K_first = tangent(model(comm), 0.005, 1)[0]
    scale = comm.allreduce(np.abs(K_petsc).max(), op=MPI.MAX)
    # the same additions in the same order: equal to round-off of the sums
    # (checked on every rank before asserting: a rank failing alone would
    # leave the other waiting in a collective call)
    same = np.allclose(K_direct, K_petsc, rtol=0, atol=1e-14 * scale)
    assert comm.allreduce(same, op=MPI.LAND)
    # not vacuous: the second state's tangent differs from the first's
    differs = not np.allclose(K_first, K_petsc, rtol=0, atol=1e-6 * scale)
    assert comm.allreduce(differs, op=MPI.LOR)
