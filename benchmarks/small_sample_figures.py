"""Figures of the virtual tests on the tests' small sample, measured, not
asserted: the 2 x 2 plain weave of monofilaments (R = 0.1 mm, E = 5 GPa,
nu = 0.35) 6 yarn widths apart of tests/virtual/test_fabric_tests.py.

Prints:

- the membrane stiffness (force per width per strain) in uniaxial tension
  (1% in 4 steps) and biaxial tension at weft/warp strain ratios 0, 0.5, 1
  (1% in 2 steps): the crimp interchange;
- the shear curve against its mirror (0.2 spacings in 5 steps, each way):
  the largest sum of the two force increments over the largest increment;
- bending (10 deg in 4 steps, 1 deg in 2): the moment per radian against
  the sum of the warp fibres' own bending stiffnesses E I / s (s: each
  fibre's length), the frictionless strip's reference, which for
  monofilaments equals the fully bonded section's;
- twisting (10 deg in 4 steps, 1 deg in 2): the moment per radian against
  the warp yarns as straight clamped beams twisted about the sample's axis,
  sum of G J / L + 12 E I y^2 / L^3 (y: each warp's distance from the axis,
  L the gauge length).

    .venv/bin/python benchmarks/small_sample_figures.py
"""
from __future__ import annotations

import math
import os
import sys
import tempfile

import numpy as np
from mpi4py import MPI

import textile
from textile import runtime
from textile.virtual_tests import Bending, Shear, Tension, Twisting
from textile.fabric import woven_state

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from tests.woven_states import plain_weave  # noqa: E402  (the tests' sample)

R = 0.1e-3
FIBRE = textile.Material(5.0e9, 0.35)
E, NU = FIBRE.young, FIBRE.poisson
I, G = math.pi * R ** 4 / 4, FIBRE.young / (2 * (1 + FIBRE.poisson))
COMM = MPI.COMM_SELF


def increments(result):
    x, y = result.curve.arrays()
    return x - x[0], y - y[0]


def warp_lengths(test):
    sample, mesh = test.sample, test.sample.model.mesh
    out = []
    for f, fibre in enumerate(mesh.fibres):
        if sample.fabric.yarn_direction(sample.fabric.fibre_yarn[f]) == "warp":
            x = sample.configuration[[mesh.node(f, k) for k in range(fibre.num_nodes)], 0:3]
            out.append(float(np.linalg.norm(np.diff(x, axis=0), axis=1).sum()))
    return out


def main():
    print(runtime.describe())
    woven = os.path.join(tempfile.mkdtemp(), "woven.h5")
    woven_state(plain_weave(FIBRE, R), woven, dict(verbose=False), COMM, report=False)
    key = "membrane stiffness (force per width per strain)"
    r = Tension(plain_weave(FIBRE, R), woven, 0.01, steps=4, comm=COMM).run()
    print(f"uniaxial tension: {r.figures[key]:.4g} N/m")
    for ratio in (0.0, 0.5, 1.0):
        r = Tension(plain_weave(FIBRE, R), woven, 0.01, ratio=ratio, steps=2, comm=COMM).run()
        print(f"biaxial tension, ratio {ratio}: {r.figures[key]:.4g} N/m")
    spacing = plain_weave(FIBRE, R).spacing[0]
    (xp, yp), (xm, ym) = (increments(Shear(plain_weave(FIBRE, R), woven, u, steps=5,
                                           comm=COMM).run())
                          for u in (0.2 * spacing, -0.2 * spacing))
    print(f"shear mirror: {np.abs(yp[1:] + ym[1:]).max() / np.abs(yp[1:]).max():.2e} of the "
          f"largest force")
    for degrees, steps in ((10.0, 4), (1.0, 2)):
        test = Bending(plain_weave(FIBRE, R), woven, math.radians(degrees), steps=steps,
                       comm=COMM)
        x, y = increments(test.run())
        reference = sum(E * I / s for s in warp_lengths(test))
        print(f"bending to {degrees} deg: M / angle over sum E I / s = "
              f"{np.round(y[1:] / np.radians(x[1:]) / reference, 3)}")
    for degrees, steps in ((10.0, 4), (1.0, 2)):
        test = Twisting(plain_weave(FIBRE, R), woven, math.radians(degrees), steps=steps,
                        comm=COMM)
        x, y = increments(test.run())
        ends = test.sample.end_positions("xmax")
        L = test.gauge
        reference = sum(G * 2 * I / L + 12 * E * I * d ** 2 / L ** 3
                        for d in ends[:, 1] - ends[:, 1].mean())
        print(f"twisting to {degrees} deg: M / angle over the straight clamped warps' = "
              f"{np.round(y[1:] / np.radians(x[1:]) / reference, 3)}")


if __name__ == "__main__":
    main()
