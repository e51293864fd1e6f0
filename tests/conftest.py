"""Shared pytest set-up: PETSc objects die on all ranks together, and a
test failing on one rank of an mpirun stops every rank."""
import gc
import os
import sys

# A pytest-xdist worker inherits the environment of the controller, whose MPI
# singleton (started by the import below, there too) wrote its identity into
# it: an mpirun the worker launches then exits at once with status 1. Each
# worker starts a singleton of its own instead.
if "PYTEST_XDIST_WORKER" in os.environ:
    _SINGLETON = ("PMIX_", "ORTE_", "OMPI_MCA_ess", "OMPI_MCA_orte_", "OMPI_MCA_pmix",
                  "OMPI_APP_CTX_")
    for _name in [k for k in os.environ if k.startswith(_SINGLETON)]:
        del os.environ[_name]

import pytest  # noqa: E402
from mpi4py import MPI  # noqa: E402
from petsc4py import PETSc


@pytest.fixture(autouse=True)
def collective_cleanup():
    yield
    gc.collect()
    PETSc.garbage_cleanup(MPI.COMM_WORLD)  # parallel objects gc left to PETSc
    MPI.COMM_WORLD.barrier()


def pytest_runtest_logreport(report):
    """Under mpirun a failure on one rank leaves the others waiting in a
    collective (the next barrier or solve) until CI's limit: print the
    failure now, with its captured output, and abort the whole run."""
    comm = MPI.COMM_WORLD
    if not report.failed or comm.size == 1:
        return
    out = sys.__stderr__
    out.write(f"\n=== rank {comm.rank}: {report.nodeid} failed ({report.when}); "
              f"aborting all ranks\n{report.longreprtext}\n")
    for name, content in report.sections:
        out.write(f"--- {name}\n{content[-4000:]}\n")
    out.flush()
    comm.Abort(1)
