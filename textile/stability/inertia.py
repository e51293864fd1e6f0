"""Is the equilibrium just found stable? And the critical modes when it is not.

Load control follows whatever equilibrium Newton converges to: past a
bifurcation (a column beyond its buckling load, a fibre pushed sideways) it
happily stays on the unstable branch. At a converged state the tangent K
restricted to the free unknowns is positive definite on a stable branch;
each negative eigenvalue is a direction in which the energy decreases.
Everything here reuses the Newton solver's last LDL^T factorization F of K
(MUMPS, with the Newton solver's own options: block low-rank, workspace):
no new factorization, only solves with F.

- **Inertia.** Sylvester's law of inertia gives the number of negative
  eigenvalues of F for free: its negative pivots (MUMPS INFOG(12)).
  Constrained rows are unit rows: they add positive pivots only. The
  factorization is of the exact tangent at the converged state or at the
  last Newton iterate but one, within the solver tolerance of it.
- **Zero-energy motions.** A motion nothing resists (a fibre's sections
  free to spin, :mod:`textile.stability.zero_motions`) is a null vector of K: its
  pivot is round-off of either sign. With Y the k zero-energy motions found
  (full column rank), the negative eigenvalues of K on the complement of Y,
  its genuine ones, number

      neg(F) + pos(S) - k,   S = Y^T F^-1 Y   (k x k, k solves with F):

  by Haynsworth's inertia additivity the bordered matrix
  M = [[F, Y], [Y^T, 0]] has In(M) = In(F) + In(-S), and a bordered
  matrix has In(M) = In(F on Y^perp) + (k, k, 0) (Chabrillac and
  Crouzeix 1984); equate the negative counts. Exact for the factorized F,
  whatever signs the round-off pivots took.
- **Critical modes** (branch switching): the eigenvectors of the negative
  eigenvalues nearest zero, by Krylov-Schur (SLEPc) on theta = 1/lambda of
  P F^-1 P, with P projecting out the constrained rows and the zero-energy
  motions (the most negative theta are the negative lambda nearest zero).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from petsc4py import PETSc


#: Krylov-Schur tolerance of the critical modes (relative residual): they
#: give a direction to perturb along, by 1% to 100% of a fibre's length
#: (SolverOptions.branch_amplitudes), not an answer.
CRITICAL_MODE_TOLERANCE = 1e-8
#: Krylov-Schur restarts before the critical modes give up (then branch
#: switching gives up with a warning); measured: 2 modes of the buckled
#: column beside a 106k-unknown composite in 0.6 of one factorization
#: (benchmarks/README.md).
CRITICAL_MODE_RESTARTS = 100


@dataclass
class Inertia:
    """Eigenvalue signs of the tangent (None where not known): genuine
    negative eigenvalues; the factorization's negative pivots (less the
    multipliers'); the zero-energy motions left out of them
    (:class:`textile.stability.zero_motions.ZeroMotion`; None: not searched, as
    there was no negative pivot they could account for)."""

    negative: int | None
    pivots: int | None = None
    motions: list | None = None

    @property
    def checked(self) -> bool:
        return self.negative is not None

    @property
    def stable(self) -> bool | None:
        return None if self.negative is None else self.negative == 0

    @property
    def zero(self) -> int | None:
        """Number of zero-energy motions (None: not searched)."""
        return None if self.motions is None else len(self.motions)


def factor_negative_pivots(ksp: PETSc.KSP) -> int | None:
    """Negative pivots of the LDL^T factorization held by ``ksp``'s PC
    (None: no LDL^T factorization)."""
    pc = ksp.getPC()
    if pc.getType() != "cholesky":
        return None
    try:
        neg, _, _ = pc.getFactorMatrix().getInertia()
    except PETSc.Error:
        return None
    return int(neg)


def zero_motion_pivots(pc: PETSc.PC, vectors: list[PETSc.Vec]) -> int:
    """How many negative pivots of the factorization held by ``pc`` the
    null vectors ``vectors`` account for: k - pos(Y^T F^-1 Y) (module
    docstring). Collective; len(vectors) solves."""
    k = len(vectors)
    if k == 0:
        return 0
    solved = []
    for y in vectors:
        z = y.duplicate()
        pc.apply(y, z)
        solved.append(z)
    S = np.array([[y.dot(z) for z in solved] for y in vectors])
    for z in solved:
        z.destroy()
    theta = np.linalg.eigvalsh(0.5 * (S + S.T))
    return k - int(np.sum(theta > 0))


class _ProjectedInverse:
    """x -> P F^-1 P x: F^-1 by the factorization held by a PC, P zeroing
    this rank's constrained rows and removing an orthonormal set of
    vectors (the zero-energy motions)."""

    def __init__(self, pc: PETSc.PC, free: PETSc.Vec, deflate: list[PETSc.Vec]):
        self.pc = pc
        self.free = free  # 1 on free rows, 0 on constrained rows
        self.deflate = deflate
        self.work = None

    def project(self, x: PETSc.Vec) -> None:
        x.pointwiseMult(x, self.free)
        for y in self.deflate:
            x.axpy(-y.dot(x), y)

    def mult(self, mat, x, y):
        if self.work is None:
            self.work = x.duplicate()
        x.copy(self.work)
        self.project(self.work)
        self.pc.apply(self.work, y)
        self.project(y)


def orthonormal(vectors: list[PETSc.Vec]) -> list[PETSc.Vec]:
    """Gram-Schmidt (twice) copies of ``vectors``."""
    out = []
    for v in vectors:
        w = v.copy()
        for _ in range(2):
            for u in out:
                w.axpy(-u.dot(w), u)
        w.scale(1.0 / w.norm())
        out.append(w)
    return out


def critical_modes(ksp: PETSc.KSP, constrained_local: np.ndarray, count: int, comm,
                   deflate: list[PETSc.Vec] = ()):
    """The ``count`` negative eigenvalues nearest zero of the tangent
    factorized in ``ksp``'s PC, and their eigenvectors (unit norm), sorted
    by eigenvalue; ``constrained_local``: this rank's constrained rows
    (indices in its owned part); ``deflate``: zero-energy motions to leave
    out. Fewer pairs when fewer converge. Collective."""
    from slepc4py import SLEPc

    K = ksp.getOperators()[0]
    free = K.createVecRight()
    free.set(1.0)
    free.getArray()[np.asarray(constrained_local, dtype=np.int64)] = 0.0
    operator = _ProjectedInverse(ksp.getPC(), free, orthonormal(list(deflate)))
    A = PETSc.Mat().createPython(K.getSizes(), operator, comm=comm)
    A.setUp()
    start = K.createVecRight()
    start.setRandom()
    operator.project(start)
    eps = SLEPc.EPS().create(comm)
    eps.setOperators(A)
    eps.setProblemType(SLEPc.EPS.ProblemType.HEP)
    eps.setDimensions(nev=count)
    # theta = 1 / lambda: the most negative theta are the negative lambda
    # nearest zero
    eps.setWhichEigenpairs(SLEPc.EPS.Which.SMALLEST_REAL)
    eps.setInitialSpace([start])
    eps.setTolerances(tol=CRITICAL_MODE_TOLERANCE, max_it=CRITICAL_MODE_RESTARTS)
    eps.solve()
    values, vectors = [], []
    for i in range(min(eps.getConverged(), count)):
        v = K.createVecRight()
        theta = eps.getEigenpair(i, v).real
        if theta >= 0:
            v.destroy()
            continue
        v.scale(1.0 / v.norm())
        values.append(1.0 / theta)
        vectors.append(v)
    eps.destroy()
    A.destroy()
    start.destroy()
    free.destroy()
    for y in operator.deflate:
        y.destroy()
    order = np.argsort(values)
    return [values[i] for i in order], [vectors[i] for i in order]
