"""Newton iterations per load step: standard versus MIP Newton.

Two paths with large rotations:

(a) roll-up: a cantilever (L=1, R=1e-3, E=1e9, nu=0.3) rolled into a ring by
    the end moment M = 2 pi E I / L in fixed load steps of 1/16 (rotation
    pi/8 a step), as tests/beam/test_rollup.py and demos/demo_fibre_rollup.py;
(b) post-buckling of the clamped-free column of demos/demo_buckled_column.py
    (L=0.5, 1.2 Euler loads, lateral perturbation 1e-4) in fixed steps.

For every mesh, predictor ("secant", "none") and Newton variant
("standard", "mip") it prints the Newton iterations per step (mean, max),
their total, the wall time, the final tip error (roll-up) or the tip
rotation reached at 1.2 P_e (column: ~67.8 degrees on the stable branch,
near 0 on the unstable mirror one), and writes
benchmarks/output/newton_variants.json. A measurement script, not a test.

    .venv/bin/python benchmarks/newton_variants.py [--quick] [--history]
"""
from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np
from mpi4py import MPI

import textile

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "output")


def rollup(num_elements, newton, predictor, step=1 / 16):
    E, nu, R, L = 1e9, 0.3, 1e-3, 1.0
    I = np.pi * R ** 4 / 4
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, nu),
                                 num_elements=num_elements, section_vector=[0, 1, 0])
    m = textile.Model(fib, comm=MPI.COMM_SELF)
    m.clamp(fib, 0)
    m.add_end_moment(fib, -1, [0, 0, 2 * np.pi * E * I / L])
    s = textile.Solver(m, dict(initial_step=step, max_step=step, newton=newton,
                               predictor=predictor, verbose=False))
    t0 = time.perf_counter()
    s.solve(1.0)
    wall = time.perf_counter() - t0
    # the ring closes: the tip is back at the clamp
    return s.history, wall, float(np.linalg.norm(m.centreline(fib)[-1]) / L)


def column(num_elements, newton, predictor, step):
    E, nu, R, L = 1.0e9, 0.3, 1e-3, 0.5
    P_e = np.pi ** 2 * E * (np.pi * R ** 4 / 4) / (4 * L ** 2)
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, nu),
                                 num_elements=num_elements, section_vector=[0, 1, 0])
    m = textile.Model(fib, comm=MPI.COMM_SELF)
    m.clamp(fib, 0)
    m.add_force(fib, -1, [-1.2 * P_e, 0, 1e-4 * P_e])
    s = textile.Solver(m, dict(initial_step=step, max_step=step, newton=newton,
                               predictor=predictor, verbose=False))
    t0 = time.perf_counter()
    s.solve(1.0)
    wall = time.perf_counter() - t0
    _, g2 = m.section_vectors(fib)
    return s.history, wall, float(np.degrees(np.arctan2(-g2[-1, 0], g2[-1, 2])))


def summary(history, select=None):
    its = np.array([h.newton_iterations for h in history
                    if select is None or select(h)])
    return dict(steps=len(history), attempts=int(sum(h.attempts for h in history)),
                mean=float(its.mean()), max=int(its.max()), total=int(its.sum()))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="one mesh per case")
    ap.add_argument("--history", action="store_true",
                    help="print the residual norms of the first steps of the 32-element roll-up")
    args = ap.parse_args(argv)
    meshes = [32] if args.quick else [16, 32, 64]
    rows = []
    print(f"{'case':8s} {'elems':>5s} {'predictor':>9s} {'newton':>8s} {'steps':>5s} "
          f"{'its/step':>8s} {'max':>4s} {'total':>5s} {'wall[s]':>8s}  result")
    for n in meshes:
        for predictor in ("secant", "none"):
            for newton in ("standard", "mip"):
                hist, wall, err = rollup(n, newton, predictor)
                r = dict(case="rollup", elements=n, predictor=predictor, newton=newton,
                         wall=wall, tip_error=err, **summary(hist))
                rows.append(r)
                print(f"{'rollup':8s} {n:5d} {predictor:>9s} {newton:>8s} {r['steps']:5d} "
                      f"{r['mean']:8.2f} {r['max']:4d} {r['total']:5d} {wall:8.2f}  "
                      f"|tip - clamp|/L = {err:.1e}", flush=True)
                if args.history and n == 32:
                    for h in hist[:2]:
                        print("      residual norms:",
                              " ".join(f"{v:.1e}" for v in h.residual_norms))
    for n in ([16] if args.quick else [16, 32]):
        for step in (0.01, 0.005):
            for newton in ("standard", "mip"):
                hist, wall, alpha = column(n, newton, "secant", step)
                post = summary(hist, lambda h: h.load_factor * 1.2 > 1.0)
                r = dict(case="column", elements=n, predictor="secant", newton=newton,
                         step=step, wall=wall, tip_rotation_deg=alpha, post_buckling=post,
                         **summary(hist))
                rows.append(r)
                print(f"{'column':8s} {n:5d} {'secant':>9s} {newton:>8s} {r['steps']:5d} "
                      f"{r['mean']:8.2f} {r['max']:4d} {r['total']:5d} {wall:8.2f}  "
                      f"step {step}: past P_e {post['mean']:.2f} its/step (max {post['max']}), "
                      f"tip rotation {alpha:.2f} deg", flush=True)
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "newton_variants.json"), "w") as fh:
        json.dump(dict(date=time.strftime("%Y-%m-%d %H:%M:%S %Z"), rows=rows), fh, indent=1)


if __name__ == "__main__":
    main()
