"""A woven state for tests that start from one: woven and saved once, on
rank 0 alone, read by every rank."""
from mpi4py import MPI

from textile.weaving import woven_state


def woven_once(tmp_path_factory, fabric, solver_options=None) -> str:
    """Path of the woven state of ``fabric`` (woven on rank 0 with
    COMM_SELF, saved in a fresh temporary directory), on every rank."""
    comm = MPI.COMM_WORLD
    path = str(tmp_path_factory.mktemp("woven") / "woven.h5") if comm.rank == 0 else None
    path = comm.bcast(path, root=0)
    if comm.rank == 0:
        woven_state(fabric, path, solver_options, MPI.COMM_SELF)
    comm.Barrier()
    return path
