"""NodeGather (textile.system.node_gather): each rank receives the current
unknowns of the fibre nodes it asks for, wherever they are owned, and
nothing else."""
import numpy as np
import pytest
from mpi4py import MPI

import textile


@pytest.mark.mpi
def test_each_rank_gets_the_nodes_it_asks_for():
    comm = MPI.COMM_WORLD
    mat = textile.Material(1e9, 0.3)
    fibres = [textile.straight_fibre([0, 0.01 * k, 0], [0.1, 0.01 * k, 0], 1e-3, mat,
                                     num_elements=6, section_vector=[0, 1, 0])
              for k in range(3)]
    model = textile.Model(fibres, comm=comm)
    for k, fib in enumerate(fibres):
        model.clamp(fib, 0)
        model.add_force(fib, -1, [0, 0, 1e-3 * (k + 1)])
    textile.Solver(model, dict(verbose=False)).solve()
    everything = model.nodal_unknowns()      # the whole state, for comparison
    mesh = model.mesh
    # each rank asks for other nodes: every third node from its rank number on
    wanted = np.arange(comm.rank, mesh.num_nodes_global, 3)
    if comm.size > 1:     # the case meant: some of them belong to another rank
        assert np.any(mesh.node_owner[wanted] != comm.rank)
    gather = model.system.node_gather(wanted)
    assert gather.num_values == 9 * len(wanted)
    assert gather.num_remote == 9 * np.count_nonzero(mesh.node_owner[wanted] != comm.rank)
    q = gather.positions(model.x)
    np.testing.assert_array_equal(q[wanted], everything[wanted])   # the same numbers
    others = np.setdiff1d(np.arange(mesh.num_nodes_global), wanted)
    assert np.all(np.isnan(q[others]))
    assert np.abs(everything[:, 2]).max() > 0    # the fibres did bend
    gather.destroy()
