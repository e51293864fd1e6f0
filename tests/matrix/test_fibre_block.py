"""A fibre tied into a dolfinx elastic block: one SNES over both fields.

The block (2 x 1 x 1, neo-Hookean, clamped on x = 0) is a dolfinx P1 field
numbered by dolfinx's own index map; the fibre's first node sits inside it
and is tied to the matrix point there by a penalty spring; the fibre runs
along +x out of the block and its far end is pulled by a dead force P.
Under ``mpirun -n 2`` the same problem is also solved on MPI.COMM_SELF on
each rank and the answers are compared; with the fibre's node order
reversed, the tied node belongs to the last rank, so the rank owning the
tie's cell (on the 2-rank box partition, not the last) assembles it
through a ghost node.
"""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.elastic_block import ElasticBlock
from textile.effects.fibre_matrix_tie import FibreMatrixTie
from textile.composite.matrix_mesh import box_mesh

pytestmark = pytest.mark.mpi

P = 20.0              # N, pull on the far end (about 2.5% fibre strain)
K_TIE = 1.0e4         # N/m
E_MATRIX, E_FIBRE, RADIUS = 1.0e3, 1.0e5, 0.05
INSIDE = np.array([1.55, 0.45, 0.52])   # tied node: a generic point, not on a cell face
OUTSIDE = INSIDE + [2.0, 0.0, 0.0]


def build_scene(comm, reverse=False, cells=(6, 3, 3)):
    """Block, fibre, tie and loads; ``reverse`` numbers the fibre from its far end."""
    block = ElasticBlock(box_mesh(comm, [0, 0, 0], [2, 1, 1], cells), E_MATRIX, 0.3,
                         clamp=lambda x: np.isclose(x[0], 0.0))
    a, b = (OUTSIDE, INSIDE) if reverse else (INSIDE, OUTSIDE)
    fib = textile.straight_fibre(a, b, RADIUS, textile.Material(E_FIBRE, 0.3), num_elements=4)
    tied, end = (-1, 0) if reverse else (0, -1)
    model = textile.Model(fib, comm=comm)
    model.add_effect(block)
    tie = FibreMatrixTie(model, block, [(fib, tied)], K_TIE)
    model.add_effect(tie)
    model.fix(fib, end, ["y", "z", "section"])
    model.add_force(fib, end, [P, 0, 0])
    return model, fib, end, block, tie


def solve_scene(comm, reverse):
    model, fib, end, block, tie = build_scene(comm, reverse)
    solver = textile.Solver(model, {"verbose": False})
    history = solver.solve()
    return {
        "reasons": [h.converged_reason for h in history],
        "load_factor": model.load_factor,
        "centreline": model.centreline(fib) - fib.points,
        "tip": model.centreline(fib)[end] - fib.points[end],
        "tie": tie.tie_forces(),
        "reaction": block.reaction(),
        "support": model.reaction(fib, end, ["y", "z"]),
    }


def close(a, b, rel):
    return np.linalg.norm(np.asarray(a) - b) <= rel * np.linalg.norm(b)


@pytest.mark.parametrize("reverse", [False, True], ids=["tied-first", "tied-last"])
def test_fibre_pulls_block(reverse):
    res = solve_scene(MPI.COMM_WORLD, reverse)
    assert res["load_factor"] == 1.0 and all(r > 0 for r in res["reasons"])
    # the tip moves along +x by fibre stretch plus matrix deformation
    assert res["tip"][0] > 0.05
    # each body's internal forces sum to zero (its energy is translation
    # invariant), so at convergence the forces on it balance to round-off:
    # the fibre carries P, the tie and the tip's y, z supports ...
    assert close(res["tie"], [P, *res["support"]], 1e-9)
    assert abs(res["tie"][0] - P) <= 1e-9 * P
    # ... and the block the tie and its clamp
    assert close(res["reaction"], -res["tie"], 1e-9)
    # the same problem solved by each rank alone gives the same answer
    ref = solve_scene(MPI.COMM_SELF, reverse)
    for key in ("centreline", "tip", "tie", "reaction"):
        assert close(res[key], ref[key], 1e-10), key


def test_jacobian_matches_finite_differences():
    """Assembled tangent of the coupled model (beam, block, tie, Dirichlet
    rows) against central differences of its residual, at a random state."""
    model, _, _, _, _ = build_scene(MPI.COMM_SELF, cells=(3, 2, 2))
    model.setup()
    model.load_factor = 0.8
    x, b = model.x, model.b
    n = x.getSize()
    rng = np.random.default_rng(1)
    x.array[:] = 1e-2 * rng.standard_normal(n)
    model.apply_constraints(x)
    model.jacobian(None, x, model.A, model.A)
    J = model.A.getValues(np.arange(n, dtype=np.int32), np.arange(n, dtype=np.int32))
    fixed = model.constrained_positions()
    free = np.setdiff1d(np.arange(n), fixed)
    x0, h = x.array.copy(), 1e-7
    fd = np.zeros((n, len(free)))
    for k, j in enumerate(free):
        for sign in (1.0, -1.0):
            x.array[:] = x0
            x.array[j] += sign * h
            model.residual(None, x, b)
            fd[:, k] += sign * b.array / (2 * h)
    x.array[:] = x0
    err = np.abs(J[:, free] - fd).max()
    assert err <= 1e-6 * np.abs(J).max(), err
    # constrained rows (beam supports and the block's clamp) are identity rows
    assert np.array_equal(J[fixed], np.eye(n)[fixed])
    # the matrix field and the coupling blocks are really there
    nb = model.layout.field("beam").size_local
    assert np.abs(J[nb:, :nb]).max() > 0 and np.abs(J[nb:, nb:]).max() > 0


def test_point_basis_reproduces_position():
    """P1 basis values at points reproduce the points, and each point is
    taken by exactly one rank."""
    block = ElasticBlock(box_mesh(MPI.COMM_WORLD, [0, 0, 0], [2, 1, 1], [6, 3, 3]), 1.0, 0.3)
    pts = np.random.default_rng(2).uniform([0, 0, 0], [2, 1, 1], size=(40, 3))
    pts[0] = [1.0, 0.5, 0.5]   # a vertex shared by several cells (and ranks)
    cells, phi = block.point_basis(pts)
    mine = cells >= 0
    X = block.node_coordinates()
    dofs = block.cell_dofs(cells[mine])
    assert np.allclose(np.einsum("pi,pij->pj", phi[mine], X[dofs]), pts[mine], atol=1e-12)
    assert np.allclose(phi[mine].sum(axis=1), 1.0) and phi[mine].min() > -1e-12
    taken = MPI.COMM_WORLD.allreduce(mine.astype(int), op=MPI.SUM)
    assert np.all(taken == 1)
    with pytest.raises(ValueError, match="outside the matrix mesh"):
        block.point_basis([[2.5, 0.5, 0.5]])


def test_tie_after_setup_is_refused():
    model, fib, _, block, _ = build_scene(MPI.COMM_WORLD, cells=(3, 2, 2))
    model.setup()
    with pytest.raises(RuntimeError, match="final once the model is set up"):
        FibreMatrixTie(model, block, [(fib, 1)], K_TIE)
