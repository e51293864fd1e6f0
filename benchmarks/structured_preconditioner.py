"""A preconditioner that follows the fabric's structure, against the full
factorization (issue 20 §3): one linear solve of a woven fabric's tangent.

Every large run spends 80-90% of its time in one full sparse factorization
per Newton iteration. The lever measured here: the yarns as subdomains,
each factorized exactly, coupled by a Krylov method on the exact tangent
(PETSc's PCASM with user subdomains: one per yarn, its fibres' unknowns;
one more for the rigid bodies' unknowns and multipliers), against MUMPS's
LU of the whole tangent (the solver's default on a frictional scene).

The scene: a plain weave of flat yarns woven as the weaving benchmark does
(``Weaving``, default options), its tangent assembled at the woven state.
The right-hand side is A x* for a random x* (so the error is known). Per
variant: setup (factorizations), solve, Krylov iterations, the error
|x - x*| / |x*| and the relative residual; for ASM the subdomains' sizes and
the mean factorization time of one subdomain (what refactorizing only the
subdomains whose contacts changed would cost each).

    .venv/bin/python benchmarks/structured_preconditioner.py [--yarns 4]
        [--fibres 7] [--spacing 2] [--overlap 0 1 2] [--rtol 1e-8]

One rank (user subdomains are per rank). Appends to
``output/structured_preconditioner.json``. A measurement, not a test.
"""
from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

import textile
from textile import runtime
from textile.fabric import Fabric, Weaving, Yarn

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "output")
R = 0.1e-3
MAT = textile.Material(5.0e9, 0.35)


def woven_tangent(yarns: int, fibres: int, spacing: float):
    """(A, one subdomain per yarn as index arrays, how many unknowns are not
    the fibres', fabric, weave seconds)."""
    yarn = Yarn(fibres, R, MAT, packing="layers 1")
    fabric = Fabric(yarn, num_warp=yarns, num_weft=yarns, spacing=spacing * yarn.width,
                    pattern="plain", elements_per_crossing=4)
    weaving = Weaving(fabric, comm=MPI.COMM_SELF)
    model = weaving.model
    t0 = time.perf_counter()
    textile.Solver(model, dict(verbose=False)).run(weaving.stages())
    weave_seconds = time.perf_counter() - t0
    model.jacobian(None, model.x, model.A, model.A)
    A = model.A
    n = A.getSize()[0]
    dofs = model.beam_global_dofs(constrained=True).reshape(-1, 9)
    first = model.mesh.first_node
    subdomains = []
    for k in range(fabric.num_yarns):
        fib = np.flatnonzero(fabric.fibre_yarn == k)
        rows = np.concatenate([dofs[first[f]:first[f + 1]].ravel() for f in fib])
        subdomains.append(np.sort(rows).astype(np.int32))
    # the rest (the yarn ends' bodies, their multipliers) joins the yarn it
    # couples to: a multiplier's row is empty on its diagonal, and a
    # subdomain needs the unknowns it constrains to be nonsingular
    owner = np.full(n, -1)
    for k, s in enumerate(subdomains):
        owner[s] = k
    rest = np.flatnonzero(owner < 0)
    for _ in range(3):          # multipliers couple to fibres, bodies to multipliers
        for i in rest[owner[rest] < 0]:
            cols, _ = A.getRow(int(i))
            known = owner[cols][owner[cols] >= 0]
            if len(known):
                owner[i] = np.bincount(known).argmax()
    owner[owner < 0] = 0     # held components: identity rows, coupled to nothing
    subdomains = [np.flatnonzero(owner == k).astype(np.int32) for k in range(len(subdomains))]
    return A, subdomains, len(rest), fabric, weave_seconds


def solve(A, b, x_true, configure) -> dict:
    ksp = PETSc.KSP().create(comm=MPI.COMM_SELF)
    ksp.setOperators(A)
    configure(ksp)
    x = b.duplicate()
    t0 = time.perf_counter()
    ksp.setUp()
    setup = time.perf_counter() - t0
    t0 = time.perf_counter()
    ksp.solve(b, x)
    solve_s = time.perf_counter() - t0
    r = b.duplicate()
    A.mult(x, r)
    r.axpy(-1.0, b)
    out = dict(setup_seconds=setup, solve_seconds=solve_s, iterations=ksp.getIterationNumber(),
               reason=int(ksp.getConvergedReason()),
               error=float((x - x_true).norm() / x_true.norm()),
               residual=float(r.norm() / b.norm()))
    ksp.destroy()
    return out


def full_lu(ksp):
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setType("lu")
    pc.setFactorSolverType("mumps")


def asm(subdomains, overlap, rtol):
    def configure(ksp):
        prefix = f"asm{overlap}_"
        opts = PETSc.Options()
        # each subdomain factorized exactly (the options reach the sub-solvers
        # before their set-up: no throw-away ILU)
        opts[f"{prefix}sub_ksp_type"] = "preonly"
        opts[f"{prefix}sub_pc_type"] = "lu"
        opts[f"{prefix}sub_pc_factor_mat_solver_type"] = "mumps"
        ksp.setOptionsPrefix(prefix)
        ksp.setType("gmres")
        ksp.setGMRESRestart(200)
        ksp.setTolerances(rtol=rtol, atol=0.0, max_it=1000)
        # right preconditioning: the test is on the true residual
        ksp.setPCSide(PETSc.PC.Side.RIGHT)
        pc = ksp.getPC()
        pc.setType("asm")
        pc.setASMType(PETSc.PC.ASMType.RESTRICT)
        sets = [PETSc.IS().createGeneral(s, comm=MPI.COMM_SELF) for s in subdomains]
        pc.setASMLocalSubdomains(len(sets), sets)
        pc.setASMOverlap(overlap)
        ksp.setFromOptions()
    return configure


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--yarns", type=int, default=4)
    p.add_argument("--fibres", type=int, default=7)
    p.add_argument("--spacing", type=float, default=2.0)
    p.add_argument("--overlap", type=int, nargs="*", default=[0, 1, 2])
    p.add_argument("--rtol", type=float, default=1e-8)
    args = p.parse_args()
    A, subdomains, others, fabric, weave_seconds = woven_tangent(
        args.yarns, args.fibres, args.spacing)
    n = A.getSize()[0]
    print(f"{args.yarns} x {args.yarns} plain weave of {args.fibres}-fibre flat yarns: "
          f"{n} unknowns, {A.getInfo()['nz_used']:.0f} nonzeros (woven in {weave_seconds:.1f} s)")
    rng = np.random.default_rng(0)
    x_true = A.createVecRight()
    x_true.setArray(rng.standard_normal(n))
    b = A.createVecLeft()
    A.mult(x_true, b)
    runs = {"full LU (MUMPS)": solve(A, b, x_true, full_lu)}
    for overlap in args.overlap:
        runs[f"GMRES + ASM, {len(subdomains)} yarns, overlap {overlap}"] = solve(
            A, b, x_true, asm(subdomains, overlap, args.rtol))
    for name, r in runs.items():
        print(f"{name:48s} setup {r['setup_seconds']:7.3f} s  solve {r['solve_seconds']:7.3f} s  "
              f"its {r['iterations']:4d}  error {r['error']:.1e}  residual {r['residual']:.1e}"
              f"  (reason {r['reason']})")
    os.makedirs(OUT, exist_ok=True)
    path = os.path.join(OUT, "structured_preconditioner.json")
    old = json.load(open(path)) if os.path.exists(path) else []
    old.append(dict(date=time.strftime("%Y-%m-%d %H:%M"), machine=runtime.describe(),
                    yarns=args.yarns,
                    fibres=args.fibres, spacing=args.spacing, unknowns=n,
                    subdomain_sizes=[len(s) for s in subdomains], other_unknowns=others,
                    weave_seconds=weave_seconds, rtol=args.rtol, runs=runs))
    with open(path, "w") as f:
        json.dump(old, f, indent=1)


if __name__ == "__main__":
    main()
