"""A folded element is outside the model's domain (textile.GeometryError).

St Venant-Kirchhoff gives a fibre reversed onto itself (stretch -1) zero
energy, so a folded element can look like an equilibrium: a clamped fibre
pushed axially by 0.06 L in one step used to converge with its end element
folded (mid node beyond the tip). The kernel refuses det F <= 0.
"""
import numpy as np
import pytest
from mpi4py import MPI

import textile

E, NU, R, L = 1e9, 0.3, 1e-3, 0.2   # L / R = 200


def two_fibres():
    mat = textile.Material(E, NU)
    fibres = [textile.straight_fibre([0, 10 * R * k, 0], [L, 10 * R * k, 0], R, mat,
                                     num_elements=16, section_vector=[0, 1, 0])
              for k in range(2)]
    model = textile.Model(fibres, comm=MPI.COMM_SELF)
    model.setup()
    return model


def test_assembly_of_a_folded_state_names_element_and_fibre():
    model = two_fibres()
    u = model.state().u["beam"].copy()
    # fibre 1, element 3 (nodes 6, 7, 8 of the fibre): its mid node pushed
    # beyond its last node reverses the centre line at one Gauss point
    first = 33  # 2 * 16 + 1 nodes per fibre
    mid = first + 7
    u[9 * mid] += 0.75 * L / 16
    asm = model.beam._assembler
    b = np.zeros_like(u)
    with pytest.raises(textile.GeometryError, match=r"element 3 of fibre 1: .*det F = -"):
        asm.assemble_vector(u, b)
    with pytest.raises(textile.GeometryError, match=r"element 3 of fibre 1: .*det F = -"):
        asm.assemble_matrix(model.A, u, model.state().dofs["beam"])
    # the same displacement without the fold is fine (the check is not a tolerance)
    u[9 * mid] -= 0.5 * L / 16
    asm.assemble_vector(u, b)


def test_axial_push_in_one_step_does_not_fold():
    """The case that used to end folded: the solver now rejects the folded
    iterates and reaches the uniformly compressed fibre."""
    mat = textile.Material(E, NU)
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, mat, num_elements=16,
                                 section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    model.fix(fib, -1, ["x"], [-0.06 * L])
    # the uniform compression is far past Euler's load: keep that unstable
    # state (no branch switching) to check it, and check it is flagged
    solver = textile.Solver(model, dict(initial_step=1.0, max_step=1.0, verbose=False,
                                        branch_switching=False))
    with pytest.warns(textile.solver.StabilityWarning, match="stability lost"):
        solver.solve(1.0)
    assert solver.history[-1].stability["negative_eigenvalues"] > 0
    x = model.centreline(fib)[:, 0]
    assert np.all(np.diff(x) > 0)  # no node beyond its neighbour
    strain = model.beam.element_fields(model.state().u["beam"])[:, 2]
    # uniform compression E33 = (0.94^2 - 1) / 2, up to the clamp's boundary
    # layer (its fixed section vectors restrain the Poisson contraction;
    # measured 8e-4 off in the first element)
    assert np.allclose(strain, 0.5 * (0.94 ** 2 - 1), rtol=3e-3)
    # the element stretches add up to the imposed shortening (measured 1e-6:
    # Gauss-point averages of the strain, not exact element stretches)
    assert np.mean(np.sqrt(1 + 2 * strain)) == pytest.approx(0.94, rel=4e-6)
