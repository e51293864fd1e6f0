"""Assembly throughput versus the direct solve, on a bundle of straight fibres.

N straight, parallel quadratic fibres (default 50 x 64 elements; spaced 10
radii apart in y and z, with nothing coupling them), each clamped at one end,
with a small random deformation. Measures (best of --repeats):

  * ``_cpp.BeamAssembler.assemble_vector`` alone (the C++ element loop),
  * the model's SNES callbacks ``residual`` and ``jacobian`` (what SNES calls;
    includes the Python glue: state views, scatter, constraints),
  * ``assemble_matrix`` alone (zeroEntries + C++ loop + MatAssembly),
  * one MUMPS LU of model.A and one solve (petsc4py KSP preonly + LU/mumps),
    both "first" (symbolic + numeric) and "refactor" (numeric only, the
    case of every Newton iteration after the first),
  * one full Newton iteration: the model's own SNES (``Solver.snes``) with
    max_it = 1 from the deformed state, after a warm-up solve so that the
    symbolic factorization is already done,

with the beam element loops on ``--threads`` threads (PETSc insertion and
MUMPS as configured),

and prints elements per second and the ratio Newton iteration / (LU + solve).
A measurement script, not a test: it asserts nothing.

    cd /work/main && PYTHONPATH=/work/main /usr/bin/python3 benchmarks/assembly_throughput.py
"""
from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np
from petsc4py import PETSc

import textile  # noqa: F401  (initializes petsc4py)
from textile import Material, Model, Solver, straight_fibre

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "output")


def best(fn, repeats, setup=None):
    """Best wall time of ``fn()`` over ``repeats`` calls (``setup()`` untimed before each)."""
    ts = []
    for _ in range(repeats):
        if setup is not None:
            setup()
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return min(ts), float(np.median(ts))


def build(num_fibres, num_elements, seed=0):
    R, L = 1e-3, 1.0
    mat = Material(1e9, 0.3)
    side = int(np.ceil(np.sqrt(num_fibres)))
    fibres = []
    for i in range(num_fibres):
        y, z = 10 * R * (i % side), 10 * R * (i // side)
        fibres.append(straight_fibre([0, y, z], [L, y, z], R, mat, num_elements=num_elements,
                                     order=2, section_vector=[0, 1, 0]))
    m = Model(fibres)
    for i in range(num_fibres):
        m.clamp(i, 0)
    m.setup()
    rng = np.random.default_rng(seed)
    n = m.x.getLocalSize()
    # small random deformation: 1e-3 R on positions, 1e-4 on section vectors
    scale = np.tile(np.r_[1e-3 * R * np.ones(3), 1e-4 * np.ones(6)], n // 9)
    m.x.setArray(scale * rng.standard_normal(n))
    m.apply_constraints(m.x)
    return m


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--fibres", type=int, default=50)
    ap.add_argument("--elements", type=int, default=64, help="quadratic elements per fibre")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--threads", type=int, default=None,
                    help="threads of the beam element loops (default: TEXTILE_NUM_THREADS, "
                         "else the cores of this process)")
    args = ap.parse_args(argv)
    rep = args.repeats

    t0 = time.perf_counter()
    m = build(args.fibres, args.elements)
    if args.threads is not None:
        m.beam._assembler.num_threads = args.threads
    threads = m.beam._assembler.num_threads
    t_build = time.perf_counter() - t0
    n_el = args.fibres * args.elements
    n_dofs = m.x.getSize()
    x = m.x.copy()
    asm = m.beam._assembler
    u = m.state(x).u["beam"]
    b_local = np.zeros_like(u)

    res = {}

    def vec_only():
        b_local[:] = 0.0
        asm.assemble_vector(u, b_local)

    res["assemble_vector"] = best(vec_only, rep)
    res["residual"] = best(lambda: m.residual(None, x, m.b), rep)
    dofs = m.state(x).dofs["beam"]

    def mat_only():
        m.A.zeroEntries()
        asm.assemble_matrix(m.A, u, dofs)
        m.A.assemble()

    # the model's jacobian first: it also inserts the identity on constrained
    # rows, whose slots a final assembly without them would compress away
    res["jacobian"] = best(lambda: m.jacobian(None, x, m.A, m.A), rep)
    res["assemble_matrix"] = best(mat_only, rep)
    m.jacobian(None, x, m.A, m.A)
    nnz = m.A.getInfo()["nz_used"]

    # --- MUMPS LU + solve on the same Jacobian --------------------------------
    rhs = m.b.copy()
    m.residual(None, x, rhs)
    dx = rhs.duplicate()
    holder = {}

    def new_ksp():
        if "ksp" in holder:
            holder["ksp"].destroy()
        ksp = PETSc.KSP().create(m.comm)
        ksp.setType("preonly")
        pc = ksp.getPC()
        pc.setType("lu")
        pc.setFactorSolverType("mumps")
        ksp.setOperators(m.A)
        holder["ksp"] = ksp

    def lu_solve():
        holder["ksp"].setUp()
        holder["ksp"].solve(rhs, dx)

    res["lu_first+solve"] = best(lu_solve, rep, setup=new_ksp)

    # numeric refactorization only: new matrix values (state bump) handed to
    # the same KSP, as SNES does every Newton iteration
    def new_values():
        m.jacobian(None, x, m.A, m.A)   # (MatScale(1.0) is a no-op: no state bump)
        holder["ksp"].setOperators(m.A)

    res["lu_refactor+solve"] = best(lu_solve, rep, setup=new_values)
    res["solve_only"] = best(lambda: holder["ksp"].solve(rhs, dx), rep)
    res["lu_refactor"] = (res["lu_refactor+solve"][0] - res["solve_only"][0],
                          res["lu_refactor+solve"][1] - res["solve_only"][1])
    holder["ksp"].destroy()

    # --- one Newton iteration of the model's own SNES --------------------------
    s = Solver(m, dict(verbose=False))
    snes = s.snes
    snes.setTolerances(max_it=1)
    m.load_factor = 0.0

    def reset_x():
        x.copy(m.x)

    reset_x()
    snes.solve(None, m.x)   # warm-up: symbolic factorization, allocations
    res["newton_iteration"] = best(lambda: snes.solve(None, m.x), rep, setup=reset_x)
    its = snes.getIterationNumber()
    fevals = snes.getFunctionEvaluations()

    lu = res["lu_refactor+solve"][0]
    newton = res["newton_iteration"][0]
    composed = res["residual"][0] * 2 + res["jacobian"][0] + lu

    print(f"bundle: {args.fibres} fibres x {args.elements} quadratic elements = {n_el} elements, "
          f"{n_dofs} unknowns, nnz(A) = {int(nnz)}; model build+setup {t_build:.2f} s; "
          f"best of {rep}; {os.cpu_count()} cores, 1 MPI rank, {threads} element threads")
    print(f"{'operation':34s} {'best [ms]':>10s} {'median [ms]':>12s} {'elements/s':>12s}")
    for k, label in [("assemble_vector", "_cpp assemble_vector (C++ only)"),
                     ("residual", "model.residual (SNES callback)"),
                     ("assemble_matrix", "assemble_matrix (zero+C+++assembly)"),
                     ("jacobian", "model.jacobian (SNES callback)"),
                     ("lu_first+solve", "MUMPS LU first (symb+num) + solve"),
                     ("lu_refactor+solve", "MUMPS LU refactor (num) + solve"),
                     ("lu_refactor", "  of which numeric factorization"),
                     ("solve_only", "  of which triangular solves"),
                     ("newton_iteration", "one Newton iteration (SNES, max_it=1)")]:
        bt, md = res[k]
        per_element = k in ("assemble_vector", "residual", "assemble_matrix", "jacobian")
        eps = n_el / bt if per_element else None
        print(f"{label:34s} {1e3 * bt:10.2f} {1e3 * md:12.2f} "
              f"{(f'{eps:12.3e}' if eps else ''):>12s}")
    print()
    print(f"SNES iteration count {its}, function evaluations per solve {fevals}")
    sec = {k: v[0] for k, v in res.items()}   # best times
    print(f"residual callback / C++ assemble_vector      = "
          f"{sec['residual'] / sec['assemble_vector']:.2f}")
    print(f"jacobian callback / assemble_matrix          = "
          f"{sec['jacobian'] / sec['assemble_matrix']:.2f}")
    print(f"jacobian / residual                          = "
          f"{sec['jacobian'] / sec['residual']:.2f}")
    print(f"Newton iteration / (LU refactor + solve)     = {newton / lu:.2f}")
    print(f"Newton iteration / (LU first + solve)        = {newton / sec['lu_first+solve']:.2f}")
    print(f"(2 residuals + jacobian + LU refactor + solve) = {1e3 * composed:.2f} ms "
          f"vs measured Newton iteration {1e3 * newton:.2f} ms")
    print(f"share of a Newton iteration: assembly (2 r + J) "
          f"{100 * (2 * res['residual'][0] + res['jacobian'][0]) / newton:.0f}%, "
          f"LU + solve {100 * lu / newton:.0f}%")

    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "assembly_throughput.json"), "w") as fh:
        json.dump(dict(date=time.strftime("%Y-%m-%d %H:%M:%S %Z"), fibres=args.fibres,
                       elements_per_fibre=args.elements, elements=n_el, unknowns=n_dofs,
                       nnz=int(nnz), repeats=rep, cpus=os.cpu_count(), threads=threads,
                       best_seconds={k: v[0] for k, v in res.items()},
                       median_seconds={k: v[1] for k, v in res.items()},
                       newton_over_lu_solve=newton / lu), fh, indent=1)


if __name__ == "__main__":
    main()
