"""Aitken relaxation of the contact loop (textile/solver/loop_relaxation.py):
the factor of a linear contraction lands on its fixed point, its bounds
hold, and a contact loop whose frozen quantity converges linearly settles
in a few passes with it where the plain loop cannot, at the same answer."""
import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

import textile
from textile import _cpp
from textile.effects.base import Effect
from textile.solver import DIVERGED_EFFECTS_UNSETTLED, SolverOptions
from textile.solver.contact_loop import ContactLoop
from textile.solver.loop_relaxation import RELAXATION_BOUNDS, AitkenRelaxation

from .test_solver_parts import EI, NU, QUIET, E, L, R, set_up


def _vec(values):
    v = PETSc.Vec().createSeq(len(values), comm=PETSc.COMM_SELF)
    v.setArray(np.asarray(values, dtype=float))
    return v


@pytest.mark.parametrize("rate", [0.9, 0.5, -0.6])
def test_a_linear_contraction_lands_on_its_fixed_point(rate):
    """G(y) = y* + rate (y - y*): the second relaxed pass moves to y*
    (w = 1 / (1 - rate)); the first has no history (w = 1)."""
    fixed = np.array([1.0, -2.0, 0.5])
    relaxation = AitkenRelaxation()
    y = _vec([0.0, 0.0, 0.0])
    for k in range(2):
        x = _vec(fixed + rate * (y.getArray() - fixed))   # G(y)
        w = relaxation.relax(y, x, capped=False)
        y.destroy()
        y = x
    assert relaxation.factors[0] == 1.0
    assert w == pytest.approx(1 / (1 - rate), rel=1e-12)
    assert np.allclose(y.getArray(), fixed, rtol=0, atol=1e-12)
    y.destroy()
    relaxation.destroy()


def test_the_factor_is_bounded_and_restarts_with_another_map():
    """A standing loop (rate 0.99: w = 100) is followed only to w = 10;
    capped and full solves are different maps: no history across."""
    relaxation = AitkenRelaxation()
    y = _vec([0.0])
    for capped in (False, False, True):
        x = _vec([1.0 + 0.99 * (y.getArray()[0] - 1.0)])
        relaxation.relax(y, x, capped=capped)
        y.destroy()
        y = x
    assert relaxation.factors == [1.0, RELAXATION_BOUNDS[1], 1.0]
    # one pass moved; the restart keeps the attempt's mark (the loop's trend)
    assert relaxation.relaxed_passes == 1 and relaxation.started and not relaxation.waiting
    y.destroy()
    relaxation.destroy()


class _LaggedSpring(Effect):
    """A force rate * K * w on the cantilever's tip deflection w, with K its
    linear stiffness 3 EI / L^3 and w frozen at the last update: a fixed
    point that the plain loop approaches by about ``rate`` a pass (like a
    contact normal held within Newton). Its change: the frozen deflection's
    change in units of 1e-6 L."""

    fields = ("beam",)

    def __init__(self, rate):
        self.k = rate * 3 * EI / L ** 3
        self.frozen, self.change = 0.0, np.inf

    def setup(self, model):
        self.tip = 9 * int(model.mesh.global_to_local([model.mesh.X_global.shape[0] - 1])[0]) + 2

    def _deflection(self, model):
        return float(model.beam_positions(model.state())[-1, 2])

    def prepare(self, model):
        self.frozen = self._deflection(model)

    def update(self, model):
        w = self._deflection(model)
        self.change = abs(w - self.frozen) / (1e-6 * L)
        self.frozen = w
        return self.change > 1

    def update_change(self):
        return self.change

    def residual(self, state, b):
        b["beam"][self.tip] -= self.k * self.frozen


class _Spring(_LaggedSpring):
    """The same spring on the current deflection, in Newton's tangent: the
    loop's fixed point solved directly."""

    def prepare(self, model):
        self.change = 0.0

    def update(self, model):
        self.frozen = self._deflection(model)
        return False

    def residual(self, state, b):
        b["beam"][self.tip] -= self.k * (self.X + state.u["beam"][self.tip])

    def jacobian(self, state, A):
        row = np.array([state.dofs["beam"][self.tip]], dtype=np.int32)
        _cpp.add_diagonal(A, row, -self.k)

    def setup(self, model):
        super().setup(model)
        self.X = float(model.mesh.X_global[-1, 2])


def _spring_attempt(relaxation, max_updates=20, rate=0.85, spring=_LaggedSpring):
    # a small tip force: deflections of a few % of L, near the linear
    # stiffness the spring is scaled by
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, NU),
                                 num_elements=8, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    model.add_force(fib, -1, [0, 0, 0.01 * EI / L ** 2])
    spring = spring(rate)
    model.add_effect(spring)
    options = SolverOptions(loop_relaxation=relaxation, max_updates=max_updates, **QUIET)
    attempt = ContactLoop(set_up(model, options)).step_to(1.0)
    return attempt, spring.frozen


def test_a_linearly_converging_loop_settles_in_a_few_relaxed_passes():
    """The lagged spring at 0.85 a pass: the plain loop's trend cannot
    settle within 20 solves (from 3 333 at 15% a pass) and fails; relaxed,
    it settles in 6 passes (17 Newton iterations; the plain loop, given 200
    solves, took 51 and 119), 3.7e-8 L from the fixed point (its last
    change, 0.0066e-6 L, times 0.85 / 0.15; the plain loop stops 5.2e-6 L
    short: its last change, 0.93e-6 L, times 0.85 / 0.15)."""
    plain, _ = _spring_attempt("none")
    assert plain.reason == DIVERGED_EFFECTS_UNSETTLED and not plain.converged
    assert "too slowly to settle" in plain.message
    relaxed, w = _spring_attempt("aitken")
    assert relaxed.converged, relaxed.message
    assert relaxed.updates == 6 and relaxed.iterations == 17, relaxed.passes
    # the loop's 1 / (1 - 0.85) = 6.7 (measured 6.66, 6.62)
    assert relaxed.relaxation[0] == 1.0 and 6.4 < max(relaxed.relaxation) < 6.8
    direct, w_fixed = _spring_attempt("none", spring=_Spring)
    assert direct.converged
    assert abs(w - w_fixed) <= 1e-7 * L        # 3.7e-8 L measured: its last change's lag
    long, w_plain = _spring_attempt("none", max_updates=200)
    assert long.converged and long.updates == 51
    assert 4e-6 * L < abs(w_plain - w_fixed) < 7e-6 * L   # 5.2e-6 L measured


def test_the_option_is_checked_and_is_a_stage_option():
    with pytest.raises(ValueError, match="loop_relaxation"):
        SolverOptions(loop_relaxation="anderson")
    assert "loop_relaxation" in textile.Solver.STAGE_OPTIONS
