"""Pulling a woven fabric: uniaxial and biaxial tension, and crimp interchange.

What this demo shows
--------------------
A 2 x 2 plain weave (yarns of ``--fibres`` fibres packed as ``--packing``;
by default the main demo's 7-fibre hexagonal bundles) is
woven first (or read from ``--woven``), then pulled along the warp (x) to
``--strain`` in three ways, each from the woven state
(:class:`textile.virtual_tests.Tension`):

1. **uniaxial**: the warp yarns' ends clamped by one rigid body per side
   (xmin fixed, xmax pulled along x); the weft yarns' ends are free;
2. **biaxial**, weft strain ``ratio`` times the warp strain (``--ratios``,
   default 0, 0.5 and 1): every yarn end clamped by a body of its own,
   all moved with the homogeneous stretch of the sample (a multi-clamp
   rig: the yarn ends of a side spread as the other direction stretches);
3. **shear** as in the paper (:class:`textile.virtual_tests.Shear`), for the
   in-plane shear stiffness.

Woven yarns are crimped: pulled, a yarn first straightens, pressing the
crossing yarns of the other direction into more crimp (crimp interchange).
The more the weft is stretched too, the less it gives way, and the stiffer
the warp: the membrane stiffness (force per width per strain, from the
small-strain part of each curve) rises with the ratio, staying below the
straight yarns'. (Yarns of one fibre stiffen visibly as their crimp is
pulled out; in the bundles the fibres also slide on each other within a
yarn, and the curves stay nearly straight to 1%.)

What to look at
---------------
- ``tension.png``: force on side xmax along x against the warp strain, one
  curve per case; the printed table of the effective membrane stiffnesses
  (tensile per case, and shear);
- per case (``uniaxial/``, ``biaxial_<ratio>/``): ``tension.csv``,
  ``tension.json`` (per step Newton iterations, force balance, most loaded
  fibre), ``fibres.pvd`` for ParaView, ``tension_fibres.txt``.

Run: ``python3 demos/demo_fabric_tension.py [--output DIR] [--woven FILE]
[--fibres N] [--packing P] [--spacing S] [--strain E] [--ratios R ...]
[--steps N]`` (about 3 minutes on 2 ranks, the weave included;
``--fibres 1 --spacing 6`` for a quick monofilament variant).
"""
import argparse
import math
import os

from mpi4py import MPI

import textile
from textile.fabric import Fabric, Yarn, woven_state
from textile.virtual_tests import Shear, Tension, figures_table

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--output", default=os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                     "output", "demo_fabric_tension"))
parser.add_argument("--woven", default=None, help="a saved woven state of the same fabric")
parser.add_argument("--fibres", type=int, default=7, help="fibres per yarn")
parser.add_argument("--packing", default="hexagonal",
                    help='fibres in the yarn section: "hexagonal", "layers 1" (flat), ...')
parser.add_argument("--spacing", type=float, default=2.0, help="yarn spacing, in yarn widths")
parser.add_argument("--strain", type=float, default=0.01, help="warp strain at the end")
parser.add_argument("--ratios", type=float, nargs="*", default=[0.0, 0.5, 1.0],
                    help="weft / warp strain ratios of the biaxial cases")
parser.add_argument("--steps", type=int, default=4, help="load steps of each case")
args = parser.parse_args()
comm = MPI.COMM_WORLD
os.makedirs(args.output, exist_ok=True)

# The fabric: polyester fibres of 0.2 mm diameter, E = 5 GPa, in bundles
# (friction 0.2 within a bundle, and between yarns in the virtual tests).
R = 0.1e-3
fibre = textile.Material(5.0e9, 0.35)
yarn = Yarn(args.fibres, R, fibre, packing=args.packing)
fabric = Fabric(yarn, num_warp=2, num_weft=2, spacing=args.spacing * yarn.width,
                pattern="plain", elements_per_crossing=4)

# 1. The woven state: weave now unless a saved one is given.
woven = args.woven or woven_state(fabric, os.path.join(args.output, "woven.h5"), comm=comm)

# 2. The cases, each from the woven state; and the paper's shear test, for
#    the in-plane shear stiffness beside the tensile ones.
cases = [("uniaxial", None)] + [(f"biaxial_{r:g}", r) for r in args.ratios]
results = {}
for label, ratio in cases:
    test = Tension(fabric, woven, args.strain, ratio=ratio, steps=args.steps,
                   solver_options=dict(verbose=comm.rank == 0),
                   output=os.path.join(args.output, label), comm=comm)
    results[label] = test.run()
results["shear"] = Shear(fabric, woven, 0.1 * fabric.spacing[0], steps=args.steps,
                         solver_options=dict(verbose=comm.rank == 0), comm=comm).run()

# 3. The curves together and the membrane stiffnesses.
if comm.rank == 0:
    first = results["uniaxial"]
    first.curve.title = "tension of the woven 2 x 2 plain weave"
    others = [results[label].curve for label, _ in cases[1:]]
    first.curve.write_png(os.path.join(args.output, "tension.png"), others=others,
                          labels=["uniaxial"] + [f"biaxial, weft/warp strain {r:g}"
                                                 for _, r in cases[1:]])
    # the effective membrane stiffnesses (N/m; shear: N/m per radian) from the
    # small-strain part of each curve, beside the straight warp yarns' E A / p
    straight = args.fibres * fibre.young * math.pi * R ** 2 / fabric.spacing[0]
    print(f"\nstraight warp yarns: {straight:.4g} N/m\n" + figures_table(results))
    print(f"files in {args.output}: tension.png, " + ", ".join(f"{label}/" for label, _ in cases))
