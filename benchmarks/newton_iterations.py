"""Newton iterations per load step, and what they cost, for every Newton variant.

Cases:

- **roll-up**: a cantilever (L/R = 1000, E = 1 GPa, nu = 0.3) rolled into a
  ring by an end moment in 16 load steps of pi/8 (16, 32, 64 quadratic
  elements; tests/beam/test_rollup.py, demos/demo_fibre_rollup.py); the
  answer is the tip's distance to the clamp over L (0 exactly);
- **buckled column**: a clamped-free column under 1.2 P_cr with a 1e-4 P_cr
  lateral force, steps of 0.01 and 0.005 (demos/demo_buckled_column.py);
  the answer is the tip rotation in degrees (67.8 on the stable branch);
- **bundle**: the 61-fibre compressed bundle of ``contact_costs.py`` (contact,
  friction 0.2, zone penalties adapted); the answer is the largest
  displacement.

- **squeezed bar**: a bar held straight (4 elements), its end pushed to
  stretch 0.724 in steps of 0.03 (displacement-driven, below the SVK limit
  point at 0.577); the answer is the spread of the element stretches (0 on
  the uniform, stable state; a localized state is unstable).

Variants: ``newton`` "standard" or "mip" (SolverOptions.newton) times
``predictor`` "auto", "secant", "parabola" or "none". For each: steps, Newton iterations per
step (mean, max), all Newton iterations and factorizations counted by the
solver (failed attempts included), Newton solves, failed attempts, wall
time, the answer. ``--history`` prints the residual history of one roll-up
step per variant.

    .venv/bin/python benchmarks/newton_iterations.py [--quick] [--history]

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
VARIANTS = [(n, p) for n in ("standard", "mip") for p in ("auto", "secant", "parabola", "none")]


def run(model, options, answer) -> dict:
    import warnings

    solver = textile.Solver(model, dict(verbose=False, **options))
    t0 = time.perf_counter()
    error = ""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # counted below instead
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
                wall_seconds=wall, answer=answer(), error=error,
                unstable_steps=sum(bool(h.stability.get("negative_eigenvalues"))
                                   for h in solver.history),
                histories=[h.residual_norms for h in solver.history])


def rollup(newton, predictor, elements=32) -> dict:
    R, L = 1e-3, 1.0
    EI = E * np.pi * R ** 4 / 4
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, NU),
                                 num_elements=elements, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    model.add_end_moment(fib, -1, [0, 0, 2 * np.pi * EI / L])
    opts = dict(initial_step=1 / 16, max_step=1 / 16, newton=newton, predictor=predictor)
    return run(model, opts, lambda: float(np.linalg.norm(model.centreline(fib)[-1]) / L))


def buckled_column(newton, predictor, step=0.01, elements=16) -> dict:
    R, L = 1e-3, 0.5
    EI = E * np.pi * R ** 4 / 4
    P = np.pi ** 2 * EI / (4 * L ** 2)
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, NU),
                                 num_elements=elements)
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    model.add_force(fib, -1, [-1.2 * P, 0, 1e-4 * 1.2 * P])
    opts = dict(initial_step=step, max_step=step, newton=newton, predictor=predictor)

    def tip_rotation():
        x = model.centreline(fib)
        t = x[-1] - x[-2]
        return float(np.degrees(np.arctan2(t[2], t[0])))

    return run(model, opts, tip_rotation)


def squeezed_bar(newton, predictor) -> dict:
    R, L = 1e-3, 0.05
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, NU),
                                 num_elements=4, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.fix(fib, 0, ["position", "g1x", "g1z", "g2x", "g2y"])
    for i in range(1, fib.num_nodes):
        model.fix(fib, i, ["y", "z"])
    model.fix(fib, -1, "x", -0.276 * L)
    opts = dict(initial_step=0.05, max_step=0.05, newton=newton, predictor=predictor)

    def spread():
        x = model.centreline(fib)[::2, 0]
        return float(np.ptp(np.diff(x)) / (L / 4))

    return run(model, opts, spread)


def bundle(newton, predictor, quick) -> dict:
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import contact_costs
    from textile.effects.fibre_contact import FibreContact

    rings, elements = (3, 6) if quick else (4, 8)
    spacing = 0.5 * 40 * contact_costs.R / elements
    contact = FibreContact(dict(penalty=1e6 / spacing, friction=0.2))
    model = contact_costs.bundle_model(rings, elements, contact)
    X = model.mesh.X_global
    opts = dict(initial_step=0.5, max_step=0.5, newton=newton, predictor=predictor)
    return run(model, opts, lambda: float(np.abs(model.nodal_unknowns() - X)[:, :3].max()))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer meshes, smaller bundle")
    parser.add_argument("--history", action="store_true", help="residual histories")
    args = parser.parse_args()
    print(runtime.describe())
    cases = [(f"roll-up {n} el.", (lambda n: lambda v, p: rollup(v, p, n))(n))
             for n in ((32,) if args.quick else (16, 32, 64))]
    cases += [(f"column, steps {s}", (lambda s: lambda v, p: buckled_column(v, p, s))(s))
              for s in (0.01, 0.005)]
    cases += [("squeezed bar", squeezed_bar)]
    cases += [("61-fibre bundle" if not args.quick else "37-fibre bundle",
               lambda v, p: bundle(v, p, args.quick))]
    results = {}
    print(f"{'case':<20} {'newton':<9} {'predictor':<9} {'steps':>5} {'its/step':>8} {'max':>4} "
          f"{'all its':>7} {'solves':>6} {'factor.':>7} {'failed':>6} {'unstab.':>7} "
          f"{'wall [s]':>8}  answer")
    for name, fn in cases:
        for newton, predictor in VARIANTS:
            r = fn(newton, predictor)
            results.setdefault(name, {})[f"{newton}/{predictor}"] = r
            print(f"{name:<20} {newton:<9} {predictor:<9} {r['steps']:5d} "
                  f"{r['mean_per_step'] or 0:8.2f} {r['max_per_step'] or 0:4d} "
                  f"{r['newton_iterations']:7d} {r['newton_solves']:6d} {r['factorizations']:7d} "
                  f"{r['failed_attempts']:6d} {r['unstable_steps']:7d} "
                  f"{r['wall_seconds']:8.2f}  {r['answer']:.6g} "
                  f"{r['error'][:50]}", flush=True)
            if args.history and name.startswith("roll-up") and len(r["histories"]) > 3:
                print("    step 4 residuals: " + " ".join(f"{v:.1e}" for v in r["histories"][3]))
    os.makedirs(OUT, exist_ok=True)
    path = os.path.join(OUT, "newton_iterations.json")
    for case in results.values():
        for r in case.values():
            r.pop("histories")
    with open(path, "w") as f:
        json.dump(dict(date=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
                       blas=runtime.blas_info(), results=results), f, indent=1)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
