"""The virtual tests of a fabric alone on bundles: the 2 x 2 plain weave of
the main demo (``--fibres`` hexagonal bundles, R = 0.1 mm, E = 5 GPa, 2
yarn widths apart, lifting weave) woven once, then from its woven state
tension (1%), the paper's shear both ways (``--shear`` spacings), bending
and twisting (10 degrees), each in ``--steps`` steps, with friction
``--friction`` between yarns (0.2 within a bundle, the bundle default).

Prints and writes to ``output/virtual_tests_bundles_<fibres>.json`` per
test whether it reached its last step (or where it stopped and why), its
curve, its figures, Newton iterations and attempts per step, the solver's
counters, the side bodies' force balance and the wall time
(benchmarks/README.md, "Virtual tests on 7-fibre bundles").

    mpirun -n 2 .venv/bin/python benchmarks/virtual_tests_bundles.py [--fibres 7]
        [--steps 4] [--friction 0.2] [--tests tension shear bending twisting]
"""
from __future__ import annotations

import argparse
import json
import math
import os
import time

from mpi4py import MPI

import textile
from textile.fabric import Fabric, Yarn, woven_state
from textile.virtual_tests import Bending, IncompleteTest, Shear, Tension, Twisting

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "output")
R = 0.1e-3
MAT = textile.Material(5.0e9, 0.35)
TESTS = ("tension", "shear", "shear reversed", "bending", "twisting")


def build(name: str, fabric, woven: str, args, comm):
    options = dict(steps=args.steps, contact=dict(friction=args.friction),
                   solver_options=dict(verbose=False), comm=comm)
    if name == "tension":
        return Tension(fabric, woven, 0.01, **options)
    if name.startswith("shear"):
        sign = -1.0 if name.endswith("reversed") else 1.0
        return Shear(fabric, woven, sign * args.shear * fabric.spacing[0], **options)
    kind = Bending if name == "bending" else Twisting
    return kind(fabric, woven, math.radians(10.0), **options)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fibres", type=int, default=7)
    parser.add_argument("--steps", type=int, default=4)
    parser.add_argument("--friction", type=float, default=0.2)
    parser.add_argument("--shear", type=float, default=0.3, help="in yarn spacings")
    parser.add_argument("--tests", nargs="*", default=list(TESTS), choices=TESTS)
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    yarn = Yarn(args.fibres, R, MAT, packing="hexagonal")
    fabric = Fabric(yarn, num_warp=2, num_weft=2, spacing=2 * yarn.width, pattern="plain",
                    elements_per_crossing=4)
    os.makedirs(OUT, exist_ok=True)
    path = os.path.join(OUT, f"virtual_tests_bundles_{args.fibres}_woven.h5")
    t0 = time.perf_counter()
    woven_state(fabric, path, solver_options=dict(verbose=False), comm=comm)
    out = dict(fibres=args.fibres, ranks=comm.size, friction=args.friction, steps=args.steps,
               weave_seconds=time.perf_counter() - t0, tests={})
    for name in args.tests:
        test = build(name, fabric, path, args, comm)
        t0 = time.perf_counter()
        try:
            result, stopped = test.run(), None
        except IncompleteTest as error:
            result, stopped = error.result, str(error)
        out["tests"][name] = dict(
            finished=stopped is None, stopped=stopped, wall_seconds=time.perf_counter() - t0,
            curve=dict(x=result.curve.x, y=result.curve.y, xlabel=result.curve.xlabel,
                       ylabel=result.curve.ylabel),
            figures={k: v for k, v in result.figures.items() if isinstance(v, float)},
            steps=[dict(load_factor=s["load_factor"], newton_iterations=s["newton_iterations"],
                        attempts=s["attempts"]) for s in result.steps],
            force_balance=result.force_balance, counters=result.counters)
        if comm.rank == 0:
            r = out["tests"][name]
            its = [s["newton_iterations"] for s in r["steps"]]
            print(f"{name:<15} {'finished' if r['finished'] else 'STOPPED'}  "
                  f"{r['wall_seconds']:6.1f} s  Newton per step {its}  "
                  f"failed attempts {r['counters'].get('failed_attempts')}  "
                  + "  ".join(f"{k}: {v:.4g}" for k, v in r["figures"].items()), flush=True)
    if comm.rank == 0:
        print(f"weave {out['weave_seconds']:.1f} s ({comm.size} ranks)")
        with open(os.path.join(OUT, f"virtual_tests_bundles_{args.fibres}.json"), "w") as f:
            json.dump(out, f, indent=1, default=float)


if __name__ == "__main__":
    main()
