"""Fabric-level results against independent references (issue 22, item 3):
the woven shape of a monofilament plain weave and its small-strain tension,
against the crimped-yarn beam of tests/virtual/crimped_yarn.py (a plane
Timoshenko beam between the clamps, held at the crossings; derived there);
the bending of a frictionless strip between its fibres' own stiffness and
the fully bonded section's (test_frictionless_strip_bends_as_its_fibres).

The sample is the virtual tests' 2 x 2 plain weave of monofilaments (R = 0.1
mm, E = 5 GPa, nu = 0.35) 6 yarn widths apart (1.2 mm), woven with the
weaving tension 1e-4 E A. The picture frame's kinematics to locking against
the pin-joint model are in test_picture_frame.py
(test_locking_angle_grows_with_spacing).
"""
import math
import os
import tempfile

import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.virtual_tests import Bending, Tension
from textile.fabric import Weaving

from tests.virtual.crimped_yarn import CrimpedYarn
from tests.woven_states import plain_weave

R = 0.1e-3
FIBRE = textile.Material(5.0e9, 0.35)
EA = FIBRE.young * math.pi * R ** 2
EI = FIBRE.young * math.pi * R ** 4 / 4
QUIET = dict(verbose=False)


def fabric():
    return plain_weave(FIBRE, R)


@pytest.fixture(scope="module")
def woven(tmp_path_factory):
    """(the weaving run, the path of its saved woven state): woven on this
    rank alone (half a second)."""
    f = fabric()
    weaving = Weaving(f, comm=MPI.COMM_SELF)
    weaving.run(solver_options=QUIET)
    path = str(tmp_path_factory.mktemp("woven") / "woven.h5")
    textile.save_state(weaving.model, path, fibre_data={"yarn": f.fibre_yarn})
    return weaving, path


def quadratic_at(s, nodes_s, nodes_z):
    """z at s on a centre line of quadratic elements (node triplets)."""
    e = min(int(np.searchsorted(nodes_s, s, side="right") - 1) // 2, (len(nodes_s) - 3) // 2)
    ss, zz = nodes_s[2 * e:2 * e + 3], nodes_z[2 * e:2 * e + 3]
    return float(sum(zz[a] * np.prod([(s - ss[b]) / (ss[a] - ss[b]) for b in range(3) if b != a])
                     for a in range(3)))


def yarns(weaving):
    """Per yarn (monofilaments: yarn k is fibre k): its model
    (CrimpedYarn, heights from the woven state), the woven centre line
    (along-yarn coordinate, height), its length and its crossing forces
    (contact normal forces, per crossing yarn)."""
    f, model = weaving.fabric, weaving.model
    lines = [model.centreline(k) for k in range(f.num_yarns)]
    contact = weaving.contact.elements()
    out = []
    for k, line in enumerate(lines):
        along, across = (0, 1) if f.yarn_direction(k) == "warp" else (1, 0)
        s, z = line[:, along], line[:, 2] - line[0, 2]
        others = [j for j in range(f.num_yarns) if f.yarn_direction(j) != f.yarn_direction(k)]
        # where each crossing yarn passes: its position along this yarn, at
        # this yarn's transverse position
        at = [float(np.interp(line[0, across], lines[j][:, across], lines[j][:, along]))
              for j in others]
        heights = [quadratic_at(c, s, z) for c in at]
        forces = []
        for j in others:
            pair = ((contact["fibre_i"] == k) & (contact["fibre_j"] == j)) | \
                   ((contact["fibre_i"] == j) & (contact["fibre_j"] == k))
            forces.append(float(contact["normal_force"][pair].sum()))
        beam = CrimpedYarn((s[0], s[-1]), at, heights, FIBRE.young, FIBRE.poisson, R,
                           tension=weaving.tension * EA)
        length = float(np.linalg.norm(np.diff(line, axis=0), axis=1).sum())
        out.append(dict(beam=beam, s=s, z=z, heights=np.array(heights),
                        forces=np.array(forces), length=length,
                        direction=f.yarn_direction(k)))
    return out


def test_woven_shape_is_the_crimped_beam(woven):
    """Reference (d): every yarn of the woven monofilament plain weave has
    the shape of the beam held at its crossing heights (the heights, 0.91
    to 1.01 R, taken from the woven state), and the contact holds it there
    with the beam's crossing forces.

    Measured: centre lines within 1.5-1.7% of the crossing height of the
    beam's (1.7 micrometres), crossing forces 2.1 to 2.3 N, the beam's 3.0
    to 3.2% below them. The model's error: small rotations, while the
    yarns turn by up to 0.25 rad (a few %, its square's order), the crossing
    yarn as a point. Tolerances: 5% of the height for the shape, 10% for
    the forces, about 3 times the measured."""
    for yarn in yarns(woven[0]):
        beam = yarn["beam"]
        model_z, model_forces = beam.woven_shape()
        a = np.abs(yarn["heights"]).max()
        assert 0.85 * R < a < 1.05 * R   # crossing heights: crimp of the order of R
        deviation = np.abs(np.interp(yarn["s"], beam.x, model_z) - yarn["z"]).max()
        assert deviation < 0.05 * a, (yarn["direction"], deviation / a)
        # the beam's crossing forces (on the yarn, along z) against the
        # contact's normal forces (their magnitude: the normal is vertical
        # at a crossing)
        assert np.allclose(np.abs(model_forces), yarn["forces"], rtol=0.10), \
            (model_forces, yarn["forces"])


def test_small_strain_tension_is_the_crimp_interchange_model(woven):
    """Reference (a): uniaxial tension (warp ends clamped, weft ends free),
    0.1% strain in one step. Each warp yarn is the crimped beam pulled with
    its crossings free (the weft yarns turn about their axes at no cost):
    end force per displacement k = 1 / (s / (E A) + f . K^-1 f), the crimp
    straightening against the yarn's bending and shear (crimped_yarn.py).
    The fabric's force per strain is the gauge length times the sum over
    the warp yarns.

    Measured: 0.5153 of the straight yarns' 2 E A (secant over 0.1%),
    the model 0.5077 (0.521 and 0.494 for the two warps): 1.5% apart. The
    model's error: the secant against the model's tangent (the curve
    stiffens: 0.5153 over 0.1%, 0.5230 over 0.2%, so the secant lies about
    1% above the tangent); small rotations (a few % in the woven shape,
    test above); the contact loop's update tolerance (1e-3 of the contact
    forces, 2 N, against a force increment of 0.16 N: 1.3%). Tolerance 3%,
    twice the measured: the secant's bias alone is 1%."""
    weaving, path = woven
    test = Tension(fabric(), path, 1e-3, steps=1, comm=MPI.COMM_SELF)
    x, y = test.run().curve.arrays()
    secant = (y[1] - y[0]) / (x[1] - x[0])
    warps = [yarn for yarn in yarns(weaving) if yarn["direction"] == "warp"]
    model = test.gauge * sum(y["beam"].tension_stiffness(y["length"]) for y in warps)
    assert secant == pytest.approx(model, rel=0.03)
    # both well below the straight yarns' 2 E A: the crimp halves it
    assert model < 0.6 * 2 * EA


class FrictionlessStripBending(Bending):
    """Bending (opposite rotations of the warp ends about y, xmax free along
    x) of a frictionless sample whose weft ends' bodies keep their spin
    (about y, a weft's own axis) and their turn about z: without friction a
    monofilament weft could spin, and turn about z at the crossings, at no
    cost (zero-stiffness modes: Newton fails on an inverted element). Both
    holds are rotations that the strip's bending about y does not ask of
    the wefts' ends through frictionless (normal, centre-line) contacts."""

    def drive(self):
        for body in self.sample.end_bodies:
            body.fix(("ry", "rz"))
        return super().drive()


def strip_bending(spacing):
    """(measured, lower, upper) bending stiffnesses (moment per unit
    curvature, curvature = bending angle over the gauge) of the 2 x 2
    monofilament plain weave ``spacing`` yarn widths apart, friction 0, bent
    by 1 degree in 2 steps; the bounds of
    test_frictionless_strip_bends_as_its_fibres from its woven state."""
    f = plain_weave(FIBRE, R, spacing=spacing)
    weaving = Weaving(f, comm=MPI.COMM_SELF)
    weaving.run(solver_options=QUIET)
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "woven.h5")
        textile.save_state(weaving.model, path, fibre_data={"yarn": f.fibre_yarn})
        test = FrictionlessStripBending(plain_weave(FIBRE, R, spacing=spacing), path,
                                        math.radians(1.0), steps=2,
                                        contact=dict(friction=0.0), comm=MPI.COMM_SELF)
        measured = test.run().figures["stiffness (moment per unit curvature)"]
    warps = [weaving.model.centreline(k) for k in range(f.num_yarns)
             if f.yarn_direction(k) == "warp"]
    lengths = [np.linalg.norm(np.diff(line, axis=0), axis=1).sum() for line in warps]
    lower = sum(EI * test.gauge / s for s in lengths)
    x = np.linspace(warps[0][0, 0], warps[0][-1, 0], 4001)
    z = np.array([np.interp(x, line[:, 0], line[:, 2]) for line in warps])
    bonded = (EI + EA * (z - z.mean(axis=0)) ** 2).sum(axis=0)
    compliance = float(np.sum(0.5 * (1 / bonded[1:] + 1 / bonded[:-1]) * np.diff(x)))
    return measured, lower, test.gauge / compliance


def test_frictionless_strip_bends_as_its_fibres():
    """Reference (b): a frictionless woven strip bends with the stiffness of
    its fibres sliding freely, far below the fully bonded section.

    The strip: the 2 x 2 monofilament plain weave, bent about y by its warp
    ends (Bending: xmax free along x, so the end rotations are the only
    load: a constant moment M along the strip), friction 0. Per unit
    curvature k = M g / theta (theta: the bending angle, g: the gauge).

    Lower bound, the fibres sliding freely: contacts that carry no
    tangential force cannot make the strip softer than its warp fibres
    without contact (fewer constraints, less stiffness; the wefts are not
    held by the bent sides, so alone they carry nothing). Each warp fibre,
    clamped at both ends and turned by theta with no end force, carries M_i
    with curvature change M_i / (E I) along its length s_i:
    theta = M_i s_i / (E I), so k >= sum_i E I g / s_i (s_i > g by the
    crimp).

    Upper bound, the fully bonded section: gluing the warps into one beam
    whose sections stay plane adds constraints: at x its bending stiffness
    is E I_b(x) = sum_i E (I + A (z_i(x) - zbar(x))^2), z_i the warps'
    woven heights, zbar their mean (the neutral axis of equal fibres), and
    under a constant moment theta = M int dx / (E I_b), so
    k <= g / int dx / (E I_b(x)). The wefts left out only lower this bound
    (bonded, they would stiffen it where they cross), so it stays an upper
    one. With crossing heights about 0.98 R it is 1.92 times the lower.

    Both bounds are those of an unstressed strip. The woven strip is not:
    its crossings carry the forces that hold the crimp (of the order of
    pi^4 E I a / p^3 for a crimp amplitude a over a spacing p), and their
    geometric stiffness softens the tangent below the lower bound.
    Measured (k over the lower bound): 0.805 at 24 yarn widths, 0.965 at
    48, 0.9939 at 96; the deficit falls 5.5-5.8 times a doubling of the
    spacing, faster than (R / p)^2 (4 times); at 12 widths k is 0.03 of the
    lower bound, at 6 (the other tests' sample) negative. So the reference
    is taken where the crimp is shallow, 96 yarn widths apart (p = 192 R,
    crossing heights 0.98 R): k 0.61% below the lower bound, the bonded
    bound 92% above it. (Friction changes little there: 1.0005 of the lower
    bound with friction 0.2 or 1, the crossing forces it scales being
    small.) What this catches: a wrong bending stiffness of the beam, a
    wrong moment or curvature in Bending's figure, stiffness from contacts
    that should carry no tangential force. Tolerances: within 2% of the
    lower bound, 3 times the measured deficit; the deficit at 48 widths at
    least 3 times the one at 96 (measured 5.8), as a pre-stress vanishing
    with (R / p)^2 or faster does, and an error of the beam or of the
    measure would not."""
    measured, lower, upper = strip_bending(96.0)
    assert upper > 1.5 * lower                                  # far apart: 1.92 measured
    assert lower * (1 - 0.02) < measured < lower * (1 + 0.02), (measured / lower)
    assert measured < upper
    closer, closer_lower, _ = strip_bending(48.0)
    deficit = 1 - measured / lower
    assert 1 - closer / closer_lower > 3 * deficit, (closer / closer_lower, measured / lower)
