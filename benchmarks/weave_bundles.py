"""Weaving bundles: 2 x 2 plain weaves of bundles, by lifting
(heddles, the default for bundles) or by ordered contact (the paper's).

Weaves a 2 x 2 plain weave (``--yarns``, ``--pattern``) of ``--fibres``
bundles (``--packing``, hexagonal by default; R = 0.1 mm, E = 5 GPa;
``--twist`` turns per R), ``--spacing`` yarn widths (diameters, twisted)
apart. ``--method lifting``: the
lifting weave's three stages (:class:`textile.fabric.weaving.Weaving`).
``--method ordered``: the ordered weave, per case with the weaving stage's
``easy_iterations`` and an optional :class:`~textile.effects.ViscousDrag`
fading as (1 - s)^2 over the weaving stage, the relaxation optional (where
the ordered weave stops on bundles). Prints, and adds to
``output/weave_bundles.json`` (``--output``; with the date and arguments), how far
each case got (load factor of the stage that stopped, the error), its
Newton iterations per step (failed
attempts counted in the solver's counters), the crossings in pattern order,
the largest penetration, the crimp, the sections' height over width and the
wall time (benchmarks/README.md, "Bundles").

    .venv/bin/python benchmarks/weave_bundles.py --method lifting [--fibres 3 7]
        [--twist 0.016667 --drag 0.1 --newton-per-pass 0]
        [--yarns 4 --pattern "twill 2/2" --drag 0.1 --lifting-drag 0.1]
        [--fibres 19 --free-length 2 --pull fibre]
        [--fibres 28 --free-length 2 --pull fibre --amplitude 0.45 --drag 0.1
         --viscous-fading] [--spacing 1.5 --amplitude 0.45]
        [--solver newton=standard line_search=l2]
    .venv/bin/python benchmarks/weave_bundles.py [--fibres 3 7] [--spacing 2]
        [--easy 4 12] [--drag 0 1] [--relax]
"""
from __future__ import annotations

import argparse
import ast
import fcntl
import itertools
import json
import os
import sys
import time

from mpi4py import MPI

import textile
from textile.effects import ViscousDrag
from textile.fabric import Fabric, Weaving, Yarn

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "output")
R = 0.1e-3
MAT = textile.Material(5.0e9, 0.35)


def weave(fibres: int, spacing: float, easy: int, drag: float, relax: bool, comm,
          relaxation_steps: int = 1, make_up: bool = False, method: str = "ordered",
          free_length: float = 0.5, twist: float = 0.0, newton_per_pass=None,
          lifting_drag: float = 0.0, pattern: str = "plain", num: int = 2,
          pull: str = "yarn", verbose: bool = False, packing: str = "hexagonal",
          amplitude: float | None = None, viscous_fading: bool = False) -> dict:
    # a twisted yarn's fibres lie on helices: a clearance keeps neighbours apart
    yarn = Yarn(fibres, R, MAT, packing=packing, twist=twist / R,
                **({"clearance": 0.1} if twist else {}))
    across = yarn.diameter if twist else yarn.width
    fabric = Fabric(yarn, num_warp=num, num_weft=num, spacing=spacing * across,
                    pattern=pattern, elements_per_crossing=4,
                    free_length=free_length * spacing * across)
    # with a drag the fading stage ends the weave: no relaxation stage to count
    weaving = Weaving(fabric, comm=comm, relaxation_steps=None if drag > 0 else relaxation_steps,
                      method=method,
                      **(dict(drag=drag, lifting_drag=lifting_drag, viscous_fading=viscous_fading,
                              newton_per_pass=newton_per_pass, pull=pull)
                         if method == "lifting" else {}),
                      **({} if amplitude is None else dict(amplitude=amplitude)), **WEAVING)
    stages = weaving.stages()
    if method == "lifting":
        t0 = time.perf_counter()
        solver = textile.Solver(weaving.model, dict(verbose=verbose, **SOLVER))
        error = ""
        try:
            solver.run(stages)
        except textile.ConvergenceError as e:
            error = str(e)
        return _row(weaving, solver, error, time.perf_counter() - t0,
                    dict(fibres=fibres, spacing=spacing, method=method, free_length=free_length,
                         drag=drag, twist=twist, newton_per_pass=weaving.newton_per_pass,
                         lifting_drag=lifting_drag, pattern=pattern, yarns=num, pull=pull,
                         packing=packing, amplitude=amplitude, viscous_fading=viscous_fading,
                         **SOLVER, **WEAVING))
    stages[0].solver.update(easy_iterations=easy)
    if make_up:
        stages[1].effects[weaving.contact]["make_up_penetrations"] = True
    if drag > 0:
        effect = ViscousDrag(drag)
        weaving.model.add_effect(effect)
        stages[0].effects[effect] = dict(coefficient=lambda s: drag * (1 - s) ** 2)
        stages[1].effects[effect] = dict(coefficient=0.0)
    solver = textile.Solver(weaving.model, dict(verbose=verbose, **SOLVER))
    t0 = time.perf_counter()
    error = ""
    try:
        solver.run(stages if relax else stages[:1])
    except textile.ConvergenceError as e:
        error = str(e)
    return _row(weaving, solver, error, time.perf_counter() - t0,
                dict(fibres=fibres, spacing=spacing, method=method, easy_iterations=easy,
                     drag=drag, relaxation=relax, relaxation_steps=relaxation_steps,
                     make_up=make_up, free_length=free_length))


def _row(weaving, solver, error: str, wall: float, case: dict) -> dict:
    summary = weaving.summary()
    counters = solver.counters
    return dict(**case, stage=solver.history[-1].stage if solver.history else "",
                load_factor=float(weaving.model.load_factor), error=error[:300],
                wall_seconds=wall,
                newton_per_step=[h.newton_iterations for h in solver.history],
                newton_iterations=counters["newton_iterations"],
                failed_attempts=counters["failed_attempts"],
                crossings_in_order=int(summary["crossings in pattern order"]),
                crossings=int(summary["crossings"]),
                max_penetration_over_radius=float(summary["max penetration / radius"]),
                crimp=float(summary["warp crimp"]),
                height_over_width=float(summary["warp section height"]
                                        / summary["warp section width"]))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fibres", type=int, nargs="+", default=[3, 7])
    p.add_argument("--spacing", type=float, default=2.0)
    p.add_argument("--easy", type=int, nargs="+", default=[4, 12])
    p.add_argument("--drag", type=float, nargs="+", default=None,
                   help="drag coefficients (default 0 and 1 ordered, 0 lifting)")
    p.add_argument("--relax", action="store_true", help="run the relaxation stage too")
    p.add_argument("--relaxation-steps", type=int, default=1)
    p.add_argument("--make-up", action="store_true",
                   help="the relaxation makes up the penetrations it starts with")
    p.add_argument("--method", choices=("ordered", "lifting"), default="ordered",
                   help="ordered contact (the paper's) or lifting (heddles); lifting ignores "
                        "--easy, --relax and --make-up (it runs all its stages) and takes "
                        "--drag as Weaving's drag (default 0 there)")
    p.add_argument("--newton-per-pass", type=int, default=None,
                   help="lifting: Weaving's newton_per_pass (default its NEWTON_PER_PASS)")
    p.add_argument("--lifting-drag", type=float, default=0.0,
                   help="lifting: Weaving's lifting_drag")
    p.add_argument("--pull", choices=("yarn", "fibre"), default="yarn",
                   help="lifting: Weaving's pull (a pull body per yarn or per fibre)")
    p.add_argument("--pattern", default="plain", help="weave pattern (e.g. \"twill 2/2\")")
    p.add_argument("--verbose", action="store_true", help="one line per step (long runs)")
    p.add_argument("--yarns", type=int, default=2, help="yarns each way")
    p.add_argument("--viscous-fading", action="store_true",
                   help="lifting with a drag: the fading stage's drag a viscosity (Weaving's "
                        "viscous_fading)")
    p.add_argument("--amplitude", type=float, default=None,
                   help="lifting: the heddles' lift, in yarn heights (Weaving's amplitude, "
                        "default 0.55)")
    p.add_argument("--packing", default="hexagonal",
                   help="the yarns' packing (Yarn.packing: hexagonal, round, \"layers n\")")
    p.add_argument("--twist", type=float, default=0.0,
                   help="yarn twist, turns per fibre radius (e.g. 0.016667: a turn per 60 R)")
    p.add_argument("--free-length", type=float, default=None,
                   help="yarn tails beyond the outer crossings, in spacings (default 0.5, "
                        "1.0 for lifting)")
    p.add_argument("--solver", nargs="+", default=[], metavar="NAME=VALUE",
                   help="SolverOptions for every stage, e.g. newton=standard line_search=l2")
    p.add_argument("--weaving", nargs="+", default=[], metavar="NAME=VALUE",
                   help="other Weaving arguments, e.g. settling_steps=8")
    p.add_argument("--output", default=os.path.join(OUT, "weave_bundles.json"),
                   help="the JSON the rows are added to (default output/weave_bundles.json; "
                        "another for scratch runs, which then stay out of the record)")
    args = p.parse_args()
    for items, options in ((args.solver, SOLVER), (args.weaving, WEAVING)):
        for item in items:
            name, _, value = item.partition("=")
            try:
                options[name] = ast.literal_eval(value)
            except (ValueError, SyntaxError):
                options[name] = value     # a string: newton=standard
    free = args.free_length or (1.0 if args.method == "lifting" else 0.5)
    rows = []
    drags = args.drag or ([0.0, 1.0] if args.method == "ordered" else [0.0])
    cases = itertools.product(args.fibres, [0] if args.method == "lifting" else args.easy,
                              drags)
    for fibres, easy, drag in cases:
        row = weave(fibres, args.spacing, easy, drag, args.relax, MPI.COMM_SELF,
                    args.relaxation_steps, args.make_up, args.method, free, args.twist,
                    args.newton_per_pass, args.lifting_drag, args.pattern, args.yarns,
                    args.pull, args.verbose, args.packing, args.amplitude,
                    args.viscous_fading)
        rows.append(row)
        print(f"{fibres} fibres, {args.method}, easy_iterations {easy}, drag {drag:g}: "
              f"{row['stage']} s={row['load_factor']:.3f}, "
              f"{row['newton_iterations']} Newton iterations "
              f"({row['failed_attempts']} failed attempts), "
              f"{row['crossings_in_order']}/{row['crossings']} crossings in order, "
              f"penetration {row['max_penetration_over_radius']:.3f} R, "
              f"crimp {row['crimp']:.4f}, height/width {row['height_over_width']:.2f}, "
              f"{row['wall_seconds']:.1f} s{'; ' + row['error'][:120] if row['error'] else ''}",
              flush=True)
    record(rows, args.output)


#: solver options and other Weaving arguments given on the command line
#: (--solver, --weaving)
SOLVER: dict = {}
WEAVING: dict = {}


def record(rows: list[dict], path: str) -> None:
    """Add this run's rows, with its date and arguments, to ``path``
    (--output): earlier runs are kept (runs of hours are often started side
    by side; a lock keeps two finishing together from losing one)."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    stamp = dict(date=time.strftime("%Y-%m-%d %H:%M"), arguments=sys.argv[1:])
    with open(path + ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        runs = []
        if os.path.exists(path):
            try:
                with open(path) as f:
                    runs = json.load(f).get("runs", [])
            except (OSError, ValueError, AttributeError):
                runs = []     # unreadable (e.g. the old one-run format): start again
        runs += [dict(stamp, **row) for row in rows]
        with open(path + ".tmp", "w") as f:
            json.dump(dict(runs=runs), f, indent=1)
        os.replace(path + ".tmp", path)


if __name__ == "__main__":
    main()
