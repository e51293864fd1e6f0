"""Rigid bodies holding fibre ends: exact couplings, any rotation, reactions."""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from tests.finite_differences import assembled_tangent_and_differences

E, NU, R = 1.0e9, 0.3, 1e-3
A, J = np.pi * R ** 2, np.pi * R ** 4 / 2
MAT = textile.Material(E, NU)
QUIET = dict(verbose=False)


def yarn(count, L=0.1, elements=8):
    """``count`` parallel fibres along x, 3 radii apart (not touching)."""
    return [textile.straight_fibre([0, 3 * R * k, 0], [L, 3 * R * k, 0], R, MAT,
                                   num_elements=elements, section_vector=[0, 1, 0])
            for k in range(count)]


def pulled(count, drive, L=0.1, comm=MPI.COMM_SELF):
    """A yarn clamped by one end body, pulled along x by the other: by a
    force (``drive="force"``, 0.005 E A a fibre) or by the end displacement
    that force produced (``drive`` a number)."""
    fibres = yarn(count, L)
    model = textile.Model(fibres, comm=comm)
    clamp = textile.RigidBody("clamp", sections=[(f, 0) for f in fibres]).fix()
    end = textile.RigidBody("end", sections=[(f, -1) for f in fibres])
    end.fix(["y", "z", "rotation"])
    if drive == "force":
        end.add_force([0.005 * E * A * count, 0, 0])
    else:
        end.prescribe("x", drive)
    model.add_rigid_body(clamp)
    model.add_rigid_body(end)
    solver = textile.Solver(model, QUIET)
    solver.solve()
    return model, solver, fibres


def test_yarn_of_seven_carries_seven_times_one_fibre():
    m1, s1, _ = pulled(1, "force")
    u1 = m1.rigid_bodies.positions()[1, 0] - 0.1
    m7, s7, _ = pulled(7, u1)  # the same stretch, displacement-driven
    r = m7.rigid_bodies.reactions()
    # the clamp holds 7x the single fibre's force: measured 1.4e-14 relative
    assert -r[0, 0] == pytest.approx(7 * 0.005 * E * A, rel=1e-9)
    # reactions balance: what the two bodies exert on the yarn sums to zero
    assert np.abs(r[0] + r[1]).max() <= 1e-9 * 7 * 0.005 * E * A


def test_force_and_displacement_driven_agree():
    mf, sf, ff = pulled(3, "force")
    u = mf.rigid_bodies.positions()[1, 0] - 0.1
    md, sd, fd = pulled(3, u)
    # same state: node positions to 1e-12 L; and the reaction of the driven
    # body equals the applied force (force-driven equilibrium)
    assert np.abs(mf.nodal_unknowns() - md.nodal_unknowns()).max() <= 1e-12 * 0.1
    assert md.rigid_bodies.reactions()[1, 0] == pytest.approx(3 * 0.005 * E * A, rel=1e-8)
    assert mf.rigid_bodies.reactions()[1, 0] == pytest.approx(3 * 0.005 * E * A, rel=1e-8)
    # the end stretches as one fibre in tension (docs/references.md §1), less the
    # Poisson contraction the bodies block at the ends (about R of 100 R on
    # each side): measured 1.0e-3 stiffer
    lam = 1 + u / 0.1
    assert E * A * lam * (lam ** 2 - 1) / 2 == pytest.approx(0.005 * E * A, rel=5e-3)


def test_a_full_turn_twists_a_fibre_by_exactly_two_pi():
    """An end body turned by 2 pi about the fibre's axis, the other end
    clamped: the end section comes back exactly, the mid section has turned
    by pi, and the torque is G J tau (docs/references.md §3)."""
    L = 1000 * R  # tau R = 2 pi / 1000: the SVK correction is below 3e-5
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, MAT, num_elements=16,
                                 section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.add_rigid_body(textile.RigidBody("clamp", sections=[(fib, 0)]).fix())
    end = textile.RigidBody("twist", sections=[(fib, -1)]).fix(["y", "z", "ry", "rz"])
    end.prescribe("rx", 2 * np.pi)  # the axial displacement stays free
    model.add_rigid_body(end)
    solver = textile.Solver(model, dict(initial_step=1 / 16, max_step=1 / 16, **QUIET))
    solver.solve()
    bodies = model.rigid_bodies
    assert bodies.turned[1] == pytest.approx([2 * np.pi, 0, 0], abs=1e-12)
    assert np.abs(bodies.rotation[1] - np.eye(3)).max() < 1e-14
    g1, g2 = model.section_vectors(fib)
    # end section back to its reference directions (held by the body)
    assert np.abs(g1[-1] / np.linalg.norm(g1[-1]) - [0, 1, 0]).max() < 1e-12
    mid = fib.num_nodes // 2
    assert g1[mid] / np.linalg.norm(g1[mid]) == pytest.approx([0, -1, 0], abs=1e-6)
    G = E / (2 * (1 + NU))
    torque = bodies.reactions()[1, 3]
    # measured 1.8e-4 off G J tau (finite strain at tau R = 6e-3, free shortening)
    assert torque == pytest.approx(G * J * 2 * np.pi / L, rel=1e-3)


def test_unknown_components_and_bad_bodies():
    fib = yarn(1)[0]
    with pytest.raises(ValueError, match="unknown rigid-body component 'rw'"):
        textile.RigidBody("b", sections=[(fib, 0)]).prescribe("rw", 1.0)
    with pytest.raises(ValueError, match="holds nothing"):
        textile.RigidBody("b")
    with pytest.raises(ValueError, match="finite 3-vector"):
        textile.RigidBody("b", sections=[(fib, 0)]).add_force([1, np.nan, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.add_rigid_body(textile.RigidBody("b", sections=[(fib, 0)]))
    with pytest.raises(ValueError, match="already in the model"):
        model.add_rigid_body(textile.RigidBody("b", sections=[(fib, -1)]))


@pytest.mark.mpi
def test_parallel_equals_serial():
    """Bodies owned by rank 0, couplings by the ranks owning the fibre ends:
    the same state and reactions on any number of ranks (round-off)."""
    ms, _, _ = pulled(3, "force", comm=MPI.COMM_SELF)
    mp, _, _ = pulled(3, "force", comm=MPI.COMM_WORLD)
    assert np.abs(ms.nodal_unknowns() - mp.nodal_unknowns()).max() <= 1e-13
    rs, rp = ms.rigid_bodies.reactions(), mp.rigid_bodies.reactions()
    assert np.abs(rs - rp).max() <= 1e-10 * np.abs(rs).max()


def test_assembled_tangent_with_bodies_matches_finite_differences():
    """Couplings of sections and pins, body forces and moments, prescribed
    and free components: the assembled tangent is the residual's derivative
    at a state with finite body rotations and multipliers."""
    fibres = yarn(2, L=0.05, elements=2)
    model = textile.Model(fibres, comm=MPI.COMM_SELF)
    a = textile.RigidBody("a", sections=[(fibres[0], 0)], pins=[(fibres[1], 0)]).fix("x")
    a.add_moment([1e-3, -2e-3, 5e-4])
    b = textile.RigidBody("b", sections=[(f, -1) for f in fibres])
    b.add_force([1.0, -0.5, 2.0])
    model.add_rigid_body(a)
    model.add_rigid_body(b)
    model.setup()
    model.load_factor = 0.6
    rng = np.random.default_rng(5)
    x = model.x
    x.setArray(rng.normal(scale=0.002, size=x.getLocalSize()))  # no folded element
    model.apply_constraints(x)
    J, Jfd, free = assembled_tangent_and_differences(model, x, h=1e-7)
    # central differences: truncation ~h^2 relative; measured ~1e-9
    assert np.linalg.norm(J[:, free] - Jfd) / np.linalg.norm(Jfd) < 1e-6
