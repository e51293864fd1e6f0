"""The beam element loops on several threads give the serial results.

The matrix is identical (elements are computed on threads but added in
order by one thread); the internal force differs by round-off only (the
threads' partial sums are added at the end); a kernel error on any thread
reaches the caller with its element and fibre.
"""
import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

import textile


def bundle():
    mat = textile.Material(1e9, 0.3)
    fibres = [textile.straight_fibre([0, 0.01 * k, 0], [0.2, 0.01 * k, 0], 1e-3, mat,
                                     num_elements=12, section_vector=[0, 1, 0])
              for k in range(3)]
    m = textile.Model(fibres, comm=MPI.COMM_SELF)
    m.clamp(0, 0)
    m.setup()
    rng = np.random.default_rng(4)
    n = m.x.getLocalSize()
    m.x.setArray(np.tile(np.r_[1e-5 * np.ones(3), 1e-3 * np.ones(6)], n // 9)
                 * rng.standard_normal(n))
    m.apply_constraints(m.x)
    return m


def assemble(m, threads):
    asm = m.beam._assembler
    asm.num_threads = threads
    st = m.state()
    b = np.zeros_like(st.u["beam"])
    energy = asm.assemble_vector(st.u["beam"], b)
    m.jacobian(None, m.x, m.A, m.A)
    m.jacobian(None, m.x, m.A, m.A)  # the second one adds at precomputed positions
    return energy, b, m.A.convert("dense", PETSc.Mat()).getDenseArray().copy()


def test_threads_give_the_serial_results():
    m = bundle()
    e1, b1, K1 = assemble(m, 1)
    for threads in (2, 5):
        e, b, K = assemble(m, threads)
        assert np.array_equal(K, K1)  # same blocks added in the same order
        # partial sums in another order: round-off only (measured: b equal,
        # energy 2e-16 apart)
        assert np.allclose(b, b1, rtol=0, atol=1e-15 * np.abs(b1).max())
        assert e == pytest.approx(e1, rel=1e-15)


def test_kernel_error_on_a_thread_reaches_the_caller():
    m = bundle()
    asm = m.beam._assembler
    asm.num_threads = 3
    u = m.state().u["beam"].copy()
    # fold element 10 of fibre 2 (the last third of the elements: thread 2)
    mid = 2 * 25 + 21
    u[9 * mid] += 0.75 * 0.2 / 12
    with pytest.raises(textile.GeometryError, match=r"element 10 of fibre 2: "):
        asm.assemble_vector(u, np.zeros_like(u))
    with pytest.raises(textile.GeometryError, match=r"element 10 of fibre 2: "):
        asm.assemble_matrix(m.A, u, m.state().dofs["beam"])
