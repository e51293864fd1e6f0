"""Bending a textile composite: a woven plain weave embedded in a matrix.

What this demo shows
--------------------
The 2 x 2 plain weave of ``demo_plain_weave.py`` (yarns of 7 fibres side by
side) is woven first (or read from a saved woven state, ``--woven``).
Then a matrix is added around it (METHOD.md sections 6-7):

1. **the matrix**: gmsh meshes a box around the woven fibres with
   tetrahedra a few fibre diameters across (not conforming to the fibres:
   it overlaps them); through the thickness the box encloses every fibre
   under a thin skin, in the plane its sides pass through the yarn ends.
   dolfinx assembles its finite-strain neo-Hookean elasticity. The matrix
   is stress-free in the woven configuration; the fibres keep their crimp
   and the stresses weaving left in them;
2. **junctions**: at every Gauss point of every fibre element five fibre
   particles (the centroid and four points of the section, so the sections
   cannot turn freely about the fibre axis) are tied to the matrix points
   where they sit, with a penalty of the order of the matrix's Young's
   modulus per unit fibre length;
3. **side rigid bodies**: the body of side ``xmin`` gathers the warp yarns'
   start sections and the matrix nodes of that face; the body of ``xmax``
   their end sections and that face's nodes.

The composite is then bent by opposite rotations of the two side bodies
about y (each turns by half the bending angle; ``xmax`` is free to move
along x, so the sample is not stretched), after a first stage in which
the forces that held the weft yarns' ends during weaving are let go. Fibres, contacts, junctions and
matrix are one system, solved by one PETSc SNES (MUMPS), also under
``mpirun -n 2``.

What to look at
---------------
- ``moment_rotation.png`` / ``moment_rotation.csv``: bending moment on the
  ``xmax`` body against the bending angle;
- ``scene.pvd`` in ParaView: fibres and matrix of every step together
  (fibres: *Tube* filter on ``radius``, colour by ``yarn``; matrix:
  colour by ``von_mises`` or ``J``, and lower its opacity);
- ``results.json``: per step the Newton iterations, the contact and
  junction figures, the smallest det F of the matrix.

Run: ``python3 demos/demo_composite_bending.py [--output DIR] [--woven FILE]
[--fibres N] [--angle DEG] [--steps N] [--size H]`` (a minute or two on 2
cores; ``--fibres 1 --spacing 6`` for a quick monofilament variant).
"""
import argparse
import csv
import math
import os

import numpy as np
from mpi4py import MPI

import textile
from textile.composite import Composite
from textile.fabric import Fabric
from textile.io.plots import plot_curve
from textile.weaving import Weaving
from textile.yarn import Yarn

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--output", default=os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                     "output", "demo_composite_bending"))
parser.add_argument("--woven", default=None, help="a saved woven state of the same fabric")
parser.add_argument("--fibres", type=int, default=7, help="fibres per yarn")
parser.add_argument("--spacing", type=float, default=2.0, help="yarn spacing, in yarn widths")
parser.add_argument("--angle", type=float, default=10.0, help="bending angle (degrees)")
parser.add_argument("--steps", type=int, default=5, help="load steps of the bending")
parser.add_argument("--size", type=float, default=None,
                    help="matrix element size, in fibre radii (default 8: four diameters)")
parser.add_argument("--degree", type=int, default=2,
                    help="matrix displacement degree: 2 (default) or 1 (linear tetrahedra "
                         "lock in bending with one element through the thickness)")
args = parser.parse_args()
comm = MPI.COMM_WORLD
os.makedirs(args.output, exist_ok=True)

# The fabric (as in demo_plain_weave.py): polyester fibres of 0.2 mm
# diameter, E = 5 GPa, in flat yarns; the matrix an epoxy, E = 3 GPa.
R = 0.1e-3
fibre_material = textile.Material(5.0e9, 0.35)
matrix_material = textile.Material(3.0e9, 0.35)
yarn = Yarn(args.fibres, R, fibre_material, packing="layers 1")
fabric = Fabric(yarn, num_warp=2, num_weft=2, spacing=args.spacing * yarn.width,
                pattern="plain", elements_per_crossing=4)

# 1. The woven state: weave now unless a saved one is given.
woven = args.woven
if woven is None:
    woven = os.path.join(args.output, "woven.h5")
    weaving = Weaving(fabric, steps=5, tension=1e-4, comm=comm)
    weaving.run()
    textile.save_state(weaving.model, woven, fibre_data={"yarn": fabric.fibre_yarn})
    woven_summary = weaving.summary()   # collective: every rank
    if comm.rank == 0:
        print(f"woven: {woven_summary['crossings in pattern order']} of "
              f"{woven_summary['crossings']} crossings in pattern order")

# 2. The composite around it: matrix, junctions, side bodies.
size = None if args.size is None else args.size * R
composite = Composite(fabric, woven, matrix_material, size=size, degree=args.degree,
                      sides=("xmin", "xmax"), comm=comm)
left, right = composite.sides["xmin"], composite.sides["xmax"]
left.fix(("x", "y", "z", "rx", "rz"))
right.fix(("y", "z", "rx", "rz"))       # x free: the sample is not stretched
left_turn = left.prescribe("ry", 0.0)
right_turn = right.prescribe("ry", 0.0)
half = math.radians(args.angle) / 2
stages = [
    # the weaving run's yarn-end bodies let go: the matrix takes the yarns' pre-stress
    composite.release_stage(steps=2),
    textile.Stage("bending", ramp={left_turn: -half, right_turn: half},
                  solver=dict(initial_step=1.0 / args.steps, max_step=1.0 / args.steps)),
]
stats = composite.junctions.statistics()   # collective
if comm.rank == 0:
    print(f"matrix box {composite.corners[0]} .. {composite.corners[1]}; "
          f"{stats['junctions']} junctions ({stats['junctions_outside']} particles outside)")

# 3. Bend, step by step; the moment on the xmax body against the angle.
angles, moments = [], []


def record(solver, rec):
    if rec.stage == "bending":
        angles.append(math.degrees(2 * half * rec.load_factor))
        moments.append(float(composite.side_reaction("xmax")[4]))
    elif rec.load_factor == 1.0:   # released: the curve starts here
        angles.append(0.0)
        moments.append(float(composite.side_reaction("xmax")[4]))


output = composite.output(args.output)
solver = textile.Solver(composite.model, dict(verbose=comm.rank == 0), output=output,
                        on_step=record)
solver.run(stages)

if comm.rank == 0:
    with open(os.path.join(args.output, "moment_rotation.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["bending angle [deg]", "moment My [N m]"])
        w.writerows(zip(angles, moments))
    plot_curve(os.path.join(args.output, "moment_rotation.png"), np.array(angles),
               np.array(moments), "bending angle [deg]", "moment M_y on side xmax [N m]",
               title="plain-weave composite in bending")
    print(f"moment at {angles[-1]:.1f} deg: {moments[-1]:.4g} N m")
    print(f"files in {args.output}: scene.pvd, moment_rotation.png, moment_rotation.csv, "
          f"results.json, woven.h5")
