"""Yarns (packings, twist) and fabrics (the straight, coplanar starting state)."""
import math

import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.fabric import Fabric, Weaving
from textile.fabric.fabric import interpolated_section_scale
from textile.fabric.yarn import Yarn, helix_distances, round_rings

MAT = textile.Material(1.0e9, 0.3)
R = 1e-3


def centre_distances(p):
    d = np.hypot(*(p[:, None] - p[None]).transpose(2, 0, 1))
    d[np.diag_indices(len(p))] = np.inf
    return d


def same_set(p, q):
    """The point sets p and q (fibres 2 R apart or more) are equal to round-off:
    every point of each has one of the other within 1e-12 R."""
    d = np.hypot(*(p[:, None] - q[None]).transpose(2, 0, 1))
    return len(p) == len(q) and max(d.min(axis=0).max(), d.min(axis=1).max()) < 1e-12 * R


# -- packings -----------------------------------------------------------------------------
@pytest.mark.parametrize("packing", ["hexagonal", "round"])
def test_packings_touch_without_overlap(packing):
    """Every count up to 37: centred, no two fibres closer than a diameter,
    the closest touching, the bundle no wider than the smallest full rings
    (7, 19, 37 fibres: 3R, 5R, 7R) that hold it, but for a hexagonal bundle
    one short of them (6, 18, 36): its rings have a gap and it is re-centred
    (6: a centre and 5 of 6, outer radius (1 + sqrt(43)/3) R = 3.186 R; the
    ring of 6 alone would be 3R round a hole a fibre fits in)."""
    short = {6: 1 + math.sqrt(43) / 3, 18: 5.116, 36: 7.085}  # measured for 18 and 36
    for count in range(2, 38):
        y = Yarn(count, R, MAT, packing=packing)
        p = y.offsets
        assert np.abs(p.mean(axis=0)).max() < 5e-15 * R  # round-off: measured <= 1.1e-15 R
        # touching to round-off (measured <= 7e-16 relative; yarn.ROUND_OFF allows 1e-9)
        assert centre_distances(p).min() == pytest.approx(2 * R, rel=1e-12)
        full = next(n for n in (7, 19, 37) if count <= n)
        outer = short[count] if packing == "hexagonal" and count in short else \
            {7: 3, 19: 5, 37: 7}[full]
        assert y.diameter / 2 <= outer * R * (1 + 1e-4)  # 1e-4: the 4 digits of 18 and 36


@pytest.mark.parametrize("count,outer", [(7, 3.0), (19, 5.0), (37, 7.0),
                                         (28, 1 + 2 * math.sqrt(7))])
def test_hexagonal_bundles_are_round(count, outer):
    """Whole rings about a fibre: outer radius 3R, 5R, 7R. 28 = the 19 of two
    rings and 9 of the 12 sites at sqrt(7) pitches, taken every 3 of 4: a
    bundle with the lattice's 3-fold symmetry (outer radius (1 + 2 sqrt 7) R;
    it was 6.60 R, lopsided, before the sites were spread evenly)."""
    y = Yarn(count, R, MAT)
    assert y.diameter / 2 == pytest.approx(outer * R, rel=1e-12)
    p = y.offsets
    turn = 2 * math.pi / 3
    rotated = p @ np.array([[math.cos(turn), math.sin(turn)], [-math.sin(turn), math.cos(turn)]])
    assert same_set(p, rotated)


def test_round_packing_rings():
    """28 fibres: a core of 3 touching fibres, rings of 9 and 16, one pitch
    apart, each as full as it can be (one more fibre would overlap); outer
    radius (2/sqrt 3 + 5) R. 7, 19, 37: a centre fibre and rings of 6, 12, 18."""
    core = 1 / math.sqrt(3)  # 1 / (2 sin(pi/3)) pitches
    rings = round_rings(28)
    assert [n for n, _ in rings] == [3, 9, 16]
    assert [r for _, r in rings] == pytest.approx([core, core + 1, core + 2], rel=1e-15)
    for n, r in rings[1:]:  # as many as fit: neighbours a pitch or more apart, not with one more
        assert 2 * r * math.sin(math.pi / n) >= 1 > 2 * r * math.sin(math.pi / (n + 1))
    y = Yarn(28, R, MAT, packing="round")
    p = y.offsets
    radius = np.hypot(*p.T)
    for n, r in rings:  # each ring evenly spaced at its radius (pitch 2 R)
        on_ring = np.isclose(radius, 2 * R * r, rtol=1e-12)
        assert np.count_nonzero(on_ring) == n
        angles = np.sort(np.mod(np.arctan2(p[on_ring, 1], p[on_ring, 0]), 2 * math.pi))
        assert np.diff(angles) == pytest.approx(2 * math.pi / n, rel=1e-12)
    assert y.diameter / 2 == pytest.approx((2 / math.sqrt(3) + 5) * R, rel=1e-12)
    assert same_set(p, p * [1, -1])  # symmetric about the fabric plane
    # touching: the core (3 pairs), the core and the 9-ring at 0, 120, 240 deg (3), the
    # 9- and 16-rings at 0 deg (1); ring neighbours 0.158 R and 0.011 R apart
    d = centre_distances(p)
    assert np.count_nonzero(np.isclose(d, 2 * R, rtol=1e-12)) // 2 == 7
    for n, r in rings[1:]:
        gap = 2 * R * (2 * r * math.sin(math.pi / n) - 1)
        on_ring = np.isclose(radius, 2 * R * r, rtol=1e-12)
        assert d[np.ix_(on_ring, on_ring)].min() - 2 * R == pytest.approx(gap, rel=1e-9)
    gaps = [2 * (2 * r * math.sin(math.pi / n) - 1) for n, r in rings[1:]]  # in R
    assert [round(g, 3) for g in gaps] == [0.158, 0.011]
    for count, counts in ((7, [1, 6]), (19, [1, 6, 12]), (37, [1, 6, 12, 18])):
        assert [n for n, _ in round_rings(count)] == counts
    # a count that does not fill its last ring: 40 = 2 + 9 + 15 + 14 of 21, spread evenly
    rings = round_rings(40)
    assert [n for n, _ in rings] == [2, 9, 15, 14]
    assert 2 * rings[-1][1] * math.sin(math.pi / 21) >= 1  # room for 21 on the last ring
    p = Yarn(40, R, MAT, packing="round").offsets
    last = np.isclose(np.hypot(*p.T), 2 * R * rings[-1][1], rtol=1e-12)
    angles = np.sort(np.mod(np.arctan2(p[last, 1], p[last, 0]), 2 * math.pi))
    assert np.diff(angles) == pytest.approx(2 * math.pi / 14, rel=1e-12)


def test_layered_packing_is_flat():
    y = Yarn(28, R, MAT, packing="layers 2")
    assert y.height == pytest.approx(2 * R + math.sqrt(3) * R)
    assert y.width == pytest.approx(2 * R * 14 + R)  # 14 a row, staggered by a radius


def test_layered_packing_has_the_layers_asked_for():
    """7 fibres in 5 layers: rows of 2, 2, 1, 1, 1 (it made 4 rows of 2, 2,
    2, 1 before the rows were balanced)."""
    y = Yarn(7, R, MAT, packing="layers 5")
    h = np.round(y.offsets[:, 1] / (math.sqrt(3) * R), 9)
    assert len(np.unique(h)) == 5
    assert sorted(np.unique(h, return_counts=True)[1].tolist()) == [1, 1, 1, 2, 2]
    assert y.height == pytest.approx(2 * R + 4 * math.sqrt(3) * R)
    assert centre_distances(y.offsets).min() == pytest.approx(2 * R, rel=1e-12)


def test_neighbours_are_the_fibres_next_to_each_other():
    """Yarn.neighbours: a hexagonal 7's 12 bonds (the centre's 6 and the
    ring's 6, not its second neighbours sqrt 3 pitches apart); a round 37's
    ring and cross-ring neighbours (up to 1.31 of the closest distance,
    none past NEIGHBOUR_DISTANCE); a row's side by side ones; none for a
    monofilament. Fabric.neighbour_fibres: each yarn's, in fibre numbers."""
    def lengths(y):
        i, j = y.neighbours().T
        return np.linalg.norm(y.offsets[i] - y.offsets[j], axis=1) / (2 * R)

    hexagonal = Yarn(7, R, MAT)
    assert len(hexagonal.neighbours()) == 12
    assert lengths(hexagonal) == pytest.approx(np.ones(12), rel=1e-12)
    assert len(Yarn(5, R, MAT, packing="layers 1").neighbours()) == 4
    assert len(Yarn(1, R, MAT).neighbours()) == 0
    round37 = Yarn(37, R, MAT, packing="round")
    d = centre_distances(round37.offsets) / (2 * R)
    d = d[np.triu_indices(37, 1)]
    assert lengths(round37).max() == pytest.approx(d[d < 1.5].max(), rel=1e-12)
    assert 1.3 < lengths(round37).max() and not np.any((d > 1.5) & (d < 1.6))
    assert len(round37.neighbours()) == np.count_nonzero(d < 1.5)
    fab = Fabric(hexagonal, num_warp=2, num_weft=2, spacing=8 * R)
    pairs = fab.neighbour_fibres()
    assert len(pairs) == 4 * 12
    assert np.array_equal(fab.fibre_yarn[pairs[:, 0]], fab.fibre_yarn[pairs[:, 1]])
    assert np.array_equal(pairs[12:24], pairs[:12] + 7)


def test_clearance_and_custom_offsets():
    assert Yarn(7, R, MAT, clearance=0.5).width == pytest.approx(2 * R * 1.25 * 2 + 2 * R)
    y = Yarn(2, R, MAT, packing=[[-R, 0], [R, 0]])
    assert y.width == pytest.approx(4 * R)
    assert Yarn(2, R, MAT, packing=[[0, -R], [0, R]]).diameter == pytest.approx(4 * R)


@pytest.mark.parametrize("kwargs,error,match", [
    (dict(count=0), ValueError, r"count must be a positive integer, got 0"),
    (dict(count=-3), ValueError, r"count must be a positive integer"),
    (dict(count=7.5), ValueError, r"count must be a positive integer"),
    (dict(count=True), ValueError, r"count must be a positive integer"),
    (dict(radius=-1e-3), ValueError, r"radius must be positive"),
    (dict(radius=0.0), ValueError, r"radius must be positive"),
    (dict(radius=float("nan")), ValueError, r"radius must be positive and finite"),
    (dict(radius=float("inf")), ValueError, r"radius must be positive and finite"),
    (dict(material="steel"), TypeError, r"material must be a textile.Material"),
    (dict(packing="square"), ValueError, r"unknown Yarn.packing 'square'.*'round'"),
    (dict(packing="layers 0"), ValueError, r"number of layers must be in 1..7"),
    (dict(packing="layers 8"), ValueError, r"number of layers must be in 1..7"),
    (dict(count=2, packing=[[0, 0], [R, 0]]), ValueError, r"fibres 0 and 1 overlap"),
    (dict(count=2, packing=[[0, 0]]), ValueError, r"\(2, 2\) array, got shape \(1, 2\)"),
    (dict(count=2, packing=[[0, 0, 0], [3 * R, 0, 0]]), ValueError, r"\(2, 2\) array"),
    (dict(count=2, packing=[[0, 0], [np.nan, 0]]), ValueError, r"finite \(2, 2\) array"),
    (dict(count=2, packing=[["a", "b"], ["c", "d"]]), TypeError, r"Yarn.packing must be"),
    (dict(count=2, packing=[[0, 0], [3 * R, 0]], clearance=0.1), ValueError,
     r"clearance applies to the lattice packings"),
    (dict(clearance=-1), ValueError, r"clearance must be >= 0"),
    (dict(clearance=float("nan")), ValueError, r"clearance must be a finite number"),
    (dict(twist=float("nan")), ValueError, r"twist must be a finite number"),
    (dict(twist=float("inf")), ValueError, r"twist must be a finite number"),
    (dict(count=1, twist=1 / (3 * R)), ValueError, r"shorter than two fibre diameters"),
    # touching side by side: any twist crosses the helices (module docstring)
    (dict(twist=1 / (1000 * R)), ValueError, r"helices of fibres \d+ and \d+ come"),
    (dict(packing="round", count=28, twist=1 / (1000 * R)), ValueError, r"helices of fibres"),
    (dict(friction=-0.1), ValueError, r"Yarn.friction must be in \[0, 10\)"),
    (dict(friction=True), ValueError, r"Yarn.friction must be in"),
    (dict(friction="0.2"), ValueError, r"Yarn.friction must be in"),
])
def test_bad_yarns(kwargs, error, match):
    args = dict(count=7, radius=R, material=MAT)
    args.update(kwargs)
    with pytest.raises(error, match=match):
        Yarn(**args)


def test_bundles_have_friction_within_the_yarn():
    """Yarn.friction's default: BUNDLE_FRICTION where fibres are stacked
    (a frictionless stack is unstable, Yarn docstring) or twisted, the
    contact's (None) for a single row or a monofilament; the weaving's
    contact takes each yarn's."""
    from textile.fabric.yarn import BUNDLE_FRICTION
    assert Yarn(7, R, MAT, packing="hexagonal").friction == BUNDLE_FRICTION
    assert Yarn(28, R, MAT, packing="round").friction == BUNDLE_FRICTION
    assert Yarn(14, R, MAT, packing="layers 2").friction == BUNDLE_FRICTION
    assert Yarn(7, R, MAT, packing="layers 1").friction is None
    assert Yarn(1, R, MAT).friction is None
    assert Yarn(7, R, MAT, packing="hexagonal", friction=0.35).friction == 0.35
    weft = Yarn(3, R, MAT, packing="hexagonal", friction=0.1)
    fab = Fabric(Yarn(7, R, MAT, packing="layers 1"), weft, num_warp=2, num_weft=2,
                 spacing=30 * R, pattern="plain", elements_per_crossing=4)
    w = Weaving(fab, contact=dict(friction=0.05), method="ordered", comm=MPI.COMM_SELF)
    assert w.contact.yarn_friction.tolist() == [0.05, 0.05, 0.1, 0.1]


def test_a_fabric_of_bundles_weaves_by_lifting_with_longer_tails():
    """Fabric.has_bundles (warp or weft a Yarn.is_bundle: stacked or
    twisted fibres) is the one test behind three defaults: the weaving
    method (lifting, else ordered), the free length (one spacing, else
    half) and a loading's capped Newton solves; a twisted row of two fibres
    is a bundle, as its friction default already said."""
    row, hexa = Yarn(7, R, MAT, packing="layers 1"), Yarn(7, R, MAT, packing="hexagonal")
    twisted = Yarn(2, R, MAT, packing=[[-1.05 * R, 0], [1.05 * R, 0]], twist=1 / (30 * R))
    for warp, weft, bundles in ((row, row, False), (row, hexa, True), (twisted, row, True),
                                (Yarn(1, R, MAT), Yarn(1, R, MAT), False)):
        fab = Fabric(warp, weft, num_warp=2, num_weft=2, spacing=30 * R, pattern="plain",
                     elements_per_crossing=4)
        assert fab.has_bundles is bundles
        assert fab.free_length == pytest.approx((1.0 if bundles else 0.5) * 30 * R)
        w = Weaving(fab, comm=MPI.COMM_SELF)
        assert w.method == ("lifting" if bundles else "ordered")


# -- twist ---------------------------------------------------------------------------------
def brute_helix_distance(a, b, twist):
    """Distance between the helices of offsets a and b (fibre a at s = 0,
    fibre b sampled over two turns either side, the best sample refined by
    zooming in)."""
    k, pitch = 2 * math.pi * twist, 1 / twist
    lo, hi = -2 * pitch, 2 * pitch
    for _ in range(6):
        s = np.linspace(lo, hi, 20001)
        c, si = np.cos(k * s), np.sin(k * s)
        d2 = s ** 2 + (a[0] - c * b[0] + si * b[1]) ** 2 + (a[1] - si * b[0] - c * b[1]) ** 2
        m = int(np.argmin(d2))
        lo, hi = s[max(m - 1, 0)], s[min(m + 1, len(s) - 1)]
    return math.sqrt(d2[m])


def test_helix_distances_against_sampling():
    """The exact 1-D minimum against sampling the helices over two turns
    (which does not assume |u| <= pi): random pairs, helix angles up to 85
    deg (convex and not). Measured agreement 1.3e-15 relative."""
    rng = np.random.default_rng(1)
    for _ in range(25):
        a, b = rng.normal(size=(2, 2)) * rng.uniform(0.2, 5, size=(2, 1)) * R
        twist = 10 ** rng.uniform(-3, 0.3) / R
        d = helix_distances(np.array([a, b]), twist)[0, 1]
        assert d == pytest.approx(brute_helix_distance(a, b, twist), rel=1e-9)  # sampling: ~1e-12


def test_ring_neighbours_come_closer_by_cos_of_the_helix_angle():
    """A ring of n fibres: ring neighbours' helices are d cos(alpha) apart
    (d their distance in the section), up to O((2 pi/n)^2) (measured 0.024
    (2 pi/n)^2 at alpha = 30 deg, n = 60 and 120); radial neighbours keep d."""
    deviations = []
    for n in (60, 120):
        r = 1.2 * R / math.sin(math.pi / n)
        angle = 2 * np.pi * np.arange(n) / n
        offsets = r * np.column_stack([np.cos(angle), np.sin(angle)])
        d0 = 2 * r * math.sin(math.pi / n)
        alpha = math.radians(30)
        twist = math.tan(alpha) / (2 * math.pi * r)
        d = helix_distances(offsets, twist)[0, 1]
        deviations.append(abs(d / (d0 * math.cos(alpha)) - 1) / (2 * math.pi / n) ** 2)
    assert max(deviations) < 0.05  # 2x the measured 0.024
    assert deviations[1] == pytest.approx(deviations[0], rel=0.01)  # second order: same constant
    radial = np.array([[2 * R, 0.0], [4.5 * R, 0.0]])
    assert helix_distances(radial, 0.1 / R)[0, 1] == pytest.approx(2.5 * R, rel=1e-14)


def test_twist_limit_is_where_helices_touch():
    """A 7-fibre yarn with clearance 0.1 (ring neighbours 2.1 R apart, 60 deg
    round the axis): the largest twist it admits, read from the error, is
    where the ring neighbours' helices (sampled independently) are 2 R apart,
    at a helix angle of 20.0 deg; the small-angle estimate cos(alpha) =
    2/2.1 (17.8 deg) is conservative for neighbours so far round the ring."""
    with pytest.raises(ValueError, match=r"admits \|twist\| <= ") as e:
        Yarn(7, R, MAT, clearance=0.1, twist=0.1 / R)
    limit = float(str(e.value).split("admits |twist| <= ")[1].split(",")[0].split(" ")[0])
    y = Yarn(7, R, MAT, clearance=0.1, twist=limit * (1 - 1e-3))  # admitted below it
    ring = y.offsets[np.isclose(np.hypot(*y.offsets.T), 2.1 * R, rtol=1e-12)]
    neighbours = ring[np.argsort(np.arctan2(ring[:, 1], ring[:, 0]))][:2]
    # the limit is printed to 4 digits: the distance there is 2 R to ~1e-4
    assert brute_helix_distance(*neighbours, limit) == pytest.approx(2 * R, rel=2e-4)
    alpha = math.degrees(math.atan(2 * math.pi * limit * 2.1 * R))
    assert alpha == pytest.approx(20.0, abs=0.05)  # 4 digits of the limit: +-0.01 deg
    assert math.degrees(math.acos(2 / 2.1)) == pytest.approx(17.75, abs=0.01)


def test_twisted_yarn_makes_helices():
    """Each fibre's nodes lie on the helix c(s) = a + s t + r (cos(phi + 2 pi
    tau s) e_d + sin(phi + 2 pi tau s) e_h), one turn over 40 radii."""
    twist = 1 / (40 * R)
    yarn = Yarn(7, R, MAT, clearance=0.2, twist=twist)
    fab = Fabric(yarn, num_warp=2, num_weft=2, spacing=(10 * R, 20 * R), elements_per_crossing=8)
    assert fab.elements_per_turn(0) == pytest.approx(16)  # 8 a crossing of 20 R, 40 R a turn
    a, b = fab.yarn_axis(0)
    for f, (d, h) in zip(fab.fibres()[:7], yarn.offsets):
        s = f.points[:, 0] - a[0]
        r, phi = math.hypot(d, h), math.atan2(h, d)
        expected = np.column_stack([a[0] + s, a[1] + r * np.cos(phi + 2 * math.pi * twist * s),
                                    r * np.sin(phi + 2 * math.pi * twist * s)])
        assert np.abs(f.points - expected).max() < 1e-15 * (b[0] - a[0])  # round-off
        assert np.diff(s) == pytest.approx(np.full(len(s) - 1, (b[0] - a[0]) / (len(s) - 1)))


# -- fabrics -------------------------------------------------------------------------------
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
    # warps span the wefts plus the free length (bundles: the smallest spacing)
    a, b = fab.yarn_axis(0)
    assert b[0] - a[0] == pytest.approx(3 * 10 * R + 2 * 8 * R)
    # yarns one fibre high: half the smallest spacing
    flat = Fabric(Yarn(3, R, MAT, packing="layers 1"), num_warp=2, num_weft=4,
                  spacing=(8 * R, 10 * R))
    a, b = flat.yarn_axis(0)
    assert b[0] - a[0] == pytest.approx(3 * 10 * R + 2 * 4 * R)


def test_interpolated_section_scale_closed_form():
    """min |P| of the order-1 and order-2 interpolants of the unit circle
    over an element turning by `turn`, against sampling the interpolants."""
    x = np.linspace(-1, 1, 20001)
    for turn in (2 * math.pi / 10, 2 * math.pi / 4, 2.5):
        phi = turn / 2
        nodes = {1: np.array([-1.0, 1.0]), 2: np.array([-1.0, 0.0, 1.0])}
        for order, xi in nodes.items():
            values = np.exp(1j * phi * xi)
            shape = np.array([np.prod([(x - xi[m]) / (xi[n] - xi[m]) for m in range(len(xi))
                                       if m != n], axis=0) for n in range(len(xi))])
            sampled = np.abs(values @ shape).min()
            # sampled at steps of 1e-4 in x: error ~1e-11 (measured 4e-12)
            assert interpolated_section_scale(order, turn) == pytest.approx(sampled, rel=1e-10)
    assert interpolated_section_scale(1, 2 * math.pi / 10) == pytest.approx(0.9511, abs=5e-5)
    # radial neighbours 2 R (1 + c/2) apart stay 2 R apart at that scale for c >= 0.103
    scale = interpolated_section_scale(1, 2 * math.pi / 10)
    assert 2 / scale - 2 == pytest.approx(0.103, abs=5e-4)
    assert interpolated_section_scale(2, 2 * math.pi / 10) == pytest.approx(0.9997, abs=5e-5)


def test_twisted_yarn_needs_elements_enough_per_turn():
    """Two fibres 2.1 R apart across the axis turn once per crossing spacing,
    so elements_per_crossing = elements per turn. Their helices stay 2.1 R
    apart; chords of order 1 bring them to 2.1 R cos(pi/N): below 2 R for N
    <= 10 (threshold pi / acos(1/1.05) = 10.14). Order 2 keeps them apart
    with 4 a turn. Fewer than 2 node intervals a turn cannot turn at all."""
    p = 10 * R
    yarn = Yarn(2, R, MAT, packing=[[-1.05 * R, 0], [1.05 * R, 0]], twist=1 / p)

    def fabric(epc, order):
        return Fabric(yarn, spacing=p, elements_per_crossing=epc, order=order)

    assert fabric(11, 1).elements_per_turn(0) == pytest.approx(11)
    with pytest.raises(ValueError, match=r"10 elements of order 1 per turn.*at least 10.1 "):
        fabric(10, 1)
    fabric(4, 2)
    with pytest.raises(ValueError, match=r"node interval turns by pi"):
        fabric(2, 1)
    with pytest.raises(ValueError, match=r"node interval turns by pi"):
        fabric(1, 2)
    # the refusal is real: mid-chord, the two fibres' order-1 elements of a
    # turn in N are 2.1 R cos(pi/N) apart (nodes on the helices)
    for n, overlap in ((10, True), (11, False)):
        s = np.arange(2) * p / n
        turn = 2 * math.pi * s / p
        ends = [np.column_stack([s, r * np.cos(turn), r * np.sin(turn)])
                for r in (-1.05 * R, 1.05 * R)]
        mid = [e.mean(axis=0) for e in ends]
        assert (np.linalg.norm(mid[1] - mid[0]) < 2 * R) == overlap


def test_yarns_may_touch_side_by_side_but_not_overlap():
    """Width = spacing: touching neighbours are accepted (refused before);
    a twisted yarn sweeps its diameter, so a yarn narrower than the spacing
    but taller is refused once twisted (accepted before)."""
    Fabric(Yarn(3, R, MAT, packing="layers 1"), spacing=6 * R)
    stack = [[0, -1.1 * R], [0, 1.1 * R]]
    Fabric(Yarn(2, R, MAT, packing=stack), spacing=3 * R)
    with pytest.raises(ValueError, match=r"sweep a diameter of 0.0042 .*only 0.003 apart"):
        Fabric(Yarn(2, R, MAT, packing=stack, twist=1 / (40 * R)), spacing=3 * R)


@pytest.mark.parametrize("kwargs,match", [
    (dict(num_warp=0), "num_warp must be a positive integer"),
    (dict(spacing=-1.0), "warp spacing must be positive"),
    (dict(spacing=float("nan")), "warp spacing must be positive and finite"),
    (dict(spacing=(1.0, 0.0)), "weft spacing must be positive"),
    (dict(spacing=5 * R), "warp yarns are 0.006 wide.*only 0.005 apart"),
    (dict(pattern="herringbone"), "unknown weave pattern"),
    (dict(pattern=[[1, 2], [0, 1]]), r"entry \(0, 1\) is 2"),
    (dict(pattern="twill 2/2"), "does not fit 2 weft x 2 warp yarns"),
    (dict(free_length=0), "free_length must be positive"),
    (dict(free_length=-R), "free_length must be positive"),
    (dict(free_length=float("nan")), "free_length must be positive and finite"),
    (dict(elements_per_crossing=0), "elements_per_crossing must be a positive integer"),
    (dict(elements_per_crossing=2.5), "elements_per_crossing must be a positive integer"),
    (dict(order=3), r"order \(of the fibres' elements\) must be 1 or 2, got 3"),
    (dict(order=0), r"order .* must be 1 or 2"),
    (dict(order=2.0), r"order .* must be 1 or 2"),
    (dict(order=True), r"order .* must be 1 or 2"),
])
def test_bad_fabrics_fail_before_any_computation(kwargs, match):
    args = dict(warp=Yarn(7, R, MAT), num_warp=2, num_weft=2, spacing=10 * R)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        Fabric(**args)
