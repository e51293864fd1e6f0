"""Pictures of the state weaving starts from: a 2 x 2 plain weave.

What this demo shows
--------------------
The straight, coplanar start of docs/method.md §6 for a plain weave of
2 warp and 2 weft yarns of 7 fibres each (hexagonal packing, fibre radius
0.1 mm, yarns 1 mm apart): every yarn straight, all yarn axes in the plane
z = 0, so warp and weft interpenetrate at every crossing. Nothing is
solved: these are the pictures ``textile.Output`` draws of a state
(``pictures="last"``), drawn here directly from the fibres.

What to look at
---------------
- ``sample.png``: the fibres as tubes of their true radius, coloured by
  yarn (warp 0, warp 1, weft 0, weft 1), seen obliquely; at each crossing
  the two yarns pass through each other.
- ``sample_top.png``: the same from above (x to the right, y up).
- ``cut_warp.png``: the plane normal to x through weft 0's axis cuts the
  warp yarns across: their 7-fibre hexagonal sections, with weft 0 lying
  in the plane as a band through them (Durville 2010, Fig. 10, after
  weaving the sections sit above and below the band).
- ``cut_weft.png``: the same across the weft yarns, through warp 0.

Run: ``python3 demos/render_weave_start.py [--output DIR]`` (a few seconds;
VTK off-screen, or a matplotlib sketch with a warning when VTK cannot draw).
"""
import argparse
import os

from mpi4py import MPI

import textile
from textile.fabric import Fabric, Yarn
from textile.io.sample_pictures import draw_sample_pictures, fabric_labels, yarn_axes

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--output", default=os.path.join(os.path.dirname(__file__), "output",
                                                     "render_weave_start"))
args = parser.parse_args()

# lengths in mm: fibres of radius 0.1, yarns 1 apart (6 radii wide: 0.4 of gap)
yarn = Yarn(7, 0.1, textile.Material(3.0e3, 0.35))
fabric = Fabric(yarn, num_warp=2, num_weft=2, spacing=1.0, pattern="plain")
fibres = fabric.fibres()
labels = fabric_labels(fabric)

if MPI.COMM_WORLD.rank == 0:     # pictures are serial: one rank draws (as Output does)
    os.makedirs(args.output, exist_ok=True)
    drawn, errors = draw_sample_pictures(args.output, [f.points for f in fibres],
                                         [f.radius for f in fibres],
                                         labels["fibre_data"]["yarn"],
                                         yarn_axes(labels["yarn_directions"]), unit="mm")
    for name, backend in sorted(drawn.items()):
        print(f"{os.path.join(args.output, name)}  ({backend})")
    for error in errors:
        print(f"not drawn: {error}")
