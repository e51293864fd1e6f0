"""The BLAS under MUMPS is OpenBLAS and never oversubscribes the cores."""
import os

import pytest

import textile


@pytest.mark.mpi
def test_openblas_with_sane_threads():
    info = textile.runtime.blas_info()
    # .ci/install brings libopenblas0-pthread; the reference BLAS makes
    # MUMPS 4-6x slower, so its presence is a set-up failure
    assert info["openblas"], info
    assert "warning" not in info
    if "OPENBLAS_NUM_THREADS" not in os.environ and "OMP_NUM_THREADS" not in os.environ:
        # one thread per core, shared by the ranks on the node
        assert info["threads"] * info["ranks_on_node"] <= max(info["cores"], info["ranks_on_node"])
        assert info["threads"] >= 1
    else:
        # the user's count is kept (.ci/test runs pytest's two workers with 1)
        requested = os.environ.get("OPENBLAS_NUM_THREADS") or os.environ["OMP_NUM_THREADS"]
        assert info["threads"] == int(requested)
    assert "thread(s) per rank" in textile.runtime.describe()


@pytest.mark.mpi
def test_describe_on_one_rank_does_not_block():
    # benchmarks print the BLAS line on rank 0 only: the node's rank count
    # (a collective) must already be known from the import
    from mpi4py import MPI
    if MPI.COMM_WORLD.rank == 0:
        assert "rank(s) on" in textile.runtime.describe()
    MPI.COMM_WORLD.Barrier()


@pytest.mark.mpi
def test_waiting_ranks_sleep_instead_of_spinning():
    # while rank 0 draws the pictures (a VTK process of its own) the other
    # ranks wait in waiting_quietly; a blocking MPI barrier would spin,
    # using its core for the whole wait (measured: ~0.3 s of CPU in 0.3 s)
    import time
    from mpi4py import MPI
    comm = MPI.COMM_WORLD
    late = 0.3
    if comm.rank == 0:
        time.sleep(late)
    cpu, wall = time.process_time(), time.perf_counter()
    textile.runtime.waiting_quietly(comm)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    if comm.size > 1 and comm.rank > 0:
        assert wall > 0.5 * late                 # it did wait for rank 0
        # measured ~0.01 s of CPU (polls every 5 ms); a spinning wait ~0.3 s
        assert cpu < 0.25 * late, (cpu, wall)
    else:
        assert wall < late                       # nobody to wait for
