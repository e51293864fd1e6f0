"""What contact costs: detection scaling and the split of a Newton iteration.

(a) Detection scaling. One detection pass (proximity zones by a uniform grid
    over the centre-line segments, then contact elements on the zones'
    intermediate geometries: ``textile._cpp.detect_contacts``) on random
    bundles of 1x, 4x and 16x the fibres at constant density. Target: at 4x
    the fibres the time is at most 4.5x (cost O(segments + close pairs), never
    O(fibres^2)). The same pass without the Python layer is timed by the C++
    target ``bench_detection`` (``cmake --build build --target bench_detection``).
(b) A bundle of 61 parallel fibres (hexagonal, four rings around a centre)
    compressed laterally, with friction: the fraction of the solve spent in
    detection (loops 1-2), contact assembly, beam assembly and the linear
    solve (the rest of SNES: MUMPS factorization and solve).

Prints tables; writes benchmarks/output/contact_costs.json. A measurement,
not a test: it asserts nothing.

    PYTHONPATH=$PWD /usr/bin/python3 benchmarks/contact_costs.py [--quick]
"""
from __future__ import annotations

import argparse
import json
import os
import time
from collections import defaultdict

import numpy as np
from mpi4py import MPI

import textile
from textile import _cpp
from textile.effects.beam_elasticity import BeamElasticity
from textile.effects.fibre_contact import FibreContact

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "output")
E, NU, R = 1.0e9, 0.3, 1e-3


def random_bundle(n_fibres: int, elements: int, rng) -> tuple:
    """Curved random fibres in a box whose volume grows with their number."""
    length = 40 * R
    side = length * (n_fibres / 25) ** (1 / 3) * 1.5
    nodes = 2 * elements + 1
    q, first = [], [0]
    for _ in range(n_fibres):
        a = rng.uniform(0, side, 3)
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        bend = rng.normal(size=3) * 0.1 * length
        s = np.linspace(0, 1, nodes)[:, None]
        x = a + s * length * d + np.sin(np.pi * s) * bend
        g1 = np.cross(d, [0.3, 0.5, 0.8])
        g1 /= np.linalg.norm(g1)
        g2 = np.cross(d, g1)
        q.append(np.hstack([x, np.tile(g1, (nodes, 1)), np.tile(g2, (nodes, 1))]))
        first.append(first[-1] + nodes)
    return np.ascontiguousarray(np.vstack(q)), np.array(first, dtype=np.int64)


def detection_scaling(base: int, repeats: int) -> list[dict]:
    rng = np.random.default_rng(1)
    rows = []
    for factor in (1, 4, 16):
        q, first = random_bundle(base * factor, 20, rng)
        radius = np.full(len(first) - 1, R)
        best, found = np.inf, None
        for _ in range(repeats):
            t0 = time.perf_counter()
            found = _cpp.detect_contacts(q, first, 2, radius, 2.0, 20 * R, R, np.radians(10))
            best = min(best, time.perf_counter() - t0)
        rows.append(dict(fibres=base * factor, segments=2 * 20 * base * factor,
                         zones=int(found["num_zones"]), elements=len(found["zone"]), seconds=best))
    for r in rows:
        r["time_ratio"] = r["seconds"] / rows[0]["seconds"]
        r["work_ratio"] = (r["segments"] + r["elements"]) / (rows[0]["segments"] + rows[0]["elements"])
    return rows


def hex_bundle(rings: int) -> list[np.ndarray]:
    centres = [np.zeros(2)]
    for ring in range(1, rings + 1):
        for side in range(6):
            a0, a1 = 2 * np.pi * side / 6, 2 * np.pi * (side + 1) / 6
            p0 = 2 * R * ring * np.array([np.cos(a0), np.sin(a0)])
            p1 = 2 * R * ring * np.array([np.cos(a1), np.sin(a1)])
            for k in range(ring):
                centres.append(p0 + k / ring * (p1 - p0))
    return centres


class Timers:
    """Wall time accumulated per label, by wrapping methods."""

    def __init__(self):
        self.seconds = defaultdict(float)

    def wrap(self, owner, name, label):
        original = getattr(owner, name)

        def timed(*args, **kwargs):
            t0 = time.perf_counter()
            try:
                return original(*args, **kwargs)
            finally:
                self.seconds[label] += time.perf_counter() - t0

        setattr(owner, name, timed)


class TimedSNES:
    """Proxy timing SNES.solve (petsc4py's methods cannot be replaced)."""

    def __init__(self, snes, timers):
        self._snes, self._timers = snes, timers

    def solve(self, *args):
        t0 = time.perf_counter()
        try:
            return self._snes.solve(*args)
        finally:
            self._timers.seconds["snes total"] += time.perf_counter() - t0

    def __getattr__(self, name):
        return getattr(self._snes, name)


def bundle_split(rings: int, elements: int) -> dict:
    L = 40 * R
    centres = hex_bundle(rings)
    fibres = [textile.straight_fibre([*(c * (1 - 1e-4)), 0], [*(c * (1 - 1e-4)), L], R,
                                     textile.Material(E, NU), num_elements=elements,
                                     section_vector=[1, 0, 0]) for c in centres]
    model = textile.Model(fibres, comm=MPI.COMM_SELF)
    outer = [i for i, c in enumerate(centres) if np.linalg.norm(c) > 2 * R * rings - 1e-9]
    for i, f in enumerate(fibres):
        model.fix(f, 0, ["z", "g1z", "g2x", "g2y"])
        if i == 0:
            for n in (0, -1):
                model.fix(f, n, ["x", "y"])
        if i == outer[0]:
            for n in (0, -1):
                model.fix(f, n, "y")
        if i in outer:
            radial = -centres[i] / np.linalg.norm(centres[i])
            for n in range(f.num_nodes):
                w = (0.5 if n in (0, f.num_nodes - 1) else 1.0) * L / (f.num_nodes - 1)
                model.add_force(f, n, [*(2.0 * w * radial), 0.0])
    contact = FibreContact(dict(penalty=1e6, friction=0.2))
    model.add_effect(contact)
    timers = Timers()
    for name in ("residual", "jacobian"):
        timers.wrap(BeamElasticity, name, f"beam {name}")
    for name, label in (("residual_global", "contact residual"), ("jacobian", "contact jacobian"),
                        ("prepare", "detection"), ("update", "detection")):
        timers.wrap(FibreContact, name, label)
    solver = textile.Solver(model, dict(initial_step=0.5, max_step=0.5, verbose=False))
    solver.snes = TimedSNES(solver.snes, timers)
    t0 = time.perf_counter()
    solver.solve()
    total = time.perf_counter() - t0
    s = timers.seconds
    iterations = sum(h.newton_iterations for h in solver.history)
    assembly = s["beam residual"] + s["beam jacobian"] + s["contact residual"] + s["contact jacobian"]
    # SNES time not spent in our callbacks: MUMPS factorization + solve, vector work
    linear = s["snes total"] - assembly
    split = {
        "detection (loops 1-2)": s["detection"],
        "contact assembly": s["contact residual"] + s["contact jacobian"],
        "beam assembly": s["beam residual"] + s["beam jacobian"],
        "linear solve (rest of SNES)": linear,
    }
    return dict(fibres=len(fibres), elements_per_fibre=elements, unknowns=model.A.getSize()[0],
                newton_iterations=iterations,
                updates=sum(h.updates for h in solver.history),
                contact_elements=solver.history[-1].effects["contact_elements"],
                active_contacts=solver.history[-1].effects["active_contacts"],
                total_seconds=total, split_seconds=split,
                split_fraction={k: v / sum(split.values()) for k, v in split.items()},
                per_newton_iteration={k: v / iterations for k, v in split.items()})


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller sizes")
    args = parser.parse_args()
    base = 25 if args.quick else 50
    print("(a) detection pass vs fibre count (random bundle, constant density, best of 3)")
    rows = detection_scaling(base, 3)
    print(f"{'fibres':>7} {'segments':>9} {'zones':>7} {'elements':>9} {'time [ms]':>10} "
          f"{'time ratio':>11} {'work ratio':>11}")
    for r in rows:
        print(f"{r['fibres']:7d} {r['segments']:9d} {r['zones']:7d} {r['elements']:9d} "
              f"{1e3 * r['seconds']:10.2f} {r['time_ratio']:11.2f} {r['work_ratio']:11.2f}")
    print(f"4x fibres -> {rows[1]['time_ratio']:.2f}x time (target <= 4.5x); "
          f"16x -> {rows[2]['time_ratio']:.2f}x")

    rings = 3 if args.quick else 4
    print(f"\n(b) hexagonal bundle, {rings} rings, compressed laterally, friction 0.2")
    b = bundle_split(rings, 6 if args.quick else 8)
    print(f"{b['fibres']} fibres, {b['unknowns']} unknowns, {b['contact_elements']} contact "
          f"elements ({b['active_contacts']} active), {b['newton_iterations']} Newton iterations, "
          f"{b['updates']} Newton solves, {b['total_seconds']:.2f} s")
    print(f"{'part':<30} {'seconds':>9} {'fraction':>9} {'per Newton it [ms]':>19}")
    for k, v in b["split_seconds"].items():
        print(f"{k:<30} {v:9.3f} {b['split_fraction'][k]:9.1%} "
              f"{1e3 * b['per_newton_iteration'][k]:19.2f}")
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "contact_costs.json"), "w") as f:
        json.dump(dict(date=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
                       detection=rows, bundle=b), f, indent=1)
    print(f"\nwrote {os.path.join(OUT, 'contact_costs.json')}")


if __name__ == "__main__":
    main()
