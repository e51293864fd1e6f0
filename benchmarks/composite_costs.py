"""Where a composite's Newton iteration goes, on 1 and on 2 ranks.

The composite: a matrix block L x W x H (neo-Hookean, gmsh tetrahedra)
with an n x n grid of straight fibres along x embedded in it and tied by
junctions (FibreMatrixJunctions), pulled to a stretch of 1 + --strain by
two side rigid bodies (each gathers the fibre end sections and the matrix
nodes of its face), in --steps load steps. The same scene runs on every
rank count it is started with; per Newton iteration it prints the wall time
split into matrix assembly (dolfinx), fibre assembly (beams), junctions,
rigid bodies, contact (none here: a scene without contact pays nothing
for it) and the linear solve (MUMPS factorizations and solves, from
PETSc's event log), and writes them to ``output/composite_costs_<n>ranks.json``.
Run it on 1 rank, then on 2; the second run reads the first's JSON and
prints the speed-up (goal >= 1.7).

    .venv/bin/python benchmarks/composite_costs.py [--fibres 10] [--cells 40]
    mpirun -n 2 .venv/bin/python benchmarks/composite_costs.py
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import time

from mpi4py import MPI

import textile
from textile import runtime
from textile.scene.block_nodes import BlockNodes
from textile.effects.elastic_block import ElasticBlock
from textile.effects.fibre_matrix_junction import FibreMatrixJunctions
from textile.composite.matrix_mesh import gmsh_box

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "output")
L, W, H = 10.0e-3, 4.0e-3, 4.0e-3          # m
E_M, E_F, NU = 3.0e9, 70.0e9, 0.3           # Pa: epoxy, glass


def scene(comm, fibres: int, cells: int, elements: int, extra=()):
    """The composite; ``extra``: more fibres in the model, tied to nothing."""
    size = L / cells
    mesh = gmsh_box(comm, [0, 0, 0], [L, W, H], size)
    block = ElasticBlock(mesh, E_M, NU)
    pitch = W / fibres
    radius = 0.2 * pitch
    mat = textile.Material(E_F, NU)
    fibre_list = [textile.straight_fibre([0, (i + 0.5) * pitch, (j + 0.5) * pitch],
                                         [L, (i + 0.5) * pitch, (j + 0.5) * pitch], radius, mat,
                                         num_elements=elements, section_vector=[0, 1, 0])
                  for i in range(fibres) for j in range(fibres)]
    model = textile.Model(fibre_list + list(extra), comm=comm)
    model.add_effect(block)
    junctions = FibreMatrixJunctions(model, block)
    model.add_effect(junctions)
    left = textile.RigidBody("xmin", sections=[(f, 0) for f in fibre_list],
                             block_nodes=BlockNodes(block, "xmin"))
    right = textile.RigidBody("xmax", sections=[(f, -1) for f in fibre_list],
                              block_nodes=BlockNodes(block, "xmax"))
    left.fix()
    right.fix(("y", "z", "rotation"))
    model.add_rigid_body(left)
    model.add_rigid_body(right)
    return model, right, junctions


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fibres", type=int, default=10, help="fibres per row (n x n)")
    parser.add_argument("--cells", type=int, default=40, help="matrix cells along L")
    parser.add_argument("--elements", type=int, default=40, help="elements per fibre")
    parser.add_argument("--strain", type=float, default=0.02)
    parser.add_argument("--steps", type=int, default=4)
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    os.makedirs(OUT, exist_ok=True)
    if comm.rank == 0:
        print(runtime.describe())
    t0 = time.perf_counter()
    model, right, junctions = scene(comm, args.fibres, args.cells, args.elements)
    right.prescribe("x", args.strain * L)
    model.setup()
    setup = time.perf_counter() - t0
    solver = textile.Solver(model, dict(verbose=comm.rank == 0, initial_step=1.0 / args.steps,
                                        max_step=1.0 / args.steps))
    t1 = time.perf_counter()
    solver.solve()
    wall = time.perf_counter() - t1
    c = solver.counters
    its = c["newton_iterations"]
    # assembly seconds per effect, the slowest rank's (what the others wait for)
    seconds = {}
    for (name, kind), s in model.effect_seconds.items():
        seconds[name] = seconds.get(name, 0.0) + s
    names = sorted(seconds)
    slowest = {n: comm.allreduce(seconds[n], op=MPI.MAX) for n in names}
    split = {"matrix assembly (ElasticBlock)": slowest.get("ElasticBlock", 0.0),
             "fibre assembly (BeamElasticity)": slowest.get("BeamElasticity", 0.0),
             "junctions (FibreMatrixJunctions)": slowest.get("FibreMatrixJunctions", 0.0),
             "rigid bodies (RigidBodies)": slowest.get("RigidBodies", 0.0),
             "contact (FibreContact)": slowest.get("FibreContact", 0.0),
             "linear solve (factorizations + solves)": c["factorization_seconds"]
             + c["linear_solves_seconds"]}
    split["other (Python glue, norms, predictor, checks)"] = wall - sum(split.values())
    stats = junctions.statistics()
    force = float(model.rigid_bodies.reactions()[1, 0])
    size = dict(unknowns=int(model.A.getSize()[0]),
                fibre_nodes=int(model.mesh.num_nodes_global),
                matrix_nodes=int(model.layout.field("matrix").index_map.size_global),
                junctions=int(stats["junctions"]),
                junction_off_rank_fraction=float(stats["junction_off_rank_fraction"]))
    peak = comm.allreduce(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)
    if comm.rank != 0:
        return
    print(f"\n{comm.size} rank(s): {size}")
    print(f"set-up {setup:.1f} s; solve {wall:.1f} s, {its} Newton iterations in "
          f"{len(solver.history)} steps, {c['factorizations']} factorizations; "
          f"force {force:.6g} N")
    print(f"{'per Newton iteration':<48} {'[s]':>8} {'share':>7}")
    for k, v in split.items():
        print(f"  {k:<46} {v / its:8.3f} {v / wall:7.1%}")
    print(f"  {'total':<46} {wall / its:8.3f}")
    out = dict(date=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), blas=runtime.blas_info(),
               ranks=comm.size, args=vars(args), size=size, setup_seconds=setup,
               solve_seconds=wall, newton_iterations=its, steps=len(solver.history),
               factorizations=c["factorizations"], force=force,
               seconds_per_iteration={k: v / its for k, v in split.items()},
               peak_memory_mib=peak)
    other = os.path.join(OUT, "composite_costs_1ranks.json")
    if comm.size > 1 and os.path.exists(other):
        with open(other) as f:
            serial = json.load(f)
        if serial["args"] == out["args"]:
            speedup = serial["solve_seconds"] / wall
            out["speedup_over_1_rank"] = speedup
            out["force_difference_vs_1_rank"] = abs(force - serial["force"]) / abs(serial["force"])
            print(f"speed-up over 1 rank: {speedup:.2f} (goal >= 1.7); force differs by "
                  f"{out['force_difference_vs_1_rank']:.1e}")
    path = os.path.join(OUT, f"composite_costs_{comm.size}ranks.json")
    with open(path, "w") as f:
        json.dump(out, f, indent=1, default=float)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
