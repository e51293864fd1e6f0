"""Is the equilibrium just found stable? And the critical modes when it is not.

Load control follows whatever equilibrium Newton converges to: past a
bifurcation (a column beyond its buckling load, a fibre pushed sideways) it
happily stays on the unstable branch. At a converged state the tangent K
restricted to the free unknowns is positive definite on a stable branch;
each negative eigenvalue is a direction in which the energy decreases.

- **Inertia.** When the scene's tangent is symmetric, Newton factorizes it
  as LDL^T (MUMPS), and Sylvester's law of inertia gives the number of
  negative eigenvalues for free: the count of negative pivots of the last
  factorization (MUMPS INFOG(12)). Constrained rows are unit rows: they add
  positive pivots only. The last factorization is at the last Newton iterate
  but one, within the solver tolerance of the converged state.
- **Critical modes** (on demand: stability loss, failures): eigenvectors of
  the tangent at the eigenvalues nearest zero (SLEPc, Krylov-Schur with
  shift-and-invert at 0, MUMPS LDL^T inside), with the constrained rows
  moved far from zero so that only structural modes come out.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from petsc4py import PETSc


@dataclass
class Inertia:
    """Eigenvalue signs of the tangent (None where not known)."""

    negative: int | None
    zero: int | None = None

    @property
    def checked(self) -> bool:
        return self.negative is not None

    @property
    def stable(self) -> bool | None:
        return None if self.negative is None else self.negative == 0


def factor_inertia(ksp: PETSc.KSP) -> Inertia:
    """Inertia of the LDL^T factorization held by ``ksp``'s PC (or unknown)."""
    pc = ksp.getPC()
    if pc.getType() != "cholesky":
        return Inertia(None)
    try:
        neg, zero, _ = pc.getFactorMatrix().getInertia()
    except PETSc.Error:
        return Inertia(None)
    return Inertia(int(neg), int(zero))


def critical_modes(K: PETSc.Mat, constrained: np.ndarray, count: int, comm):
    """The ``count`` eigenpairs of the symmetric tangent K nearest zero,
    sorted by eigenvalue; ``constrained``: global row indices of this rank's
    constrained (unit) rows. Returns (eigenvalues, eigenvectors)."""
    from slepc4py import SLEPc

    A = K.copy()
    # constrained rows are unit rows: push their eigenvalue far from zero
    diagonal = A.getDiagonal()
    big = 1e6 * max(abs(diagonal.max()[1]), 1.0)
    rows = np.asarray(constrained, dtype=PETSc.IntType)
    diagonal.setValues(rows, np.full(len(rows), big))
    diagonal.assemble()
    A.setDiagonal(diagonal)
    diagonal.destroy()
    eps = SLEPc.EPS().create(comm)
    eps.setOperators(A)
    eps.setProblemType(SLEPc.EPS.ProblemType.HEP)
    eps.setDimensions(nev=count)
    eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_MAGNITUDE)
    eps.setTarget(0.0)
    st = eps.getST()
    st.setType("sinvert")
    ksp = st.getKSP()
    ksp.setType("preonly")
    ksp.getPC().setType("cholesky")
    ksp.getPC().setFactorSolverType("mumps")
    eps.setTolerances(tol=1e-10, max_it=200)
    eps.solve()
    values, vectors = [], []
    for i in range(min(eps.getConverged(), count)):
        v = A.createVecRight()
        lam = eps.getEigenpair(i, v)
        values.append(float(lam.real))
        vectors.append(v)
    order = np.argsort(values)
    eps.destroy()
    A.destroy()
    return [values[i] for i in order], [vectors[i] for i in order]
