"""The paper's virtual tests on its 336-fibre sample (docs/method.md §10).

Starts from the woven state ``weave_sample.py`` saved (6 x 6 flat yarns of
28 fibres, plain weave, 2 yarn widths apart; give ``--woven`` for another;
``--fibres`` and ``--packing`` name a sample of other yarns, e.g. 7-fibre
hexagonal bundles, whose woven state, figures and curves carry their
fibre count and packing: ``output/virtual_tests_sample_7_hexagonal.json``)
and runs

- **shear** (the paper's set-up, no matrix): 30 steps; side xmax moved along
  y by ``--shear`` yarn spacings;
- **bending** and **twisting** (with matrix): 15 steps each, opposite
  rotations of sides xmin and xmax by ``--angle`` degrees in all;

printing per step the wall time and Newton iterations beside the paper's
figures (6 processors: about 2 h a step without matrix, 3 h with it; 30-40
global iterations a step), and where the time goes: contact detection
(FibreContact.prepare/update), assembly per effect (residual and tangent),
factorizations and solves (PETSc's event log), the rest. Written to
``output/virtual_tests_sample.json`` after every step (a long run stopped
later keeps what it did; tests not run again keep their earlier entry).

    mpirun -n 2 .venv/bin/python benchmarks/virtual_tests_sample.py
        [--tests shear bending twisting] [--steps-shear 30] [--steps-rotation 15]
        [--fibres 7 --packing hexagonal] [--free-length 2] [--checkpoint | --resume]
        [--solver '{"low_rank_tolerance": 1e-8, "branch_switching": false,
                    "describe_instability": true}']

Run the composite tests one per invocation on the 336-fibre sample: each
holds 7-12 GB a rank (benchmarks/README.md), and a second test in the same process starts
before the first one's scene is freed (the twisting after the bending was
killed for memory at 12.5 GB on rank 0, 2026-12-01). The stability check
is on in every test (its default): it reads the inertia of the Newton
factorization and factorizes the tangent at the solution where Newton's
last factorization was not at it. Branch switching is off by default
here (``--solver``'s default): on the composite its perturbed solves ran
past 13 minutes without an answer (benchmarks/README.md); a step that
loses stability is warned about and its critical mode computed and
recorded instead (``describe_instability``: one SLEPc eigen-solve, with
the mode checked against the assembled tangent). Each step's record
carries its counters (factorizations, the check's own seconds, the
eigen-solve's, branch switching's) and the check's findings: negative
eigenvalues, the critical mode: benchmarks/README.md, "Twisting of the
336-fibre composite with the stability check on".
"""
from __future__ import annotations

import argparse
import json
import math
import os
import resource
import time

from mpi4py import MPI

import textile
from textile import runtime
from textile.effects.fibre_contact import FibreContact
from textile.fabric import Fabric, Yarn
from textile.virtual_tests import Bending, IncompleteTest, Shear, Twisting

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "output")
R = 0.1e-3
FIBRE = textile.Material(5.0e9, 0.35)    # as weave_sample.py
MATRIX = textile.Material(3.0e9, 0.35)   # an epoxy
PAPER = {"shear": dict(hours_per_step=2.0, steps=30, newton_per_step="30-40"),
         "bending": dict(hours_per_step=3.0, steps=15, newton_per_step="30-40"),
         "twisting": dict(hours_per_step=3.0, steps=15, newton_per_step="30-40")}
#: the solver counters recorded per step (textile.Solver.counters)
STEP_COUNTERS = ("newton_iterations", "newton_solves", "factorizations", "factorization_seconds",
                 "linear_solves_seconds", "stability_check_seconds", "factorizations_at_solution",
                 "zero_motion_searches", "zero_motion_seconds", "branch_switches",
                 "branch_attempts",
                 "branch_switch_seconds", "eigen_solve_seconds")


class DetectionClock:
    """Wall time spent in FibreContact.prepare and update (detection)."""

    def __init__(self):
        self.seconds = 0.0
        self._originals = {}

    def __enter__(self):
        for name in ("prepare", "update"):
            original = getattr(FibreContact, name)
            self._originals[name] = original

            def timed(effect, *args, _original=original, **kwargs):
                t0 = time.perf_counter()
                try:
                    return _original(effect, *args, **kwargs)
                finally:
                    self.seconds += time.perf_counter() - t0
            setattr(FibreContact, name, timed)
        return self

    def __exit__(self, *exc):
        for name, original in self._originals.items():
            setattr(FibreContact, name, original)


def sample_suffix(fibres: int, packing: str, yarns: int = 6) -> str:
    """'' for the 6 x 6 flat-row sample, else its yarns' fibre count and
    packing and, other than 6 x 6, its size (as weave_sample.woven_name: a
    4 x 4 sample's results went into the 6 x 6 one's file)."""
    suffix = "" if (fibres, packing) == (28, "layers 1") else \
        f"_{fibres}_{packing.replace(' ', '')}"
    return suffix + (f"_{yarns}x{yarns}" if yarns != 6 else "")


def run_test(name: str, fabric, woven: str, steps: int, args, comm, progress,
             earlier_rows: list | None = None) -> dict:
    """One test; ``earlier_rows``: the per-step rows of the run a
    ``--resume`` goes on from."""
    L = fabric.spacing[0]
    suffix = sample_suffix(args.fibres, args.packing, args.yarns)
    checkpoint = os.path.join(OUT, f"virtual_tests_sample{suffix}_{name}_checkpoint") \
        if args.checkpoint or args.resume else None
    options = dict(steps=steps, solver_options=dict(args.solver, verbose=comm.rank == 0),
                   checkpoint=checkpoint, comm=comm)
    if name == "shear":
        test = Shear(fabric, woven, args.shear * L, settle_drag=args.settle_drag, **options)
    else:
        kind = Bending if name == "bending" else Twisting
        test = kind(fabric, woven, math.radians(args.angle), matrix=MATRIX,
                    composite=dict(size=args.matrix_size * R), release_steps=2, **options)
    model = test.sample.model
    error = ""
    # every step's figures go to the JSON at once: a long run stopped later
    # keeps what it did
    started = time.perf_counter()
    done = list(earlier_rows or [])

    counted = {}

    def on_step(solver, rec):
        # collective (every rank calls on_step): each rank's peak memory so far
        rss = comm.gather(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
        # what this step cost, from the solver's counters (failed attempts
        # and the stability check included)
        now = {k: solver.counters[k] for k in STEP_COUNTERS}
        cost = {k: v - counted.get(k, 0) for k, v in now.items()}
        counted.update(now)
        # a resumed run: rows of the stopped run from this step on were not
        # kept in its checkpoint (stopped between the two writes)
        done[:] = [r for r in done if r["step"] < rec.step]
        done.append(dict(step=rec.step, stage=rec.stage, load_factor=rec.load_factor,
                         newton_iterations=rec.newton_iterations, attempts=rec.attempts,
                         wall_seconds=rec.wall_time,
                         elapsed_seconds=time.perf_counter() - started,
                         peak_rss_mib_ranks=rss, stability=rec.stability, counters=cost))
        progress(dict(test=name, unfinished=True, steps_so_far=done))
    test.on_step = on_step
    with DetectionClock() as detection:
        t0 = time.perf_counter()
        try:
            result = test.run(resume=args.resume)
        except IncompleteTest as e:
            # the steps done still count (figures of that range)
            error, result = str(e), e.result
        wall = time.perf_counter() - t0
    assembly = {f"{effect} {kind}": seconds
                for (effect, kind), seconds in sorted(model.effect_seconds.items())}
    if result is not None:
        wall = result.wall_seconds   # a resumed run's earlier part included
    out = dict(test=name, steps_asked=steps, unknowns=int(model.A.getSize()[0]),
               fibres=len(model.mesh.fibres), wall_seconds=wall, error=error,
               resumed=bool(args.resume),
               paper=PAPER[name], detection_seconds=detection.seconds,
               assembly_seconds=assembly)
    if result is not None:
        c = result.counters
        steps_out = [dict(step=s["step"], load_factor=s["load_factor"],
                          newton_iterations=s["newton_iterations"], attempts=s["attempts"],
                          wall_seconds=s["wall_seconds"], x=s["x"], y=s["y"],
                          force_balance=s["force_balance"]) for s in result.steps]
        out.update(curve=dict(x=result.curve.x, y=result.curve.y, xlabel=result.curve.xlabel,
                              ylabel=result.curve.ylabel),
                   figures=result.figures, steps=steps_out, counters=c,
                   factorization_seconds=c["factorization_seconds"],
                   solve_seconds=c["linear_solves_seconds"],
                   newton_iterations=c["newton_iterations"],
                   newton_per_step=c["newton_iterations"] / max(len(steps_out), 1))
        if comm.rank == 0:
            result.write(os.path.join(OUT, f"virtual_tests_sample{suffix}_{name}"))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--woven", default=None,
                        help="woven state (default: weave_sample.py's plain weave of these "
                             "yarns)")
    parser.add_argument("--tests", nargs="+", default=["shear", "bending", "twisting"])
    parser.add_argument("--fibres", type=int, default=28)
    parser.add_argument("--packing", default="layers 1",
                        help="the yarns' packing, as weave_sample.py's")
    parser.add_argument("--settle-drag", type=float, default=0.0,
                        help="the shear's first stage with a drag faded out (Sample's "
                             "settle_drag; not needed since bundles' free end bodies keep "
                             "their orientation)")
    parser.add_argument("--yarns", type=int, default=6)
    parser.add_argument("--elements", type=int, default=4)
    parser.add_argument("--spacing", type=float, default=2.0, help="in yarn widths")
    parser.add_argument("--free-length", type=float, default=None,
                        help="yarn tails beyond the outer crossings, in spacings, as "
                             "weave_sample.py's (default: Fabric's)")
    parser.add_argument("--steps-shear", type=int, default=30)
    parser.add_argument("--steps-rotation", type=int, default=15)
    parser.add_argument("--shear", type=float, default=0.2,
                        help="shear displacement of side xmax, in yarn spacings")
    parser.add_argument("--angle", type=float, default=10.0,
                        help="bending / twist angle in all (degrees)")
    parser.add_argument("--matrix-size", type=float, default=8.0,
                        help="matrix element size in fibre radii")
    parser.add_argument("--solver", type=json.loads,
                        default={"low_rank_tolerance": 1e-8, "branch_switching": False,
                                 "describe_instability": True})
    parser.add_argument("--checkpoint", action="store_true",
                        help="keep each test's state and rows after every step "
                             "(output/virtual_tests_sample<suffix>_<test>_checkpoint.h5 / .json)")
    parser.add_argument("--resume", action="store_true",
                        help="go on from each test's checkpoint (an earlier --checkpoint run's; "
                             "the steps, counters and wall time count both runs, the detection "
                             "and assembly seconds the resumed part's only)")
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    if comm.rank == 0:
        print(runtime.describe())
    suffix = sample_suffix(args.fibres, args.packing, args.yarns)
    if args.woven is None:
        args.woven = os.path.join(OUT, f"weave_sample_plain{suffix}.h5")
    if not os.path.exists(args.woven):
        raise SystemExit(f"{args.woven}: no woven state; run weave_sample.py first")
    yarn = Yarn(args.fibres, R, FIBRE, packing=args.packing)
    fabric = Fabric(yarn, num_warp=args.yarns, num_weft=args.yarns,
                    spacing=args.spacing * yarn.width, pattern="plain",
                    elements_per_crossing=args.elements,
                    free_length=None if args.free_length is None
                    else args.free_length * args.spacing * yarn.width)
    path = os.path.join(OUT, f"virtual_tests_sample{suffix}.json")
    # tests run before (another day, another invocation) stay in the file
    # unless run again; each test carries its own date and machine
    kept, unfinished = [], {}
    if comm.rank == 0 and os.path.exists(path):
        with open(path) as f:
            before = json.load(f)
        kept = [dict(dict(date=before.get("date"), machine=before.get("machine"),
                          ranks=before.get("ranks")), **t)
                for t in before.get("tests", []) if t.get("test") not in args.tests]
        # the rows of a stopped run that --resume goes on from
        unfinished = {t["test"]: t.get("steps_so_far", []) for t in before.get("tests", [])
                      if t.get("unfinished")}
    kept, unfinished = comm.bcast((kept, unfinished))
    results = dict(woven=args.woven, tests=kept)
    for name in args.tests:
        steps = args.steps_shear if name == "shear" else args.steps_rotation

        def progress(partial, _done=list(results["tests"])):
            if comm.rank == 0:
                os.makedirs(OUT, exist_ok=True)
                with open(path, "w") as f:
                    json.dump(dict(results, tests=_done + [partial]), f, indent=1, default=float)
        out = run_test(name, fabric, args.woven, steps, args, comm, progress,
                       unfinished.get(name) if args.resume else None)
        out["peak_rss_mib_ranks"] = comm.gather(
            resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
        out.update(date=time.strftime("%Y-%m-%d"), machine=runtime.describe(), ranks=comm.size)
        results["tests"].append(out)
        if comm.rank == 0:
            paper = PAPER[name]
            print(f"\n{name}: {out['wall_seconds']:.0f} s for {len(out.get('steps', []))} of "
                  f"{steps} steps ({out['unknowns']} unknowns)"
                  f"{' FAILED: ' + out['error'] if out['error'] else ''}")
            for s in out.get("steps", []):
                print(f"  step {s['step']:3d}  newton {s['newton_iterations']:3d}  "
                      f"{s['wall_seconds']:7.1f} s   (paper: ~{paper['hours_per_step']:.0f} h, "
                      f"{paper['newton_per_step']} iterations)")
            print(f"  detection {out['detection_seconds']:.0f} s, factorizations "
                  f"{out.get('factorization_seconds', 0):.0f} s, solves "
                  f"{out.get('solve_seconds', 0):.0f} s, assembly "
                  f"{sum(out['assembly_seconds'].values()):.0f} s")
            os.makedirs(OUT, exist_ok=True)
            with open(path, "w") as f:
                json.dump(results, f, indent=1, default=float)


if __name__ == "__main__":
    main()
