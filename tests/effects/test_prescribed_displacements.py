"""Prescribed displacements are an effect like every other constraint
(issue 23 §2): Model.fix and Model.clamp add components to one
PrescribedDisplacements, whose constraints the model reads as it reads a
rigid body's; a release frees them; a scene without any has none."""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.prescribed_displacements import PrescribedDisplacements

R, L = 1e-3, 0.2
MAT = textile.Material(1.0e9, 0.3)


def fibre():
    return textile.straight_fibre([0, 0, 0], [L, 0, 0], R, MAT, num_elements=4,
                                  section_vector=[0, 1, 0])


def prescribed(model):
    found = [e for e in model.effects if isinstance(e, PrescribedDisplacements)]
    assert len(found) <= 1
    return found[0] if found else None


def test_a_scene_without_prescriptions_has_no_such_effect():
    fib = fibre()
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.add_force(fib, -1, [0, 0, 1.0])
    model.setup()
    assert prescribed(model) is None
    # its (empty) schedule is still listed first: state files name it
    assert model.schedules()[0].name == "prescribed displacements"


def test_fix_and_clamp_are_constraints_of_the_effect_and_a_release_frees_them():
    fib = fibre()
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    pull = model.fix(fib, -1, "x", 2e-4)
    model.fix(fib, -1, "x", 1e-4)          # fixed again: its value replaced, no new row
    model.setup()
    effect = prescribed(model)
    dofs, values = effect.constraints(0.5)["beam"]
    last = 9 * (model.mesh.num_nodes_global - 1)
    # the clamp's 9 unknowns of node 0 and the tip's x: 10 rows, ramped values
    assert sorted(dofs) == list(range(9)) + [last]
    assert values[list(dofs).index(last)] == pytest.approx(0.5e-4, rel=1e-14)
    assert np.all(values[np.asarray(dofs) < 9] == 0.0)
    solver = textile.Solver(model, dict(verbose=False))
    solver.run([textile.Stage("pull"), textile.Stage("release", release=[pull])])
    dofs, _ = effect.constraints(1.0)["beam"]
    assert sorted(dofs) == list(range(9))   # the tip is free again
    # released with no load on it: the tip goes back to the fibre's length
    assert model.centreline(fib)[-1, 0] == pytest.approx(L, rel=1e-9)


def test_a_bad_value_is_refused_before_anything_is_added():
    fib = fibre()
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    with pytest.raises(ValueError, match="NaN"):
        model.fix(fib, 0, "x", float("nan"))
    model.setup()
    assert prescribed(model) is None
