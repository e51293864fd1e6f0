"""Weaving a plain weave: from straight, interpenetrating yarns to a fabric.

What this demo shows
--------------------
Two warp yarns (along x) and two weft yarns (along y), each a bundle of 7
fibres (a hexagon: one fibre and its six neighbours), 2 yarn widths apart,
start straight, in one plane, interpenetrating at their four crossings.
The weave pattern (plain: warp over, weft over, alternating) says which
yarn lies on top at each crossing. The solver *weaves* the fabric
(docs/method.md §6, Durville 2007). Bundles weave by *lifting*
(docs/method.md §6.4):

1. **lifting stage**: heddles (soft vertical springs at the crossings)
   lift each yarn where it passes over another and press it where it
   passes under, while warp and weft pass through each other (no contact
   between them yet); fibres of one yarn touch and rub (friction 0.2).
   One end of each yarn is clamped through a rigid body; the other end's
   body slides in the fabric plane under a small axial tension, so the
   yarns shorten as they bend (crimp);
2. **settling stage**: ordinary contact everywhere, the heddles letting
   go: the yarns come down onto each other and the bundles flatten where
   they cross (lens-shaped sections, as in the paper's Fig. 10);
3. **relaxation**: no heddles: the woven state.

The yarns' tails are one spacing long (lifted, the yarns crimp by up to
20% before they settle). About 20 s on 2 cores (``bash .ci/demo`` runs it
on two ranks). Twills and twisted bundles weave with a pseudo-time drag
(``Weaving(drag=..., lifting_drag=...)``, docs/method.md §6.4).

Flat yarns (``--packing "layers 1"``) and monofilaments (``--fibres 1``,
woven screens, filter fabrics; a few seconds) weave as in the paper:

1. **weaving stage** (5 load steps): a contact between fibres of a warp
   and a weft yarn takes the vertical as its normal and the sign of its gap
   from the crossing order, so the yarns are pushed over and under each
   other; contacts within a yarn are ordinary. One end of each yarn is
   clamped through a rigid body; the other end's body slides in the fabric
   plane under a small axial tension, so the yarns shorten as they bend
   (crimp);
2. **relaxation stage**: ordinary contact everywhere (normals between the
   fibres' intermediate geometries), tensions held: the woven state.

Then the fabric's figures: warp and weft crimp and shrinkage, each yarn's
section (width and height) at each crossing, fibre curvatures, the order
check at every crossing (every fibre of the yarn on top above every fibre
of the other), and the largest penetration over all contacts.

What to look at
---------------
- ``sample.png``: the woven sample, fibres drawn as tubes at their true
  radius, coloured by yarn; ``cut_warp.png`` / ``cut_weft.png``: cuts
  across the yarns, as in Durville's Fig. 10;
- ``fibres.pvd`` in ParaView (*Tube* filter on ``radius``, colour by
  ``yarn``), ``contacts.pvd`` (threshold ``normal_force > 0``);
- ``results.json``: per step its stage, Newton iterations, contact loops,
  crimp and shrinkage; ``woven.h5``: the woven state, to start loading tests
  from (``textile.load_state``).

Run: ``mpirun -n 2 python3 demos/demo_plain_weave.py [--output DIR]
[--fibres N] [--packing P] [--elements N] [--spacing S] [--amplitude A]``
(about 20 s on 2 ranks, 30 s 1.5 widths apart; a few seconds with ``--fibres 1
--spacing 6``). Bundles 1.5 widths apart weave with the heddles lifting
less, ``--spacing 1.5 --amplitude 0.45`` (at the default 0.55 the lifted
yarns, steeper, fold elements and the lifting stage stops at 0.95;
benchmarks/README.md, "A line contact's point past its patch").
"""
import argparse
import os

from mpi4py import MPI

import textile
from textile.fabric import Fabric, Weaving, Yarn

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--output", default=os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                     "output", "demo_plain_weave"))
parser.add_argument("--fibres", type=int, default=7, help="fibres per yarn")
parser.add_argument("--packing", default="hexagonal",
                    help='fibres in the yarn section: "layers 1" (flat), "hexagonal", ...')
parser.add_argument("--elements", type=int, default=4,
                    help="fibre elements between neighbouring crossings")
parser.add_argument("--spacing", type=float, default=2.0,
                    help="yarn spacing, in yarn widths")
parser.add_argument("--amplitude", type=float, default=None,
                    help="bundles: the heddles' lift, in yarn heights (Weaving's amplitude, "
                         "default 0.55; 0.45 for 1.5 widths apart)")
args = parser.parse_args()

# Fibres: polyester monofilaments, 0.2 mm diameter (E = 5 GPa, nu = 0.35).
R = 0.1e-3
mat = textile.Material(5.0e9, 0.35)
yarn = Yarn(args.fibres, R, mat, packing=args.packing)  # fibres touching
spacing = args.spacing * yarn.width
# Tails beyond the outer crossings: one spacing for bundles (woven by
# lifting, they crimp and pull their ends in), half for flat rows.
fabric = Fabric(yarn, num_warp=2, num_weft=2, spacing=spacing, pattern="plain",
                elements_per_crossing=args.elements)
comm = MPI.COMM_WORLD
if comm.rank == 0:
    print(fabric)

# The scene: fibres, yarn-end rigid bodies, contact (and heddles for
# bundles); its stages.
lifting = {} if args.amplitude is None else dict(amplitude=args.amplitude)
weaving = Weaving(fabric, tension=1e-4, **lifting)
output = weaving.output(args.output)
weaving.run(output)

# The woven state: figures, a check, and the state saved for later runs.
summary = weaving.summary()
textile.save_state(weaving.model, os.path.join(args.output, "woven.h5"),
                   fibre_data={"yarn": fabric.fibre_yarn})
if comm.rank == 0:
    print("\nwoven state:")
    for key, value in summary.items():
        print(f"  {key:<28} {value:.4g}" if isinstance(value, float) else f"  {key:<28} {value}")
    # every crossing follows the pattern, and no fibre penetrates another by
    # more than 10% of its radius
    ok = summary["crossings in pattern order"] == summary["crossings"] \
        and summary["max penetration / radius"] <= 0.1
    print("\n" + ("every crossing follows the pattern" if ok else "WOVEN STATE CHECK FAILED"))
    print(f"files in {args.output}: fibres.pvd, contacts.pvd, results.json, sample.png, "
          f"cut_warp.png, cut_weft.png, woven.h5")
    if not ok:
        raise SystemExit(1)
