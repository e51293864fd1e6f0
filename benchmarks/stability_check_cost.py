"""What the stability check costs against one Newton factorization.

The scene is composite_costs.py's (a neo-Hookean block with an n x n grid
of glass fibres tied by junctions, two side rigid bodies; --fibres 10:
about 105k unknowns), pulled by one load step, beside it a clamped-free
glass column of L/R = 1000 (32 elements) compressed to 1.39 times its
Euler load in the same step: load control leaves it straight, an unstable
state with 2 negative eigenvalues (branch switching off). At it each
part of the check is timed on the tangent the Newton solver factorized,
and compared with the mean time of the run's Newton LDL^T factorizations
(PETSc's event log):

- the inertia: the negative pivots of the Newton factorization (free);
- the search for zero-energy motions (textile.stability.zero_motions), which the
  solver runs only at steps with negative pivots; here forced, on every
  fibre's candidates (the fibres are held by junctions and rigid-body
  multipliers, not by constrained rows, so all of them are admissible);
- one solve with the factorization (the zero motions' pivots take one
  each);
- the critical modes of branch switching: Krylov-Schur (SLEPc) on the
  factorization's inverse, 2 modes, solves only.

    .venv/bin/python benchmarks/stability_check_cost.py [--fibres 10] [--cells 40]
    mpirun -n 2 .venv/bin/python benchmarks/stability_check_cost.py
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import time

import numpy as np
from mpi4py import MPI

import textile
from textile import runtime
from textile.stability.inertia import critical_modes, factor_negative_pivots, zero_motion_pivots
from textile.stability.zero_motions import zero_energy_motions

from composite_costs import E_F, NU, OUT, L, W, scene


def timed(comm, f):
    """(result, seconds of the slowest rank)."""
    comm.Barrier()
    t0 = time.perf_counter()
    out = f()
    return out, comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fibres", type=int, default=10, help="fibres per row (n x n)")
    parser.add_argument("--cells", type=int, default=40, help="matrix cells along L")
    parser.add_argument("--elements", type=int, default=40, help="elements per fibre")
    parser.add_argument("--solver", default="{}", help="SolverOptions as JSON")
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    os.makedirs(OUT, exist_ok=True)
    if comm.rank == 0:
        print(runtime.describe())
    radius = L / 1000
    column = textile.straight_fibre([0, -2 * W, 0], [L, -2 * W, 0], radius,
                                    textile.Material(E_F, NU), num_elements=32)
    model, right, _ = scene(comm, args.fibres, args.cells, args.elements, extra=[column])
    right.prescribe("x", 0.02 * L)
    model.clamp(column, 0)
    euler = np.pi ** 2 * E_F * np.pi * radius ** 4 / 4 / (4 * L ** 2)
    model.add_force(column, -1, [-1.39 * euler, 0, 0])
    options = dict(verbose=comm.rank == 0, initial_step=1.0, max_step=1.0,
                   branch_switching=False)
    options.update(json.loads(args.solver))
    solver = textile.Solver(model, options)
    solver.solve()
    c = solver.counters
    factorization = c["factorization_seconds"] / c["factorizations"]
    ksp = solver.snes.getKSP()
    pivots, t_inertia = timed(comm, lambda: factor_negative_pivots(ksp))
    negative = solver.history[-1].stability["negative_eigenvalues"]
    motions, t_search = timed(comm, lambda: zero_energy_motions(model, model.A))
    probe = model.A.createVecRight()
    probe.setRandom()
    _, t_solve = timed(comm, lambda: zero_motion_pivots(ksp.getPC(), [probe]))
    constrained = model.constrained_positions()
    (values, modes), t_modes = timed(comm, lambda: critical_modes(ksp, constrained, 2, comm))
    peak = comm.allreduce(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
                          op=MPI.MAX)
    if comm.rank != 0:
        return
    out = dict(date=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), blas=runtime.blas_info(),
               ranks=comm.size, args=vars(args), unknowns=int(model.A.getSize()[0]),
               fibres=len(model.mesh.fibres), factorizations=c["factorizations"],
               factorization_seconds=factorization, negative_pivots=pivots,
               negative_eigenvalues=negative,
               saddle_point_rows=model.saddle_point_rows,
               zero_motion_search_seconds=t_search, zero_motions_found=len(motions),
               solve_seconds=t_solve, critical_modes_seconds=t_modes,
               critical_modes_found=len(modes), critical_values=values,
               inertia_seconds=t_inertia, peak_memory_mib=peak)
    print(f"\n{comm.size} rank(s), {out['unknowns']} unknowns, {out['fibres']} fibres")
    print(f"Newton LDL^T factorization (mean of {c['factorizations']}): {factorization:.2f} s; "
          f"{pivots} negative pivots, {model.saddle_point_rows} of them multipliers', "
          f"{negative} negative eigenvalue(s)")
    for name, seconds in [("inertia (negative pivots)", t_inertia),
                          (f"zero-motion search ({len(motions)} found)", t_search),
                          ("one solve (per zero motion)", t_solve),
                          (f"critical modes ({len(modes)} of 2)", t_modes)]:
        print(f"  {name:<40} {seconds:8.3f} s  {seconds / factorization:6.3f} x")
    path = os.path.join(OUT, f"stability_check_cost_{comm.size}ranks.json")
    with open(path, "w") as f:
        json.dump(out, f, indent=1, default=float)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
