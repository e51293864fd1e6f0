"""What the effect machinery itself costs (issue 21 section 4): a scene pays
only for its effects.

(a) A fibre-only scene (``--fibres`` cantilevers of ``--elements`` quadratic
    elements, clamped at one end, a tip force bending them through about
    60 degrees in 4 load steps) solved by ``textile.Solver`` with its
    default options, against a lower bound with no effect machinery at all:
    the same fibres' C++ beam kernels (``_cpp.BeamAssembler``) assembling
    the residual and the tangent into a plain PETSc AIJ matrix, solved with
    the same KSP/PC (preonly + MUMPS LDL^T, null-pivot detection on, as
    ``textile.solver.linear_solver`` sets it), the same Newton iterations in each
    step (the ones the solver needed), the same residual evaluations (one
    more a step than iterations) -- no Model, Solver, effects, layout or
    dolfinx. Time per Newton iteration and peak memory (ru_maxrss of a
    fresh process; its growth during the solve; tracemalloc's peak of the
    Python allocations during the solve, in a separate untimed run).

(b) A 4 x 4 plain weave of monofilaments (8 elements between crossings;
    ``Weaving``, 5 + 1 steps) whose contact has friction 0.2 switched off in the weaving stage
    (``friction=False``, a stage option) and on in the relaxation, against
    the same scene built without friction: the weaving stage's time per
    Newton iteration, with the solver's own choice of factorization (per
    stage: LDL^T where the stage's tangent is symmetric, so in the
    switched-off weaving stage too) and with LU forced in both.

Every variant runs ``--repeats`` times, each in a fresh interpreter, one
after the other; medians are reported. Writes
``benchmarks/output/effect_overhead.json``. A measurement script, not a
test: it asserts nothing.

    .venv/bin/python benchmarks/effect_overhead.py [--repeats 5] [--quick]
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "output")
ROOT = os.path.dirname(HERE)


def rss_mb() -> float:
    """Resident set size now, MB."""
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2 ** 20


def peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


# -- (a) fibre-only -----------------------------------------------------------------
def fibres(num, elements):
    import textile

    R, L = 1e-3, 0.5
    mat = textile.Material(1e9, 0.3)
    side = int(np.ceil(np.sqrt(num)))
    out = []
    for i in range(num):
        y, z = 10 * R * (i % side), 10 * R * (i // side)
        out.append(textile.straight_fibre([0, y, z], [L, y, z], R, mat, num_elements=elements,
                                          order=2, section_vector=[0, 1, 0]))
    # tip force: P L^2 / (2 E I) = 1, about 60 degrees of end rotation
    force = 2 * mat.young * (np.pi * R ** 4 / 4) / L ** 2
    return out, np.array([0.0, 0.0, -force])


STEP = 0.25


def run_model(args, trace: bool) -> dict:
    """The scene through Model and Solver (default options, 4 steps)."""
    import tracemalloc

    import textile

    fibs, force = fibres(args.fibres, args.elements)
    model = textile.Model(fibs)
    for k in range(len(fibs)):
        model.clamp(k, 0)
        model.add_force(k, -1, force)
    t0 = time.perf_counter()
    model.setup()
    setup = time.perf_counter() - t0
    solver = textile.Solver(model, dict(verbose=False, initial_step=STEP, max_step=STEP))
    before = rss_mb()
    if trace:
        tracemalloc.start()
    t0 = time.perf_counter()
    history = solver.solve()
    seconds = time.perf_counter() - t0
    traced = tracemalloc.get_traced_memory()[1] / 2 ** 20 if trace else None
    counts = dict(solver._counts)   # what the solver counted (eigen-solves, searches, ...)
    tip = model.centreline(0)[-1]
    return dict(seconds=seconds, setup_seconds=setup,
                newton_per_step=[h.newton_iterations for h in history],
                attempts=[h.attempts for h in history], tip=tip.tolist(),
                unknowns=int(model.x.getSize()), linear=solver.linear.kind,
                matrix_type=model.A.getType(), block_size=int(model.A.getBlockSize()),
                threads=int(model.beam._assembler.num_threads),
                rss_before_mb=before, peak_mb=peak_mb(), traced_peak_mb=traced,
                counts={k: v for k, v in counts.items() if isinstance(v, (int, float))})


def run_bound(args, trace: bool, newton_per_step) -> dict:
    """The lower bound: C++ beam kernels + the same PETSc KSP/PC, the same
    Newton iterations; no Model, Solver, effects or dolfinx."""
    import tracemalloc

    import textile  # noqa: F401  (PETSc initialized, BLAS threads as the model's)
    from petsc4py import PETSc
    from textile import _cpp
    from textile.effects.beam_elasticity import element_threads

    fibs, force = fibres(args.fibres, args.elements)
    el = textile.BeamElement()
    t0 = time.perf_counter()
    first, elements, groups, numbers = [], [], [], []
    n0 = 0
    for f, fib in enumerate(fibs):
        first.append(n0)
        ne = (fib.num_nodes - 1) // 2
        elements.append(n0 + 2 * np.arange(ne)[:, None] + np.arange(3)[None, :])
        groups.append(np.full(ne, f, dtype=np.int32))
        numbers.append(np.arange(ne, dtype=np.int32))
        n0 += fib.num_nodes
    elements = np.vstack(elements).astype(np.int32)
    X = np.vstack([fib.reference_dofs() for fib in fibs])
    rule = _cpp.ElementRule(el.order + 1, el.axial_points, el.poisson_cure)
    asm = _cpp.BeamAssembler(rule, elements, np.concatenate(groups),
                             [_cpp.Material(f.material.young, f.material.poisson) for f in fibs],
                             [_cpp.SectionQuadrature(f.radius, el.section_order) for f in fibs],
                             np.ascontiguousarray(X.ravel()), np.concatenate(numbers))
    asm.num_threads = element_threads()
    N = 9 * n0
    clamped = (9 * np.array(first)[:, None] + np.arange(9)[None, :]).ravel()
    tips = np.array([first[f] + fib.num_nodes - 1 for f, fib in enumerate(fibs)])
    dofs = np.arange(N, dtype=np.int32)
    dofs[clamped] = -1
    rows = clamped.astype(np.int32)
    f_ext = np.zeros(N)
    for t in tips:
        f_ext[9 * t:9 * t + 3] = force
    # preallocation: a node couples with the nodes of its elements
    neighbours = np.zeros(n0, dtype=np.int32)
    for e in elements:
        neighbours[e] += 3
    neighbours[elements[1:, 0]] -= 1   # a shared end node counts itself once
    neighbours = np.minimum(neighbours, 5)
    A = PETSc.Mat().createAIJ([N, N], bsize=9, nnz=np.repeat(9 * neighbours, 9),
                              comm=PETSc.COMM_SELF)
    A.setLGMap(PETSc.LGMap().create(np.arange(N, dtype=np.int32), comm=PETSc.COMM_SELF))
    A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
    opts = PETSc.Options()
    opts["bound_mat_mumps_icntl_24"] = 1
    ksp = PETSc.KSP().create(PETSc.COMM_SELF)
    ksp.setOptionsPrefix("bound_")
    ksp.setType("preonly")
    ksp.getPC().setType("cholesky")
    ksp.getPC().setFactorSolverType("mumps")
    ksp.setFromOptions()
    u = np.zeros(N)
    r = np.zeros(N)
    b, dx = A.createVecs()
    setup = time.perf_counter() - t0
    before = rss_mb()
    if trace:
        tracemalloc.start()

    def residual(t):
        r[:] = 0.0
        asm.assemble_vector(u, r)
        r[:] -= t * f_ext
        r[clamped] = 0.0

    t0 = time.perf_counter()
    du = None
    for k, its in enumerate(newton_per_step):
        t = (k + 1) * STEP
        residual(t)
        for _ in range(its):
            A.zeroEntries()
            asm.assemble_matrix(A, u, dofs, du)
            _cpp.add_diagonal(A, rows, 1.0)   # the clamped rows: identity
            A.assemble()
            ksp.setOperators(A)
            b.setArray(-r)
            ksp.solve(b, dx)
            du = dx.getArray().copy()
            u += du
            residual(t)
    seconds = time.perf_counter() - t0
    traced = tracemalloc.get_traced_memory()[1] / 2 ** 20 if trace else None
    return dict(seconds=seconds, setup_seconds=setup, newton_per_step=list(newton_per_step),
                residual_norm=float(np.linalg.norm(r)),
                tip=(X[tips[0]] + u[9 * tips[0]:9 * tips[0] + 9])[:3].tolist(),
                unknowns=N, rss_before_mb=before, peak_mb=peak_mb(), traced_peak_mb=traced)


# -- (b) fabric: friction switched off in a stage --------------------------------------
def run_fabric(args, variant: str, factorization: str) -> dict:
    """variant "switched": friction 0.2, off in the weaving stage, on in the
    relaxation; "none": friction 0 in the scene."""
    from mpi4py import MPI

    import textile
    from textile.effects.weaving_contact import weaving_mode
    from textile.fabric import Fabric
    from textile.fabric import Weaving
    from textile.fabric import Yarn

    R = 0.1e-3
    yarn = Yarn(1, R, textile.Material(5.0e9, 0.35), packing="layers 1")
    fabric = Fabric(yarn, num_warp=args.yarns, num_weft=args.yarns, spacing=6 * yarn.width,
                    pattern="plain", elements_per_crossing=args.crossing_elements)
    mu = 0.2 if variant == "switched" else 0.0
    weaving = Weaving(fabric, steps=5, contact=dict(friction=mu), comm=MPI.COMM_WORLD)
    c = weaving.contact
    off = dict(friction=False) if variant == "switched" else {}
    on = dict(friction=True) if variant == "switched" else {}
    stages = [textile.Stage("weaving", effects={c: dict(weaving_mode(fabric), **off)},
                            solver=dict(initial_step=0.2, max_step=0.2)),
              textile.Stage("relaxation", effects={c: dict(mode="ordinary", **on)},
                            solver=dict(initial_step=1.0, max_step=1.0))]
    solver = textile.Solver(weaving.model, dict(verbose=False, factorization=factorization))
    out = {}
    for stage in stages:
        n = len(solver.history)
        histories = []
        commit = c.commit

        def counted(model, commit=commit):
            commit(model)
            histories.append(c.set.num_friction_histories)

        c.commit = counted
        t0 = time.perf_counter()
        solver.run_stage(stage)
        seconds = time.perf_counter() - t0
        c.commit = commit
        records = solver.history[n:]
        its = sum(h.newton_iterations for h in records)
        out[stage.name] = dict(seconds=seconds, newton_iterations=its, steps=len(records),
                               per_iteration=seconds / max(its, 1),
                               friction_histories=max(histories, default=0),
                               linear=solver.linear.kind)
    out["linear"] = out["weaving"]["linear"]   # the factorization of the stage compared
    out["summary"] = {k: v for k, v in weaving.summary().items() if isinstance(v, (int, float))}
    return out


# -- driver -------------------------------------------------------------------------
def child(argv) -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--child")
    ap.add_argument("--fibres", type=int)
    ap.add_argument("--elements", type=int)
    ap.add_argument("--trace", action="store_true")
    ap.add_argument("--its", default="")
    ap.add_argument("--factorization", default="auto")
    ap.add_argument("--yarns", type=int, default=4)
    ap.add_argument("--crossing-elements", type=int, default=8)
    args = ap.parse_args(argv)
    if args.child == "model":
        out = run_model(args, args.trace)
    elif args.child == "bound":
        out = run_bound(args, args.trace, [int(v) for v in args.its.split(",")])
    else:
        out = run_fabric(args, args.child, args.factorization)
    print("RESULT " + json.dumps(out))


def spawn(*argv) -> dict:
    run = subprocess.run([sys.executable, os.path.abspath(__file__), *map(str, argv)],
                         capture_output=True, text=True, cwd=ROOT)
    if run.returncode:
        raise RuntimeError(f"{argv}: {run.stderr[-3000:]}")
    return json.loads(run.stdout.split("RESULT ", 1)[1])


def median(runs, key):
    return float(np.median([r[key] for r in runs]))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--fibres", type=int, default=40)
    ap.add_argument("--elements", type=int, default=48)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--yarns", type=int, default=4, help="warp (and weft) yarns of (b)")
    ap.add_argument("--crossing-elements", type=int, default=8,
                    help="fibre elements between crossings in (b)")
    ap.add_argument("--quick", action="store_true", help="3 repeats, 12 fibres, 2 x 2 yarns")
    args = ap.parse_args(argv)
    if args.quick:
        args.repeats, args.fibres, args.yarns = 3, 12, 2
    import textile.runtime

    rep = args.repeats
    result = dict(date=time.strftime("%Y-%m-%d"), cpus=os.cpu_count(), repeats=rep,
                  blas=textile.runtime.describe() if hasattr(textile.runtime, "describe")
                  else None)

    # (a) -------------------------------------------------------------------------
    size = ["--fibres", args.fibres, "--elements", args.elements]
    models, bounds = [], []
    for _ in range(rep):   # interleaved: drifts of the machine hit both alike
        m = spawn("--child", "model", *size)
        models.append(m)
        bounds.append(spawn("--child", "bound", *size, "--its",
                            ",".join(map(str, m["newton_per_step"]))))
    its = sum(models[0]["newton_per_step"])
    assert all(sum(m["newton_per_step"]) == its for m in models)
    traced_m = spawn("--child", "model", *size, "--trace")
    traced_b = spawn("--child", "bound", *size, "--trace", "--its",
                     ",".join(map(str, models[0]["newton_per_step"])))
    a = dict(fibres=args.fibres, elements_per_fibre=args.elements,
             unknowns=models[0]["unknowns"], newton_iterations=its,
             newton_per_step=models[0]["newton_per_step"], linear=models[0]["linear"],
             matrix_type=models[0]["matrix_type"], matrix_block_size=models[0]["block_size"],
             element_threads=models[0]["threads"],
             model_per_iteration_ms=1e3 * median(models, "seconds") / its,
             bound_per_iteration_ms=1e3 * median(bounds, "seconds") / its,
             model_seconds=[m["seconds"] for m in models],
             bound_seconds=[b["seconds"] for b in bounds],
             model_setup_seconds=median(models, "setup_seconds"),
             bound_setup_seconds=median(bounds, "setup_seconds"),
             model_peak_mb=median(models, "peak_mb"), bound_peak_mb=median(bounds, "peak_mb"),
             model_solve_growth_mb=float(np.median([m["peak_mb"] - m["rss_before_mb"]
                                                    for m in models])),
             bound_solve_growth_mb=float(np.median([b["peak_mb"] - b["rss_before_mb"]
                                                    for b in bounds])),
             model_traced_peak_mb=traced_m["traced_peak_mb"],
             bound_traced_peak_mb=traced_b["traced_peak_mb"],
             model_counts=models[0]["counts"],
             tip_model=models[0]["tip"], tip_bound=bounds[0]["tip"],
             bound_residual_norm=bounds[0]["residual_norm"])
    a["overhead_time"] = a["model_per_iteration_ms"] / a["bound_per_iteration_ms"] - 1
    a["overhead_peak_memory"] = a["model_peak_mb"] / a["bound_peak_mb"] - 1
    result["fibre_only"] = a
    print(f"(a) fibre-only: {args.fibres} fibres x {args.elements} quadratic elements, "
          f"{a['unknowns']} unknowns, {its} Newton iterations {a['newton_per_step']}, "
          f"{a['linear']} ({a['matrix_type']}, block size {a['matrix_block_size']}), "
          f"{a['element_threads']} element threads; "
          f"median of {rep}")
    print(f"    per Newton iteration: model {a['model_per_iteration_ms']:.1f} ms, lower bound "
          f"{a['bound_per_iteration_ms']:.1f} ms: overhead {100 * a['overhead_time']:+.1f}%")
    print(f"    peak RSS: model {a['model_peak_mb']:.1f} MB, lower bound {a['bound_peak_mb']:.1f} "
          f"MB ({100 * a['overhead_peak_memory']:+.1f}%); growth during the solve "
          f"{a['model_solve_growth_mb']:.1f} vs {a['bound_solve_growth_mb']:.1f} MB; Python "
          f"allocations (tracemalloc peak) {a['model_traced_peak_mb']:.2f} vs "
          f"{a['bound_traced_peak_mb']:.2f} MB")
    print(f"    set-up: model {a['model_setup_seconds']:.3f} s, lower bound "
          f"{a['bound_setup_seconds']:.3f} s; tips {np.round(a['tip_model'], 6)} vs "
          f"{np.round(a['tip_bound'], 6)}")

    # (b) -------------------------------------------------------------------------
    fabric = {}
    for factorization in ("auto", "lu"):
        runs = {"switched": [], "none": []}
        for _ in range(rep):
            for variant in runs:
                runs[variant].append(spawn("--child", variant, "--factorization",
                                           factorization, "--yarns", args.yarns,
                                           "--crossing-elements", args.crossing_elements))
        row = {}
        for variant, rs in runs.items():
            row[variant] = dict(
                linear=rs[0]["linear"],
                weaving_per_iteration_ms=1e3 * float(np.median(
                    [r["weaving"]["per_iteration"] for r in rs])),
                weaving_seconds=float(np.median([r["weaving"]["seconds"] for r in rs])),
                weaving_newton_iterations=rs[0]["weaving"]["newton_iterations"],
                weaving_friction_histories=max(r["weaving"]["friction_histories"] for r in rs),
                relaxation_per_iteration_ms=1e3 * float(np.median(
                    [r["relaxation"]["per_iteration"] for r in rs])),
                relaxation_newton_iterations=rs[0]["relaxation"]["newton_iterations"],
                relaxation_friction_histories=rs[0]["relaxation"]["friction_histories"],
                summary=rs[0]["summary"])
        row["overhead_time"] = (row["switched"]["weaving_per_iteration_ms"]
                                / row["none"]["weaving_per_iteration_ms"] - 1)
        fabric[factorization] = row
        s, n = row["switched"], row["none"]
        print(f"(b) {args.yarns} x {args.yarns} plain weave, monofilaments, "
              f"factorization={factorization}: weaving stage with friction switched off "
              f"({s['linear']}) {s['weaving_per_iteration_ms']:.1f} ms a Newton iteration "
              f"({s['weaving_newton_iterations']} its, "
              f"{s['weaving_friction_histories']} friction histories), scene without friction "
              f"({n['linear']}) {n['weaving_per_iteration_ms']:.1f} ms "
              f"({n['weaving_newton_iterations']} its): overhead "
              f"{100 * row['overhead_time']:+.1f}%; relaxation with friction on: "
              f"{s['relaxation_per_iteration_ms']:.1f} ms ({s['relaxation_friction_histories']} "
              f"histories) vs {n['relaxation_per_iteration_ms']:.1f} ms without")
    result["fabric"] = fabric
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "effect_overhead.json"), "w") as fh:
        json.dump(result, fh, indent=1)
    print(f"written {os.path.join(OUT, 'effect_overhead.json')}")


if __name__ == "__main__":
    if "--child" in sys.argv:
        child(sys.argv[1:])
    else:
        main()
