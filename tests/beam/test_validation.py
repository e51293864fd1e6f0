"""Bad input is refused with a clear error naming the field."""
import numpy as np
import pytest
from mpi4py import MPI

import textile

MAT = textile.Material(1e9, 0.3)


@pytest.mark.parametrize("radius", [0.0, -1e-3, float("nan"), float("inf")])
def test_radius_must_be_positive(radius):
    with pytest.raises(ValueError, match="radius"):
        textile.Fibre([[0, 0, 0], [1, 0, 0]], radius, MAT)


def test_radius_must_be_a_number():
    with pytest.raises(TypeError, match="radius"):
        textile.Fibre([[0, 0, 0], [1, 0, 0]], "thin", MAT)


def test_points():
    with pytest.raises(ValueError, match="at least two points"):
        textile.Fibre([[0, 0, 0]], 1e-3, MAT)
    with pytest.raises(ValueError, match="repeated point"):
        textile.Fibre([[0, 0, 0], [1, 0, 0], [1, 0, 0]], 1e-3, MAT)
    with pytest.raises(ValueError, match="NaN"):
        textile.Fibre([[0, 0, 0], [np.nan, 0, 0]], 1e-3, MAT)
    with pytest.raises(ValueError, match="NaN"):
        textile.Fibre([[0, 0, 0], [np.inf, 0, 0]], 1e-3, MAT)
    with pytest.raises(ValueError, match="shape"):
        textile.Fibre([[0, 0], [1, 0]], 1e-3, MAT)


@pytest.mark.parametrize("nu", [-1.0, 0.5, 0.7, float("nan")])
def test_poisson_ratio_range(nu):
    with pytest.raises(ValueError, match="poisson"):
        textile.Material(1e9, nu)


def test_young_modulus():
    with pytest.raises(ValueError, match="young"):
        textile.Material(-1.0, 0.3)


def test_section_vector_along_tangent():
    with pytest.raises(ValueError, match="section_vector"):
        textile.straight_fibre([0, 0, 0], [1, 0, 0], 1e-3, MAT, section_vector=[1, 0, 0])


def test_unknown_options_and_dofs():
    fib = textile.straight_fibre([0, 0, 0], [1, 0, 0], 1e-3, MAT, num_elements=2)
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    with pytest.raises(ValueError, match="unknown solver option"):
        textile.Solver(model, {"max_iterations": 3})
    with pytest.raises(ValueError, match="unknown dof name"):
        model.fix(fib, 0, "rotation")
    with pytest.raises(ValueError, match="out of range"):
        model.clamp(fib, 7)
    with pytest.raises(ValueError, match="order"):
        textile.BeamElement(order=3)
    with pytest.raises(ValueError, match="section_order"):
        textile.BeamElement(section_order=1)
    with pytest.raises(ValueError, match="odd number of nodes"):
        textile.Model(textile.Fibre([[0, 0, 0], [1, 0, 0]], 1e-3, MAT), comm=MPI.COMM_SELF)
    with pytest.raises(ValueError, match="moment"):
        model.add_end_moment(fib, -1, [0, np.nan, 1])
    with pytest.raises(ValueError, match="force"):
        model.add_force(fib, -1, [0, 1])
