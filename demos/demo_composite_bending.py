"""Bending a textile composite: a woven plain weave embedded in a matrix.

What this demo shows
--------------------
The 2 x 2 plain weave of ``demo_plain_weave.py`` (7-fibre hexagonal bundles)
is woven first (or read from a saved woven state, ``--woven``).
Then the virtual bending test (``textile.virtual_tests.Bending`` with a
matrix) adds a matrix around it (docs/method.md §7-8):

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
along x, so the sample is not stretched), after a first stage (two steps)
in which the forces that held the weft yarns' ends during weaving are let
go: the matrix takes them. Fibres, contacts, junctions and matrix are one
system, solved by one PETSc SNES (MUMPS), also under ``mpirun -n 2``.

A positive angle bends the sample convex upwards: the fibres below its
mid-plane are compressed. At every step the test follows the fibre pairs
the contact found in proximity at the start of loading and reports the
largest gap opening among those on the compressed side (voids between
fibres, the paper's Fig. 15; ``textile.virtual_tests.voids``).

What to look at
---------------
- ``bending.png`` / ``bending.csv``: bending moment on the ``xmax`` body
  against the bending angle; ``bending.json``: per step the Newton
  iterations, the reactions' balance, the most loaded fibre and the voids,
  and the summary (bending stiffness); ``bending_fibres.txt``: the most
  loaded fibres at the last step;
- ``scene.pvd`` in ParaView: fibres and matrix of every step together
  (fibres: *Tube* filter on ``radius``, colour by ``yarn``; matrix:
  colour by ``von_mises`` or ``J``, and lower its opacity);
- ``results.json``: per step the Newton iterations, the contact and
  junction figures, the smallest det F of the matrix.

The moment is compared with the matrix plate bent cylindrically,
E b h^3 / (12 (1 - nu^2)) theta / L, and checked between two plate
references (``textile.virtual_tests.plate_references``): the matrix free to
curl across its width with fibres not bonded to it, and the matrix in plane
strain with perfectly bonded fibres. The demo fails (exit status 1) when
the moment falls outside.

Run: ``python3 demos/demo_composite_bending.py [--output DIR] [--woven FILE]
[--fibres N] [--packing P] [--spacing S] [--angle DEG] [--steps N] [--size H]
[--degree D]`` (about a minute on 2 ranks from a saved woven state, two
with the weave; ``--fibres 1 --spacing 6`` for a quick monofilament variant).
"""
import argparse
import math
import os

from mpi4py import MPI

import textile
from textile.fabric import Fabric, Yarn, woven_state
from textile.virtual_tests import Bending, plate_references

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--output", default=os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                     "output", "demo_composite_bending"))
parser.add_argument("--woven", default=None, help="a saved woven state of the same fabric")
parser.add_argument("--fibres", type=int, default=7, help="fibres per yarn")
parser.add_argument("--packing", default="hexagonal",
                    help='fibres in the yarn section: "hexagonal", "layers 1" (flat), ...')
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
# diameter, E = 5 GPa, in bundles; the matrix an epoxy, E = 3 GPa.
R = 0.1e-3
fibre_material = textile.Material(5.0e9, 0.35)
matrix_material = textile.Material(3.0e9, 0.35)
yarn = Yarn(args.fibres, R, fibre_material, packing=args.packing)
fabric = Fabric(yarn, num_warp=2, num_weft=2, spacing=args.spacing * yarn.width,
                pattern="plain", elements_per_crossing=4)

# 1. The woven state: weave now unless a saved one is given.
woven = args.woven or woven_state(fabric, os.path.join(args.output, "woven.h5"), comm=comm)

# 2. The test: the composite around the woven state (matrix, junctions,
#    side bodies), its release (two steps), then the bending.
size = 8.0 * R if args.size is None else args.size * R
test = Bending(fabric, woven, math.radians(args.angle), steps=args.steps,
               matrix=matrix_material, composite=dict(size=size, degree=args.degree),
               release_steps=2, solver_options=dict(verbose=comm.rank == 0),
               output=args.output, comm=comm)
composite = test.sample
stats = composite.junctions.statistics()   # collective
if comm.rank == 0:
    print(f"matrix box {composite.corners[0]} .. {composite.corners[1]}; "
          f"{stats['junctions']} junctions ({stats['junctions_outside']} particles outside)")

# 3. Bend, step by step: the moment on the xmax body against the angle, and
#    the voids on the compressed side.
result = test.run()

# 4. The check: between the plate references
#    (textile.virtual_tests.plate_references), the matrix free to curl with
#    unbonded fibres (lower) and the matrix in plane strain with perfectly
#    bonded fibres (upper). A wrong answer (a locking matrix, lost
#    junctions) falls outside; the demo then fails.
lower, upper = plate_references.bending_bracket(composite)
plate = plate_references.matrix_plate_bending(composite)
if comm.rank == 0:
    print("angle [deg]  moment [N m]  (M - M0) / matrix plate  largest gap opening on the "
          "compressed side [m] (fibres)")
    m0 = result.curve.y[0]   # the moment the release left
    ratios = []
    for s in result.steps:
        ratios.append((s["y"] - m0) / (plate * math.radians(s["x"])))
        opening = s.get("largest gap opening on the compressed side")
        words = "-" if opening is None else \
            f"{opening:.3e} {s['fibres of the largest gap opening']}"
        print(f"{s['x']:11.3f}  {s['y']:12.5g}  {ratios[-1]:23.4f}  {words}")
    stiffness = result.figures["bending stiffness per width (moment per width per unit "
                               "curvature)"]
    print(f"moment at {result.curve.x[-1]:.1f} deg: {result.curve.y[-1]:.4g} N m; bending "
          f"stiffness per width {stiffness:.4g} N m; force balance {result.force_balance:.1e}")
    ok = all(lower / plate < r < upper / plate for r in ratios)
    print(f"(M - M0) / angle between the plate references {lower / plate:.4f} and "
          f"{upper / plate:.4f} of the matrix plate: "
          + ("yes" if ok else "NO: BENDING CHECK FAILED"))
    print(f"files in {args.output}: scene.pvd, bending.png, bending.csv, bending.json, "
          f"bending_fibres.txt, results.json" + ("" if args.woven else ", woven.h5"))
    if not ok:
        raise SystemExit(1)
