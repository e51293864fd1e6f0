"""Euler buckling and post-buckling of a clamped-free column.

What this demo shows
--------------------
A slender fibre (L = 0.5, R = 1 mm), clamped at its base, is compressed by
a dead axial force at its free end.

1. **Critical load.** ``textile.analysis.linear_buckling`` compares the
   tangent of the unloaded column with the tangent under a small load and
   finds the load factor at which it becomes singular. Euler's value for a
   clamped-free column is P_cr = pi^2 E I / (4 L^2); at nu = 0.3 it is only
   reached because the element cures Poisson locking (without the cure the
   column is (1 - nu)/((1 + nu)(1 - 2 nu)) = 1.346 times too stiff).
2. **Post-buckling path.** A second column gets a compressive force growing
   to 1.2 P_cr plus a small lateral force (1e-3 P_cr) that picks the
   buckling direction (with a much smaller one, Newton may land on the
   unstable complementary branch past P_cr: load control has no way to
   choose). Past P_cr the column bends away sideways along the
   elastica branch, P / P_cr = 1.01540 at a tip rotation of 20 degrees and
   1.15172 at 60 degrees (inextensible elastica).

What to look at
---------------
- the printed critical load and the load at 20 and 60 degrees of tip
  rotation against the elastica;
- ``load_rotation.png``: P / P_cr against the tip rotation, elastica points;
- ``shape.png`` and ``fibres.pvd``: the bent column (ParaView: *Tube* with
  ``radius``, colour by ``stress_33``: compression on one side, tension on
  the other).

Run: ``python3 demos/demo_buckled_column.py [--output DIR] [--elements N]``
(a few seconds).
"""
import argparse
import os

import numpy as np

import textile
from textile.analysis import linear_buckling
from textile.io import plot_curve

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--output", default=os.path.join(os.path.dirname(__file__), "output",
                                                     "demo_buckled_column"))
parser.add_argument("--elements", type=int, default=16, help="elements in the column")
args = parser.parse_args()

E, nu, R, L = 1.0e9, 0.3, 1e-3, 0.5
I = np.pi * R ** 4 / 4
P_euler = np.pi ** 2 * E * I / (4 * L ** 2)
mat = textile.Material(E, nu)


def column(load):
    """A clamped column along x with a dead end force ``load`` (3-vector)."""
    fibre = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, mat, num_elements=args.elements,
                                   section_vector=[0, 1, 0])
    model = textile.Model(fibre)
    model.clamp(fibre, 0)
    model.add_force(fibre, -1, load)
    return fibre, model


# 1. Linearized buckling: the load factor of P_euler at which the tangent
#    becomes singular (the two smallest: the round section buckles in two
#    planes at the same load).
_, model = column([-P_euler, 0, 0])
mu = linear_buckling(model, num=2)
if model.comm.rank == 0:
    print(f"critical load: {mu[0]:.6f} x Euler's pi^2 EI/(4 L^2) "
          f"(second mode {mu[1]:.6f}, the other bending plane)")

# 2. Post-buckling: compress to 1.2 P_cr with a small lateral perturbation.
P_max = 1.2 * P_euler
fibre, model = column([-P_max, 0, 1e-3 * P_euler])


def tip_rotation(m):
    """Angle (degrees) of the tip's tangent from the column's axis."""
    x = m.centreline(fibre)
    t = x[-1] - x[-2]
    return float(np.degrees(np.arctan2(abs(t[2]), t[0])))


output = textile.Output(args.output, extra=lambda m: {
    "load_over_euler": m.load_factor * P_max / P_euler,
    "tip_rotation_deg": tip_rotation(m),
    "tip_deflection": float(m.centreline(fibre)[-1, 2])})
# small steps near the bifurcation, growing afterwards
solver = textile.Solver(model, dict(initial_step=0.02, max_step=0.02, min_step=1e-4),
                        output=output)
solver.solve()

if model.comm.rank == 0:
    rec = output._log.records
    load = np.array([r["load_over_euler"] for r in rec])
    angle = np.array([r["tip_rotation_deg"] for r in rec])
    elastica = {20.0: 1.01540, 60.0: 1.15172}
    print("\npost-buckling (elastica: P/P_cr = 1.01540 at 20 deg, 1.15172 at 60 deg)")
    for a, ref in elastica.items():
        if angle.max() >= a:
            p = np.interp(a, angle, load)
            print(f"  tip rotation {a:4.0f} deg: P/P_cr = {p:.5f} (elastica {ref:.5f}, "
                  f"difference {100 * (p / ref - 1):+.2f}%)")
    plot_curve(os.path.join(args.output, "load_rotation.png"), angle, load,
               "tip rotation (degrees)", "P / P_cr", title="Clamped-free column: post-buckling",
               label="textile", reference=(list(elastica), list(elastica.values()),
                                           "inextensible elastica"))
    print(f"\nfiles in {args.output}: fibres.pvd, results.json, load_rotation.png, shape.png")
output.plot_shape(model, view="xz", title="Buckled column at 1.2 P_cr")
