"""Yarns (packings) and fabrics (the straight, coplanar starting state)."""
import math

import numpy as np
import pytest

import textile
from textile.fabric import Fabric
from textile.yarn import Yarn

MAT = textile.Material(1.0e9, 0.3)
R = 1e-3


@pytest.mark.parametrize("count", [1, 7, 19, 28, 37])
def test_hexagonal_packing_touching_and_compact(count):
    y = Yarn(count, R, MAT)
    p = y.offsets
    assert p.shape == (count, 2)
    assert np.allclose(p.mean(axis=0), 0, atol=1e-15)
    if count > 1:
        d = np.hypot(*(p[:, None] - p[None]).transpose(2, 0, 1))
        d[np.diag_indices(count)] = np.inf
        assert d.min() == pytest.approx(2 * R)  # touching, never overlapping
    if count in (7, 19, 37):  # whole rings: round bundles
        rings = {7: 1, 19: 2, 37: 3}[count]
        assert y.width == pytest.approx(2 * R * (2 * rings + 1))


def test_layered_packing_is_flat():
    y = Yarn(28, R, MAT, packing="layers 2")
    assert y.height == pytest.approx(2 * R + math.sqrt(3) * R)
    assert y.width == pytest.approx(2 * R * 14 + R)  # 14 a row, staggered by a radius


def test_clearance_and_custom_offsets():
    assert Yarn(7, R, MAT, clearance=0.5).width == pytest.approx(2 * R * 1.25 * 2 + 2 * R)
    y = Yarn(2, R, MAT, packing=[[-R, 0], [R, 0]])
    assert y.width == pytest.approx(4 * R)


@pytest.mark.parametrize("kwargs,match", [
    (dict(count=0), "count must be a positive integer"),
    (dict(radius=-1e-3), "radius must be positive"),
    (dict(radius=float("nan")), "radius must be positive"),
    (dict(packing="square"), "unknown Yarn.packing"),
    (dict(packing="layers 0"), "number of layers"),
    (dict(count=2, packing=[[0, 0], [R, 0]]), "overlap"),
    (dict(count=2, packing=[[0, 0]]), r"\(2, 2\) array"),
    (dict(clearance=-1), "clearance must be >= 0"),
])
def test_bad_yarns(kwargs, match):
    args = dict(count=7, radius=R, material=MAT)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        Yarn(**args)


def test_starting_state_is_straight_coplanar_interpenetrating():
    yarn = Yarn(7, R, MAT)
    fab = Fabric(yarn, num_warp=2, num_weft=4, spacing=(8 * R, 10 * R), pattern="plain")
    fibres = fab.fibres()
    assert len(fibres) == 6 * 7
    assert fab.fibre_yarn.tolist() == [k for k in range(6) for _ in range(7)]
    assert [fab.yarn_direction(k) for k in range(6)] == ["warp"] * 2 + ["weft"] * 4
    # yarn axes in z = 0 (the bundles' centroids), every fibre straight
    for k in range(6):
        members = [f for f, y in zip(fibres, fab.fibre_yarn) if y == k]
        centroid = np.mean([f.points for f in members], axis=0)
        assert np.allclose(centroid[:, 2], 0, atol=1e-15)
        for f in members:
            d = f.points[-1] - f.points[0]
            assert np.allclose(np.cross(f.points - f.points[0], d), 0, atol=1e-15)
            assert np.allclose(f.g2, [0, 0, 1])  # G2 vertical
    # a warp and a weft cross at the right place and interpenetrate there
    (i, j, point, warp_on_top), = [c for c in fab.crossings() if c[0] == 1 and c[1] == 0]
    assert point == pytest.approx([-5 * R, -4 * R, 0])
    assert warp_on_top == bool(fab.order[1, 0]) == False  # noqa: E712 (plain weave)
    # warps span the wefts plus the free length (half the smallest spacing)
    a, b = fab.yarn_axis(0)
    assert b[0] - a[0] == pytest.approx(3 * 10 * R + 2 * 4 * R)


def test_twisted_yarn_makes_helices():
    yarn = Yarn(7, R, MAT, twist=1 / (40 * R))  # one turn over 40 radii
    fab = Fabric(yarn, num_warp=2, num_weft=2, spacing=(10 * R, 20 * R), elements_per_crossing=8)
    outer = fab.fibres()[1]  # a fibre of the first ring
    r = np.hypot(outer.points[:, 1] - fab.yarn_axis(0)[0][1], outer.points[:, 2])
    assert np.allclose(r, 2 * R)  # stays on its ring while turning
    angle = np.unwrap(np.arctan2(outer.points[:, 2], outer.points[:, 1] - fab.yarn_axis(0)[0][1]))
    length = np.ptp(outer.points[:, 0])
    assert angle[-1] - angle[0] == pytest.approx(2 * math.pi * length / (40 * R))


@pytest.mark.parametrize("kwargs,match", [
    (dict(num_warp=0), "num_warp must be a positive integer"),
    (dict(spacing=-1.0), "warp spacing must be positive"),
    (dict(spacing=(1.0, 0.0)), "weft spacing must be positive"),
    (dict(spacing=5 * R), "warp yarns are 0.006 wide.*only 0.005 apart"),
    (dict(pattern="herringbone"), "unknown weave pattern"),
    (dict(pattern=[[1, 2], [0, 1]]), r"entry \(0, 1\) is 2"),
    (dict(pattern="twill 2/2"), "does not fit 2 weft x 2 warp yarns"),
    (dict(free_length=0), "free_length must be positive"),
])
def test_bad_fabrics_fail_before_any_computation(kwargs, match):
    args = dict(warp=Yarn(7, R, MAT), num_warp=2, num_weft=2, spacing=10 * R)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        Fabric(**args)
