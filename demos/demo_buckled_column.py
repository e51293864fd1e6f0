"""Euler buckling and post-buckling of a clamped-free column
=========================================================

This demo shows how to

* find a critical load with linearized buckling
  (:func:`textile.stability.buckling.linear_buckling`),
* follow the post-buckling path of the same column by load stepping, with a
  tiny lateral force that picks the buckling direction,
* record a load curve with ``on_step`` and ``Output(extra=...)``.

Physics
-------
A straight fibre of length :math:`L = 0.5` and radius :math:`R = L / 2000`
(a fibre's slenderness: a glass filament of 7 micrometres radius is 14 mm
long at that; ``--slenderness`` sets L/R), :math:`I = \\pi R^4/4`,
:math:`E = 1` GPa and :math:`\\nu = 0.3`, is
clamped at its base and compressed by a dead axial force :math:`P` on its
free end. Euler's critical load of this clamped-free column is

.. math:: P_{cr} = \\pi^2 E I / (4 L^2).

1. **Critical load.** ``linear_buckling`` evaluates the tangent of the
   unloaded column :math:`K_0` and the tangent under a small load
   :math:`K_1`; the geometric stiffness is their difference and the
   critical load factors are the smallest :math:`\\mu` with
   :math:`\\det(K_0 + \\mu K_g) = 0`. Because the round section buckles
   equally in both bending planes the two smallest factors coincide. At
   :math:`\\nu = 0.3` Euler's value is only recovered because the element
   cures Poisson locking of the deformable section (a locked section would
   make the column :math:`(1-\\nu)/((1+\\nu)(1-2\\nu)) = 1.35` times too
   stiff in bending).

2. **Post-buckling.** Past :math:`P_{cr}` the straight column is unstable
   and bends sideways along the *elastica*: the inextensible elastica of a
   clamped-free column with tip rotation :math:`\\alpha` carries
   :math:`P / P_{cr} = (2 K(\\sin(\\alpha/2)) / \\pi)^2` (:math:`K` the
   complete elliptic integral of the first kind), e.g. 1.01540 at
   :math:`\\alpha = 20` degrees and 1.15172 at 60 degrees. A lateral force
   of :math:`10^{-4} P_{cr}` (along z) breaks the symmetry and picks the
   side; it is small enough not to shift the curve visibly. Load control
   cannot tell the branches apart: past :math:`P_{cr}` Newton may well
   converge to the straight column, an unstable equilibrium. The solver's
   stability check sees it (two negative eigenvalues of the tangent, one
   per bending plane, however tiny next to the column's axial stiffness)
   and branch switching (on by default) moves the column onto the buckled
   branch, on the side the lateral force pushes. Steps of 0.01 draw the
   curve; with ``--step 0.05`` the column is found straight and unstable
   past :math:`P_{cr}` and switched (printed on the log).

What to look at
---------------
The printed critical load against Euler's and P/P_cr at 20 and 60 degrees
of tip rotation against the elastica. In
``demos/output/demo_buckled_column/``:

* ``fibres.pvd`` in ParaView: play the series; nothing visible happens until
  the load factor passes :math:`1/1.2 = 0.83`, then the column swings out
  in the xz plane. *Tube* filter with ``radius``, colour by ``displacement``;
  glyph ``g2`` to see the tip section turn.
* ``load_rotation.png``: P/P_cr against the tip rotation with the elastica
  curve (dashed) and its two tabulated points;
* ``load_deflection.png``: P/P_cr against the lateral tip deflection w/L;
* ``shape.png``: the bent column at 1.2 P_cr (xz plane) over the straight
  one;
* ``results.json``: per step, P/P_cr, tip rotation and deflection.

Running
-------
::

    python3 demos/demo_buckled_column.py [--output DIR] [--elements N] [--slenderness L/R]
        [--step DT]

The defaults (16 quadratic elements, L/R = 2000, steps of 0.01) run in a
few seconds. At the end the demo checks that every recorded state is
stable and that the last one is on the elastica (``FINAL_TOLERANCE``).
"""

import argparse
import os

import numpy as np
import scipy.special
from mpi4py import MPI

import textile
from textile.stability.buckling import linear_buckling
from textile.io.plots import plot_curve

parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
parser.add_argument("--output", default=os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                     "output", "demo_buckled_column"),
                    help="directory for the ParaView series, results.json and PNGs")
parser.add_argument("--elements", type=int, default=16, help="number of quadratic elements")
parser.add_argument("--slenderness", type=float, default=2000.0,
                    help="length over radius of the column (a fibre: 10^3 to 10^4)")
parser.add_argument("--step", type=float, default=0.01,
                    help="load step (fraction of 1.2 P_cr); larger steps land on the "
                         "unstable straight column, which branch switching leaves")
args, _ = parser.parse_known_args()  # PETSc options pass through
comm = MPI.COMM_WORLD

# Column and reference values
# ---------------------------

E, nu, L = 1.0e9, 0.3, 0.5
R = L / args.slenderness
I = np.pi * R**4 / 4
P_euler = np.pi**2 * E * I / (4 * L**2)
material = textile.Material(E, nu)


def elastica_load(alpha):
    """P/P_cr of the inextensible clamped-free elastica at tip rotation alpha
    (radians): (2 K(k) / pi)^2 with k = sin(alpha / 2); scipy's ellipk takes
    the parameter m = k^2."""
    return (2 * scipy.special.ellipk(np.sin(np.asarray(alpha) / 2) ** 2) / np.pi) ** 2


def column(force):
    """A fresh model: the column along x, clamped at node 0, a dead force
    (3-vector, reached at load factor 1) on its tip. g1 = y, so g2 = z lies
    in the plane in which the perturbation makes it buckle (xz)."""
    fibre = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, material,
                                   num_elements=args.elements, section_vector=[0, 1, 0],
                                   name="column")
    model = textile.Model(fibre)
    model.clamp(0, 0)
    model.add_force(0, -1, force)
    return model


# 1. Linearized buckling
# ----------------------
#
# The load is Euler's force, so the critical factors are P_cr / P_euler.
# linear_buckling needs a model in its unloaded state (it solves one small
# probe step itself), hence a model of its own.

mu = linear_buckling(column([-P_euler, 0, 0]), num=2)
P_cr = mu[0] * P_euler
if comm.rank == 0:
    print(f"Linear buckling: P_cr = {P_cr:.6e} N, Euler pi^2 EI/(4 L^2) = {P_euler:.6e} N, "
          f"ratio {mu[0]:.6f}")
    print(f"  second factor {mu[1]:.6f} (the other bending plane of the round section)\n")

# 2. Post-buckling path
# ---------------------
#
# A new model: compression growing to 1.2 P_cr plus the perturbation along z.

P_max = 1.2 * P_cr
model = column([-P_max, 0, 1e-4 * P_cr])


def tip_state(model):
    """P/P_cr, tip rotation (degrees, from the tip's section vector g2, which
    starts along z and turns with the section in the xz plane) and lateral
    tip deflection w/L."""
    g1, g2 = model.section_vectors(0)
    alpha = np.degrees(np.arctan2(-g2[-1, 0], g2[-1, 2]))
    w = model.centreline(0)[-1, 2]
    return dict(load_over_pcr=model.load_factor * P_max / P_cr,
                tip_rotation_deg=float(alpha), tip_deflection_over_L=float(w / L))


output = textile.Output(args.output, extra=tip_state)
curve = [tip_state(model)]  # the unloaded state, then one entry per step
solver = textile.Solver(model, dict(initial_step=args.step, max_step=args.step),
                        output=output, on_step=lambda s, rec: curve.append(tip_state(s.model)))
solver.solve(1.0)

load = np.array([c["load_over_pcr"] for c in curve])
alpha = np.array([c["tip_rotation_deg"] for c in curve])
w = np.array([c["tip_deflection_over_L"] for c in curve])

# Comparison with the elastica
# ----------------------------
#
# The computed curve is interpolated at the tabulated rotations (the tip
# rotation grows monotonically along the path).

elastica = {20.0: 1.01540, 60.0: 1.15172}
#: |P / P_elastica - 1| at 1.2 P_cr: measured at most 0.040% (8 and 16 elements, L/R
#: 500 to 10^4, steps 0.01 to 0.1)
FINAL_TOLERANCE = 1e-3
if comm.rank == 0:
    assert np.all(np.diff(alpha) >= -1e-9), "the path must not turn back"
    print("\nPost-buckling: P/P_cr at given tip rotations, textile vs inextensible elastica")
    print(f"{'rotation':>9} {'textile':>9} {'elastica':>9} {'diff':>8}")
    for a, ref in elastica.items():
        p = np.interp(a, alpha, load) if alpha[-1] >= a else float("nan")
        print(f"{a:7.0f} deg {p:9.5f} {ref:9.5f} {100 * (p / ref - 1):+7.3f}%")
    final = elastica_load(np.radians(alpha[-1]))
    print(f"At 1.2 P_cr: tip rotation {alpha[-1]:.2f} deg, tip deflection w/L = {w[-1]:.4f}; "
          f"the elastica carries {final:.5f} P_cr at that rotation "
          f"({100 * (load[-1] / final - 1):+.3f}%)")
    # every recorded state stable, the last one on the elastica (the
    # unstable straight column has no rotation at all)
    assert all(h.stability["negative_eigenvalues"] == 0 for h in solver.history)
    assert abs(load[-1] / final - 1) < FINAL_TOLERANCE, "the column is off the elastica"

# Plots
# -----
#
# Load against rotation with the elastica dashed and its tabulated points
# (one-point curves: markers only), load against deflection, and the bent column.

if comm.rank == 0:
    a_ref = np.linspace(0, np.radians(alpha[-1]), 200)
    plot_curve(os.path.join(args.output, "load_rotation.png"),
               [alpha] + [[a] for a in elastica], [load] + [[p] for p in elastica.values()],
               "tip rotation [deg]", "P / P_cr",
               title="Clamped-free column: post-buckling",
               label=["textile"] + [f"elastica {a:.0f} deg: {p:.5f}" for a, p in elastica.items()],
               reference=(np.degrees(a_ref), elastica_load(a_ref), "inextensible elastica"))
    plot_curve(os.path.join(args.output, "load_deflection.png"), w, load,
               "lateral tip deflection w / L", "P / P_cr",
               title="Clamped-free column: tip deflection", label="textile")
output.plot_shape(model, "shape.png", view="xz", title="Buckled column at 1.2 P_cr")
if comm.rank == 0:
    print(f"\nWrote {args.output}/fibres.pvd, results.json, load_rotation.png, "
          f"load_deflection.png, shape.png")
