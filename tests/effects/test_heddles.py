"""Heddles (the lifting weave's springs, textile/effects/heddles.py): exact
tangent, a push towards the heddle's side only, nothing computed when off,
named errors."""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile import _cpp
from textile.effects import heddles
from textile.effects.heddles import Heddles
from textile.fabric import Fabric, Yarn
from tests.finite_differences import assembled_tangent_and_differences

R = 1e-3
MAT = textile.Material(1.0e9, 0.3)


def fabric_and_model(**options):
    """A 2 x 2 plain weave of monofilaments, 8 R apart, each fibre clamped
    at its start, with heddles of amplitude 2 R."""
    fab = Fabric(Yarn(1, R, MAT), num_warp=2, num_weft=2, spacing=8 * R, pattern="plain",
                 elements_per_crossing=4)
    fibres = fab.fibres()
    model = textile.Model(fibres, comm=MPI.COMM_SELF)
    for f in fibres:
        model.fix(f, 0, "all")
    h = Heddles(fab, 2 * R, **options)
    model.add_effect(h)
    return fab, model, h


def test_tangent_matches_finite_differences():
    """Residual and tangent (the beams' and the heddles', whose force moves
    with the node along its yarn) against central differences, at a state
    where nodes sit in the heddles' tapers, on both sides of their shelves
    and within the regularization."""
    _, model, h = fabric_and_model(stiffness=5.0, lift=0.6)
    model.setup()
    x = model.x
    # smooth centre-line displacements of about a radius (no folded element)
    X = model.mesh.X_local[: model.mesh.num_owned]
    a, b = X[:, 0] / R, X[:, 1] / R
    v = np.zeros(x.getLocalSize())
    v[0::9][: len(a)] = 0.6 * R * np.sin(0.7 * a + 0.3 * b)
    v[1::9][: len(a)] = 0.6 * R * np.cos(0.5 * a - 0.4 * b)
    v[2::9][: len(a)] = 1.3 * R * np.sin(0.5 * a + 1.1 * b + 0.2)
    x.setArray(v)
    model.apply_constraints(x)
    u = model.state().u["beam"]
    w, dw, side, p = h._springs(u, 0.6)
    # the state exercises every branch of the law
    assert np.any((w > 0) & (p > h.regularization)) and np.any((w > 0) & (p < 0))
    assert np.any((w > 0) & (p > 0) & (p < h.regularization)) and np.any(dw != 0)
    J, Jfd, free = assembled_tangent_and_differences(model, x, h=1e-9)
    err = np.linalg.norm(J[:, free] - Jfd) / np.linalg.norm(Jfd)
    assert err < 1e-6  # central differences: truncation ~1e-10 relative
    # the heddles are there: without them the tangent differs by more
    _, bare, _ = fabric_and_model(stiffness=0.0)
    bare.setup()
    y = bare.x
    y.setArray(x.getArray())
    Jb, _, _ = assembled_tangent_and_differences(bare, y, h=1e-9)
    assert np.linalg.norm(J - Jb) > 1e-3 * np.linalg.norm(J)


def test_pushes_towards_its_side_only():
    """A warp passing over weft 0 is lifted there (force up, residual < 0)
    when it is below its shelf and left alone above it; under weft 1 it is
    pressed down."""
    fab, model, h = fabric_and_model(stiffness=1.0, lift=1.0)
    model.setup()
    st = model.state()
    u = st.u["beam"]
    b = {"beam": np.zeros_like(u)}
    h.residual(st, b)
    rz = b["beam"][2::9][: model.mesh.num_owned]
    X = model.mesh.X_local[: model.mesh.num_owned]
    warp0 = np.flatnonzero(np.asarray(fab.fibre_yarn)[
        np.searchsorted(model.mesh.first_node, np.arange(model.mesh.num_owned),
                        side="right") - 1] == 0)
    over, under = fab.yarn_axis(2)[0][0], fab.yarn_axis(3)[0][0]   # weft 0 and weft 1 at x
    at_over = warp0[np.abs(X[warp0, 0] - over) < 1e-12]
    at_under = warp0[np.abs(X[warp0, 0] - under) < 1e-12]
    assert fab.order[0, 0] and not fab.order[1, 0]   # plain: warp 0 over weft 0
    assert rz[at_over].max() < 0 and rz[at_under].min() > 0
    # above its shelf: nothing
    v = model.x.getArray().copy()
    v[9 * at_over + 2] = 3 * R
    model.x.setArray(v)
    st = model.state()
    b = {"beam": np.zeros_like(st.u["beam"])}
    h.residual(st, b)
    assert np.all(b["beam"][9 * at_over + 2] == 0)


def test_off_computes_nothing(monkeypatch):
    """Stiffness 0: no entries inserted (the relaxation stage after the
    heddles)."""
    calls = []

    class Counting:   # the heddles module's view of the C++ module
        def add_entries(self, *args):
            calls.append(1)
            _cpp.add_entries(*args)

    monkeypatch.setattr(heddles, "_cpp", Counting())
    _, model, h = fabric_and_model(stiffness=0.0, lift=0.2)
    textile.Solver(model, dict(verbose=False)).solve()
    assert calls == []
    _, on, _ = fabric_and_model(stiffness=1.0, lift=0.2)   # control: on, it inserts
    textile.Solver(on, dict(verbose=False)).solve()
    assert calls


def test_bad_input_is_named():
    fab = Fabric(Yarn(1, R, MAT), num_warp=2, num_weft=2, spacing=8 * R)
    with pytest.raises(TypeError, match="Fabric"):
        Heddles("fabric", R)
    with pytest.raises(ValueError, match="amplitude"):
        Heddles(fab, 0.0)
    with pytest.raises(ValueError, match="amplitude"):
        Heddles(fab, float("nan"))
    with pytest.raises(ValueError, match="reach"):
        Heddles(fab, R, reach=0.6)
    with pytest.raises(ValueError, match="lift"):
        Heddles(fab, R, lift=2.0)
    with pytest.raises(ValueError, match="stiffness"):
        Heddles(fab, R, stiffness=-1.0)
    with pytest.raises(ValueError, match="unknown option"):
        Heddles(fab, R).configure(height=1.0)
