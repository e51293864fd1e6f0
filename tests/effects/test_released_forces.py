"""ReleasedForces: a dead force vector held at full value at the start of a
stage and released (linearly in the load factor) over it, e.g. the friction
forces a sample's woven state carried (tests/virtual/test_bundle_tests.py).

A cantilever carries a tip force P as released forces: over a stage of 4
steps its tip deflection is (1 - s) times the small-deflection answer, then
zero; the forces survive a saved state."""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.nodal_loads import ReleasedForces

from tests.beam.common import QUIET, section

E, NU, R, L, P = 1.0e9, 0.3, 1e-3, 0.2, 1e-4


def cantilever(comm=MPI.COMM_SELF):
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, NU),
                                 num_elements=4)
    model = textile.Model(fib, comm=comm)
    model.clamp(fib, 0)
    released = ReleasedForces("tip force")
    model.add_effect(released)
    model.setup()
    forces = np.zeros(9 * model.mesh.num_nodes_global)
    # residual sign (internal - external): an applied force -P e_z is +P
    # each rank gives its share (they add up): here rank 0 all of it
    if comm.rank == 0:
        forces[9 * model.mesh.node(fib, -1) + 2] = P
    released.set(forces)
    return model, fib, released, forces


def release(comm=MPI.COMM_SELF):
    """The tip deflection at each step of a releasing stage, and the effect."""
    model, fib, released, _ = cantilever(comm)
    tips = {}
    solver = textile.Solver(model, dict(initial_step=0.25, max_step=0.25, **QUIET),
                            on_step=lambda s, rec: tips.setdefault(
                                rec.load_factor, -model.centreline(fib)[-1, 2]))
    solver.run([textile.Stage("release")])
    return tips, released


def test_the_force_goes_to_zero_over_the_stage():
    tips, released = release()
    A, I, _, G = section(E, NU, R)
    full = P * L ** 3 / (3 * E * I) + P * L / (G * A)
    assert sorted(tips) == pytest.approx([0.25, 0.5, 0.75, 1.0])
    # linear in the load: geometric nonlinearity ~(w/L)^2 ~ 1e-6 of the
    # deflection (the cantilever test measures 3e-6); tolerance 1e-5
    for s, tip in tips.items():
        assert tip == pytest.approx((1 - s) * full, rel=1e-5, abs=1e-12 * L)
    # released: the next stages hold it at zero
    assert released.scale() == 0.0


def test_nothing_held_when_the_forces_are_zero():
    model, _, released, forces = cantilever()
    released.set(np.zeros_like(forces))
    assert released.scale() == 0.0 and released.save_state(model) == {}


def test_bad_forces_are_refused():
    _, _, released, forces = cantilever()
    with pytest.raises(ValueError, match="finite values"):
        released.set(forces[:-1])
    bad = forces.copy()
    bad[0] = np.nan
    with pytest.raises(ValueError, match="finite values"):
        released.set(bad)


def test_the_forces_survive_a_saved_state(tmp_path):
    model, fib, released, forces = cantilever()
    path = str(tmp_path / "held.h5")
    textile.save_state(model, path)
    other, _, again, _ = cantilever()
    again.set(np.zeros_like(forces))     # nothing held, until the state is read
    textile.load_state(other, path)
    assert np.array_equal(again.save_state(other)["forces"], forces)
    assert again.scale() == 1.0


@pytest.mark.mpi
def test_two_ranks_release_as_one():
    tips, _ = release(MPI.COMM_WORLD)
    serial, _ = release()
    # the same steps and Newton path, the sums over ranks in another order:
    # measured 3e-12 relative (the zero tip at the end: 4e-17 m)
    assert list(tips) == list(serial)
    assert np.allclose(list(tips.values()), list(serial.values()), rtol=1e-10, atol=1e-14 * L)
