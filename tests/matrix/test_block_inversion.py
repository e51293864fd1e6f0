"""An inverted matrix element is a domain error: the step is cut, never
accepted. A bar is squashed to -20% of its length (no orientation-
preserving state exists): the run stops with ConvergenceError, having
met the named domain error, and every accepted state is finite and
uninverted. St Venant-Kirchhoff would otherwise go straight through
J = 0 (its energy is finite there: the control shows it)."""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.elastic_block import ElasticBlock
from textile.composite.matrix_mesh import gmsh_box

from block_scenes import SideDisplacement, block_model

E, NU, L = 1.0e3, 0.3, 1.0
SQUASH = -1.2 * L          # x = L side moved past x = 0


def squash_scene(comm, law, degree, check=True):
    mm = gmsh_box(comm, [0, 0, 0], [L, 0.5, 0.5], 0.25)
    block = ElasticBlock(mm, E, NU, law=law, degree=degree)
    if not check:
        block.check_inverted = lambda u: None     # the control: no domain check
    model = block_model(comm, block, force_scale=E * 0.25)
    for side, c in (("xmin", 0), ("ymin", 1), ("zmin", 2)):
        model.add_effect(SideDisplacement(block, side, [c], [0.0]))
    model.add_effect(SideDisplacement(block, "xmax", [0], [SQUASH]))
    return model, block


@pytest.mark.mpi
@pytest.mark.parametrize("law, degree", [("neo-hookean", 1), ("svk", 1), ("neo-hookean", 2)])
def test_inverting_load_is_cut_never_accepted(law, degree, capsys):
    model, block = squash_scene(MPI.COMM_WORLD, law, degree)
    accepted = []
    solver = textile.Solver(model, {"verbose": True, "initial_step": 0.25, "max_step": 0.25,
                                    "min_step": 1e-3})
    solver.on_step = lambda s, rec: accepted.append((rec.load_factor, block.min_det_F(),
                                                     np.isfinite(model.x.norm())))
    with pytest.raises(textile.ConvergenceError):
        solver.solve()
    log = capsys.readouterr().out
    if MPI.COMM_WORLD.rank == 0:
        # the domain error was met and named
        assert "inverted matrix element: cell" in log, log[-2000:]
    # the run got somewhere, and every accepted state is finite and uninverted
    assert accepted and model.load_factor < 1.0
    assert all(J > 0 and finite for _, J, finite in accepted), accepted
    # the bar cannot be squashed past x = 0 without inverting
    assert model.load_factor * abs(SQUASH) < L


def test_control_svk_goes_through_inversion_without_the_check():
    """Without the check, SVK reaches the inverted state (the test above
    would accept it): the check is what stops it."""
    model, block = squash_scene(MPI.COMM_SELF, "svk", 1, check=False)
    solver = textile.Solver(model, {"verbose": False, "initial_step": 0.25, "max_step": 0.25,
                                    "min_step": 1e-3})
    try:
        solver.solve()
    except textile.ConvergenceError:
        pass
    assert model.load_factor * abs(SQUASH) > L     # past x = 0 ...
    assert block.min_det_F() < 0              # ... with inverted cells


def test_inverted_state_is_a_named_geometry_error():
    """The residual at an inverted state raises GeometryError naming the
    cell; the model turns it into a domain error (infinite residual)."""
    mm = gmsh_box(MPI.COMM_SELF, [0, 0, 0], [1, 1, 1], 0.5)
    block = ElasticBlock(mm, E, NU, degree=2)
    model = block_model(MPI.COMM_SELF, block)
    model.setup()
    X = block.node_coordinates()
    u = np.zeros_like(X)
    u[:, 0] = -2.0 * X[:, 0]            # x -> -x: every cell inverted, J = -1
    off = model.layout.offset(block.name)
    x = model.x.getArray()
    x[off:off + u.size] = u.ravel()
    with pytest.raises(textile.GeometryError, match=r"inverted matrix element: cell \d+ .* "
                                                    r"det F = -1 <= 0"):
        block.check_inverted(u.ravel())
    model.residual(None, model.x, model.b)
    assert isinstance(model.domain_error, textile.GeometryError)
    assert np.all(np.isinf(model.b.getArray()))
