"""Newton iterations per load step, and what they cost: Newton variants side by side.

Cases (each run with every Newton variant of ``SolverOptions.newton``):

- **roll-up**: a cantilever (L/R = 1000, 32 quadratic elements) rolled into a
  full ring by an end moment in 16 load steps of pi/8;
- **buckled column**: a clamped-free column under 1.2 P_cr with a 1e-4 P_cr
  lateral force, load steps of 0.01 (the demo's set-up), post-buckling;
- **bundle**: the 61-fibre compressed bundle of ``contact_costs.py``
  (contact and friction), when that script is importable.

For each: Newton iterations per step (accepted steps), all iterations and
factorizations counted (failed attempts included, from the solver's
counters), Newton solves, wall time, and the answer (so that variants can be
compared: they must agree to the solver tolerance).

    .venv/bin/python benchmarks/newton_iterations.py [--quick]

Writes benchmarks/output/newton_iterations.json. A measurement, not a test.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np
from mpi4py import MPI

import textile
from textile import runtime

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "output")
E, NU = 1.0e9, 0.3
VARIANTS = ("standard", "mip")


def run(model, options, answer) -> dict:
    solver = textile.Solver(model, dict(verbose=False, **options))
    t0 = time.perf_counter()
    error = ""
    try:
        solver.solve()
    except textile.ConvergenceError as e:
        error = str(e)
    wall = time.perf_counter() - t0
    c = solver.counters
    its = [h.newton_iterations for h in solver.history]
    return dict(iterations_per_step=its, steps=len(its),
                mean_per_step=float(np.mean(its)) if its else None,
                max_per_step=max(its) if its else None,
                newton_iterations=c["newton_iterations"], newton_solves=c["newton_solves"],
                factorizations=c["factorizations"], failed_attempts=c["failed_attempts"],
                wall_seconds=wall, answer=answer(), error=error)


def rollup(newton: str, elements=32) -> dict:
    R, L = 1e-3, 1.0
    EI = E * np.pi * R ** 4 / 4
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, NU),
                                 num_elements=elements, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    model.add_end_moment(fib, -1, [0, 0, 2 * np.pi * EI / L])
    opts = dict(initial_step=1 / 16, max_step=1 / 16, newton=newton)
    # the ring closes: the tip is back at the clamp (REFERENCES.md 2)
    return run(model, opts, lambda: float(np.linalg.norm(model.centreline(fib)[-1]) / L))


def buckled_column(newton: str, elements=16) -> dict:
    R, L = 1e-3, 0.5
    EI = E * np.pi * R ** 4 / 4
    P = np.pi ** 2 * EI / (4 * L ** 2)
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, NU),
                                 num_elements=elements)
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    model.add_force(fib, -1, [-1.2 * P, 0, 1e-4 * 1.2 * P])
    opts = dict(initial_step=0.01, max_step=0.01, newton=newton)
    # lateral tip deflection w / L at 1.2 P_cr
    return run(model, opts, lambda: float(model.centreline(fib)[-1, 2] / L))


def bundle(newton: str, quick: bool) -> dict | None:
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    try:
        import contact_costs
    except ImportError:
        return None
    if not hasattr(contact_costs, "bundle_model"):
        return None
    model, answer, opts = contact_costs.bundle_model(3 if quick else 4, 6 if quick else 8)
    return run(model, dict(opts, newton=newton), answer)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller bundle")
    args = parser.parse_args()
    print(runtime.describe())
    results = {}
    cases = [("roll-up, pi/8 steps", rollup), ("buckled column, 0.01 steps", buckled_column),
             ("61-fibre bundle", lambda v: bundle(v, args.quick))]
    print(f"{'case':<28} {'newton':<9} {'steps':>5} {'its/step':>9} {'max':>4} {'all its':>8} "
          f"{'solves':>7} {'factor.':>8} {'failed':>7} {'wall [s]':>9}  answer")
    for name, fn in cases:
        for v in VARIANTS:
            r = fn(v)
            if r is None:
                continue
            results.setdefault(name, {})[v] = r
            print(f"{name:<28} {v:<9} {r['steps']:5d} {r['mean_per_step'] or 0:9.2f} "
                  f"{r['max_per_step'] or 0:4d} {r['newton_iterations']:8d} "
                  f"{r['newton_solves']:7d} {r['factorizations']:8d} {r['failed_attempts']:7d} "
                  f"{r['wall_seconds']:9.2f}  {r['answer']:.6e} {r['error'][:60]}", flush=True)
    os.makedirs(OUT, exist_ok=True)
    path = os.path.join(OUT, "newton_iterations.json")
    with open(path, "w") as f:
        json.dump(dict(date=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
                       blas=runtime.blas_info(), results=results), f, indent=1)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
