"""Load stepping: step cutting, clean failure, nothing lost, never NaN."""
import json
import math

import numpy as np
import pytest
from mpi4py import MPI

import textile

from .common import QUIET, section


def bar(n=2):
    """A fibre held straight (lateral centroid dofs fixed at every node) so
    that compression has a limit point instead of buckling."""
    E, nu, R, L = 1.0e9, 0.3, 1e-3, 0.05
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, nu),
                                 num_elements=n, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.fix(fib, 0, ["position", "g1x", "g1z", "g2x", "g2y"])
    for i in range(1, fib.num_nodes):
        model.fix(fib, i, ["y", "z"])
    A, _, _, _ = section(E, nu, R)
    return fib, model, E * A


def test_force_beyond_the_limit_point_fails_cleanly(tmp_path):
    """Compression beyond N = 0.19245 E A (the SVK limit point, docs/references.md §1)
    has no equilibrium: the run must end with ConvergenceError, keep the
    converged steps on disk, and write no NaN."""
    fib, model, EA = bar()
    model.add_force(fib, -1, [-0.3 * EA, 0, 0])
    out = textile.Output(str(tmp_path), pictures=False)
    solver = textile.Solver(model, dict(initial_step=0.25, max_step=0.25, min_step=1e-3, **QUIET),
                            output=out)
    with pytest.raises(textile.ConvergenceError, match="did not converge"):
        solver.solve()
    # the limit point is at load factor 0.19245 / 0.3 = 0.6415
    t_last = solver.history[-1].load_factor
    assert 0.55 < t_last < 0.6415
    assert len(solver.history) >= 2
    data = json.loads((tmp_path / "results.json").read_text())
    assert len(data["steps"]) == len(solver.history)
    assert "did not converge" in data["meta"]["failure"]
    assert all(math.isfinite(s["energy"]) for s in data["steps"])
    assert len(list(tmp_path.glob("fibres_*.vtu"))) == len(solver.history)
    # the state left in the model is the last converged one, finite
    assert np.all(np.isfinite(model.nodal_unknowns()))


def test_steps_are_cut_and_grow_again():
    """A large compressive step fails near the limit point, is cut, and
    easy steps make the increment grow again."""
    fib, model, EA = bar()
    model.add_force(fib, -1, [-0.19 * EA, 0, 0])
    # few Newton iterations allowed: the full step near the limit point fails
    solver = textile.Solver(model, dict(initial_step=1.0, max_step=1.0, min_step=1e-3,
                                        max_it=4, **QUIET))
    solver.solve()
    assert solver.history[-1].load_factor == pytest.approx(1.0)
    assert solver.history[0].attempts > 1  # the first step was cut
    # (increments then shrink towards the limit point: each step is harder)
    # N = E A lambda (lambda^2 - 1)/2 at the converged stretch
    lam = model.centreline(fib)[-1, 0] / fib.points[-1, 0]
    assert EA * lam * (lam ** 2 - 1) / 2 == pytest.approx(-0.19 * EA, rel=1e-8)


def test_easy_steps_grow():
    fib, model, EA = bar()
    model.add_force(fib, -1, [0.01 * EA, 0, 0])
    solver = textile.Solver(model, dict(initial_step=0.1, max_step=0.5, grow=1.5, **QUIET))
    solver.solve()
    dt = np.diff([0.0] + [h.load_factor for h in solver.history])
    assert dt[:3] == pytest.approx([0.1, 0.15, 0.225])  # x1.5 after each easy step
    assert dt.max() <= 0.5


def test_options_reach_petsc():
    fib, model, EA = bar()
    model.add_force(fib, -1, [0.01 * EA, 0, 0])
    solver = textile.Solver(model, dict(petsc_options={"snes_max_it": 1}, **QUIET))
    assert solver.snes.getTolerances()[3] == 1
