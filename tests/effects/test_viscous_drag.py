"""ViscousDrag: exact tangent, nothing computed when off, the structure's
own equilibrium once it is off, and a path through a bundle's weaving."""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile import _cpp
from textile.effects import ViscousDrag, viscous_drag
from tests.finite_differences import assembled_tangent_and_differences

E, NU, R, L = 1.0e9, 0.3, 1e-3, 0.1
EI = E * np.pi * R ** 4 / 4
F = 0.5 * EI / L ** 2
QUIET = dict(verbose=False)


def cantilever(drag=None):
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, NU),
                                 num_elements=8, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    force = model.add_force(fib, -1, [0, 0, F])
    if drag is not None:
        model.add_effect(drag)
    return fib, model, force


def test_tangent_matches_finite_differences():
    """The drag's residual eta (x - x_n) and its diagonal tangent, with the
    beam's, against central differences at a deformed state away from the
    reference."""
    drag = ViscousDrag(2.0)
    _, model, _ = cantilever(drag)
    model.setup()
    drag.prepare(model)                      # the reference: the undeformed state
    x = model.x
    x.setArray(np.random.default_rng(5).normal(scale=1e-3 * R, size=x.getLocalSize()))
    model.apply_constraints(x)
    J, Jfd, free = assembled_tangent_and_differences(model, x, h=1e-9)
    err = np.linalg.norm(J[:, free] - Jfd) / np.linalg.norm(Jfd)
    assert err < 1e-6  # central differences: truncation ~1e-10 relative
    # the drag is there: the tangent differs from the beam's alone by eta on
    # the centre-line diagonal (12 E I / L_e^3 times 2)
    _, bare, _ = cantilever()
    bare.setup()
    y = bare.x
    y.setArray(x.getArray())
    Jb, _, _ = assembled_tangent_and_differences(bare, y, h=1e-9)
    eta = 2.0 * 12 * EI / (L / 8) ** 3
    diagonal = np.diag(J - Jb)[free]
    assert np.isclose(diagonal.max(), eta, rtol=1e-12)
    assert np.count_nonzero(np.abs(diagonal) > 1e-9 * eta) == 3 * 16   # 16 free nodes, x y z


def test_off_computes_nothing(monkeypatch):
    """Coefficient 0 (the stage option that switches it off): no diagonal
    inserted, the same Newton iterations and state as without the effect."""
    calls = []

    class Counting:   # the drag module's view of the C++ module
        def add_diagonal(self, *args):
            calls.append(1)
            _cpp.add_diagonal(*args)

    monkeypatch.setattr(viscous_drag, "_cpp", Counting())
    drag = ViscousDrag(0.0)
    _, with_drag, _ = cantilever(drag)
    s1 = textile.Solver(with_drag, QUIET)
    s1.solve()
    _, without, _ = cantilever()
    s2 = textile.Solver(without, QUIET)
    s2.solve()
    assert calls == []
    assert [h.newton_iterations for h in s1.history] == \
        [h.newton_iterations for h in s2.history]
    assert np.array_equal(with_drag.nodal_unknowns(), without.nodal_unknowns())
    # control: the counter sees the drag when it is on
    _, on, _ = cantilever(ViscousDrag(1.0))
    textile.Solver(on, QUIET).solve()
    assert len(calls) > 0


def test_a_stage_without_it_ends_at_the_structures_equilibrium():
    """Loaded with the drag, then a stage with coefficient 0: the tip where
    the drag-free run puts it (to the Newton tolerance), while the state at
    the end of the dragged stage lags behind it."""
    drag = ViscousDrag(5.0)
    fib, model, force = cantilever(drag)
    solver = textile.Solver(model, dict(initial_step=0.5, max_step=0.5, verbose=False))
    solver.run_stage(textile.Stage("dragged"))
    lagging = model.nodal_unknowns()[-1, 2]
    assert solver.history[-1].effects["drag_force"] > 0
    solver.run_stage(textile.Stage("settle", effects={drag: dict(coefficient=0.0)}))
    assert solver.history[-1].effects["drag_force"] == 0.0
    _, free, _ = cantilever()
    textile.Solver(free, dict(initial_step=0.5, max_step=0.5, verbose=False)).solve()
    tip = free.nodal_unknowns()[-1, 2]
    assert model.nodal_unknowns()[-1, 2] == pytest.approx(tip, rel=1e-9)
    assert lagging < 0.9 * tip   # the drag held it back (5 bending stiffnesses)


@pytest.mark.parametrize("value", [-1.0, float("nan"), "1", True])
def test_bad_coefficients_are_named_errors(value):
    with pytest.raises(ValueError, match="ViscousDrag: coefficient must be a finite number"):
        ViscousDrag(value)
    with pytest.raises(ValueError, match="ViscousDrag: coefficient must be a finite number"):
        ViscousDrag().configure(coefficient=value)
    with pytest.raises(ValueError, match=r"unknown option\(s\) \['speed'\]"):
        ViscousDrag().configure(speed=1)


def _first_step_tip(options: dict, dt: float) -> float:
    drag = ViscousDrag(0.0)
    fib, model, force = cantilever(drag)
    solver = textile.Solver(model, dict(initial_step=dt, max_step=dt, verbose=False))
    solver.run_stage(textile.Stage("dragged", effects={drag: options}), t_end=dt)
    return model.nodal_unknowns()[-1, 2]


def test_with_a_step_it_is_a_viscosity():
    """``step`` h: eta = coefficient * h / (s - s_n). A step of h/2 drags as
    twice the coefficient does without ``step``, a step of h as the
    coefficient itself (the first step's tip, to the Newton tolerance);
    and it does drag (the tip lags the drag-free one)."""
    viscous = _first_step_tip(dict(coefficient=5.0, step=0.5), 0.25)
    assert viscous == pytest.approx(_first_step_tip(dict(coefficient=10.0), 0.25), rel=1e-9)
    assert viscous < 0.95 * _first_step_tip(dict(coefficient=5.0), 0.25)
    nominal = _first_step_tip(dict(coefficient=5.0, step=0.25), 0.25)
    assert nominal == pytest.approx(_first_step_tip(dict(coefficient=5.0), 0.25), rel=1e-9)


@pytest.mark.parametrize("value", [0.0, -0.1, 1.5, float("nan"), True, "0.1"])
def test_bad_steps_are_named_errors(value):
    with pytest.raises(ValueError, match=r"ViscousDrag: step is a load-factor increment"):
        ViscousDrag().configure(step=value)


# -- a drag on the relative motion of fibre pairs -----------------------------

def two_cantilevers(drag=None, comm=MPI.COMM_SELF, partition="place", elements=(8, 8)):
    """Two parallel cantilevers 3 R apart (no contact), the second pulled
    sideways at its tip."""
    fibres = [textile.straight_fibre([0, y, 0], [L, y, 0], R, textile.Material(E, NU),
                                     num_elements=n, section_vector=[0, 1, 0])
              for y, n in zip((0.0, 3 * R), elements)]
    model = textile.Model(fibres, comm=comm, partition=partition)
    for fib in fibres:
        model.clamp(fib, 0)
    model.add_force(fibres[1], -1, [0, 0, F])
    if drag is not None:
        model.add_effect(drag)
    return fibres, model


def test_pairs_tangent_matches_finite_differences():
    """With pairs: the relative drag eta (d_a - d_b) node by node and a
    share of the absolute one, residual and tangent against central
    differences; the tangent is the beams' plus the pairs' Laplacian."""
    drag = ViscousDrag(2.0, pairs=[(0, 1)], absolute_share=0.25)
    _, model = two_cantilevers(drag)
    model.setup()
    drag.prepare(model)
    x = model.x
    x.setArray(np.random.default_rng(7).normal(scale=1e-3 * R, size=x.getLocalSize()))
    model.apply_constraints(x)
    J, Jfd, free = assembled_tangent_and_differences(model, x, h=1e-9)
    err = np.linalg.norm(J[:, free] - Jfd) / np.linalg.norm(Jfd)
    assert err < 1e-6  # central differences: truncation ~1e-10 relative
    _, bare = two_cantilevers()
    bare.setup()
    y = bare.x
    y.setArray(x.getArray())
    Jb, _, _ = assembled_tangent_and_differences(bare, y, h=1e-9)
    eta = 2.0 * 12 * EI / (L / 8) ** 3
    D = (J - Jb)[np.ix_(free, free)]
    # per free position unknown: eta (pair) + 0.25 eta (own) on the diagonal,
    # -eta against the same unknown of the same node of the other fibre
    assert np.isclose(np.diag(D).max(), 1.25 * eta, rtol=1e-12)
    assert np.count_nonzero(np.abs(np.diag(D)) > 1e-9 * eta) == 2 * 3 * 16
    assert np.isclose(D.min(), -eta, rtol=1e-12)
    assert np.count_nonzero(D < -1e-9 * eta) == 2 * 3 * 16


def test_pairs_do_not_drag_a_common_motion():
    """Both fibres moved alike: only the absolute share drags (the pairs'
    force is zero); moved apart, the pair's force is there."""
    drag = ViscousDrag(1.0, pairs=[(0, 1)], absolute_share=0.0)
    fibres, model = two_cantilevers(drag)
    model.setup()
    drag.prepare(model)
    x = model.x.copy()
    v = x.getArray().reshape(-1, 9)
    v[:, 2] = 1e-4 * R * (np.arange(len(v)) % 17)      # node i of both fibres alike
    x.setArray(v.ravel())
    r = model.b.duplicate()
    model.residual(None, x, r)
    assert drag.drag_force == 0.0
    v[17:, 2] += 1e-3 * R                              # the second fibre's 17 nodes apart
    x.setArray(v.ravel())
    model.residual(None, x, r)
    assert drag.drag_force == pytest.approx(1e-3 * R * 12 * EI / (L / 8) ** 3, rel=1e-9)


def test_pairs_with_other_node_counts_are_named_errors():
    with pytest.raises(ValueError, match="fibres 0 and 1 of a pair have 17 and 13 nodes"):
        _, model = two_cantilevers(ViscousDrag(1.0, pairs=[(0, 1)]), elements=(8, 6))
        model.setup()
    with pytest.raises(ValueError, match="pairs name fibre 2, the model has 2"):
        _, model = two_cantilevers(ViscousDrag(1.0, pairs=[(0, 2)]))
        model.setup()
    for pairs in ([(0, 0)], [(0, -1)], [(0, 1.5)], [(0, 1, 2)], "a"):
        with pytest.raises(ValueError, match="ViscousDrag: pairs are"):
            ViscousDrag(1.0, pairs=pairs)
    for share in (-0.1, 1.5, True, float("nan")):
        with pytest.raises(ValueError, match="absolute_share is in"):
            ViscousDrag(1.0, pairs=[(0, 1)], absolute_share=share)
    with pytest.raises(ValueError, match="absolute_share < 1 needs pairs"):
        ViscousDrag(1.0, absolute_share=0.5)


def _pulled_pair(comm, partition):
    drag = ViscousDrag(3.0, pairs=[(0, 1)], absolute_share=0.1)
    fibres, model = two_cantilevers(drag, comm=comm, partition=partition)
    solver = textile.Solver(model, dict(initial_step=0.5, max_step=0.5, verbose=False))
    solver.run_stage(textile.Stage("dragged"))
    return model.nodal_unknowns(), [h.newton_iterations for h in solver.history]


def test_pairs_hold_the_other_fibre_back():
    """The pulled fibre drags the other along (its tip moves), a drag
    without pairs does not."""
    u, _ = _pulled_pair(MPI.COMM_SELF, "place")
    assert u[16, 2] > 0.1 * u[-1, 2] > 0           # fibre 0's tip follows fibre 1's


@pytest.mark.mpi
def test_two_ranks_drag_pairs_as_one():
    """Split by numbers, fibre 0 on one rank and fibre 1 on the other: each
    pair's second node is a ghost of the rank assembling it
    (Effect.fibre_ghosts); the same path and state as on one rank."""
    u2, its2 = _pulled_pair(MPI.COMM_WORLD, "numbers")
    u1, its1 = _pulled_pair(MPI.COMM_SELF, "numbers")
    assert its2 == its1
    # sums over ranks in another order: round-off of the Newton tolerance
    assert np.allclose(u2, u1, rtol=1e-9, atol=1e-12 * L)
