"""MUMPS scaling: the tangent scaled by its diagonal against MUMPS's own scaling.

``SolverOptions.scaling``: with "diagonal" (the default) MUMPS's LU
factorizations see the tangent scaled symmetrically by its diagonal and
scale nothing themselves; with "mumps" they see it unscaled and compute
their automatic (iterative row and column) scaling again at every numeric
factorization. This script weaves the same scene with each, in turn
(``--repeats`` pairs, the order alternating), on the ranks it is run with,
and prints, for each run, the Newton iterations, the LU factorizations and
their seconds (PETSc's event log, this rank), the solving time and the
largest distance between the two woven states (in yarn spacings).

Cases: ``demo`` (the main demo: 2 x 2 plain weave of 7-fibre bundles,
2 widths apart) and ``close`` (the same, 1.5 widths apart, amplitude 0.45).

    mpirun -n 2 .venv/bin/python benchmarks/mumps_scaling.py [--cases demo close]
        [--repeats 2]

Adds its runs, with date, machine and arguments, to
``benchmarks/output/mumps_scaling.json``. A measurement: it asserts nothing.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time

import numpy as np
from mpi4py import MPI

import textile
from textile.fabric import Fabric, Weaving, Yarn

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "output")
R = 0.1e-3
MAT = textile.Material(5.0e9, 0.35)
CASES = {"demo": dict(spacing=2.0), "close": dict(spacing=1.5, amplitude=0.45)}


def weave(case: str, scaling: str, comm) -> tuple[dict, np.ndarray, float]:
    """One woven state of ``case`` with ``scaling``: (figures, positions on
    every rank, spacing)."""
    c = CASES[case]
    yarn = Yarn(7, R, MAT, packing="hexagonal")
    fabric = Fabric(yarn, num_warp=2, num_weft=2, spacing=c["spacing"] * yarn.width,
                    pattern="plain", elements_per_crossing=4)
    weaving = Weaving(fabric, tension=1e-4, comm=comm,
                      **({"amplitude": c["amplitude"]} if "amplitude" in c else {}))
    t0 = time.perf_counter()
    solver = weaving.run(None, solver_options=dict(scaling=scaling, verbose=False))
    seconds = time.perf_counter() - t0
    counters = solver.counters
    summary = weaving.summary()
    row = dict(case=case, scaling=scaling, ranks=comm.size, solve_seconds=seconds,
               newton_iterations=int(counters["newton_iterations"]),
               failed_attempts=int(counters["failed_attempts"]),
               steps=len(solver.history),
               lu_factorizations=int(counters["lu_factorizations"]),
               lu_factorization_seconds=float(counters["lu_factorizations_seconds"]),
               crossings_in_order=int(summary["crossings in pattern order"]),
               crossings=int(summary["crossings"]),
               max_penetration_over_radius=float(summary["max penetration / radius"]),
               crimp=float(summary["warp crimp"]))
    return row, weaving.model.nodal_unknowns()[:, 0:3], float(fabric.spacing[0])


def machine() -> dict:
    cpu = [line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo")
           if line.startswith("model name")] if os.path.exists("/proc/cpuinfo") else []
    return dict(uname=" ".join(platform.uname()), cpu=cpu[0] if cpu else platform.processor(),
                cpus=os.cpu_count(), blas_threads=os.environ.get("OPENBLAS_NUM_THREADS", ""))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cases", nargs="+", choices=sorted(CASES), default=["demo", "close"])
    p.add_argument("--repeats", type=int, default=1, help="pairs of runs per case")
    args = p.parse_args()
    comm = MPI.COMM_WORLD
    rows = []
    for case in args.cases:
        states = {}
        for k in range(args.repeats):
            order = ("mumps", "diagonal") if k % 2 == 0 else ("diagonal", "mumps")
            for scaling in order:
                row, q, spacing = weave(case, scaling, comm)
                states[scaling] = q
                rows.append(row)
                if comm.rank == 0:
                    print(f"{case:6s} {scaling:8s} {comm.size} rank(s): "
                          f"{row['newton_iterations']} Newton iterations "
                          f"({row['failed_attempts']} failed attempts, {row['steps']} steps), "
                          f"{row['lu_factorizations']} LU factorizations "
                          f"{row['lu_factorization_seconds']:.2f} s, solving "
                          f"{row['solve_seconds']:.2f} s; "
                          f"{row['crossings_in_order']}/{row['crossings']} in order, "
                          f"penetration {row['max_penetration_over_radius']:.4f} R, "
                          f"crimp {row['crimp']:.5f}", flush=True)
        apart = float(np.abs(states["mumps"] - states["diagonal"]).max() / spacing)
        for row in rows:
            if row["case"] == case:
                row["states_apart_spacings"] = apart
        if comm.rank == 0:
            print(f"{case}: the woven states {apart:.2e} spacings apart", flush=True)
    if comm.rank == 0:
        os.makedirs(OUT, exist_ok=True)
        path = os.path.join(OUT, "mumps_scaling.json")
        runs = []
        if os.path.exists(path):
            with open(path) as f:
                runs = json.load(f).get("runs", [])
        stamp = dict(date=time.strftime("%Y-%m-%d %H:%M"), machine=machine(),
                     arguments=sys.argv[1:])
        runs += [dict(stamp, **row) for row in rows]
        with open(path, "w") as f:
            json.dump(dict(runs=runs), f, indent=1)
        print(f"written {path}")


if __name__ == "__main__":
    main()
