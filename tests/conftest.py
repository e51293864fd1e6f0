"""Shared pytest set-up: PETSc objects die on all ranks together."""
import gc

import pytest
from mpi4py import MPI


@pytest.fixture(autouse=True)
def collective_cleanup():
    yield
    gc.collect()
    MPI.COMM_WORLD.barrier()
