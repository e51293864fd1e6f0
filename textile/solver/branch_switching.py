"""Branch switching: an unstable converged state perturbed along the
critical modes of its tangent (SLEPc, on the Newton factorization) and
solved again at the same load, so that Newton settles on a stable branch
(the buckled column instead of the straight one). Used by
:class:`textile.solver.stability_check.StabilityCheck` when
``SolverOptions.branch_switching`` is on; its cost is counted apart from
the check's (``branch_switches``, ``branch_attempts``: the perturbed
states solved, ``branch_switch_seconds``).
"""
from __future__ import annotations

import time

import numpy as np
from petsc4py import PETSc

from ..stability.inertia import Inertia


def max_op():
    from mpi4py import MPI

    return MPI.MAX


class BranchSwitching:
    """Branch switching for ``check`` (a StabilityCheck: its model, options,
    counters, inertia, critical modes, load pattern and step_to)."""

    def __init__(self, check):
        self.check = check
        self.system = check.system
        self.options = check.options
        self.comm = check.comm
        self.counts = check.counts
        #: the last switch's critical mode (eigenvalue, share of each group
        #: of unknowns in it) and, once switched, the largest move of a
        #: position unknown and the potential energy released
        self.found: dict = {}

    def switch(self, t: float, found: Inertia, before: int) -> Inertia | None:
        """Perturb the unstable converged state along its critical modes and
        solve again at the same load; a stable answer is kept.

        The direction is the part of the load pattern f along the critical
        modes, d = sum_i (phi_i . f) phi_i, oriented so that the load does
        positive work along it: an imperfection (a small lateral force)
        picks its own branch, as the physical structure would, and the first
        stable equilibrium along d is kept (-d is tried only where d finds
        none). A perfect structure (f does no work along the modes) falls
        back to the first mode, both signs, and keeps the stable
        equilibrium of least potential energy. Each amplitude of
        ``branch_amplitudes`` is tried in turn, the smallest first."""
        t0 = time.perf_counter()
        self.found = {}
        self.check.log(f"  t={t:.6g}: unstable ({found.negative} negative eigenvalue(s)): "
                       f"branch switching along the critical modes (SLEPc)")
        try:
            values, modes = self.describe(t, found, before)
            if not modes:
                return None
            f = self.check.load_pattern(t)
            d = modes[0].duplicate()
            d.set(0.0)
            for mode in modes:
                d.axpy(mode.dot(f), mode)
            work = d.dot(f)
            oriented = work > 1e-12 * f.norm() * d.norm()
            directions = [d, -d] if oriented else [modes[0], -modes[0]]
            return self._perturb_and_solve(t, before, directions, oriented, values[0])
        finally:
            self.counts["branch_switches"] += 1
            self.counts["branch_switch_seconds"] += time.perf_counter() - t0

    def describe(self, t: float, found: Inertia, before: int):
        """The critical modes of the unstable state (SLEPc, on the Newton
        factorization) and, in ``self.found`` and the log, what the first
        one is: its eigenvalue, the share of each group of unknowns in its
        norm (a mode on the multipliers alone is a redundant constraint, not
        an instability) and its check with the assembled tangent. Returns
        (eigenvalues, modes)."""
        self.found = {}
        values, modes = self.check.critical_modes(found.negative - before,
                                                  [z.vector for z in found.motions or []])
        if not modes:
            return values, modes
        groups = self.system.residual_groups
        norms = groups.norms(modes[0].getArray(readonly=True))
        self.found = dict(eigenvalue=float(values[0]), mode_share={
            n: float(v ** 2) for n, v in zip(groups.names, norms)},
            **self.with_the_matrix(modes[0]))
        shares = ", ".join(f"{n} {v:.3g}" for n, v in self.found["mode_share"].items() if v > 1e-3)
        self.check.log(f"    critical mode at t={t:.6g}: eigenvalue {values[0]:.4g} "
                       f"(v.Kv with the assembled tangent "
                       f"{self.found['rayleigh_with_the_matrix']:.4g}); share: {shares}")
        return values, modes

    def with_the_matrix(self, mode: PETSc.Vec) -> dict:
        """The critical mode (unit norm) checked with the assembled tangent K
        itself rather than its factorization (approximate with block low-rank
        compression): the Rayleigh quotient v.PKPv and |PKPv| (P zeroing the
        constrained rows). An eigenpair of K has |PKPv| = |v.PKPv| = |lambda|;
        much more than |lambda| means the factorization's eigenvalue is not
        the tangent's."""
        K = self.check.newton.snes.getKSP().getOperators()[0]
        free = np.ones(len(mode.getArray(readonly=True)), dtype=bool)
        free[self.system.constrained_positions()] = False
        v = mode.copy()
        v.getArray()[~free] = 0.0
        w = v.duplicate()
        K.mult(v, w)
        w.getArray()[~free] = 0.0
        out = dict(rayleigh_with_the_matrix=float(v.dot(w)),
                   image_norm_with_the_matrix=float(w.norm()))
        v.destroy()
        w.destroy()
        return out

    def _perturb_and_solve(self, t, before, directions, oriented, eigenvalue):
        """switch's attempts: the state perturbed along each
        direction and amplitude, solved at t; see switch."""
        m, o = self.system, self.options
        unstable = m.x.copy()
        length = max(f_.length for f_ in m.mesh.fibres)
        positions = m.residual_groups.rows["positions"]
        stable = []  # (state, inertia) of stable equilibria found
        last = None  # the stable equilibrium the model is at (no re-solve needed)
        for amplitude in o.branch_amplitudes:
            for direction in directions:
                scale = self.comm.allreduce(
                    float(np.abs(direction.getArray(readonly=True)[positions]).max(initial=0.0)),
                    op=max_op())
                if scale == 0:
                    continue
                unstable.copy(m.x)
                m.x.axpy(amplitude * length / scale, direction)
                for e in m.effects:
                    e.restore(m)
                attempt = self.check.step_to(t, predict=False)
                self.counts["branch_attempts"] += 1
                inertia = self.check.inertia()
                last = None
                if attempt.converged and inertia.checked and inertia.negative <= before:
                    stable.append((m.x.copy(), inertia))
                    last = len(stable) - 1
                    if oriented:
                        break  # the branch the load picks
            if stable:
                break
        if not stable:
            unstable.copy(m.x)
            for e in m.effects:
                e.restore(m)
            self.check.step_to(t, predict=False)  # effects, residual and tangent at it again
            self.check.warn(f"branch switching at t={t:.6g} found no stable equilibrium near "
                            f"the unstable one (amplitudes {o.branch_amplitudes} of the fibre "
                            f"length)")
            return None
        # of several stable equilibria, the one of least potential energy
        chosen = 0
        for i in range(1, len(stable)):
            if self.energy_difference(stable[chosen][0], stable[i][0]) < 0:
                chosen = i
        best, inertia = stable[chosen]
        # how far the switch moved the fibres and the energy it released
        positions = m.residual_groups.rows["positions"]
        moved = (best.getArray(readonly=True)[positions]
                 - unstable.getArray(readonly=True)[positions])
        self.found.update(moved=self.comm.allreduce(float(np.abs(moved).max(initial=0.0)),
                                                    op=max_op()),
                          energy_released=-self.energy_difference(unstable, best))
        self.check.log(f"    branch switched at t={t:.6g} along the critical mode(s) "
                       f"(eigenvalue {eigenvalue:.3g})")
        if chosen == last:
            return inertia  # the model (effects, tangent) is already at it
        best.copy(m.x)
        for e in m.effects:
            e.restore(m)
        # effects and tangent at the chosen state
        attempt = self.check.step_to(t, predict=False)
        return self.check.inertia() if attempt.converged else inertia

    def energy_difference(self, xa: PETSc.Vec, xb: PETSc.Vec) -> float:
        """Potential energy of state b minus state a (same load factor):
        the residual integrated along the straight path between them (4-point
        Gauss), over the free unknowns (exact for conservative effects)."""
        m = self.system
        dx = xb.copy()
        dx.axpy(-1.0, xa)
        free = np.ones(len(dx.getArray()), dtype=bool)
        free[m.residual_groups.rows["constraints"]] = False
        x = xa.duplicate()
        r = m.b.duplicate()
        total = 0.0
        points, weights = np.polynomial.legendre.leggauss(4)
        for p, w in zip(points, weights):
            xa.copy(x)
            x.axpy(0.5 * (p + 1.0), dx)
            m.residual(None, x, r)
            total += 0.5 * w * float(np.dot(r.getArray(readonly=True)[free],
                                            dx.getArray(readonly=True)[free]))
        return self.comm.allreduce(total)
