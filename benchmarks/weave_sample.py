"""The paper's sample woven: 6 warp x 6 weft yarns of 28 fibres (336 fibres).

Weaves the sample (plain weave, then a 2/2 twill) with the default
weaving scene (:class:`textile.fabric.weaving.Weaving`), prints its size as in the
paper's Table 1 (fibres, fibre nodes, fibre unknowns, contact elements),
the wall time and Newton iterations of every step (failed attempts
included), the woven fabric's figures, and writes them to
``output/weave_sample.json``; the woven states go to
``output/weave_sample_<pattern>.h5``.

    .venv/bin/python benchmarks/weave_sample.py [--patterns plain "twill 2/2"]
        [--fibres 28] [--yarns 6] [--elements 4] [--spacing 2] [--packing "layers 1"]
        [--weaving-steps 5] [--crossing-patch 2]
        [--solver '{"low_rank_tolerance": 1e-8}']
        [--weaving '{"drag": 0.1, "lifting_drag": 0.1, "viscous_fading": true}']
    mpirun -n 2 .venv/bin/python benchmarks/weave_sample.py

Bundles (``--packing hexagonal``, ``round``) weave by lifting, the 6 x 6
sample with the drags of ``--weaving`` (Weaving's options) and
``--solver '{"max_it": 50}'`` (benchmarks/README.md, "The fading's last
step is the relaxation"); the paper's 28-fibre bundles with ``--free-length
2 --weaving '{"pull": "fibre", "amplitude": 0.45, "drag": 0.1,
"lifting_drag": 0.1, "viscous_settling": true, "viscous_fading": true}'``
(benchmarks/README.md, "The paper's sample of 28-fibre bundles": not yet
woven to the end; with ``"lagged_path": true`` added it settles 2.6 times
sooner to s = 0.78, "A contact loop that lags on the drag's path"); their
woven states go to
``output/weave_sample_<pattern>_<fibres>_<packing>.h5``, the flat-row
sample's keep their name. Each woven state's pictures (the sample in 3D
and from above, cuts across warp and weft) go to a directory of the
state's name, with ``figures.json``: each yarn's section width and height
at each crossing, the fibre curvature's distribution; ``--from-state``
makes both again from the saved states, without weaving; ``--side-by-side``
puts a sample's cuts and figures beside the flat-row sample's. A long weave
with ``--checkpoint`` saves its state after every step; ``--resume`` goes
on from there (its row counts the steps, iterations and time of both);
each checkpointed step also prints the fabric's shape (mean crimp, section
height / width at the crossings), kept in the row as ``shapes``;
``--keep-steps`` keeps every step's state, and ``--motion`` then says how
far each lies from the woven state (the yarns' own motion, axial and
vertical, and the fibres' within their yarn: benchmarks/README.md, "Where
the 28-fibre weave's motion happens").

The figures of benchmarks/README.md (2 ranks): the plain weave with
``--patterns plain --solver '{"low_rank_tolerance": 1e-8}'`` (since
2026-12-03 with ``--crossing-patch 1``: with the default 2 its first
weaving step fails, README "Crossing patches"); the 2/2 twill
3 yarn widths apart (2 widths apart its first weaving step does not
converge in 0.2 or 0.1 of the stage) with ``--patterns "twill 2/2"
--spacing 3 --solver '{"low_rank_tolerance": 1e-6}'``.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import time

import numpy as np
from mpi4py import MPI

import textile
from textile import runtime
from textile.fabric import Fabric, Weaving, Yarn, measures

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "output")
R = 0.1e-3
MAT = textile.Material(5.0e9, 0.35)


def woven_name(pattern: str, fibres: int, packing: str, yarns: int = 6) -> str:
    """The woven state's file name (in OUT): the flat-row sample's keeps
    its name, other yarns' carry their fibre count and packing, and a
    sample of other than 6 x 6 yarns its size (two sizes' runs overwrote
    each other's states and checkpoints)."""
    name = pattern.replace(" ", "_").replace("/", "-")
    if (fibres, packing) != (28, "layers 1"):
        name += f"_{fibres}_{packing.replace(' ', '')}"
    if yarns != 6:
        name += f"_{yarns}x{yarns}"
    return f"weave_sample_{name}.h5"


def sample_fabric(pattern: str, fibres: int, yarns: int, elements: int, spacing: float,
                  packing: str, free_length: float | None = None) -> Fabric:
    yarn = Yarn(fibres, R, MAT, packing=packing)
    return Fabric(yarn, num_warp=yarns, num_weft=yarns, spacing=spacing * yarn.width,
                  pattern=pattern, elements_per_crossing=elements,
                  free_length=None if free_length is None
                  else free_length * spacing * yarn.width)


def draw_woven(fabric: Fabric, state: str) -> None:
    """sample.png, sample_top.png and the cuts across warp and weft
    (cut_warp.png, cut_weft.png: the yarns' sections, Durville's Fig. 10) of
    the woven state ``state``, in a directory of the state's name; a picture
    that fails is reported, never fatal (rank 0 only)."""
    from textile.io import draw_state_pictures, yarn_axes

    directory = os.path.splitext(state)[0]
    axes = yarn_axes([fabric.yarn_direction(k) for k in range(fabric.num_yarns)])
    # the fabric's own yarn numbers: a checkpoint drawn with --from-state
    # may not carry them
    drawn, errors = draw_state_pictures(state, directory, axes, unit="m", yarn=fabric.fibre_yarn)
    print(f"pictures in {directory}: {', '.join(sorted(drawn))}")
    for e in errors:
        print(f"  picture failed: {e}")


def woven_figures(fabric: Fabric, model, state: str) -> dict:
    """Each yarn's section width and height at each of its crossings (the
    lens shape), and the fibre curvature's distribution, of the current
    state; written to figures.json beside the state's pictures (collective)."""
    sections = measures.section_shapes(fabric, model)
    kappa = measures.fibre_curvatures(model)
    inner = kappa[kappa > 0]
    out = dict(sections=sections,
               curvature_per_m={f"p{q}": float(np.percentile(inner, q)) for q in (50, 90, 99)})
    out["curvature_per_m"].update(mean=float(kappa.mean()), max=float(kappa.max()))
    for name in ("warp", "weft"):
        ratio = [x["height"] / x["width"] for x in sections if x["direction"] == name]
        out[f"{name}_height_over_width"] = dict(min=float(min(ratio)), mean=float(np.mean(ratio)),
                                                max=float(max(ratio)))
    if model.comm.rank == 0:
        directory = os.path.splitext(state)[0]
        os.makedirs(directory, exist_ok=True)
        with open(os.path.join(directory, "figures.json"), "w") as f:
            json.dump(out, f, indent=1, default=float)
        for name in ("warp", "weft"):
            r = out[f"{name}_height_over_width"]
            print(f"  {name} sections, height / width at the crossings: min {r['min']:.3f}, "
                  f"mean {r['mean']:.3f}, max {r['max']:.3f}")
        c = out["curvature_per_m"]
        print(f"  fibre curvature [1/m]: median {c['p50']:.0f}, 90% {c['p90']:.0f}, "
              f"99% {c['p99']:.0f}, max {c['max']:.0f}")
    return out


def from_state(fabric: Fabric, state: str, comm) -> None:
    """The figures and pictures of a woven state saved before (collective)."""
    model = textile.Model(fabric.fibres(), comm=comm)
    textile.load_fibres(model, state)
    woven_figures(fabric, model, state)
    if comm.rank == 0:
        draw_woven(fabric, state)


def step_rows(solver) -> list[dict]:
    return [dict(step=h.step, stage=h.stage, load_factor=h.load_factor,
                 newton_iterations=h.newton_iterations, attempts=h.attempts,
                 updates=h.updates, wall_seconds=h.wall_time) for h in solver.history]


def path_shape(fabric: Fabric, model, rec) -> dict:
    """The fabric's shape at a step of the path (collective): mean crimp and
    mean section height / width at the crossings, per direction. A long
    weave's log shows with it where the yarns are heading (the 28-fibre
    bundles flatten through the whole fading: benchmarks/README.md)."""
    s = measures.summary(fabric, model)
    out = dict(step=rec.step, stage=rec.stage, load_factor=rec.load_factor)
    for name in ("warp", "weft"):
        out[f"{name}_crimp"] = s[f"{name} crimp"]
        out[f"{name}_height_over_width"] = s[f"{name} section height"] / s[f"{name} section width"]
    return out


class Checkpoint:
    """The run's state after every step, ``<state>_checkpoint.h5``, and what
    the run did so far (steps, counters, wall time, the fabric's shape at
    each step: :func:`path_shape`), ``.json`` beside it: ``--resume`` goes
    on from there, and its figures count both parts."""

    def __init__(self, state: str, comm, fabric: Fabric, earlier: dict | None = None,
                 keep: bool = False):
        stem = state.removesuffix(".h5")
        self.h5, self.json, self.comm = stem + "_checkpoint.h5", stem + "_checkpoint.json", comm
        self.fabric = fabric
        self.earlier = earlier or dict(steps=[], counters={}, wall_seconds=0.0)
        #: the fabric's shape after each step of this run (path_shape)
        self.shapes = []
        self.t0 = time.perf_counter()
        #: a directory keeping every step's state (``--keep-steps``), else None
        self.steps = stem + "_steps" if keep else None

    def forget_steps(self) -> None:
        """A run from the start: the states an earlier run kept go (they
        would mix with this run's in ``--motion``)."""
        if self.steps is not None and self.comm.rank == 0 and os.path.isdir(self.steps):
            for name in os.listdir(self.steps):
                if name.startswith("step_") or name == "motion.json":
                    os.remove(os.path.join(self.steps, name))
        self.comm.barrier()

    @classmethod
    def resumed(cls, state: str, model, solver, comm, fabric: Fabric, keep: bool = False):
        """Load the checkpoint of ``state`` into ``model`` and ``solver``: the
        attributes load_state returned, and the checkpoint."""
        c = cls(state, comm, fabric, keep=keep)
        with open(c.json) as f:
            c.earlier = json.load(f)
        attrs = textile.load_state(model, c.h5, solver)
        c.t0 = time.perf_counter()
        return attrs, c

    def so_far(self, solver) -> dict:
        counters = dict(self.earlier["counters"])
        for k, v in solver.counters.items():
            counters[k] = counters.get(k, 0) + v
        return dict(steps=self.earlier["steps"] + step_rows(solver), counters=counters,
                    wall_seconds=self.earlier["wall_seconds"] + time.perf_counter() - self.t0,
                    shapes=self.earlier.get("shapes", []) + self.shapes)

    def __call__(self, solver, rec) -> None:
        shape = path_shape(self.fabric, solver.model, rec)
        self.shapes.append(shape)
        if self.comm.rank == 0:
            print(f"  the fabric at {rec.stage} s={rec.load_factor:.4f}: crimp "
                  f"{100 * shape['warp_crimp']:.3f}% / {100 * shape['weft_crimp']:.3f}%, "
                  f"section height / width "
                  f"{shape['warp_height_over_width']:.3f} / {shape['weft_height_over_width']:.3f} "
                  f"(warp / weft)", flush=True)
        textile.save_state(solver.model, self.h5, solver,
                           fibre_data={"yarn": self.fabric.fibre_yarn})
        if self.steps is not None:
            if self.comm.rank == 0:
                os.makedirs(self.steps, exist_ok=True)
            self.comm.barrier()
            textile.save_state(solver.model, os.path.join(self.steps, f"step_{rec.step:04d}.h5"))
        if self.comm.rank == 0:
            with open(self.json, "w") as f:
                json.dump(self.so_far(solver), f, default=float)


def weave(pattern: str, fibres: int, yarns: int, elements: int, spacing: float, packing: str,
          solver_options: dict, comm, weaving_steps: int = 5,
          free_length: float | None = None, crossing_patch: int = 2,
          weaving_options: dict | None = None, checkpoint: bool = False,
          resume: bool = False, keep_steps: bool = False,
          contact_options: dict | None = None) -> dict:
    fabric = sample_fabric(pattern, fibres, yarns, elements, spacing, packing, free_length)
    weaving = Weaving(fabric, steps=weaving_steps, comm=comm,
                      contact=dict(contact_options or {}, crossing_patch=crossing_patch),
                      **(weaving_options or {}))
    model = weaving.model
    state = os.path.join(OUT, woven_name(pattern, fibres, packing, yarns))
    error = ""
    t0 = time.perf_counter()
    saving = Checkpoint(state, comm, fabric, keep=keep_steps) \
        if checkpoint or resume or keep_steps else None
    if saving is not None and not resume:
        saving.forget_steps()
    solver = textile.Solver(model, dict(solver_options, verbose=comm.rank == 0), on_step=saving)
    resumed = None
    if resume:
        resumed, saving = Checkpoint.resumed(state, model, solver, comm, fabric, keep_steps)
        solver.on_step = saving
    try:
        solver.run(weaving.stages(), resumed=resumed)
    except textile.ConvergenceError as e:
        error = str(e)
    run = saving.so_far(solver) if saving is not None else None
    wall = run["wall_seconds"] if run else time.perf_counter() - t0
    stats = solver.history[-1].effects if solver.history else {}
    size = dict(fibres=len(model.mesh.fibres), fibre_nodes=int(model.mesh.num_nodes_global),
                fibre_unknowns=9 * int(model.mesh.num_nodes_global),
                unknowns=int(model.A.getSize()[0]),
                contact_elements=int(stats.get("contact_elements", 0)),
                active_contacts=int(stats.get("active_contacts", 0)))
    steps = run["steps"] if run else step_rows(solver)
    summary = weaving.summary() if not error else {}
    textile.save_state(model, state, solver, fibre_data={"yarn": fabric.fibre_yarn})
    figures = woven_figures(fabric, model, state) if not error else {}
    if comm.rank == 0:
        draw_woven(fabric, state)
    return dict(pattern=pattern, yarns=yarns, fibres_per_yarn=fibres, packing=packing,
                free_length=fabric.free_length / fabric.spacing[0],
                spacing_in_widths=spacing, weaving_steps=weaving_steps,
                crossing_patch=crossing_patch, weaving_options=weaving_options or {},
                contact_options=contact_options or {},
                stages=[st.name for st in weaving.stages()],
                solver_options=solver_options, size=size, wall_seconds=wall,
                counters=run["counters"] if run else solver.counters, steps=steps,
                shapes=run["shapes"] if run else [],
                resumed=bool(resume), summary=summary, error=error,
                **{k: v for k, v in figures.items() if k != "sections"})


def motion_to_woven(fabric: Fabric, state: str, comm) -> list[dict]:
    """How far each step's state kept by ``--keep-steps`` lies from the
    woven state ``state``, in fibre radii: the root mean square and the
    largest node distance, split into the yarns' own motion (the mean over
    a yarn's fibres, node by node: a bundle moving as a whole), its axial
    and vertical parts, and the fibres' motion relative to their yarn's
    (rearrangement within the yarn). Printed and written to
    ``<state>_steps/motion.json`` (rank 0); collective."""
    stem = state.removesuffix(".h5")
    directory = stem + "_steps"
    with open(stem + "_checkpoint.json") as f:
        where = {s["step"]: (s["stage"], s["load_factor"]) for s in json.load(f)["steps"]}

    model = textile.Model(fabric.fibres(), comm=comm)

    def load(path: str):
        """Node positions and yarn centre lines (measures.yarn_centrelines) of a state."""
        textile.load_fibres(model, path)
        return model.nodal_unknowns()[:, :3], measures.yarn_centrelines(fabric, model)

    woven, woven_yarns = load(state)
    yarns = [np.stack([model.mesh.fibre_nodes(int(f))
                       for f in np.flatnonzero(fabric.fibre_yarn == k)])
             for k in range(fabric.num_yarns)]
    rows = []
    for name in sorted(n for n in os.listdir(directory) if n.startswith("step_")):
        step = int(name[5:9])
        x, lines = load(os.path.join(directory, name))
        d = woven - x
        own, axial, vertical, relative = 0.0, 0.0, 0.0, 0.0
        for k, nodes in enumerate(yarns):
            a, b = fabric.yarn_axis(k)
            mean = woven_yarns[k] - lines[k]                    # (nodes along, 3)
            own += len(nodes) * (mean ** 2).sum()
            axial += len(nodes) * ((mean @ ((b - a) / np.linalg.norm(b - a))) ** 2).sum()
            vertical += len(nodes) * (mean[:, 2] ** 2).sum()
            relative += ((d[nodes] - mean) ** 2).sum()
        n, r = len(d), R
        stage, t = where.get(step, ("?", float("nan")))
        rows.append(dict(step=step, stage=stage, load_factor=t,
                         rms=float(np.sqrt((d ** 2).sum() / n) / r),
                         max=float(np.linalg.norm(d, axis=1).max() / r),
                         yarns=float(np.sqrt(own / n) / r), axial=float(np.sqrt(axial / n) / r),
                         vertical=float(np.sqrt(vertical / n) / r),
                         within_yarns=float(np.sqrt(relative / n) / r)))
    if comm.rank == 0:
        print(f"distance to the woven state, in fibre radii\n{'step':>5} {'stage':<11} "
              f"{'t':>7} {'rms':>6} {'max':>6} {'yarns':>6} {'axial':>6} {'vert.':>6} "
              f"{'within':>6}")
        for w in rows:
            print(f"{w['step']:5d} {w['stage']:<11} {w['load_factor']:7.4f} {w['rms']:6.2f} "
                  f"{w['max']:6.2f} {w['yarns']:6.2f} {w['axial']:6.2f} {w['vertical']:6.2f} "
                  f"{w['within_yarns']:6.2f}")
        with open(os.path.join(directory, "motion.json"), "w") as f:
            json.dump(rows, f, indent=1)
    return rows


def side_by_side(pattern: str, fibres: int, packing: str, runs: list[dict],
                 yarns: int = 6) -> None:
    """The flat-row sample and the sample of ``fibres``-fibre ``packing``
    yarns, woven in ``pattern`` and measured before (their pictures and
    figures.json, their rows of weave_sample.json): their cuts across warp
    and weft in one picture, ``<bundle state>/side_by_side.png``, and their
    figures printed side by side (rank 0)."""
    import matplotlib.pyplot as plt

    cases = [("flat rows of 28", 28, "layers 1"), (f"{fibres}-fibre {packing}", fibres, packing)]
    dirs = [os.path.join(OUT, woven_name(pattern, n, p, yarns).removesuffix(".h5"))
            for _, n, p in cases]
    missing = [d for d in dirs if not os.path.exists(os.path.join(d, "figures.json"))]
    if missing:
        raise SystemExit(f"no figures for {', '.join(missing)}: weave them first (or make "
                         f"them again with --from-state)")
    images = [[plt.imread(os.path.join(d, cut + ".png")) for cut in ("cut_warp", "cut_weft")]
              for d in dirs]
    aspect = max(im.shape[0] / im.shape[1] for row in images for im in row)
    fig, axes = plt.subplots(2, 2, figsize=(16, 2 * (8 * aspect + 0.4)))
    for row, ((label, _, _), d) in enumerate(zip(cases, dirs)):
        for col, cut in enumerate(("cut_warp", "cut_weft")):
            ax = axes[row, col]
            ax.imshow(images[row][col])
            ax.set_axis_off()
            ax.set_title(f"{pattern}, {label}: {cut.replace('_', ' across ')}")
    fig.tight_layout()
    picture = os.path.join(dirs[1], "side_by_side.png")
    fig.savefig(picture, dpi=120)
    plt.close(fig)
    print(f"wrote {picture}")
    rows = []
    for (label, n, p), d in zip(cases, dirs):
        with open(os.path.join(d, "figures.json")) as f:
            figures = json.load(f)
        run = [r for r in runs if r["pattern"] == pattern and r.get("fibres_per_yarn") == n
               and r.get("packing") == p and not r.get("error")]
        rows.append((label, figures, run[-1]["summary"] if run else {}))
    print(f"{'':<34}" + "".join(f"{label:>24}" for label, _, _ in rows))
    for key in ("warp crimp", "weft crimp", "warp shrinkage", "weft shrinkage"):
        values = [f"{s[key]:>24.4%}" if key in s else f"{'-':>24}" for _, _, s in rows]
        print(f"{key:<34}" + "".join(values))
    for name in ("warp", "weft"):
        print(f"{name + ' height / width (min/mean/max)':<34}" + "".join(
            "{min:>10.3f}/{mean:.3f}/{max:.3f}".format(**f[f"{name}_height_over_width"])
            for _, f, _ in rows))
    for q in ("p50", "p99", "max"):
        print(f"{'fibre curvature ' + q + ' [1/m]':<34}" + "".join(
            f"{f['curvature_per_m'][q]:>24.0f}" for _, f, _ in rows))


def run_key(r: dict) -> tuple:
    return (r["pattern"], r.get("fibres_per_yarn"), r.get("packing"), r.get("spacing_in_widths"),
            r.get("weaving_steps", 5), r.get("yarns", 6), r.get("crossing_patch", 2),
            json.dumps(r.get("weaving_options", {}), sort_keys=True),
            json.dumps(r.get("contact_options", {}), sort_keys=True))


def earlier_runs(path: str, args) -> list[dict]:
    """Runs kept from the file (other patterns, spacings, fibre counts,
    another day), each with its own date, ranks and machine; the cases run
    now replace theirs."""
    if not os.path.exists(path):
        return []
    with open(path) as f:
        before = json.load(f)
    now = {(p, args.fibres, args.packing, args.spacing, args.weaving_steps, args.yarns,
            args.crossing_patch, json.dumps(args.weaving, sort_keys=True),
            json.dumps(args.contact, sort_keys=True))
           for p in args.patterns}
    return [dict(dict(date=before.get("date"), ranks=before.get("ranks")), **r)
            for r in before.get("runs", []) if run_key(r) not in now]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--patterns", nargs="+", default=["plain", "twill 2/2"])
    parser.add_argument("--fibres", type=int, default=28, help="fibres per yarn")
    parser.add_argument("--yarns", type=int, default=6, help="yarns per direction")
    parser.add_argument("--elements", type=int, default=4,
                        help="fibre elements between neighbouring crossings")
    parser.add_argument("--spacing", type=float, default=2.0, help="yarn spacing in yarn widths")
    parser.add_argument("--packing", default="layers 1",
                        help="fibre packing in the yarn section: 'layers n', 'hexagonal' or "
                             "'round'")
    parser.add_argument("--free-length", type=float, default=None,
                        help="yarn tails beyond the outer crossings, in spacings (default: "
                             "Fabric's, one spacing for bundles, half for flat rows)")
    parser.add_argument("--weaving-steps", type=int, default=5,
                        help="steps of the weaving stage (Weaving.steps)")
    parser.add_argument("--crossing-patch", type=int, default=2, choices=(1, 2),
                        help="elements a crossing's contact point moves over within Newton "
                             "(ContactOptions.crossing_patch)")
    parser.add_argument("--solver", type=json.loads, default={},
                        help='solver options as JSON, e.g. \'{"low_rank_tolerance": 1e-8}\'')
    parser.add_argument("--weaving", type=json.loads, default={},
                        help='Weaving options as JSON, e.g. \'{"drag": 0.1, "lifting_drag": '
                             '0.1, "viscous_fading": true}\'')
    parser.add_argument("--contact", type=json.loads, default={},
                        help='the weave\'s ContactOptions as JSON, e.g. \'{"friction": 0.2}\' '
                             '(friction between yarns; within a yarn: the yarn\'s own, 0.2)')
    parser.add_argument("--checkpoint", action="store_true",
                        help="save the state after every step (output/<state>_checkpoint.h5, "
                             "with the steps so far in a .json beside it)")
    parser.add_argument("--resume", action="store_true",
                        help="go on from the checkpoint a --checkpoint run of these options "
                             "left (and keep checkpointing)")
    parser.add_argument("--keep-steps", action="store_true",
                        help="checkpoint, and keep every step's state in "
                             "output/<state>_steps/ (for --motion)")
    parser.add_argument("--motion", action="store_true",
                        help="no weaving: how far each step kept by --keep-steps lies from "
                             "the woven state (yarns' own motion, axial and vertical, and "
                             "within the yarns), in fibre radii")
    parser.add_argument("--side-by-side", action="store_true",
                        help="no weaving: the flat-row sample and this one (woven and measured "
                             "before), their cuts in one picture and their figures side by side")
    parser.add_argument("--from-state", action="store_true",
                        help="no weaving: the figures (figures.json) and pictures of the woven "
                             "states these options saved before")
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    if args.side_by_side:
        if comm.rank == 0:
            with open(os.path.join(OUT, "weave_sample.json")) as f:
                runs = json.load(f)["runs"]
            for pattern in args.patterns:
                side_by_side(pattern, args.fibres, args.packing, runs, args.yarns)
        return
    if args.motion:
        for pattern in args.patterns:
            motion_to_woven(sample_fabric(pattern, args.fibres, args.yarns, args.elements,
                                          args.spacing, args.packing, args.free_length),
                            os.path.join(OUT, woven_name(pattern, args.fibres, args.packing,
                                                         args.yarns)), comm)
        return
    if args.from_state:
        for pattern in args.patterns:
            from_state(sample_fabric(pattern, args.fibres, args.yarns, args.elements,
                                     args.spacing, args.packing, args.free_length),
                       os.path.join(OUT, woven_name(pattern, args.fibres, args.packing,
                                                    args.yarns)), comm)
        return
    os.makedirs(OUT, exist_ok=True)
    if comm.rank == 0:
        print(runtime.describe())
    path = os.path.join(OUT, "weave_sample.json")
    runs = earlier_runs(path, args) if comm.rank == 0 else []
    for pattern in args.patterns:
        r = weave(pattern, args.fibres, args.yarns, args.elements, args.spacing, args.packing,
                  args.solver, comm, args.weaving_steps, args.free_length,
                  args.crossing_patch, args.weaving, args.checkpoint, args.resume,
                  args.keep_steps, args.contact)
        r.update(date=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), ranks=comm.size,
                 machine=runtime.describe())
        runs.append(r)
        peak = comm.allreduce(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)
        r["peak_memory_mib"] = peak   # this process's peak so far: this run and any before it
        if comm.rank != 0:
            continue
        s = r["size"]
        print(f"\n{pattern}: {s['fibres']} fibres, {s['fibre_nodes']} fibre nodes, "
              f"{s['fibre_unknowns']} fibre unknowns ({s['unknowns']} in all), "
              f"{s['contact_elements']} contact elements ({s['active_contacts']} active)")
        print(f"{'step':>5} {'stage':<11} {'t':>6} {'Newton':>7} {'attempts':>9} "
              f"{'updates':>8} {'wall [s]':>9}")
        for st in r["steps"]:
            print(f"{st['step']:5d} {st['stage']:<11} {st['load_factor']:6.3f} "
                  f"{st['newton_iterations']:7d} {st['attempts']:9d} {st['updates']:8d} "
                  f"{st['wall_seconds']:9.1f}")
        print(f"total {r['wall_seconds']:.1f} s, counters {r['counters']}")
        if r["error"]:
            print(f"FAILED: {r['error']}")
        for k, v in r["summary"].items():
            print(f"  {k:<28} {v:.4g}" if isinstance(v, float) else f"  {k:<28} {v}")
        print(f"peak memory (sum over ranks) {peak:.0f} MiB")
        # written after every pattern: a long run stopped later keeps its results
        with open(path, "w") as f:
            json.dump(dict(blas=runtime.blas_info(), runs=runs, peak_memory_mib=peak), f,
                      indent=1, default=float)
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
