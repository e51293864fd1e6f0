"""Shearing a woven fabric as in the paper: one side clamped, the opposite
side moved parallel to itself.

What this demo shows
--------------------
A 2 x 2 plain weave (yarns of ``--fibres`` fibres packed as ``--packing``;
by default the main demo's 7-fibre hexagonal bundles) is
woven first (or read from a saved woven state, ``--woven``), then sheared
twice from that state, once each way (docs/method.md §10):

1. **the scene** (:class:`textile.fabric.sample.Sample`): the woven fibres with
   their crimp, their pre-stress and their contact history; contact with
   friction (mu = 0.2), which starts afresh in the woven state (every
   contact sticks where weaving left it); a rigid body on side ``xmin``
   clamping the warp yarns' start sections, one on ``xmax`` clamping their
   end sections; the weft yarns' ends are free (each yarn end keeps a
   free body of its own, loaded by what held it during weaving; at a
   bundle's end that body keeps its woven orientation, since turning it
   would let the bundle's fibres slide along each other at no cost);
2. **the test** (:class:`textile.virtual_tests.Shear`): ``xmin`` fixed;
   ``xmax`` moved along y by ``--shear`` yarn spacings in ``--steps``
   steps, free to move along x (the orthogonal displacement is free), its
   rotations held;
3. **the results**: the force on ``xmax`` along y against the shear angle
   atan(u/L), both ways; a balanced plain weave gives the mirror curve.

What to look at
---------------
- ``shear.png`` (both directions, the reversed one mirrored) and the
  ``shear.csv``/``shear.json`` of each direction (``positive/``,
  ``negative/``): the load curve, per step the Newton iterations, the
  balance of the side bodies' forces, the most loaded fibre;
- ``positive/fibres.pvd`` in ParaView (*Tube* filter on ``radius``,
  colour by ``yarn`` or ``surface_stress``): how the yarns rotate at the
  crossings, and where the fibres are most loaded
  (``positive/shear_fibres.txt`` ranks them).

Run: ``python3 demos/demo_fabric_shear.py [--output DIR] [--woven FILE]
[--fibres N] [--packing P] [--spacing S] [--shear U] [--steps N]`` (about two
minutes on 2 ranks, the weave included; ``--fibres 1 --spacing 6`` for a
quick monofilament variant).
"""
import argparse
import os

import numpy as np
from mpi4py import MPI

import textile
from textile.fabric import Fabric, Yarn, woven_state
from textile.virtual_tests import LoadCurve, Shear

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--output", default=os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                     "output", "demo_fabric_shear"))
parser.add_argument("--woven", default=None, help="a saved woven state of the same fabric")
parser.add_argument("--fibres", type=int, default=7, help="fibres per yarn")
parser.add_argument("--packing", default="hexagonal",
                    help='fibres in the yarn section: "hexagonal", "layers 1" (flat), ...')
parser.add_argument("--spacing", type=float, default=2.0, help="yarn spacing, in yarn widths")
parser.add_argument("--shear", type=float, default=0.2,
                    help="displacement of side xmax, in yarn spacings")
parser.add_argument("--steps", type=int, default=5, help="load steps each way")
args = parser.parse_args()
comm = MPI.COMM_WORLD
os.makedirs(args.output, exist_ok=True)

# The fabric: polyester fibres of 0.2 mm diameter, E = 5 GPa, in bundles
# (friction 0.2 within a bundle, and between yarns in the virtual tests).
R = 0.1e-3
yarn = Yarn(args.fibres, R, textile.Material(5.0e9, 0.35), packing=args.packing)
fabric = Fabric(yarn, num_warp=2, num_weft=2, spacing=args.spacing * yarn.width,
                pattern="plain", elements_per_crossing=4)

# 1. The woven state: weave now unless a saved one is given.
woven = args.woven or woven_state(fabric, os.path.join(args.output, "woven.h5"), comm=comm)

# 2. Shear one way, then the other, each from the woven state.
u = args.shear * fabric.spacing[0]
results = {}
for label, displacement in (("positive", u), ("negative", -u)):
    test = Shear(fabric, woven, displacement, steps=args.steps,
                 solver_options=dict(verbose=comm.rank == 0),
                 output=os.path.join(args.output, label), comm=comm)
    results[label] = test.run()

# 3. The two curves on one plot, the reversed one mirrored, and the figures.
if comm.rank == 0:
    plus, minus = results["positive"], results["negative"]
    x0, y0 = plus.curve.x[0], plus.curve.y[0]
    mirrored = LoadCurve(plus.curve.xlabel, plus.curve.ylabel,
                         x=[x0 - (x - x0) for x in minus.curve.x],
                         y=[y0 - (y - y0) for y in minus.curve.y])
    plus.curve.title = "paper's shear of the woven 2 x 2 plain weave"
    plus.curve.write_png(os.path.join(args.output, "shear.png"), others=[mirrored],
                         labels=["xmax moved along +y", "along -y, mirrored"])
    dp = np.array(plus.curve.y) - y0
    dm = np.array(minus.curve.y) - y0
    print(f"largest mirror difference: {np.abs(dp + dm)[1:].max() / np.abs(dp).max():.2e} "
          f"of the largest force increment")
    for name, value in plus.figures.items():
        print(f"{name}: {value}")
    print(f"force balance of the side bodies: {plus.force_balance:.1e} of the largest force")
    print(plus.ranked_table(count=5))
    print(f"files in {args.output}: shear.png, positive/ and negative/ (shear.csv, "
          f"shear.json, fibres.pvd, results.json, shear_fibres.txt), woven.h5")
