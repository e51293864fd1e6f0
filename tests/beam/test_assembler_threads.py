"""The beam element loops on several threads give the serial results.

Elements are computed on the threads and added in element order by the
calling thread, so vector, energy and matrix are bit for bit the serial
ones; a kernel error on any thread reaches the caller with its element and
fibre. (Threads start from 256 elements each: the bundle has 1024.)
"""
import numpy as np
import pytest
from mpi4py import MPI

import textile


def bundle():
    mat = textile.Material(1e9, 0.3)
    fibres = [textile.straight_fibre([0, 0.01 * k, 0], [0.2, 0.01 * k, 0], 1e-3, mat,
                                     num_elements=128, section_vector=[0, 1, 0])
              for k in range(8)]
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
    _, _, values = m.A.getValuesCSR()
    return energy, b, values.copy()


def test_threads_give_the_serial_results():
    m = bundle()
    e1, b1, K1 = assemble(m, 1)
    for threads in (2, 4):
        e, b, K = assemble(m, threads)
        # the same additions in the same order
        assert np.array_equal(K, K1) and np.array_equal(b, b1) and e == e1


def test_kernel_error_on_a_thread_reaches_the_caller():
    m = bundle()
    asm = m.beam._assembler
    asm.num_threads = 4
    u = m.state().u["beam"].copy()
    # fold element 100 of fibre 6 (mid node 201 of 257 in the fibre)
    mid = 6 * 257 + 201
    u[9 * mid] += 0.75 * 0.2 / 128
    with pytest.raises(textile.GeometryError, match=r"element 100 of fibre 6: "):
        asm.assemble_vector(u, np.zeros_like(u))
    with pytest.raises(textile.GeometryError, match=r"element 100 of fibre 6: "):
        asm.assemble_matrix(m.A, u, m.state().dofs["beam"])
