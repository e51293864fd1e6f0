"""Where weaving bundles stands: 2 x 2 plain weaves of hexagonal bundles.

Weaves a 2 x 2 plain weave of ``--fibres`` hexagonal bundles (R = 0.1 mm,
E = 5 GPa), ``--spacing`` yarn widths apart, with the default weaving scene
(:class:`textile.fabric.weaving.Weaving`) and, per case, the weaving stage's
``easy_iterations`` and an optional :class:`~textile.effects.ViscousDrag`
fading as (1 - s)^2 over the weaving stage. Prints and writes to
``output/weave_bundles.json`` how far each case got (load factor of the
stage that stopped, the error), its Newton iterations per step (failed
attempts counted in the solver's counters), the crossings in pattern order,
the largest penetration and the wall time. Bundles do not weave yet: the
figures say where they stop (benchmarks/README.md, "Bundles").

    .venv/bin/python benchmarks/weave_bundles.py [--fibres 3 7] [--spacing 2]
        [--easy 4 12] [--drag 0 1] [--relax]
"""
from __future__ import annotations

import argparse
import itertools
import json
import os
import time

from mpi4py import MPI

import textile
from textile.effects import ViscousDrag
from textile.fabric import Fabric, Weaving, Yarn

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "output")
R = 0.1e-3
MAT = textile.Material(5.0e9, 0.35)


def weave(fibres: int, spacing: float, easy: int, drag: float, relax: bool, comm,
          relaxation_steps: int = 1, make_up: bool = False) -> dict:
    yarn = Yarn(fibres, R, MAT, packing="hexagonal")
    fabric = Fabric(yarn, num_warp=2, num_weft=2, spacing=spacing * yarn.width,
                    pattern="plain", elements_per_crossing=4)
    weaving = Weaving(fabric, comm=comm, relaxation_steps=relaxation_steps)
    stages = weaving.stages()
    stages[0].solver.update(easy_iterations=easy)
    if make_up:
        stages[1].effects[weaving.contact]["make_up_penetrations"] = True
    if drag > 0:
        effect = ViscousDrag(drag)
        weaving.model.add_effect(effect)
        stages[0].effects[effect] = dict(coefficient=lambda s: drag * (1 - s) ** 2)
        stages[1].effects[effect] = dict(coefficient=0.0)
    solver = textile.Solver(weaving.model, dict(verbose=False))
    t0 = time.perf_counter()
    error = ""
    try:
        solver.run(stages if relax else stages[:1])
    except textile.ConvergenceError as e:
        error = str(e)
    wall = time.perf_counter() - t0
    summary = weaving.summary()
    counters = solver.counters
    return dict(fibres=fibres, spacing=spacing, easy_iterations=easy, drag=drag,
                relaxation=relax, relaxation_steps=relaxation_steps, make_up=make_up,
                stage=solver.history[-1].stage if solver.history else "",
                load_factor=float(weaving.model.load_factor), error=error[:300],
                wall_seconds=wall,
                newton_per_step=[h.newton_iterations for h in solver.history],
                newton_iterations=counters["newton_iterations"],
                failed_attempts=counters["failed_attempts"],
                crossings_in_order=int(summary["crossings in pattern order"]),
                crossings=int(summary["crossings"]),
                max_penetration_over_radius=float(summary["max penetration / radius"]))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fibres", type=int, nargs="+", default=[3, 7])
    p.add_argument("--spacing", type=float, default=2.0)
    p.add_argument("--easy", type=int, nargs="+", default=[4, 12])
    p.add_argument("--drag", type=float, nargs="+", default=[0.0, 1.0])
    p.add_argument("--relax", action="store_true", help="run the relaxation stage too")
    p.add_argument("--relaxation-steps", type=int, default=1)
    p.add_argument("--make-up", action="store_true",
                   help="the relaxation makes up the penetrations it starts with")
    args = p.parse_args()
    rows = []
    for fibres, easy, drag in itertools.product(args.fibres, args.easy, args.drag):
        row = weave(fibres, args.spacing, easy, drag, args.relax, MPI.COMM_SELF,
                    args.relaxation_steps, args.make_up)
        rows.append(row)
        print(f"{fibres} fibres, easy_iterations {easy}, drag {drag:g}: "
              f"{row['stage']} s={row['load_factor']:.3f}, "
              f"{row['newton_iterations']} Newton iterations "
              f"({row['failed_attempts']} failed attempts), "
              f"{row['crossings_in_order']}/{row['crossings']} crossings in order, "
              f"penetration {row['max_penetration_over_radius']:.3f} R, "
              f"{row['wall_seconds']:.1f} s{'; ' + row['error'][:120] if row['error'] else ''}",
              flush=True)
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "weave_bundles.json"), "w") as f:
        json.dump(dict(date=time.strftime("%Y-%m-%d"), runs=rows), f, indent=1)


if __name__ == "__main__":
    main()
