"""ElasticBlock's named sides and P2 basis: the nodes a side rigid body
gets, clamping by name, and basis values any junction kernel can take."""
import numpy as np
import pytest
from mpi4py import MPI

from textile.effects.elastic_block import ElasticBlock
from textile.composite.matrix_mesh import box_mesh, gmsh_box

pytestmark = pytest.mark.mpi
P0, P1 = np.array([0.0, 0.0, 0.0]), np.array([2.0, 1.0, 0.5])


@pytest.fixture(scope="module")
def box():
    return gmsh_box(MPI.COMM_WORLD, P0, P1, 0.3)


@pytest.mark.parametrize("degree", [1, 2])
def test_side_nodes_lie_on_their_side(box, degree):
    """Every node of a named side lies on its plane, every boundary node on
    that plane is found (a P2 side has its edge nodes too), and the owned
    ones over all ranks are the side's nodes exactly once."""
    block = ElasticBlock(box, 1.0, 0.3, degree=degree)
    X_all = block.node_coordinates()
    owned = block.num_owned_nodes
    for name in box.sides:
        k = "xyz".index(name[0])
        plane = P0[k] if name.endswith("min") else P1[k]
        nodes, X = block.side_nodes(name)
        assert np.all(np.abs(X[:, k] - plane) < 1e-12), name
        expected = np.flatnonzero(np.abs(X_all[:, k] - plane) < 1e-12)
        np.testing.assert_array_equal(nodes, expected)
        n_owned = MPI.COMM_WORLD.allreduce(int(np.sum(nodes < owned)))
        n_global = MPI.COMM_WORLD.allreduce(
            int(np.sum(np.abs(X_all[:owned, k] - plane) < 1e-12)))
        assert n_owned == n_global > 0
    # a marker selects the same nodes as the name
    by_marker, _ = block.side_nodes(lambda x: np.isclose(x[0], P1[0]))
    np.testing.assert_array_equal(by_marker, block.side_nodes("xmax")[0])
    both, _ = block.side_nodes(["xmin", "xmax"])
    np.testing.assert_array_equal(both, np.union1d(block.side_nodes("xmin")[0],
                                                   block.side_nodes("xmax")[0]))


def test_side_name_errors(box):
    with pytest.raises(ValueError, match=r"unknown side\(s\) \['top'\]"):
        ElasticBlock(box, 1.0, 0.3, clamp="top")
    with pytest.raises(ValueError, match="no named sides"):
        ElasticBlock(box_mesh(MPI.COMM_WORLD, P0, P1, [2, 2, 2]), 1.0, 0.3, clamp="xmin")
    with pytest.raises(ValueError, match="degree must be one of"):
        ElasticBlock(box, 1.0, 0.3, degree=3)


@pytest.mark.parametrize("degree", [1, 2])
def test_point_basis_interpolates_exactly(box, degree):
    """Basis values at points reproduce the points and, for P2, a quadratic
    field (a P1 basis could not): the junction kernel's phi has
    nodes_per_cell columns (4 or 10)."""
    block = ElasticBlock(box, 1.0, 0.3, degree=degree)
    assert block.nodes_per_cell == (4 if degree == 1 else 10)
    pts = np.random.default_rng(3).uniform(P0, P1, size=(50, 3))
    cells, phi = block.point_basis(pts)
    mine = cells >= 0
    assert phi.shape == (50, block.nodes_per_cell)
    X = block.node_coordinates()
    dofs = block.cell_dofs(cells[mine])
    assert dofs.shape == (mine.sum(), block.nodes_per_cell)
    np.testing.assert_allclose(np.einsum("pi,pij->pj", phi[mine], X[dofs]), pts[mine],
                               atol=1e-12)
    if degree == 2:
        field = lambda x: x[..., 0] * x[..., 1] + x[..., 2] ** 2  # noqa: E731
        np.testing.assert_allclose(np.einsum("pi,pi->p", phi[mine], field(X[dofs])),
                                   field(pts[mine]), atol=1e-12)
    assert MPI.COMM_WORLD.allreduce(int(mine.sum())) == len(pts)
