"""The linear solves of Newton: direct factorization, reuse, and what they cost.

Each Newton iteration solves K du = -r. By default the tangent K is
factorized every iteration (MUMPS LU; LDL^T when every effect of the scene
has a symmetric tangent, which halves the factorization and gives the
inertia of K for stability checks). Options trade factorizations for Krylov
iterations or accuracy:

- ``reuse_factorization = n > 1``: the exact tangent is still assembled
  every iteration and is the operator of a right-preconditioned GMRES, but
  the factorization used as its preconditioner is refreshed at the first
  iteration of every Newton solve, then every n-th iteration, or when
  GMRES needed more than half of ``krylov_max_it`` iterations or failed (the
  solver then retries the Newton solve with a fresh factorization instead of
  cutting the step). The converged answer is unchanged: the residual test is
  the same.
- ``low_rank_tolerance > 0``: MUMPS block low-rank factorization (an
  approximate LU, used as a preconditioner of GMRES on the exact tangent).

With ``SolverOptions.scaling = "diagonal"`` (the default) MUMPS LU
factorizes the tangent scaled symmetrically by its diagonal, D K D with
D = |diag K|^(-1/2) (1 on a zero diagonal: multiplier rows), and scales
nothing itself (ICNTL(8) = 0; KSP's diagonal scaling, the tangent scaled
back after each solve). MUMPS's own choice, an iterative
row and column scaling (ICNTL(8) = 7), is computed again at every
numeric factorization; the diagonal costs one pass over the entries.
With no scaling at all the pivoting degenerates (factorizations several
times slower); the diagonal one pivots as well as MUMPS's on the fibre
tangents. LU only: the LDL^T factorization is also the inverse of the
unscaled tangent for the stability check's eigen-solves (``PC.apply``),
and the Krylov paths keep an older factorization across tangents. The
measured figures are in benchmarks/README.md ("MUMPS scaling").

A MUMPS factorization that runs out of the workspace its analysis
estimated (numerical pivoting on multiplier rows can need more) is retried
with twice the relaxation ICNTL(14) (:meth:`LinearSolver.grow_workspace`,
counted in ``linear_solve_retries``).

Every factorization and solve is counted from PETSc's own event log.
"""
from __future__ import annotations

from petsc4py import PETSc

from .. import _cpp

#: PETSc log events counted by the solver (name in PETSc -> our label).
_EVENTS = {"MatLUFactorNum": "lu_factorizations", "MatCholFctrNum": "ldlt_factorizations",
           "MatLUFactorSym": "symbolic_factorizations",
           "MatCholFctrSym": "symbolic_factorizations", "KSPSolve": "linear_solves",
           "PCSetUp": "pc_setup", "MatMult": "matrix_vector_products"}


def event_counts() -> dict[str, float]:
    """Cumulated counts and times of the PETSc events the solver reports
    (process-wide since logging started)."""
    out: dict[str, float] = {}
    for name, label in _EVENTS.items():
        info = PETSc.Log.Event(name).getPerfInfo()
        out[label] = out.get(label, 0) + int(info["count"])
        out[label + "_seconds"] = out.get(label + "_seconds", 0.0) + float(info["time"])
    return out


class LinearSolver:
    """KSP/PC set-up of a Newton solve and the factorization policy.

    ``symmetric``: every effect's tangent is symmetric (LDL^T allowed).
    """

    def __init__(self, snes: PETSc.SNES, options, prefix: str, symmetric: bool, comm):
        PETSc.Log.begin()  # counts of factorizations and solves (cheap)
        self.options = options
        o = options
        if o.factorization == "auto":
            self.kind = "cholesky" if symmetric and o.linear_solver != "superlu_dist" else "lu"
        else:
            self.kind = o.factorization
        if self.kind == "cholesky" and not symmetric:
            raise ValueError("SolverOptions.factorization='cholesky' needs symmetric tangents; "
                             "this scene has a non-symmetric effect (friction, end moments)")
        if self.kind == "cholesky" and o.linear_solver == "superlu_dist":
            raise ValueError("superlu_dist has no LDL^T factorization: use factorization='lu'")
        self.reuse = o.reuse_factorization
        self.krylov = self.reuse > 1 or o.low_rank_tolerance > 0
        self.snes, self.comm, self.prefix = snes, comm, prefix
        ksp = snes.getKSP()
        if self.krylov:
            ksp.setType("gmres")
            ksp.setPCSide(PETSc.PC.Side.RIGHT)  # the test sees the true residual
            ksp.setTolerances(rtol=o.krylov_rtol, atol=0.0, max_it=o.krylov_max_it)
            ksp.setNormType(PETSc.KSP.NormType.UNPRECONDITIONED)
        else:
            ksp.setType("preonly")
        if o.linear_solver == "mumps" and o.low_rank_tolerance > 0:
            opts = PETSc.Options()
            opts[prefix + "mat_mumps_icntl_35"] = 2
            opts[prefix + "mat_mumps_cntl_7"] = o.low_rank_tolerance
        self._configure_pc()
        self._since_factor = None  # Newton iterations since the last factorization
        self.forced = 0            # factorizations forced by a failed or slow GMRES

    def _configure_pc(self) -> None:
        """The PC factorizes with ``self.kind`` (its options with it)."""
        o, prefix = self.options, self.prefix
        ksp = self.snes.getKSP()
        pc = ksp.getPC()
        pc.setType(self.kind)
        if o.linear_solver != "petsc":
            pc.setFactorSolverType(o.linear_solver)
        # the diagonal scaling instead of MUMPS's (module docstring)
        scaled = o.scaling == "diagonal" and o.linear_solver == "mumps" \
            and self.kind == "lu" and not self.krylov
        _cpp.set_diagonal_scale(ksp, scaled)
        icntl_8 = prefix + "mat_mumps_icntl_8"
        user_set = any(k.lstrip("-") == "mat_mumps_icntl_8" for k in o.petsc_options)
        if scaled and not user_set:
            PETSc.Options()[icntl_8] = 0
        elif not user_set:
            PETSc.Options().delValue(icntl_8)
        self.diagonal_scale = scaled
        if o.linear_solver == "mumps" and self.kind == "cholesky":
            opts = PETSc.Options()
            # inertia (negative pivots) for the stability check: MUMPS
            # reports it with null-pivot detection on, and in parallel
            # with the root node factorized on one process
            opts[prefix + "mat_mumps_icntl_24"] = 1
            if self.comm.size > 1:
                opts[prefix + "mat_mumps_icntl_13"] = 1
                # the root node on one process with null-pivot detection
                # outgrows MUMPS's workspace estimate (INFOG(1) = -9 on a
                # composite with side bodies): relax it by 100% (not 20%)
                opts[prefix + "mat_mumps_icntl_14"] = max(
                    100, opts.getInt(prefix + "mat_mumps_icntl_14", 0))

    def stage_symmetry(self, symmetric: bool) -> None:
        """A stage begins whose tangent is (or is not) symmetric (e.g. its
        friction is switched off): with ``factorization="auto"`` the
        factorization follows it, LDL^T where it may (half the work, and
        the inertia for the stability check), LU where it must. A change
        costs one new analysis."""
        o = self.options
        if o.factorization != "auto":
            if self.kind == "cholesky" and not symmetric:
                raise ValueError("SolverOptions.factorization='cholesky' needs symmetric "
                                 "tangents; this stage has a non-symmetric effect (friction, "
                                 "end moments)")
            return
        kind = "cholesky" if symmetric and o.linear_solver != "superlu_dist" else "lu"
        if kind == self.kind:
            return
        self.kind = kind
        self.snes.getKSP().getPC().reset()
        if kind == "lu":   # LU as a scene without symmetric stages gets it
            for icntl in (24, 13):
                PETSc.Options().delValue(f"{self.prefix}mat_mumps_icntl_{icntl}")
        self._configure_pc()
        self._since_factor = None

    # -- factorization policy --------------------------------------------------
    def operators(self, A: PETSc.Mat) -> tuple[PETSc.Mat, PETSc.Mat]:
        """(operator, preconditioning matrix) for the system matrix A: the
        same matrix; a new matrix (pattern) always gets a new factorization."""
        self._since_factor = None
        return A, A

    def refresh(self, snes: PETSc.SNES) -> None:
        """Inside the Jacobian callback, once the tangent is assembled: keep
        the last factorization as the preconditioner, or let the PC
        factorize the new tangent (SNES reads its lag after the callback)."""
        if self.reuse == 1:
            return
        ksp = snes.getKSP()
        if snes.getIterationNumber() == 0:
            # a new load or new contact elements: the old tangent is stale
            self._since_factor = None
        started = self._since_factor is not None
        last_its = ksp.getIterationNumber() if started else 0
        failed = started and ksp.getConvergedReason() < 0
        slow = last_its > self.options.krylov_max_it // 2
        due = not started or self._since_factor >= self.reuse or failed or slow
        if due:
            if started and (failed or slow):
                self.forced += 1
            self._since_factor = 0
        _cpp.set_lag_preconditioner(snes, -2 if due else -1)
        self._since_factor += 1

    def grow_workspace(self, snes: PETSc.SNES) -> bool:
        """After a failed linear solve: if MUMPS ran out of the workspace its
        analysis estimated (INFOG(1) = -8 or -9: numerical pivoting delayed
        more pivots than foreseen, as on a tangent with multiplier rows and a
        non-symmetric friction block), double the relaxation ICNTL(14) and
        reset the preconditioner so that the next solve analyses afresh with
        it; True then (the solver solves again), False otherwise or past
        1280%."""
        if self.options.linear_solver != "mumps":
            return False
        pc = snes.getKSP().getPC()
        factor = pc.getFactorMatrix()
        if factor.getMumpsInfog(1) not in (-8, -9):
            return False
        relax = factor.getMumpsIcntl(14)
        if relax >= 1280:
            return False
        PETSc.Options()[self.prefix + "mat_mumps_icntl_14"] = 2 * max(relax, 20)
        # ICNTL(14) sizes the workspace at analysis: a new analysis
        pc.reset()
        pc.setType(self.kind)
        pc.setFactorSolverType(self.options.linear_solver)
        self._since_factor = None
        return True

    def relaxation(self) -> int:
        """MUMPS's workspace relaxation ICNTL(14) set for this solver (%)."""
        return PETSc.Options().getInt(self.prefix + "mat_mumps_icntl_14", 20)

    def force_refactorization(self) -> None:
        """The next tangent is factorized (e.g. after GMRES failed)."""
        self._since_factor = None
