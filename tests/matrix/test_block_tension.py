"""Tension of a matrix block: P1 and P2 against the exact finite-strain
uniaxial answer, and P1 converging to P2's stiffness when the ends are
clamped (a non-homogeneous state)."""
import time

import numpy as np
import pytest
from mpi4py import MPI
from scipy.optimize import brentq

import textile
from textile.effects.elastic_block import ElasticBlock
from textile.composite.matrix_mesh import gmsh_box

from block_scenes import SideDisplacement, block_model

E, NU, L = 1.0e3, 0.3, 2.0             # Pa, -, m: the bar [0, L] x [0, 1] x [0, 1]
MU, LMBDA = E / (2 * (1 + NU)), E * NU / ((1 + NU) * (1 - 2 * NU))


def uniaxial_force(stretch: float, law: str) -> float:
    """Exact force (N) on the unit section of a bar stretched by ``stretch``
    with free lateral faces: the lateral stretch makes the lateral stress 0."""
    if law == "neo-hookean":
        # principal first Piola-Kirchhoff stress mu (l - 1/l) + lambda ln J / l
        P = lambda l, J: MU * (l - 1 / l) + LMBDA * np.log(J) / l  # noqa: E731
    else:
        # St Venant-Kirchhoff: P = l S, S = lambda tr E + 2 mu E_ii
        def P(l, J):
            lat = np.sqrt(J / stretch)
            trE = 0.5 * (stretch ** 2 - 1) + (lat ** 2 - 1)
            return l * (LMBDA * trE + MU * (l ** 2 - 1))
    lateral = brentq(lambda q: P(q, stretch * q * q), 0.5, 1.0 + 1e-12)
    return P(stretch, stretch * lateral ** 2)


def solve_tension(comm, degree, size, law="neo-hookean", clamped=False, strain=0.2):
    """Pull the x = L side by strain * L; return (force on x = L, seconds)."""
    mm = gmsh_box(comm, [0, 0, 0], [L, 1, 1], size)
    block = ElasticBlock(mm, E, NU, law=law, degree=degree, clamp="xmin" if clamped else None)
    model = block_model(comm, block, force_scale=E * strain)
    if clamped:
        model.add_effect(SideDisplacement(block, "xmax", [0, 1, 2], [strain * L, 0, 0]))
    else:
        # symmetry planes: the bar is free to contract laterally
        for side, c in (("xmin", 0), ("ymin", 1), ("zmin", 2)):
            model.add_effect(SideDisplacement(block, side, [c], [0.0]))
        model.add_effect(SideDisplacement(block, "xmax", [0], [strain * L]))
    t0 = time.perf_counter()
    textile.Solver(model, {"verbose": False, "initial_step": 0.5, "max_step": 0.5}).solve()
    assert model.load_factor == 1.0
    return block.reaction("xmax"), time.perf_counter() - t0


@pytest.mark.mpi
@pytest.mark.parametrize("degree, law", [(1, "neo-hookean"), (2, "neo-hookean"), (2, "svk")])
def test_uniaxial_tension_is_exact(degree, law):
    """A homogeneous deformation is in both spaces: the force is the exact
    one to round-off (measured 1e-14 relative), at 20% strain."""
    force, _ = solve_tension(MPI.COMM_WORLD, degree, 0.5, law)
    exact = uniaxial_force(1.2, law)
    # 1e-12: round-off of a few hundred cells' forces, on 1 or 2 ranks
    assert force[0] == pytest.approx(exact, rel=1e-12)
    assert np.all(np.abs(force[1:]) <= 1e-12 * exact)   # no lateral force on a free side


def test_clamped_tension_p1_converges_to_p2():
    """Clamped ends stiffen the bar (lateral contraction blocked there): no
    closed form, but E A / L < K < (lambda + 2 mu) A / L, and P1 refined
    approaches P2's value, which is closer on the coarse mesh already.
    Measured (relative to P2 at h = 0.2): P1 2.5e-2, 1.25e-2, 4.0e-3 at
    h = 0.4, 0.2, 0.1; P2 2.2e-3 at h = 0.4."""
    strain = 1e-4   # linear regime
    K = {}
    for degree, size in ((1, 0.4), (1, 0.2), (1, 0.1), (2, 0.4), (2, 0.2)):
        f, seconds = solve_tension(MPI.COMM_SELF, degree, size, clamped=True, strain=strain)
        K[degree, size] = f[0] / (strain * L)
        print(f"P{degree} h={size}: K = {K[degree, size]:.6f} N/m ({seconds:.1f} s)")
    ref = K[2, 0.2]
    assert E / L < ref < (LMBDA + 2 * MU) / L
    err = {k: abs(v - ref) / ref for k, v in K.items()}
    print({k: f"{v:.2e}" for k, v in err.items()})
    assert err[1, 0.4] > err[1, 0.2] > err[1, 0.1]     # P1 converges ...
    assert err[1, 0.1] < 0.01                           # ... to P2's stiffness
    assert err[2, 0.4] < err[1, 0.1]                    # P2 coarse beats P1 fine
