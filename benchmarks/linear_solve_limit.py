"""The linear solve at the paper's size: one factorization of a woven sample.

Durville's sample (docs/method.md §10) has 12 yarns of 28 fibres: 336
fibres. With 30 quadratic elements a fibre (61 nodes, 9 unknowns a node)
its Jacobian has 184,464 unknowns. Until the weaving issue produces the real
woven state, this script builds a Jacobian with the same structure:

- each fibre a quadratic beam chain (a node couples with the nodes of its
  elements: 3 or 5 nodes);
- each fibre touches its neighbours in the yarn (a hexagonal-like packing of
  4 x 7 fibres) along its whole length: a node couples with the two nearest
  nodes of each neighbour (line contact);
- at each of the 36 warp/weft crossings, the fibres of the two facing layers
  couple at the crossing (point contacts).

Values make it symmetric positive definite and diagonally dominant (the
factorization's cost is set by the pattern and its fill, not by the values).
Measures the MUMPS factorization (symbolic + numeric, and a numeric
refactorization as every Newton iteration does) and one solve, LU and
LDL^T, with and without block low-rank compression, on the ranks it is run
with:

    .venv/bin/python benchmarks/linear_solve_limit.py
    mpirun -n 2 .venv/bin/python benchmarks/linear_solve_limit.py

Appends its figures to benchmarks/output/linear_solve_limit.json (one entry
per rank count). A measurement, not a test: it asserts nothing.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import time

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

import textile  # noqa: F401  (PETSc init, BLAS threads)
from textile import runtime

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "output")


def woven_pattern(yarns_per_direction=6, rows=4, cols=7, elements=30):
    """Block pattern (node pairs) of the synthetic woven sample.

    Returns (num_nodes, pairs (m, 2) with i < j).
    """
    nodes_per_fibre = 2 * elements + 1
    fibres_per_yarn = rows * cols
    n_fibres = 2 * yarns_per_direction * fibres_per_yarn
    first = np.arange(n_fibres) * nodes_per_fibre
    pairs = []
    # beam chains: nodes of a quadratic element couple with each other
    e = np.arange(elements)
    local = np.array([(0, 1), (0, 2), (1, 2)])
    chain = (2 * e[:, None, None] + local[None]).reshape(-1, 2)
    for f in range(n_fibres):
        pairs.append(first[f] + chain)
    # neighbours in a yarn: (r, c) touches (r, c+1), (r+1, c), (r+1, c+-1)
    k = np.arange(nodes_per_fibre)
    for yarn in range(2 * yarns_per_direction):
        base = yarn * fibres_per_yarn
        for r in range(rows):
            for c in range(cols):
                a = base + r * cols + c
                shift = 1 if r % 2 else -1
                for rr, cc in ((r, c + 1), (r + 1, c), (r + 1, c + shift)):
                    if 0 <= rr < rows and 0 <= cc < cols:
                        b = base + rr * cols + cc
                        for d in (0, 1):  # nearest node and the next one
                            kk = np.clip(k + d, 0, nodes_per_fibre - 1)
                            pairs.append(np.column_stack([first[a] + k, first[b] + kk]))
    # crossings (plain weave): the facing rows of warp yarn w and weft yarn
    # v touch at the crossing; each fibre of one row crosses each fibre of
    # the other once, at a node spread over the yarn's width (half a pitch)
    pitch = (nodes_per_fibre - 1) // yarns_per_direction
    for w in range(yarns_per_direction):
        for v in range(yarns_per_direction):
            warp_on_top = (w + v) % 2 == 0
            warp_row = 0 if warp_on_top else rows - 1
            weft_row = rows - 1 if warp_on_top else 0
            for c in range(cols):
                for cc in range(cols):
                    a = w * fibres_per_yarn + warp_row * cols + c
                    b = (yarns_per_direction + v) * fibres_per_yarn + weft_row * cols + cc
                    on_a = pitch * v + pitch // 2 + (cc - cols // 2) * pitch // (2 * cols)
                    on_b = pitch * w + pitch // 2 + (c - cols // 2) * pitch // (2 * cols)
                    pairs.append(np.array([[first[a] + on_a, first[b] + on_b]]))
    p = np.vstack(pairs)
    p = np.sort(p, axis=1)
    p = np.unique(p[p[:, 0] != p[:, 1]], axis=0)
    return n_fibres * nodes_per_fibre, n_fibres, p


def build_matrix(comm, num_nodes, pairs, bs=9):
    """SPD AIJ matrix with 9x9 blocks on the pattern (distributed by rows)."""
    n = num_nodes * bs
    lo_node = (comm.rank * num_nodes) // comm.size
    hi_node = ((comm.rank + 1) * num_nodes) // comm.size
    rng = np.random.default_rng(0)
    # node-level graph: symmetric adjacency plus the diagonal
    both = np.vstack([pairs, pairs[:, ::-1]])
    mine = both[(both[:, 0] >= lo_node) & (both[:, 0] < hi_node)]
    rows_nodes = np.arange(lo_node, hi_node)
    diag = np.column_stack([rows_nodes, rows_nodes])
    allp = np.vstack([mine, diag])
    order = np.lexsort((allp[:, 1], allp[:, 0]))
    allp = allp[order]
    # expand each node pair to a dense 9x9 block: row-major CSR
    counts = np.bincount(allp[:, 0] - lo_node, minlength=hi_node - lo_node)
    indptr_nodes = np.concatenate([[0], np.cumsum(counts)])
    nloc = (hi_node - lo_node) * bs
    indptr = np.zeros(nloc + 1, dtype=PETSc.IntType)
    cols = []
    vals = []
    degree = np.bincount(both[:, 0], minlength=num_nodes) + 1
    for i_node in range(hi_node - lo_node):
        nb = allp[indptr_nodes[i_node]:indptr_nodes[i_node + 1], 1]
        c = (nb[:, None] * bs + np.arange(bs)[None, :]).ravel()
        for r in range(bs):
            row = i_node * bs + r
            v = -0.1 * (1 + 0.1 * rng.random(len(c)))
            dpos = np.flatnonzero(c == (lo_node + i_node) * bs + r)
            v[dpos] = 2.0 * degree[lo_node + i_node] * bs
            cols.append(c)
            vals.append(v)
            indptr[row + 1] = indptr[row] + len(c)
    cols = np.concatenate(cols).astype(PETSc.IntType)
    vals = np.concatenate(vals)
    A = PETSc.Mat().createAIJ([(nloc, n), (nloc, n)], csr=(indptr, cols, vals), comm=comm)
    # symmetric values: the random off-diagonal part is replaced by its
    # symmetric part (A + A^T) / 2
    At = A.transpose(PETSc.Mat())
    # same pattern (the node graph is symmetric): the default
    # DIFFERENT_NONZERO_PATTERN inserts value by value in parallel (minutes)
    A.axpy(1.0, At, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
    A.scale(0.5)
    At.destroy()
    A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    return A


def factor(A, kind, blr, comm):
    """Times of: symbolic + numeric factorization, numeric refactorization, one solve."""
    ksp = PETSc.KSP().create(comm)
    ksp.setOperators(A)
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setType(kind)
    pc.setFactorSolverType("mumps")
    opts = PETSc.Options()
    prefix = f"bench_{kind}_{int(blr)}_"
    ksp.setOptionsPrefix(prefix)
    if blr:
        opts[prefix + "mat_mumps_icntl_35"] = 2
        opts[prefix + "mat_mumps_cntl_7"] = 1e-8
    ksp.setFromOptions()
    b = A.createVecLeft()
    b.set(1.0)
    x = b.duplicate()
    comm.Barrier()
    t0 = time.perf_counter()
    ksp.setUp()
    comm.Barrier()
    first = time.perf_counter() - t0
    t0 = time.perf_counter()
    ksp.solve(b, x)
    comm.Barrier()
    solve = time.perf_counter() - t0
    r = b.duplicate()
    A.mult(x, r)
    r.aypx(-1.0, b)
    residual = r.norm() / b.norm()
    # a refactorization with the same pattern, as in every Newton iteration
    A.shift(1e-3)
    ksp.setOperators(A)
    comm.Barrier()
    t0 = time.perf_counter()
    ksp.setUp()
    comm.Barrier()
    refactor = time.perf_counter() - t0
    A.shift(-1e-3)
    ksp.destroy()
    return dict(factorization="LDL^T" if kind == "cholesky" else "LU", block_low_rank=blr,
                first_seconds=first, refactor_seconds=refactor, solve_seconds=solve,
                relative_residual=residual)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--elements", type=int, default=30, help="quadratic elements a fibre")
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    t0 = time.perf_counter()
    num_nodes, n_fibres, pairs = woven_pattern(elements=args.elements)
    A = build_matrix(comm, num_nodes, pairs)
    build = time.perf_counter() - t0
    info = A.getInfo(PETSc.Mat.InfoType.GLOBAL_SUM)
    n = A.getSize()[0]
    if comm.rank == 0:
        print(runtime.describe())
        print(f"{n_fibres} fibres x {2 * args.elements + 1} nodes x 9 = {n} unknowns, "
              f"{int(info['nz_used'])} nonzeros ({info['nz_used'] / n:.0f} a row), "
              f"{comm.size} rank(s); built in {build:.1f} s")
        print(f"{'factorization':>13} {'BLR':>5} {'first [s]':>10} {'refactor [s]':>13} "
              f"{'solve [s]':>10} {'residual':>9}")
    rows = []
    for kind in ("lu", "cholesky"):
        for blr in (False, True):
            r = factor(A, kind, blr, comm)
            rows.append(r)
            if comm.rank == 0:
                print(f"{r['factorization']:>13} {str(blr):>5} {r['first_seconds']:10.2f} "
                      f"{r['refactor_seconds']:13.2f} {r['solve_seconds']:10.3f} "
                      f"{r['relative_residual']:9.1e}", flush=True)
    peak = comm.allreduce(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, op=MPI.SUM)
    if comm.rank == 0:
        print(f"peak memory (sum over ranks): {peak:.0f} MiB")
        os.makedirs(OUT, exist_ok=True)
        path = os.path.join(OUT, "linear_solve_limit.json")
        data = json.load(open(path)) if os.path.exists(path) else {}
        data[f"{comm.size}_ranks"] = dict(
            date=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), blas=runtime.blas_info(),
            fibres=n_fibres, unknowns=n, nonzeros=int(info["nz_used"]), ranks=comm.size,
            peak_memory_mib=peak, results=rows)
        with open(path, "w") as f:
            json.dump(data, f, indent=1)
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
