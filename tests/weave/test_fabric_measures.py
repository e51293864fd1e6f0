"""Crimp, shrinkage, section shapes and curvature of a known yarn shape."""
import numpy as np
import pytest
import scipy.integrate
from mpi4py import MPI

import textile
from textile.fabric import Fabric, Yarn, measures as fm

MAT = textile.Material(1.0e9, 0.3)
R = 1e-3


def sine_state(amplitude, shrink):
    """Warp yarns bent to z = a sin(pi x / p) and shortened by ``shrink``
    (weft yarns left straight): a known crimp."""
    fab = Fabric(Yarn(7, R, MAT), num_warp=2, num_weft=2, spacing=10 * R,
                 elements_per_crossing=16)
    model = textile.Model(fab.fibres(), comm=MPI.COMM_SELF)
    model.setup()
    X = model.mesh.X_global
    u = np.zeros_like(X)
    p = fab.spacing[1]
    for f in np.flatnonzero(fab.fibre_yarn < fab.num_warp):
        nodes = model.mesh.fibre_nodes(f)
        x = X[nodes, 0]
        u[nodes, 0] = -shrink * x
        u[nodes, 2] = amplitude * np.sin(np.pi * x / p)
    arrays = [a.copy() for a in model.layout.get_local(model.x)]
    arrays[0][:] = u[model.mesh.local_to_global].ravel()
    model.layout.scatter(model.x, arrays)
    return fab, model, p


def test_crimp_and_shrinkage_of_a_sine():
    a, shrink = 2 * R, 0.05
    fab, model, p = sine_state(a, shrink)
    c = fm.crimp(fab, model)
    s = fm.shrinkage(fab, model)
    # exact: the arclength of z = a sin(pi x / p) over the warp's span,
    # compressed by (1 - shrink) along x
    half = fab.yarn_axis(0)[1][0]
    x = np.linspace(-half, half, 20001)
    dz = a * np.pi / p * np.cos(np.pi * x / p)
    arc = scipy.integrate.trapezoid(np.sqrt((1 - shrink) ** 2 + dz ** 2), x)
    span = 2 * half * (1 - shrink)
    # measured 1.5e-4 relative: the centre line is the polyline through the
    # nodes (64 segments a warp)
    assert c[:2] == pytest.approx((arc - span) / span, rel=1e-3)
    assert c[2:] == pytest.approx(0, abs=1e-14)  # wefts straight
    assert s[:2] == pytest.approx(shrink, rel=1e-12)
    assert s[2:] == pytest.approx(0, abs=1e-14)


def test_section_shapes_and_curvature():
    fab, model, p = sine_state(0.0, 0.0)
    shapes = fm.section_shapes(fab, model)
    assert len(shapes) == 2 * 4  # each crossing: the warp's and the weft's sections
    for x in shapes:  # undeformed 7-fibre hexagonal bundles: 6 R wide, 2 + 2 sqrt(3) R high
        assert x["width"] == pytest.approx(6 * R)
        assert x["height"] == pytest.approx((2 + 2 * np.sqrt(3)) * R)
    assert fm.fibre_curvatures(model).max() == pytest.approx(0, abs=1e-12)
    fab, model, p = sine_state(2 * R, 0.0)
    # a sine's largest curvature a (pi/p)^2 at its crests (discretized)
    kappa = fm.fibre_curvatures(model)
    assert kappa.max() == pytest.approx(2 * R * (np.pi / p) ** 2, rel=2e-2)
    summary = fm.summary(fab, model)
    assert summary["warp crimp"] > 0 and summary["weft crimp"] == pytest.approx(0, abs=1e-14)


def test_crossing_separation_reads_the_pattern():
    # warps on z = a sin(pi x / p): at the weft crossings x = -+p/2 they sit
    # at -+a; the 7-fibre yarns are 2 sqrt(3) R high (centre lines)
    a = 5 * R
    fab, model, p = sine_state(a, 0.0)
    sep = fm.crossing_separation(fab, model)
    h = 2 * np.sqrt(3) * R
    for (i, j, point, warp_on_top), s in zip(fab.crossings(), sep):
        z = a * np.sin(np.pi * point[0] / p)
        expected = (z - h) if warp_on_top else (-z - h)
        # linear interpolation between nodes of the sine (16 elements a pitch)
        assert s == pytest.approx(expected, abs=1e-3 * a)
