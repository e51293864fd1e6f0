"""Hard contact cases: each must converge, or stop with a clear message,
never produce NaN and never let fibres pass through each other."""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import FibreContact

E, NU, R = 1.0e9, 0.3, 1e-3
MAT = textile.Material(E, NU)
QUIET = dict(verbose=False)


def solve_or_fail_cleanly(model, options, on_step=None):
    """Run; a ConvergenceError is acceptable, anything else is not.
    Returns (history, converged)."""
    solver = textile.Solver(model, dict(QUIET, **options), on_step=on_step)
    try:
        solver.solve()
        converged = True
    except textile.ConvergenceError as e:
        assert "did not converge" in str(e)
        converged = False
    assert np.all(np.isfinite(model.nodal_unknowns()))  # never NaN, even after a failure
    return solver.history, converged


def crossed_pair(L=0.1, depth=0.0, angle=90.0, ne=8):
    """A fixed along y; B across it at `angle`, interpenetrating by `depth`."""
    A = textile.straight_fibre([0, -L / 2, 0], [0, L / 2, 0], R, MAT, num_elements=ne)
    th = np.radians(angle)
    axis = np.array([np.sin(th), np.cos(th), 0.0])
    c = np.array([0, 0, 2 * R - depth])
    B = textile.straight_fibre(c - L / 2 * axis, c + L / 2 * axis, R, MAT, num_elements=ne)
    model = textile.Model([A, B], comm=MPI.COMM_SELF)
    for n in range(A.num_nodes):
        model.fix(A, n, "all")
    return model, A, B, axis


def test_deep_initial_interpenetration():
    """B starts 50% of a radius into A, its ends pinned there: contact must
    push it back out to an equilibrium without flipping sides."""
    model, A, B, _ = crossed_pair(depth=0.5 * R)
    model.fix(B, 0, ["position", "g1x"])
    model.fix(B, -1, ["y", "z"])
    contact = FibreContact(dict(penalty=1e5 / (2 * R)))  # crossings of stiffness 1e5 N/m
    model.add_effect(contact)
    history, converged = solve_or_fail_cleanly(model, dict(initial_step=1.0, max_step=1.0))
    assert converged
    mid = model.centreline(B)[B.num_nodes // 2]
    assert mid[2] > 0  # B's middle stays above A's axis: no pass-through
    d = contact.elements()
    # fibre i is A, j is B: the normal points from B down to A, as set
    # at the start, even though the centroids began 1.5 R apart
    assert np.all(d["normal"][:, 2] < -0.99)
    assert -d["gap"].min() < 0.5 * R  # the penetration was reduced


def test_sweep_across_at_5_degrees():
    """B, at 5 degrees to A and pressed on it, is swept sideways across A by
    two radii: the contact travels 23 radii along A (2R / tan 5 deg),
    sliding with friction, without pass-through."""
    model, A, B, axis = crossed_pair(angle=5.0, depth=1e-6, L=0.06, ne=12)
    side = np.array([1.0, 0.0, 0.0])

    def ends(t):
        return list(2 * R * t * side + np.array([0, 0, -5e-5 * min(1.0, 5 * t)]))

    model.fix(B, 0, ["position", "g1x"], lambda t: ends(t) + [0.0])
    model.fix(B, -1, ["position"], ends)
    contact = FibreContact(dict(friction=0.2))
    model.add_effect(contact)
    heights = []
    history, converged = solve_or_fail_cleanly(
        model, dict(initial_step=0.02, max_step=0.05),
        on_step=lambda s, rec: heights.append(model.centreline(B)[:, 2].min()))
    assert converged
    assert min(heights) > 0  # B never went below A's centre line
    target = contact.options.target_penetration * contact.g_r
    for h in history:
        assert h.effects["active_contacts"] > 0  # in contact all along the sweep
        assert h.effects["max_penetration_over_radius"] * R <= 2 * target


def test_very_stiff_penalty():
    """Penalty 1e3 times the transverse stiffness 48 E I / L^3 of the pressed
    fibre: ill-conditioned but must converge (MUMPS LU, full Newton)."""
    L = 0.1
    model, A, B, _ = crossed_pair(L=L)
    I = np.pi * R ** 4 / 4
    k = 1e3 * 48 * E * I / L ** 3
    model.fix(B, 0, ["position", "g1x"], [0, 0, -1e-4, 0])
    model.fix(B, -1, ["y", "z"], [0, -1e-4])
    # per unit length: the crossing (equivalent length 2R) has stiffness k
    contact = FibreContact(dict(penalty=k / (2 * R), adapt_penalty=False))
    model.add_effect(contact)
    history, converged = solve_or_fail_cleanly(model, dict(initial_step=0.25, max_step=0.25))
    assert converged
    f = history[-1].effects["contact_force_sum"]
    g_r = contact.g_r
    p = f / k + g_r / 2 if f > 0.5 * k * g_r else np.sqrt(2 * g_r * f / k)
    # the crossed-fibre reference still holds (shear flexibility: 0.1%)
    assert f * L ** 3 / (48 * E * I) + p == pytest.approx(1e-4, rel=1e-2)
    assert max(h.newton_iterations for h in history) <= 25


def test_three_fibres_meeting_at_one_point():
    """A (x), B (y) on A, C (diagonal) on B, all crossing above one point;
    C is pressed down: two stacked contacts, and A-C within search distance."""
    L = 0.08
    A = textile.straight_fibre([-L / 2, 0, 0], [L / 2, 0, 0], R, MAT, num_elements=8)
    B = textile.straight_fibre([0, -L / 2, 2 * R - 1e-6], [0, L / 2, 2 * R - 1e-6], R, MAT,
                               num_elements=8)
    d = np.array([1, 1, 0]) / np.sqrt(2)
    c = np.array([0, 0, 4 * R - 2e-6])
    C = textile.straight_fibre(c - L / 2 * d, c + L / 2 * d, R, MAT, num_elements=8)
    model = textile.Model([A, B, C], comm=MPI.COMM_SELF)
    for n in range(A.num_nodes):
        model.fix(A, n, "all")
    for f in (B, C):
        model.fix(f, 0, ["position", "g1x"], lambda t, f=f: [0, 0, -1e-4 * t * (1 + (f is C)), 0])
        model.fix(f, -1, ["position"], lambda t, f=f: [0, 0, -1e-4 * t * (1 + (f is C))])
    contact = FibreContact(dict(penalty=1e5 / (2 * R)))  # crossings of stiffness 1e5 N/m
    model.add_effect(contact)
    history, converged = solve_or_fail_cleanly(model, dict(initial_step=0.25, max_step=0.25))
    assert converged
    data = contact.elements()
    active = data["normal_force"] > 0
    pairs = {(i, j) for i, j in zip(data["fibre_i"][active], data["fibre_j"][active])}
    assert pairs == {(0, 1), (1, 2)}  # A-B and B-C touch, A-C does not
    z = [model.centreline(f)[f.num_nodes // 2, 2] for f in (A, B, C)]
    assert z[0] < z[1] < z[2]  # the stack order is kept


def test_dense_bundle_of_19_compressed():
    """19 parallel fibres in hexagonal packing (1 + 6 + 12), the outer ring
    pushed inwards: every contact holds, the packing stays ordered."""
    L, ne = 0.02, 4
    centres = [np.zeros(2)]
    for ring, count in ((1, 6), (2, 12)):
        for k in range(count):
            if ring == 1:
                a = 2 * np.pi * k / 6
                centres.append(2 * R * np.array([np.cos(a), np.sin(a)]))
            else:
                corner, frac = divmod(k, 2)
                a0, a1 = 2 * np.pi * corner / 6, 2 * np.pi * (corner + 1) / 6
                p0 = 4 * R * np.array([np.cos(a0), np.sin(a0)])
                p1 = 4 * R * np.array([np.cos(a1), np.sin(a1)])
                centres.append(p0 + 0.5 * frac * (p1 - p0))
    shrink = 1 - 1e-4  # start just interpenetrating, so every contact is active
    fibres = [textile.straight_fibre([*(shrink * c), 0], [*(shrink * c), L], R, MAT,
                                     num_elements=ne, section_vector=[1, 0, 0]) for c in centres]
    model = textile.Model(fibres, comm=MPI.COMM_SELF)
    for i, f in enumerate(fibres):
        model.fix(f, 0, ["z", "g1z", "g2x", "g2y"])
        if i == 0:  # the central fibre holds the bundle in place
            for n in (0, -1):
                model.fix(f, n, ["x", "y"])
        if i == 7:  # without friction the rings could spin about the centre
            for n in (0, -1):
                model.fix(f, n, "y")  # tangential at this fibre (on the x axis)
        if i >= 7:  # outer ring: inward line load
            radial = -centres[i] / np.linalg.norm(centres[i])
            for n in range(f.num_nodes):
                w = (0.5 if n in (0, f.num_nodes - 1) else 1.0) * L / (f.num_nodes - 1)
                model.add_force(f, n, [*(2.0 * w * radial), 0.0])
    # line contacts of 4e8 N/m per metre (1e6 N/m per element of the
    # default spacing, half an element)
    contact = FibreContact(dict(penalty=1e6 / (0.5 * L / ne)))
    model.add_effect(contact)
    history, converged = solve_or_fail_cleanly(model, dict(initial_step=0.25, max_step=0.5))
    assert converged
    stats = history[-1].effects
    assert stats["active_contacts"] > 0
    target = contact.options.target_penetration * contact.g_r
    assert stats["max_penetration_over_radius"] * R <= 2 * target + 1e-12
    # ordered packing: no two centre lines closer than 1.9 R
    q = model.nodal_unknowns()
    mid = np.array([q[model.mesh.fibre_nodes(i)[len(f.points) // 2], :2]
                    for i, f in enumerate(fibres)])
    dist = np.linalg.norm(mid[:, None] - mid[None], axis=2) + np.eye(len(fibres))
    assert dist.min() > 1.9 * R


def test_tiny_regularization_different_radii_single_element_zone():
    """g_r a billionth of the radius, radii 1 : 0.3, a crossing (one element
    per zone), adaptive penalty: finite, bounded, converged."""
    L = 0.1
    A = textile.straight_fibre([0, -L / 2, 0], [0, L / 2, 0], R, MAT, num_elements=8)
    r = 0.3 * R
    B = textile.straight_fibre([-L / 2, 0, R + r - 1e-7], [L / 2, 0, R + r - 1e-7], r, MAT,
                               num_elements=8)
    model = textile.Model([A, B], comm=MPI.COMM_SELF)
    for n in range(A.num_nodes):
        model.fix(A, n, "all")
    model.fix(B, 0, ["position", "g1x"], [0, 0, -2e-5, 0])
    model.fix(B, -1, ["y", "z"], [0, -2e-5])
    contact = FibreContact(dict(regularization=1e-9))
    model.add_effect(contact)
    history, converged = solve_or_fail_cleanly(model, dict(initial_step=0.25, max_step=0.25))
    assert converged
    d = contact.elements()
    assert len(d["gap"]) == 1  # a crossing: a single-element zone
    lo, hi = contact.options.penalty_range
    assert lo * contact.k0 <= d["penalty"][0] <= hi * contact.k0
    assert np.isfinite(d["normal_force"]).all() and d["normal_force"][0] > 0
    assert contact.g_r == pytest.approx(1e-9 * r)  # from the smaller radius
