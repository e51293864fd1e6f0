"""The numerical libraries a run really uses, and their thread counts.

MUMPS spends its time in BLAS. Debian's default ``libblas.so.3`` is the
*reference* BLAS, 4-6 times slower than OpenBLAS (``.ci/install`` brings
``libopenblas0-pthread``, which takes over the ``libblas.so.3``
alternative). OpenBLAS starts one thread per core in every process: under
``mpirun -n 2`` on 2 cores that is 4 threads fighting for 2 cores, so at
import textile limits OpenBLAS to cores / (ranks on this node) threads,
unless the user chose a count (``OPENBLAS_NUM_THREADS`` or
``OMP_NUM_THREADS``).
"""
from __future__ import annotations

import ctypes
import functools
import os
import time

from mpi4py import MPI


def _loaded(fragment: str) -> list[str]:
    """Paths of the shared libraries mapped into this process whose name
    contains ``fragment``."""
    try:
        with open("/proc/self/maps") as f:
            paths = {line.split()[-1] for line in f if fragment in line and "/" in line}
    except OSError:
        return []
    return sorted(paths)


def _openblas():
    """ctypes handle of the loaded OpenBLAS, or None."""
    for path in _loaded("openblas"):
        try:
            lib = ctypes.CDLL(path)
            lib.openblas_get_num_threads  # noqa: B018 (probe the symbol)
            return lib
        except (OSError, AttributeError):
            continue
    return None


def blas_info() -> dict:
    """Which BLAS is loaded (its real path), whether it is OpenBLAS, its
    thread count and build configuration; the MPI ranks on this node."""
    libs = [os.path.realpath(p) for p in _loaded("libblas") + _loaded("openblas")]
    lib = _openblas()
    info = dict(blas=sorted(set(libs)), openblas=lib is not None, threads=1,
                config="", ranks_on_node=_ranks_on_node(), cores=os.cpu_count() or 1)
    if lib is not None:
        info["threads"] = int(lib.openblas_get_num_threads())
        lib.openblas_get_config.restype = ctypes.c_char_p
        info["config"] = lib.openblas_get_config().decode()
    if not info["openblas"] and any("/blas/" in p for p in libs):
        info["warning"] = ("reference BLAS: MUMPS is 4-6x slower; install libopenblas0-pthread "
                           "(bash .ci/install)")
    return info


def describe() -> str:
    """One line for benchmark and log headers."""
    i = blas_info()
    name = "OpenBLAS" if i["openblas"] else "reference BLAS" if i["blas"] else "unknown BLAS"
    return (f"{name} ({', '.join(i['blas']) or 'not found'}), {i['threads']} thread(s) per rank, "
            f"{i['ranks_on_node']} rank(s) on {i['cores']} cores")


@functools.cache
def _ranks_on_node() -> int:
    """Collective on first call (made at import by :func:`limit_blas_threads`
    on every rank); cached, so :func:`blas_info` may then run on one rank."""
    node = MPI.COMM_WORLD.Split_type(MPI.COMM_TYPE_SHARED)
    n = node.Get_size()
    node.Free()
    return n


def limit_blas_threads() -> int:
    """Give each rank on this node cores / ranks OpenBLAS threads (at least
    one), unless the user set a thread count; returns the count in use."""
    ranks = _ranks_on_node()  # collective: every rank imports textile
    lib = _openblas()
    if lib is None:
        return 1
    if "OPENBLAS_NUM_THREADS" in os.environ or "OMP_NUM_THREADS" in os.environ:
        return int(lib.openblas_get_num_threads())
    threads = max(1, (os.cpu_count() or 1) // ranks)
    if threads < lib.openblas_get_num_threads():
        lib.openblas_set_num_threads(ctypes.c_int(threads))
    return int(lib.openblas_get_num_threads())


def waiting_quietly(comm, poll: float = 0.005) -> None:
    """A barrier whose waiting ranks sleep (polling every ``poll``
    seconds) rather than spin as MPI's blocking calls do: while one rank
    works with helpers of its own (the pictures' VTK process, whose
    rasterizer runs a thread per core), the others leave it the cores.
    Collective."""
    if comm.size == 1:
        return
    request = comm.Ibarrier()
    while not request.Test():
        time.sleep(poll)
