"""Every contact-loop attempt of a run, pass by pass: Newton iterations,
the effects' change after each pass (in units of their tolerance) and the
relaxation factors (SolverOptions.loop_relaxation).

    python benchmarks/contact_loop_passes.py [--stop-at S] [--name NAME] -- script.py [args...]

runs a benchmark script (e.g. ``virtual_tests_sample.py``) with
:meth:`textile.solver.contact_loop.ContactLoop.step_to` wrapped: rank 0
prints one ``PASSES`` line an attempt and the totals (every Newton
iteration, failed attempts' too), and writes them to
``output/contact_loop_passes_<NAME>.json``. ``--stop-at S``: stop once a
step of a stage beyond load factor S (and before its end) has converged
(a partial run, compared with another by the totals through one load
factor). ``--from-log LOG``: the JSON from the ``PASSES`` lines of a
log written before (``--through S ...``: its totals through the first
converged step at or beyond each S).
"""
from __future__ import annotations

import argparse
import json
import os
import re
import runpy
import sys
import time

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "output")
LINE = re.compile(r"PASSES t=(\S+) ok=(\d) its=(\d+)(.*?)(?: W(?: (.*))?)?$")


def record(t: float, attempt) -> dict:
    return dict(load_factor=t, converged=bool(attempt.converged), iterations=attempt.iterations,
                passes=[[i, c if c != float("inf") else None] for i, c in attempt.passes],
                relaxation=list(getattr(attempt, "relaxation", [])))


def line(r: dict) -> str:
    passes = " ".join(f"{i}:{c:.3g}" if c is not None else f"{i}:inf" for i, c in r["passes"])
    factors = " ".join(f"{w:.2f}" for w in r["relaxation"])
    return (f"PASSES t={r['load_factor']:.6f} ok={int(r['converged'])} its={r['iterations']} "
            f"{passes} W {factors}")


def totals(attempts: list[dict]) -> dict:
    failed = [a for a in attempts if not a["converged"]]
    return dict(attempts=len(attempts), converged_steps=len(attempts) - len(failed),
                newton_iterations=sum(a["iterations"] for a in attempts),
                failed_attempts=len(failed),
                failed_iterations=sum(a["iterations"] for a in failed))


def through(attempts: list[dict], load_factor: float) -> dict:
    """The totals of the attempts up to the first converged step at or
    beyond ``load_factor`` (of a stage, before its end)."""
    for k, a in enumerate(attempts):
        if a["converged"] and load_factor <= a["load_factor"] < 1 - 1e-9:
            return dict(totals(attempts[:k + 1]), through=a["load_factor"])
    return dict(totals(attempts), through=None)


def write(name: str, attempts: list[dict], meta: dict) -> str:
    os.makedirs(OUT, exist_ok=True)
    path = os.path.join(OUT, f"contact_loop_passes_{name}.json")
    with open(path, "w") as f:
        json.dump(dict(meta, totals=totals(attempts), attempts=attempts), f, indent=1)
    return path


def from_log(log: str) -> list[dict]:
    attempts = []
    with open(log) as f:
        for text in f:
            m = LINE.match(text.strip())
            if not m:
                continue
            passes = []
            for item in m[4].split():
                i, c = item.split(":")
                passes.append([int(i), None if c == "inf" else float(c)])
            attempts.append(dict(load_factor=float(m[1]), converged=m[2] == "1",
                                 iterations=int(m[3]), passes=passes,
                                 relaxation=[float(w) for w in (m[5] or "").split()]))
    return attempts


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stop-at", type=float, default=None)
    parser.add_argument("--name", default=None, help="the JSON's name (default: the script's)")
    parser.add_argument("--from-log", default=None)
    parser.add_argument("--through", type=float, nargs="*", default=[],
                        help="print the totals through the first converged step at or beyond "
                             "each of these load factors")
    parser.add_argument("script", nargs=argparse.REMAINDER)
    args = parser.parse_args()
    script = [a for a in args.script if a != "--"]
    meta = dict(date=time.strftime("%Y-%m-%d %H:%M"), command=" ".join(sys.argv))
    if args.from_log:
        attempts = from_log(args.from_log)
        name = args.name or os.path.basename(args.from_log).removesuffix(".log")
        print(f"{len(attempts)} attempts: {totals(attempts)}; wrote {write(name, attempts, meta)}")
        for load_factor in args.through:
            print(f"through {load_factor}: {through(attempts, load_factor)}")
        return
    if not script:
        parser.error("give a script to run (after --)")
    from mpi4py import MPI

    import textile
    from textile.solver import contact_loop
    rank0 = MPI.COMM_WORLD.rank == 0
    name = args.name or os.path.basename(script[0]).removesuffix(".py")
    meta.update(ranks=MPI.COMM_WORLD.size, runtime=textile.runtime.describe())
    attempts, start = [], time.perf_counter()
    step_to = contact_loop.ContactLoop.step_to

    def logged(self, t, *a, **k):
        attempt = step_to(self, t, *a, **k)
        attempts.append(record(t, attempt))
        if rank0:
            print(line(attempts[-1]), flush=True)
        if args.stop_at is not None and attempt.converged and args.stop_at < t < 1 - 1e-9:
            if rank0:
                meta.update(stopped_at=t, seconds=time.perf_counter() - start)
                print(f"stopped at {t:.6f}: {totals(attempts)}; wrote "
                      f"{write(name, attempts, meta)}", flush=True)
            MPI.COMM_WORLD.Barrier()
            MPI.COMM_WORLD.Abort(0) if MPI.COMM_WORLD.size > 1 else os._exit(0)
        return attempt

    contact_loop.ContactLoop.step_to = logged
    sys.argv = script
    try:
        runpy.run_path(script[0], run_name="__main__")
    finally:
        if rank0:
            meta.update(seconds=time.perf_counter() - start)
            print(f"{totals(attempts)}; wrote {write(name, attempts, meta)}", flush=True)


if __name__ == "__main__":
    main()
