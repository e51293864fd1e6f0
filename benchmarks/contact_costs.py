"""What contact costs: detection scaling and a compressed bundle end to end.

(a) Detection scaling. One detection pass (proximity zones by a uniform grid
    over the centre-line segments, then contact points on the zones'
    intermediate geometries: ``textile._cpp.detect_contacts``) on random
    bundles of 1x, 4x and 16x the fibres at constant density. Target: at 4x
    the fibres the time is at most 4.5x (cost O(segments + close pairs), never
    O(fibres^2)). Timed as the thread's CPU time, best of several repeats:
    the machine is shared (other jobs, OpenBLAS threads), and wall time of a
    few milliseconds swings by 30% with what else runs; CPU time does not
    count the time the thread waits for a core. The same pass without
    Python: ``cmake --build build --target bench_detection``.
(b) A bundle of 61 parallel fibres (hexagonal, four rings around a centre)
    compressed laterally, with friction 0.2, in two load steps, run three
    times: with the penalty fixed and with the default penalty adaptation
    (both with the solver's defaults, as before), and adaptive without the
    secant predictor (SolverOptions.predictor = "none"). Counted:
    every Newton solve (SNES solve, failed attempts included), every Newton
    iteration, every Jacobian evaluation (``Model.jacobian`` is wrapped) and
    every LU factorization (PETSc's MatLUFactorNum events), the time split
    per Newton iteration (the linear solve from PETSc's own events: PCSetUp,
    where MUMPS factorizes, plus KSPSolve, the triangular solves), the
    contact kernel's share of
    the contact assembly (C++ timers), the peak memory (getrusage), and the
    converged positions against those of the code before per-length
    penalties (``reference/contact_costs_bundle.npz``, commit ccff956): the
    fixed-penalty run must reproduce them to the solver's tolerance; the
    adaptive run ends with other zone penalties (the adaptation rule
    changed), so its positions differ by about the change of penetration.

Penalties: per unit length of contact (``ContactOptions.penalty``); the old
runs used 1e6 N/m per element of the default spacing (half an element,
2.5e-3 m), i.e. 4e8 N/m^2.

Prints tables; writes benchmarks/output/contact_costs.json. A measurement,
not a test: it asserts nothing.

    PYTHONPATH=$PWD /usr/bin/python3 benchmarks/contact_costs.py [--quick]
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import time
from collections import defaultdict

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

import textile
from textile import _cpp
from textile.effects.beam_elasticity import BeamElasticity
from textile.effects.fibre_contact import FibreContact

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "output")
REFERENCE = os.path.join(HERE, "reference", "contact_costs_bundle.npz")
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
    factors = (1, 4, 16)
    bundles = [random_bundle(base * f, 20, rng) for f in factors]
    cpu, wall, found = [np.inf] * 3, [np.inf] * 3, [None] * 3
    # the sizes take turns, so that each one's best time comes from the same
    # stretch of whatever else runs on the machine
    for _ in range(repeats):
        for k, (q, first) in enumerate(bundles):
            radius = np.full(len(first) - 1, R)
            c0, w0 = time.thread_time(), time.perf_counter()
            found[k] = _cpp.detect_contacts(q, first, 2, radius, 2.0, 20 * R, R, np.radians(10))
            cpu[k] = min(cpu[k], time.thread_time() - c0)
            wall[k] = min(wall[k], time.perf_counter() - w0)
    rows = [dict(fibres=base * f, segments=2 * 20 * base * f, zones=int(found[k].num_zones),
                 elements=int(found[k].size), seconds=cpu[k], wall_seconds=wall[k])
            for k, f in enumerate(factors)]
    for r in rows:
        r["time_ratio"] = r["seconds"] / rows[0]["seconds"]
        r["wall_ratio"] = r["wall_seconds"] / rows[0]["wall_seconds"]
        r["work_ratio"] = ((r["segments"] + r["elements"])
                           / (rows[0]["segments"] + rows[0]["elements"]))
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


class Counters:
    """Wall time accumulated per label and call counts, by wrapping methods."""

    def __init__(self):
        self.seconds = defaultdict(float)
        self.calls = defaultdict(int)

    def wrap(self, owner, name, label):
        original = getattr(owner, name)

        def timed(*args, **kwargs):
            t0 = time.perf_counter()
            self.calls[label] += 1
            try:
                return original(*args, **kwargs)
            finally:
                self.seconds[label] += time.perf_counter() - t0

        setattr(owner, name, timed)
        return original


class CountedSNES:
    """Proxy of the solver's SNES counting every solve and its iterations
    (petsc4py's methods cannot be replaced on the object)."""

    def __init__(self, snes, counters):
        self._snes, self._counters = snes, counters

    def solve(self, *args):
        c = self._counters
        t0 = time.perf_counter()
        try:
            return self._snes.solve(*args)
        finally:
            c.seconds["snes"] += time.perf_counter() - t0
            c.calls["newton solves"] += 1
            c.calls["newton iterations"] += self._snes.getIterationNumber()
            if self._snes.getConvergedReason() <= 0:
                c.calls["failed newton solves"] += 1

    def __getattr__(self, name):
        return getattr(self._snes, name)


PETSC_EVENTS = ("KSPSolve", "PCSetUp", "MatLUFactorSym", "MatLUFactorNum", "PCApply")


def petsc_events() -> dict:
    """Seconds and calls of PETSc's events so far (PETSc.Log.begin() first)."""
    out = {}
    for name in PETSC_EVENTS:
        info = PETSc.Log.Event(name).getPerfInfo()
        out[name] = (info["time"], info["count"])
    return out


def bundle_model(rings: int, elements: int, contact: FibreContact):
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
    model.add_effect(contact)
    return model


def bundle_run(rings: int, elements: int, adapt: bool, solver_options: dict) -> dict:
    spacing = 0.5 * 40 * R / elements  # the default: half an element
    contact = FibreContact(dict(penalty=1e6 / spacing, friction=0.2, adapt_penalty=adapt))
    model = bundle_model(rings, elements, contact)
    counters = Counters()
    originals = []
    for owner, name, label in ((BeamElasticity, "residual", "beam assembly"),
                               (BeamElasticity, "jacobian", "beam assembly"),
                               (FibreContact, "residual_global", "contact residual"),
                               (FibreContact, "jacobian", "contact jacobian"),
                               (FibreContact, "prepare", "detection (loops 1-2)"),
                               (FibreContact, "update", "detection (loops 1-2)"),
                               (textile.Model, "jacobian", "jacobian evaluations"),
                               (textile.Model, "rebuild_matrix", "matrix rebuilds")):
        originals.append((owner, name, counters.wrap(owner, name, label)))
    try:
        solver = textile.Solver(model, dict(initial_step=0.5, max_step=0.5, verbose=False,
                                            **solver_options))
        solver.snes = CountedSNES(solver.snes, counters)
        events0 = petsc_events()
        t0, c0 = time.perf_counter(), time.process_time()
        solver.solve()
        total, cpu = time.perf_counter() - t0, time.process_time() - c0
        events = {k: (v[0] - events0[k][0], v[1] - events0[k][1])
                  for k, v in petsc_events().items()}
    finally:
        for owner, name, f in originals:
            setattr(owner, name, f)
    s, n = counters.seconds, counters.calls
    iterations = n["newton iterations"]
    assembly = contact.assembly_timing()
    # PCSetUp (the factorization) is logged outside KSPSolve here
    linear = events["PCSetUp"][0] + events["KSPSolve"][0]
    split = {
        "detection (loops 1-2)": s["detection (loops 1-2)"],
        "contact assembly": s["contact residual"] + s["contact jacobian"],
        "beam assembly": s["beam assembly"],
        "linear solve (PCSetUp+KSPSolve)": linear,
    }
    split["rest of SNES"] = s["snes"] - (split["contact assembly"] + split["beam assembly"]
                                         + linear)
    q = model.nodal_unknowns()
    stats = solver.history[-1].effects
    at_state = assembly_at_converged_state(model, contact)
    return dict(
        adapt_penalty=adapt, solver_options=solver_options, fibres=len(model.mesh.fibres),
        elements_per_fibre=elements,
        unknowns=model.A.getSize()[0], steps=len(solver.history),
        newton_iterations=iterations, newton_solves=n["newton solves"],
        failed_newton_solves=n["failed newton solves"],
        jacobian_evaluations=n["jacobian evaluations"], matrix_rebuilds=n["matrix rebuilds"],
        factorizations=int(events["MatLUFactorNum"][1]),
        contact_elements=stats["contact_elements"], active_contacts=stats["active_contacts"],
        total_seconds=total, cpu_seconds=cpu,
        split_seconds=split,
        per_newton_iteration_ms={k: 1e3 * v / iterations for k, v in split.items()},
        factorization_seconds=events["MatLUFactorNum"][0] + events["MatLUFactorSym"][0],
        triangular_solve_seconds=events["PCApply"][0],
        contact_assembly_cpp=dict(
            kernel_seconds=assembly["kernel"], total_seconds=assembly["total"],
            kernel_calls=assembly["kernel_calls"],
            total_over_kernel=assembly["total"] / max(assembly["kernel"], 1e-300),
            per_newton_iteration_ms=dict(kernel=1e3 * assembly["kernel"] / iterations,
                                         total=1e3 * assembly["total"] / iterations)),
        contact_assembly_at_converged_state=at_state,
        penetration=dict((k, stats[k]) for k in (
            "active_zones", "zone_penetration_min", "zone_penetration_median",
            "zone_penetration_max", "zones_below_band", "zones_above_band", "emergency_retunes",
            "max_penetration_over_radius")),
        steps_detail=[dict(load_factor=h.load_factor, newton_iterations=h.newton_iterations,
                           newton_solves=h.updates, attempts=h.attempts,
                           retuned_zones=h.effects["retuned_zones"],
                           emergency_retunes=h.effects["emergency_retunes"])
                      for h in solver.history],
        positions=q)


def assembly_at_converged_state(model, contact, repeats: int = 30) -> dict:
    """Contact assembly (residual + tangent) against the kernels it runs, at
    the converged state, best of `repeats` thread-CPU times (the in-run
    timers are wall time, inflated by whatever else shares the cores)."""
    st = model.state()
    q, dofs = model.beam_positions(st), model.beam_global_dofs(st)
    A, b = model.A, model.b
    s = contact.set

    s.assemble_matrix(q, dofs, A)  # lays out the blocks once
    parts = dict(kernels=lambda: s.run_kernels(q), vector=lambda: s.assemble_vector(q, dofs, b),
                 matrix=lambda: s.assemble_matrix(q, dofs, A))
    t = dict.fromkeys(parts, np.inf)
    for _ in range(repeats):  # in turns, as in detection_scaling
        for name, f in parts.items():
            t0 = time.thread_time()
            f()
            t[name] = min(t[name], time.thread_time() - t0)
    A.assemble()
    kernels, vector, matrix = t["kernels"], t["vector"], t["matrix"]
    return dict(kernels_ms=1e3 * kernels, residual_ms=1e3 * vector, tangent_ms=1e3 * matrix,
                assembly_over_kernels=(vector + matrix) / kernels)


def compare_with_reference(run: dict, key: str) -> dict:
    if not os.path.exists(REFERENCE):
        return {}
    ref = np.load(REFERENCE)[key]
    q = run.pop("positions")
    if ref.shape != q.shape:
        return dict(reference=key, error="shape differs")
    x, x_ref = q[:, :3], ref[:, :3]
    return dict(reference=key, max_position_difference=float(np.abs(x - x_ref).max()),
                max_position_difference_over_radius=float(np.abs(x - x_ref).max() / R),
                max_section_vector_difference=float(np.abs(q[:, 3:] - ref[:, 3:]).max()))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller sizes")
    args = parser.parse_args()
    PETSc.Log.begin()
    base = 25 if args.quick else 50
    print("(a) detection pass vs fibre count (random bundle, constant density, best of 25, "
          "thread CPU time)")
    rows = detection_scaling(base, 25)
    print(f"{'fibres':>7} {'segments':>9} {'zones':>7} {'elements':>9} {'cpu [ms]':>9} "
          f"{'wall [ms]':>10} {'cpu ratio':>10} {'wall ratio':>11} {'work ratio':>11}")
    for r in rows:
        print(f"{r['fibres']:7d} {r['segments']:9d} {r['zones']:7d} {r['elements']:9d} "
              f"{1e3 * r['seconds']:9.2f} {1e3 * r['wall_seconds']:10.2f} {r['time_ratio']:10.2f} "
              f"{r['wall_ratio']:11.2f} {r['work_ratio']:11.2f}")
    print(f"4x fibres -> {rows[1]['time_ratio']:.2f}x time (target <= 4.5x); "
          f"16x -> {rows[2]['time_ratio']:.2f}x")

    rings = 3 if args.quick else 4
    elements = 6 if args.quick else 8
    runs = {}
    # the solver's defaults (as before), then without the secant predictor:
    # extrapolating the last increment overshoots contacts in the quadratic
    # part of the penalty law (step 2's first iterate raises the residual
    # 150x here)
    for name, adapt, solver_options in (("fixed_penalty", False, {}),
                                        ("adaptive_penalty", True, {}),
                                        ("adaptive_penalty_no_predictor", True,
                                         dict(predictor="none"))):
        print(f"\n(b) hexagonal bundle, {rings} rings, compressed laterally, friction 0.2, "
              f"{'adaptive' if adapt else 'fixed'} penalty, solver options {solver_options}")
        b = bundle_run(rings, elements, adapt, solver_options)
        key = "q_adaptive" if adapt else "q_fixed"
        b["reference"] = compare_with_reference(b, key) if not args.quick else {}
        b.pop("positions", None)
        runs[name] = b
        print(f"{b['fibres']} fibres, {b['unknowns']} unknowns, {b['contact_elements']} contact "
              f"elements ({b['active_contacts']} active); {b['steps']} steps, "
              f"{b['newton_iterations']} Newton iterations in {b['newton_solves']} Newton solves "
              f"({b['failed_newton_solves']} failed), {b['jacobian_evaluations']} Jacobian "
              f"evaluations, {b['factorizations']} LU factorizations, "
              f"{b['matrix_rebuilds']} matrix rebuilds; "
              f"{b['total_seconds']:.2f} s wall, {b['cpu_seconds']:.2f} s CPU")
        print(f"{'part':<30} {'seconds':>9} {'per Newton it [ms]':>19}")
        for k, v in b["split_seconds"].items():
            print(f"{k:<30} {v:9.3f} {b['per_newton_iteration_ms'][k]:19.2f}")
        c = b["contact_assembly_cpp"]
        print(f"contact assembly in C++: {1e3 * c['total_seconds'] / b['newton_iterations']:.1f} "
              f"ms per Newton iteration, of which the element kernels "
              f"{1e3 * c['kernel_seconds'] / b['newton_iterations']:.1f} ms "
              f"(total / kernel = {c['total_over_kernel']:.2f}, target <= 2)")
        a = b["contact_assembly_at_converged_state"]
        print(f"at the converged state (best of 30, CPU): kernels {a['kernels_ms']:.1f} ms, "
              f"residual {a['residual_ms']:.1f} ms + tangent {a['tangent_ms']:.1f} ms = "
              f"{a['assembly_over_kernels']:.2f} x the kernels")
        print(f"LU factorizations {b['factorization_seconds']:.2f} s, triangular solves "
              f"{b['triangular_solve_seconds']:.2f} s")
        p = b["penetration"]
        print(f"zone penetration / target: min {p['zone_penetration_min']:.3g}, median "
              f"{p['zone_penetration_median']:.3g}, max {p['zone_penetration_max']:.3g} over "
              f"{p['active_zones']} active zones ({p['zones_below_band']} below the band, "
              f"{p['zones_above_band']} above)")
        for st in b["steps_detail"]:
            print(f"  t={st['load_factor']:.2f}: {st['newton_iterations']} its, "
                  f"{st['newton_solves']} solves, retuned {st['retuned_zones']} zones before "
                  f"the step, {st['emergency_retunes']} emergency retunes")
        if b["reference"]:
            r = b["reference"]
            print(f"positions vs the code before (ccff956, {r['reference']}): max difference "
                  f"{r['max_position_difference']:.3g} m = "
                  f"{r['max_position_difference_over_radius']:.3g} R")
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # KiB on Linux
    print(f"\npeak memory (resident set) {peak:.0f} MiB")
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "contact_costs.json"), "w") as f:
        json.dump(dict(date=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
                       detection=rows, bundle=runs, peak_memory_mib=peak), f, indent=1)
    print(f"wrote {os.path.join(OUT, 'contact_costs.json')}")


if __name__ == "__main__":
    main()
