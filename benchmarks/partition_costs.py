"""What a partition of the fibres costs each rank: couplings, exchanges, memory.

Two parts (issue 23 item 3):

1. **From the partition alone** (no solve, one process): the paper's
   sample (6 x 6 yarns of 28 fibres, flat rows, 336 fibres) and a fabric
   ten times larger (19 x 19 yarns, the same yarns and spacing: ten times
   the nodes), split over 1, 2, 8 and 64 ranks by place and by number
   (:mod:`textile.beam.node_partition`). The contact couplings are the
   pairs of elements of different fibres whose chords, in the reference
   state, come closer than the contact search's distance (the yarns'
   crossings and each fibre's neighbours in its yarn). Per rank: owned
   nodes, beam ghosts, contact pairs evaluated, fibre nodes of other ranks
   that these pairs read (what :class:`~textile.system.node_gather.NodeGather`
   moves at every residual and tangent), the fibres its detection holds
   (own and ghosts, :mod:`textile.effects.detection_view`) and their nodes
   of other ranks (moved once a detection pass), the share of pairs
   coupling two ranks, and an estimate of its memory, split into what is
   distributed (matrix rows, vectors, contact elements, the search's points
   among the fibres it holds) and what is still replicated on every rank
   (the fibre geometry and full-length node arrays, the per-zone arrays).
2. **Measured** (``--run``, under ``mpirun -n N``): the first steps of the
   sample's weaving; the contact's counters give the values moved per
   evaluation and the node blocks sent to other ranks.

    .venv/bin/python benchmarks/partition_costs.py
    mpirun -n 2 .venv/bin/python benchmarks/partition_costs.py --run [--steps 2]
        [--partition numbers] [--yarns 2] [--solver '{}']

Writes ``output/partition_costs.json`` (part 1) and
``output/partition_costs_run_<yarns>_<ranks>_<partition>.json`` (part 2).
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import time

import numpy as np
import scipy.spatial
from mpi4py import MPI

import textile
from textile import runtime
from textile.beam.fibre_mesh import FibreMesh
from textile.beam.node_partition import node_owners
from textile.fabric import Fabric, Yarn

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "output")
R = 0.1e-3
MAT = textile.Material(5.0e9, 0.35)
#: bytes a rank keeps per unit (estimates; the matrix row: 12 bytes a
#: nonzero, value and column index; a zone: 8 per-zone arrays of doubles,
#: of every zone on every rank, reduced over the ranks)
#: a contact element (ContactElementState, 512 bytes) and a detected
#: point (ContactPoint, 200 bytes): sizeof on this build
NONZERO, DOUBLE, CONTACT_ELEMENT, CONTACT_POINT, ZONE = 12, 8, 512, 200, 8 * 8
BEAM_COUPLINGS = 45          # nonzeros of a beam row: 5 nodes x 9 (quadratic elements)
VECTORS = 10                 # work vectors of the global size (Newton, SNES, MUMPS' rhs)


def sample(yarns: int, fibres: int = 28):
    """The fibre mesh (one process) of the paper's sample with ``yarns``
    per direction, 2 yarn widths apart, 4 elements between crossings."""
    yarn = Yarn(fibres, R, MAT, packing="layers 1")
    fabric = Fabric(yarn, num_warp=yarns, num_weft=yarns, spacing=2 * yarn.width,
                    pattern="plain", elements_per_crossing=4)
    return FibreMesh(MPI.COMM_SELF, fabric.fibres(), 2)


def chord_distance(a0, a1, b0, b1) -> np.ndarray:
    """Distance between segments [a0, a1] and [b0, b1], row by row."""
    d1, d2, r = a1 - a0, b1 - b0, a0 - b0
    a, e = np.einsum("ij,ij->i", d1, d1), np.einsum("ij,ij->i", d2, d2)
    b, c, f = (np.einsum("ij,ij->i", d1, d2), np.einsum("ij,ij->i", d1, r),
               np.einsum("ij,ij->i", d2, r))
    denom = a * e - b * b
    s = np.clip(np.where(denom > 1e-300, (b * f - c * e) / np.where(denom > 1e-300, denom, 1),
                         0.0), 0, 1)
    t = np.clip((b * s + f) / e, 0, 1)
    s = np.clip((b * t - c) / a, 0, 1)
    return np.linalg.norm(r + d1 * s[:, None] - d2 * t[:, None], axis=1)


def contact_pairs(mesh: FibreMesh, search_factor: float = 2.0) -> np.ndarray:
    """(pairs, 2) fibre elements of different fibres whose chords come
    closer than the contact search's distance, search_factor (r_i + r_j)
    (ContactOptions.search_factor)."""
    X = mesh.X_global[:, :3]
    e = mesh.elements_global
    mid = X[e].mean(axis=1)
    length = np.linalg.norm(X[e[:, -1]] - X[e[:, 0]], axis=1).max()
    radius = max(f.radius for f in mesh.fibres)
    reach = search_factor * 2 * radius
    pairs = scipy.spatial.cKDTree(mid).query_pairs(length + reach, output_type="ndarray")
    pairs = pairs[mesh.element_fibre[pairs[:, 0]] != mesh.element_fibre[pairs[:, 1]]]
    i, j = e[pairs[:, 0]], e[pairs[:, 1]]
    near = chord_distance(X[i[:, 0]], X[i[:, -1]], X[j[:, 0]], X[j[:, -1]]) <= reach
    return pairs[near]


def detection_fibres(mesh: FibreMesh, element_owner: np.ndarray, ranks: int,
                     search_factor: float = 2.0) -> np.ndarray:
    """(ranks, fibres) flags: the fibres each rank detects among in the
    reference state, its own and its ghosts (DetectionView.present: per
    rank and fibre the box of its elements widened by search_factor r;
    straight elements, no sag)."""
    X = mesh.X_global[:, :3]
    e, f = mesh.elements_global, mesh.element_fibre
    num_fibres = len(mesh.fibres)
    reach = search_factor * np.array([fb.radius for fb in mesh.fibres])[f]
    lo, hi = X[e].min(axis=1) - reach[:, None], X[e].max(axis=1) + reach[:, None]
    key = element_owner.astype(np.int64) * num_fibres + f
    pieces, inverse = np.unique(key, return_inverse=True)
    box_lo = np.full((len(pieces), 3), np.inf)
    box_hi = np.full((len(pieces), 3), -np.inf)
    np.minimum.at(box_lo, inverse, lo)
    np.maximum.at(box_hi, inverse, hi)
    piece_rank, piece_fibre = pieces // num_fibres, pieces % num_fibres
    flags = np.zeros((ranks, num_fibres), dtype=bool)
    for r in range(ranks):
        mine = piece_rank == r
        hit = np.all((box_lo[None, :, :] <= box_hi[mine][:, None, :])
                     & (box_lo[mine][:, None, :] <= box_hi[None, :, :]), axis=2)
        flags[r, piece_fibre[np.any(hit, axis=0)]] = True
    return flags


def figures(mesh: FibreMesh, pairs: np.ndarray, partition: str, ranks: int) -> dict:
    """Per-rank figures (max and mean over ranks) of one partition."""
    e = mesh.elements_global
    n = mesh.num_nodes_global
    owner = node_owners(partition, ranks, mesh.X_global, e)
    element_owner = owner[e[:, 0]]
    f = mesh.element_fibre
    held = detection_fibres(mesh, element_owner, ranks)
    fibre_of_node = np.repeat(np.arange(len(mesh.fibres)), np.diff(mesh.first_node))
    # evaluated_here: the first node of the element on fibre i when the
    # fibre numbers' sum is even, on fibre j when odd
    even = (f[pairs[:, 0]] + f[pairs[:, 1]]) % 2 == 0
    evaluator = np.where(even, element_owner[pairs[:, 0]], element_owner[pairs[:, 1]])
    read = np.hstack([e[pairs[:, 0]], e[pairs[:, 1]]])          # nodes a pair reads
    coupling = (owner[read] != owner[read[:, :1]]).any(axis=1)
    rows = dict(owned=[], ghosts=[], pairs=[], gathered_nodes=[], detection_fibres=[],
                detection_nodes=[], distributed_mb=[])
    for r in range(ranks):
        owned = int(np.count_nonzero(owner == r))
        mine = e[element_owner == r]
        ghosts = len(np.setdiff1d(np.unique(mine), np.flatnonzero(owner == r)))
        theirs = read[evaluator == r]
        gathered = len(np.unique(theirs[owner[theirs] != r]))
        # contact rows: each pair adds 2 x 3 node blocks of 9 x 9 to rows of its nodes
        contact_nonzeros = 2 * 81 * 3 * int(np.count_nonzero(evaluator == r))
        # detection: the pairs between fibres this rank holds, and the other
        # ranks' nodes of those fibres (moved once a pass)
        searched = int(np.count_nonzero(held[r, f[pairs[:, 0]]] & held[r, f[pairs[:, 1]]]))
        detection_nodes = int(np.count_nonzero(held[r, fibre_of_node] & (owner != r)))
        distributed = (owned * 9 * BEAM_COUPLINGS * NONZERO + contact_nonzeros * NONZERO
                       + (owned + ghosts) * 9 * DOUBLE * VECTORS
                       + int(np.count_nonzero(evaluator == r)) * CONTACT_ELEMENT
                       + searched * CONTACT_POINT)
        for k, v in zip(rows, (owned, ghosts, int(np.count_nonzero(evaluator == r)), gathered,
                               int(held[r].sum()), detection_nodes, distributed / 2 ** 20)):
            rows[k].append(v)
    # replicated on every rank: reference and current geometry (3 full
    # (nodes, 9) arrays: X, the search's q, the gather's q, NaN where the
    # rank has no values), node owners and numbering (20 bytes a node), the
    # element table, and the per-zone arrays (about one zone a pair of
    # touching fibres; every rank has all of them)
    fibre_pairs = np.unique(f[pairs[:, 0]] * len(mesh.fibres) + f[pairs[:, 1]])
    replicated = (3 * n * 9 * DOUBLE + 20 * n + e.size * 8
                  + len(fibre_pairs) * ZONE) / 2 ** 20
    out = {k: dict(max=float(np.max(v)), mean=float(np.mean(v))) for k, v in rows.items()}
    out.update(ranks=ranks, partition=partition, coupling_pairs=float(coupling.mean()),
               replicated_mb=replicated,
               total_mb_max=float(np.max(rows["distributed_mb"]) + replicated))
    return out


def from_partition() -> dict:
    out = []
    for yarns in (6, 19):
        t0 = time.perf_counter()
        mesh = sample(yarns)
        pairs = contact_pairs(mesh)
        case = dict(yarns=yarns, fibres=len(mesh.fibres), nodes=int(mesh.num_nodes_global),
                    pairs=int(len(pairs)), rows=[])
        print(f"\n{yarns} x {yarns} yarns: {case['fibres']} fibres, {case['nodes']} nodes, "
              f"{case['pairs']} contact pairs")
        print(f"{'partition':<9} {'ranks':>5} {'owned':>7} {'ghosts':>6} {'pairs':>7} "
              f"{'gathered':>8} {'det fib':>7} {'det nodes':>9} {'coupling':>8} "
              f"{'distr MB':>9} {'repl MB':>8} {'total MB':>9}")
        for partition in ("place", "numbers"):
            for ranks in (1, 2, 8, 64):
                row = figures(mesh, pairs, partition, ranks)
                case["rows"].append(row)
                print(f"{partition:<9} {ranks:5d} {row['owned']['max']:7.0f} "
                      f"{row['ghosts']['max']:6.0f} {row['pairs']['max']:7.0f} "
                      f"{row['gathered_nodes']['max']:8.0f} "
                      f"{row['detection_fibres']['max']:7.0f} "
                      f"{row['detection_nodes']['max']:9.0f} {row['coupling_pairs']:8.3f} "
                      f"{row['distributed_mb']['max']:9.1f} {row['replicated_mb']:8.1f} "
                      f"{row['total_mb_max']:9.1f}")
        case["seconds"] = time.perf_counter() - t0
        out.append(case)
    return dict(cases=out)


def measured(steps: int, comm, partition: str, solver_options: dict, yarns: int = 6) -> dict:
    """The sample's first ``steps`` weaving steps on this communicator
    (``yarns`` a direction)."""
    from textile.fabric import Weaving
    from textile.effects.fibre_contact import FibreContact
    yarn = Yarn(28, R, MAT, packing="layers 1")
    fabric = Fabric(yarn, num_warp=yarns, num_weft=yarns, spacing=2 * yarn.width,
                    pattern="plain", elements_per_crossing=4)
    weaving = Weaving(fabric, steps=5, comm=comm, partition=partition)
    model = weaving.model

    class Enough(Exception):
        pass

    def stop(s, rec):
        if len(s.history) >= steps:
            raise Enough

    solver = textile.Solver(model, dict(solver_options, verbose=comm.rank == 0), on_step=stop)
    t0 = time.perf_counter()
    try:
        solver.run(weaving.stages())
    except Enough:
        pass
    wall = time.perf_counter() - t0
    contact = next(e for e in model.effects if isinstance(e, FibreContact))
    timing = contact.assembly_timing()
    evaluations = timing["evaluations"]
    mesh = model.mesh
    mine = dict(owned=mesh.num_owned, ghosts=len(mesh.ghosts),
                elements=contact.set.size, gathered_values=timing["gathered_values"],
                off_rank_sent=timing["off_rank_sent"],
                history_bytes=timing["history_bytes_received"], evaluations=evaluations,
                detection_passes=timing["detection_passes"],
                detection_values=timing["detection_values"],
                detection_pieces=timing["detection_pieces"],
                zone_keys_received=timing["zone_keys_received"],
                own_fibres=timing["own_fibres"], ghost_fibres=timing["ghost_fibres"],
                whole_state_values=9 * mesh.num_nodes_global,
                detection_seconds=timing["detection_seconds"],
                contact_assembly_seconds=timing["total"],
                effect_seconds={f"{k[0]} {k[1]}": v
                                for k, v in model.system.effect_seconds.items()},
                peak_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)
    per_rank = comm.gather(mine, root=0)
    return dict(ranks=comm.size, partition=partition, yarns=yarns, steps=steps,
                wall_seconds=wall,
                solver_options=solver_options,
                newton_iterations=sum(h.newton_iterations for h in solver.history),
                per_rank=per_rank, counters=solver.counters)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", action="store_true", help="measure the first weaving steps")
    parser.add_argument("--steps", type=int, default=2, help="weaving steps measured (--run)")
    parser.add_argument("--partition", default="place", help="place or numbers (--run)")
    parser.add_argument("--yarns", type=int, default=6, help="yarns a direction (--run)")
    parser.add_argument("--solver", type=json.loads, default={"low_rank_tolerance": 1e-8},
                        help="solver options as JSON (--run; default BLR 1e-8 as weave_sample)")
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    os.makedirs(OUT, exist_ok=True)
    stamp = dict(date=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
                 machine=runtime.describe())
    if not args.run:
        if comm.rank == 0:
            result = dict(stamp, **from_partition())
            with open(os.path.join(OUT, "partition_costs.json"), "w") as f:
                json.dump(result, f, indent=1)
        return
    result = measured(args.steps, comm, args.partition, args.solver, args.yarns)
    if comm.rank == 0:
        result.update(stamp)
        print(json.dumps({k: v for k, v in result.items() if k != "counters"}, indent=1))
        name = f"partition_costs_run_{args.yarns}_{comm.size}_{args.partition}.json"
        with open(os.path.join(OUT, name), "w") as f:
            json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
