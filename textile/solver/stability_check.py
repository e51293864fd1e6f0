"""The stability of a converged step, as the solver uses it: inertia
(negative eigenvalues of the tangent from the Newton factorization, less
the multipliers' and the zero-energy motions'), branch switching along
the critical modes (SLEPc; :mod:`.branch_switching`) and the signs of a limit point (current
stiffness parameter). The numerics are :mod:`textile.stability.inertia` and
:mod:`textile.stability.zero_motions`; this module decides when to use them.
"""
from __future__ import annotations

import time
import warnings

from petsc4py import PETSc

from ..stability.inertia import (Inertia, critical_modes, factor_negative_pivots,
                                 zero_motion_pivots)
from ..stability.zero_motions import describe, zero_energy_motions
from .branch_switching import BranchSwitching
from .contact_loop import ContactLoop
from .options import StabilityWarning, say


class StabilityCheck:
    """Inertia, branch switching and limit points at converged steps of
    ``loop`` (a :class:`ContactLoop`: its Newton's factorization, and its
    step_to to solve again at the same load). ``warn(message)`` reports a
    lost stability or a singular tangent (a StabilityWarning by default).
    ``negative``: the negative eigenvalues at the last converged step."""

    def __init__(self, loop: ContactLoop, warn=None):
        self.loop = loop
        self.newton = loop.newton
        self.system = loop.system
        self.comm = loop.comm
        self.options = loop.options
        self.counts = loop.newton.counts
        self.warn = warn or self.warning
        self.negative = 0
        self.warned_unstable = False
        self.warned_singular = False
        self.branch_switching = BranchSwitching(self)

    def warning(self, message: str) -> None:
        """A StabilityWarning on rank 0."""
        if self.comm.rank == 0:
            warnings.warn(message, StabilityWarning, stacklevel=3)

    def log(self, msg: str) -> None:
        say(self.options, self.comm, msg)

    def step_to(self, t: float, predict: bool = True):
        return self.loop.step_to(t, predict)

    def inertia(self) -> Inertia:
        """Negative eigenvalues of the tangent at the converged state, from
        the Newton factorization (textile.stability.inertia): its negative pivots,
        less the multipliers' and the zero-energy motions'."""
        if self.options.stability_check == "off":
            return Inertia(None)
        if not self.newton.factor_near and self.newton.linear.kind == "cholesky":
            self.factorize_at_solution()
        ksp = self.newton.snes.getKSP()
        negative = factor_negative_pivots(ksp)
        if negative is None:
            return Inertia(None)
        # a saddle point (multipliers) has one negative eigenvalue per
        # constraint row by construction (Sylvester)
        pivots = negative - self.system.saddle_point_rows
        if pivots <= 0:
            return Inertia(pivots, pivots)
        # some negative pivots may be round-off of zero-energy motions
        t0 = time.perf_counter()
        try:
            motions = zero_energy_motions(self.system, self.system.A)
            negative = pivots - zero_motion_pivots(ksp.getPC(), [z.vector for z in motions])
        finally:
            self.counts["zero_motion_searches"] += 1
            self.counts["zero_motion_seconds"] += time.perf_counter() - t0
        return Inertia(negative, pivots, motions)

    def factorize_at_solution(self) -> None:
        """Factorize the exact tangent at the converged state (the Newton
        solve ended without a factorization close enough to it)."""
        m = self.system
        self.counts["factorizations_at_solution"] += 1
        newton, m.newton = m.newton, "standard"
        try:
            self.counts["jacobian_evaluations"] += 1
            m.jacobian(None, m.x, m.A, m.A)
        finally:
            m.newton = newton
        ksp = self.newton.snes.getKSP()
        ksp.setOperators(m.A, m.A)
        ksp.setUp()
        self.newton.factor_near = True

    def check(self, t: float) -> dict:
        """At a converged step: count negative eigenvalues, warn the first
        time stability is lost, switch branch if asked. Counted and timed:
        ``stability_check_seconds`` is the check's own time (inertia, a
        factorization at the solution, the zero-motion search), the branch
        switching's (``branch_switch_seconds``: critical modes and Newton
        solves) and a description's (``eigen_solve_seconds``) apart."""
        t0 = time.perf_counter()
        switching = self.counts["branch_switch_seconds"]
        eigen = self.counts["eigen_solve_seconds"]
        try:
            return self._check(t)
        finally:
            self.counts["stability_checks"] += self.options.stability_check != "off"
            # a switch's time holds its eigen-solve; a description is an
            # eigen-solve alone: either way not the check's own
            apart = max(self.counts["branch_switch_seconds"] - switching,
                        self.counts["eigen_solve_seconds"] - eigen)
            self.counts["stability_check_seconds"] += time.perf_counter() - t0 - apart

    def _check(self, t: float) -> dict:
        o = self.options
        inertia = self.inertia()
        out = dict(negative_eigenvalues=inertia.negative, negative_pivots=inertia.pivots,
                   zero_energy_motions=inertia.zero, branch_switched=False)
        if not inertia.checked:
            return out
        if inertia.motions and not self.warned_singular:
            self.warned_singular = True
            self.warn(f"the tangent is singular at t={t:.6g}: {inertia.zero} zero-energy "
                      f"motion(s): {describe(inertia.motions)}; their round-off pivots are "
                      f"not counted as negative eigenvalues (hold them if they should be)")
        before = self.negative
        if inertia.negative > before and o.branch_switching:
            switched = self.branch_switching.switch(t, inertia, before)
            out["critical_mode"] = dict(self.branch_switching.found)
            if switched is not None:
                inertia = switched
                out.update(negative_eigenvalues=inertia.negative, negative_pivots=inertia.pivots,
                           zero_energy_motions=inertia.zero, branch_switched=True)
        elif inertia.negative > before and o.describe_instability:
            self.branch_switching.describe(t, inertia, before)
            out["critical_mode"] = dict(self.branch_switching.found)
        if inertia.negative > 0 and not self.warned_unstable:
            self.warned_unstable = True
            hint = ("" if o.branch_switching else
                    "; SolverOptions(branch_switching=True) follows the stable branch")
            self.warn(f"stability lost at t={t:.6g}: the tangent has {inertia.negative} "
                      f"negative eigenvalue(s), the equilibrium followed is unstable (a "
                      f"bifurcation or limit point was passed){hint}")
        self.negative = inertia.negative
        return out

    def critical_modes(self, count: int, deflate):
        """critical_modes of the current factorization, counted and timed."""
        t0 = time.perf_counter()
        try:
            return critical_modes(self.newton.snes.getKSP(), self.system.constrained_positions(),
                                  count, self.comm, deflate)
        finally:
            self.counts["eigen_solves"] += 1
            self.counts["eigen_solve_seconds"] += time.perf_counter() - t0

    def load_pattern(self, t: float) -> PETSc.Vec:
        """d(external load)/dt at the current state: minus the residual's
        derivative in the load factor (a finite difference; exact for dead
        loads), zero on constrained rows."""
        m = self.system
        h = 1e-6 * max(abs(t), 1.0)
        r0, r1 = m.b.duplicate(), m.b.duplicate()
        m.residual(None, m.x, r0)
        m.load_factor = t + h
        m.invalidate_constraints()
        m.residual(None, m.x, r1)
        m.load_factor = t
        m.invalidate_constraints()
        m.residual(None, m.x, m.b)  # leave the model's residual at t
        f = r0
        f.axpy(-1.0, r1)
        f.scale(1.0 / h)
        f.getArray()[m.residual_groups.rows["constraints"]] = 0.0
        r1.destroy()
        return f

    def diagnose(self, t: float, previous=None, first_increment=None) -> str:
        """Why the path may have ended, from the converged steps: the
        current stiffness parameter (Bergan) S = (f.du_1/dt_1) / (f.du_n/dt_n),
        the stiffness along the load pattern f relative to the first step's,
        falls to 0 at a limit point; and the last state's stability."""
        notes = []
        if self.negative:
            notes.append(f"the last converged state is unstable ({self.negative} negative "
                         f"eigenvalue(s) of the tangent)")
        if first_increment is not None and previous is not None:
            dt1, du1 = first_increment
            t_prev, x_prev = previous
            dun = self.system.x - x_prev
            f = self.load_pattern(t)
            c1, cn = f.dot(du1) / dt1, f.dot(dun) / (t - t_prev)
            if c1 > 0 and cn != 0 and c1 / cn < 0.2:
                notes.append(f"the stiffness along the load has fallen to {100 * c1 / cn:.1f}% "
                             f"of its initial value (current stiffness parameter): a limit point "
                             f"(the largest load this structure carries) is near; load control "
                             f"cannot pass it: prescribe displacements instead")
        return "".join(f"; {n}" for n in notes)
