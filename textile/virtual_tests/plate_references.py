"""Closed-form references of a composite sample bent or twisted as a plate
(the virtual tests' Bending and Twisting with a matrix).

The sample: the matrix box of a :class:`~textile.composite.Composite`,
length L along x (between the driven sides xmin and xmax), width b along y,
thickness h along z; matrix modulus E, Poisson ratio nu, G = E / (2 (1 +
nu)). The fibres are superposed on the matrix (the matrix also fills their
volume), so each adds its own full stiffness. Moments are per radian of the
angle between the two sides (the tests' curves are in degrees).

**Bending** (rotations about y). Two limits bracket the stiffness M / angle:

- *lower*, E b h^3 / 12 / L + sum over the warp fibres of E_f I_f / L: the
  matrix free to curl across its width (anticlastic curvature, beam
  bending; the rigid side faces, which hold it, only stiffen it) and the
  fibres not bonded to it (each bent about its own axis);
- *upper*, (D b + sum over the warp fibres of E_f (I_f + A_f <z^2>)) / L
  with D = E h^3 / (12 (1 - nu^2)): the matrix in plane strain across its
  width (anticlastic curvature fully blocked) and the fibres perfectly
  bonded, each stretched as the plate's fibre at its height z above the
  mid-plane (<z^2>: along the fibre, in the woven configuration).

The weft fibres, along y, are not bent by a cylindrical bending about y.
The upper limit is an estimate, not a strict bound: the rigid side faces
also hold the faces' thickness, and a displacement finite element mesh is
stiffer than the solid it meshes; tests/virtual/test_composite_tests.py
measures where the composite lies between the two.

**Twisting** (rotations about x). Free (St Venant) torsion of a thin
rectangle, G J / L with J = b h^3 / 3 (1 - 0.63 h / b) (the exact series
within 1e-4 for b / h > 4), is a lower bound of the matrix plate's: the
rigid side faces also hold the sections' warping. Vlasov's estimate with
the warping held at both ends (G J phi'' = E_w phi'''', E_w = D b^3 / 12
the plate strip's warping rigidity) is M / angle = G J / L / (1 - tanh(m) /
m), m = (L / 2) sqrt(G J / E_w); from its one-dimensional warping field it
overshoots a fine-mesh matrix plate as long as wide by 16%.
"""
from __future__ import annotations

import math

import numpy as np


def box(composite) -> tuple[float, float, float]:
    """Length (x), width (y) and thickness (z) of the matrix box."""
    length, width, thickness = composite.corners[1] - composite.corners[0]
    return float(length), float(width), float(thickness)


def warp_fibre_sections(composite) -> tuple[float, float]:
    """(sum of E_f I_f, sum of E_f A_f <z^2>) over the warp fibres, z the
    height above the matrix box's mid-plane in the woven configuration,
    averaged along x."""
    fabric, mesh = composite.fabric, composite.model.mesh
    mid = 0.5 * (composite.corners[0][2] + composite.corners[1][2])
    own, offset = 0.0, 0.0
    for f, fibre in enumerate(mesh.fibres):
        if fabric.yarn_direction(fabric.fibre_yarn[f]) != "warp":
            continue
        nodes = [mesh.node(f, k) for k in range(fibre.num_nodes)]
        x, z = composite.configuration[nodes, 0], composite.configuration[nodes, 2] - mid
        mean_z2 = np.trapz(z ** 2, x) / (x[-1] - x[0])
        E, r = fibre.material.young, fibre.radius
        own += E * math.pi * r ** 4 / 4
        offset += E * math.pi * r ** 2 * mean_z2
    return own, offset


def bending_bracket(composite) -> tuple[float, float]:
    """(lower, upper) bending stiffness, moment per radian of the bending
    angle (module docstring)."""
    length, b, h = box(composite)
    E, nu = composite.matrix.young, composite.matrix.poisson
    own, offset = warp_fibre_sections(composite)
    lower = (E * b * h ** 3 / 12 + own) / length
    upper = (E * b * h ** 3 / (12 * (1 - nu ** 2)) + own + offset) / length
    return lower, upper


def matrix_plate_bending(composite) -> float:
    """D b / L: the matrix plate in cylindrical bending, moment per radian."""
    length, b, h = box(composite)
    E, nu = composite.matrix.young, composite.matrix.poisson
    return E * b * h ** 3 / (12 * (1 - nu ** 2)) / length


def torsion(composite) -> dict:
    """The matrix plate's twisting stiffnesses, moment per radian of the
    twist angle: ``free`` (St Venant) and ``held`` (Vlasov, warping held at
    both ends); module docstring."""
    length, b, h = box(composite)
    E, nu = composite.matrix.young, composite.matrix.poisson
    GJ = E / (2 * (1 + nu)) * b * h ** 3 / 3 * (1 - 0.63 * h / b)
    warping = E * h ** 3 / (12 * (1 - nu ** 2)) * b ** 3 / 12
    m = 0.5 * length * math.sqrt(GJ / warping)
    free = GJ / length
    return {"free": free, "held": free / (1 - math.tanh(m) / m)}
