"""Accuracy versus cost of textile's beam discretization knobs.

Two reference problems with closed-form answers:

(a) roll-up: a cantilever (L=1, R=1e-3, E=1e9, nu=0.3) under an end moment
    M = 2 pi E I / L about z, solved to load factor 0.5 (rotation pi, tip at
    (0, 2L/pi)) with 8 fixed load steps of 0.0625. Error = |tip - ref| / L.
(b) Euler buckling of a clamped-free column (L=0.5, R=1e-3, E=1e9, nu=0.3)
    under a dead end force [-P, 0, 0], by ``textile.stability.buckling.linear_buckling``.
    Error = |P_cr / (pi^2 E I / (4 L^2)) - 1|.

Swept: elements per fibre, section quadrature order, element type
(quadratic/2 axial points = default, quadratic/3 points, linear/1 point).
Plus one row showing Poisson locking (poisson_cure=False, nu=0.3).

Prints a table, writes benchmarks/output/accuracy_cost.{csv,json,png}.
This is a measurement script, not a test: it asserts nothing.

    cd /work/main && PYTHONPATH=/work/main /usr/bin/python3 benchmarks/accuracy_cost.py [--quick]
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import os
import time

import numpy as np

import textile
import textile.stability.buckling as analysis
from textile import BeamElement, Material, Model, Solver, straight_fibre

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "output")

ELEMENT_TYPES = {
    # label: (order, axial_points)
    "quad2": (2, 2),   # default: quadratic, reduced (2-point) integration
    "quad3": (2, 3),   # quadratic, full (3-point) integration
    "lin1": (1, 1),    # linear, 1 point
}


# plot: colour = section order, line style and marker = element type
SEC_COLOUR = {2: "tab:blue", 4: "tab:orange", 6: "tab:green", 8: "tab:red"}
ELEMENT_STYLE = {"quad2": dict(ls="-", marker="o"), "quad3": dict(ls="--", marker="s"),
                 "lin1": dict(ls=":", marker="^")}


class _CountingSolver(Solver):
    """Solver that reports its histories to a global list (to count the Newton
    iterations linear_buckling runs internally)."""
    log: list = []

    def solve(self, t_end=1.0):
        h = super().solve(t_end)
        _CountingSolver.log.extend(h)
        return h


analysis.Solver = _CountingSolver   # benchmark-local patch of the name used in analysis


def rollup(order, axial_points, section_order, n_el, poisson_cure=True):
    L, R, E, nu = 1.0, 1e-3, 1e9, 0.3
    I = math.pi * R ** 4 / 4
    mat = Material(E, nu)
    f = straight_fibre([0, 0, 0], [L, 0, 0], R, mat, num_elements=n_el, order=order,
                       section_vector=[0, 1, 0])
    el = BeamElement(order=order, axial_points=axial_points, section_order=section_order,
                     poisson_cure=poisson_cure)
    t0 = time.perf_counter()
    m = Model([f], el)
    m.clamp(0, 0)
    m.add_end_moment(0, f.num_nodes - 1, [0, 0, 2 * math.pi * E * I / L])
    s = Solver(m, dict(initial_step=0.0625, max_step=0.0625, verbose=False))
    try:
        s.solve(0.5)
        tip = m.centreline(0)[-1]
        err = float(np.linalg.norm(tip - np.array([0.0, 2 * L / math.pi, 0.0])) / L)
        note = ""
    except textile.ConvergenceError:
        err, note = float("nan"), "no convergence"
    wall = time.perf_counter() - t0
    its = sum(r.newton_iterations for r in s.history)
    return err, wall, its, note


def buckling(order, axial_points, section_order, n_el, poisson_cure=True):
    L, R, E, nu = 0.5, 1e-3, 1e9, 0.3
    I = math.pi * R ** 4 / 4
    P_e = math.pi ** 2 * E * I / (4 * L ** 2)
    mat = Material(E, nu)
    f = straight_fibre([0, 0, 0], [L, 0, 0], R, mat, num_elements=n_el, order=order,
                       section_vector=[0, 1, 0])
    el = BeamElement(order=order, axial_points=axial_points, section_order=section_order,
                     poisson_cure=poisson_cure)
    _CountingSolver.log = []
    t0 = time.perf_counter()
    m = Model([f], el)
    m.clamp(0, 0)
    m.add_force(0, f.num_nodes - 1, [-P_e, 0, 0])
    note = ""
    try:
        mu = float(analysis.linear_buckling(m)[0])
    except textile.ConvergenceError:
        # with the default atol (1e-13 E*A) the probe step stagnates at the
        # residual's round-off floor on fine meshes: retry with a looser one
        # (reported in the note; the wall time includes the failed attempt)
        note = "default atol stagnates; atol=1e-11: "
        m = Model([f], el)
        m.clamp(0, 0)
        m.add_force(0, f.num_nodes - 1, [-P_e, 0, 0])
        try:
            mu = float(analysis.linear_buckling(m, solver_options=dict(atol=1e-11))[0])
        except Exception as e:  # noqa: BLE001 - a failed case is a row, not a crash
            mu, note = float("nan"), note + f"failed: {type(e).__name__}"
    except Exception as e:  # noqa: BLE001
        mu, note = float("nan"), f"failed: {type(e).__name__}"
    wall = time.perf_counter() - t0
    its = sum(r.newton_iterations for r in _CountingSolver.log)
    return abs(mu - 1.0), wall, its, note, mu


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="smaller sweep (a few seconds)")
    ap.add_argument("--cases", default="rollup,buckling")
    args = ap.parse_args(argv)
    os.makedirs(OUT, exist_ok=True)

    if args.quick:
        elements = [4, 8, 16]
        sections = [2, 4]
        others = {"quad3": [4], "lin1": [4]}
    else:
        elements = [4, 8, 16, 32, 64]
        sections = [2, 4, 6, 8]
        others = {"quad3": sections, "lin1": sections}
    # sweep: default element over every section order; the other element
    # types over the listed section orders. Buckling wall time is dominated by
    # the dense generalized eigenproblem (scipy), not by Newton iterations.
    combos = [("quad2", s) for s in sections]
    for et, ss in others.items():
        combos += [(et, s) for s in ss]
    cases = args.cases.split(",")

    rows = []
    hdr = (f"{'case':9s} {'element':7s} {'elems':>5s} {'sec':>3s} {'error':>10s} "
           f"{'wall[s]':>8s} {'newton':>6s} {'s/iter':>8s}  note")
    print(hdr)
    print("-" * len(hdr))

    def emit(row):
        rows.append(row)
        n_its = row["newton_iterations"]
        tpi = row["wall_time"] / n_its if n_its else float("nan")
        row["time_per_iteration"] = tpi
        print(f"{row['case']:9s} {row['element']:7s} {row['elements']:5d} "
              f"{row['section_order']:3d} {row['error']:10.3e} {row['wall_time']:8.3f} "
              f"{n_its:6d} {tpi:8.4f}  {row['note']}", flush=True)

    # warm-up (imports, PETSc/MUMPS first-call costs) so the first row is fair
    rollup(2, 2, 4, 4)
    for case in cases:
        for et, sec in combos:
            order, pts = ELEMENT_TYPES[et]
            for n in elements:
                if case == "rollup":
                    err, wall, its, note = rollup(order, pts, sec, n)
                else:
                    err, wall, its, note, mu = buckling(order, pts, sec, n)
                    note = note + f"P_cr/P_e={mu:.6f}"
                emit(dict(case=case, element=et, elements=n, section_order=sec, error=err,
                          wall_time=wall, newton_iterations=its, note=note))
    # Poisson locking: the section-split law switched off
    if "buckling" in cases:
        n = 16
        err, wall, its, note, mu = buckling(2, 2, 4, n, poisson_cure=False)
        emit(dict(case="buckling", element="quad2-nocure", elements=n, section_order=4,
                  error=err, wall_time=wall, newton_iterations=its,
                  note=note + f"poisson_cure=False: P_cr/P_e={mu:.4f}"))

    # outputs
    stem = os.path.join(OUT, "accuracy_cost" + ("_quick" if args.quick else ""))
    keys = ["case", "element", "elements", "section_order", "error", "wall_time",
            "newton_iterations", "time_per_iteration", "note"]
    with open(stem + ".csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    with open(stem + ".json", "w") as fh:
        json.dump(dict(date=time.strftime("%Y-%m-%d %H:%M:%S %Z"), quick=args.quick,
                       cpus=os.cpu_count(), rows=rows), fh, indent=1)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(cases), figsize=(6.5 * len(cases), 5), squeeze=False)
    for ax, case in zip(axes[0], cases):
        for et, sec in combos:
            sel = [r for r in rows if r["case"] == case and r["element"] == et
                   and r["section_order"] == sec and np.isfinite(r["error"]) and r["error"] > 0]
            if not sel:
                continue
            ax.loglog([r["wall_time"] for r in sel], [r["error"] for r in sel],
                      color=SEC_COLOUR.get(sec, "k"), **ELEMENT_STYLE[et],
                      label=f"{et}, section {sec}")
            for r in sel:
                ax.annotate(str(r["elements"]), (r["wall_time"], r["error"]), fontsize=6,
                            xytext=(2, 2), textcoords="offset points")
        nc = [r for r in rows if r["case"] == case and r["element"].endswith("nocure")]
        for r in nc:
            ax.loglog([r["wall_time"]], [r["error"]], "kx", ms=9,
                      label="quad2, poisson_cure=False")
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("relative error")
        ax.set_title({"rollup": "roll-up to theta = pi (tip error / L)",
                      "buckling": "Euler buckling |P_cr/P_e - 1|"}.get(case, case))
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(stem + ".png", dpi=120)
    print(f"\nwrote {stem}.png, {stem}.csv, {stem}.json")


if __name__ == "__main__":
    main()
