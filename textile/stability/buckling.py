"""Stability analysis helpers: linearized buckling of a model's fibres.

Small dense eigenproblems, for validation and studies of single fibres or
small assemblies (a few thousand unknowns): under MPI the tangent is
gathered to rank 0, solved there, and the result broadcast.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg

from ..scene.model import Model
from ..solver import Solver


def dense_tangent(model: Model) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Dense tangent at the model's current state and load factor, restricted
    to the free (unconstrained) unknowns, in PETSc's global numbering;
    returns (K_ff, free global indices) on rank 0 and (None, None) on the
    other ranks (collective)."""
    model.setup()
    model.jacobian(None, model.x, model.A, model.A)
    lo, hi = model.A.getOwnershipRange()
    indptr, cols, vals = model.A.getValuesCSR()
    constrained = lo + np.asarray(model.constrained_positions(), dtype=np.int64)
    parts = model.comm.gather((lo, hi, indptr, cols, vals, constrained), root=0)
    if model.comm.rank != 0:
        return None, None
    n = model.A.getSize()[0]
    K = np.zeros((n, n))
    for lo_r, hi_r, ip, c, v, _ in parts:
        rows = np.repeat(np.arange(lo_r, hi_r), np.diff(ip))
        K[rows, c] = v
    free = np.setdiff1d(np.arange(n), np.concatenate([p[5] for p in parts]))
    return K[np.ix_(free, free)], free


def linear_buckling(model: Model, probe: float = 1e-3, solver_options=None,
                    num: int = 1) -> np.ndarray:
    """Critical load factors of the model's loads by linearized buckling.

    The tangent is evaluated in the unloaded state (K0) and in the
    equilibrium state at load factor ``probe`` (K1); with the geometric
    stiffness Kg = (K1 - K0) / probe, the critical factors are the smallest
    positive mu with det(K0 + mu Kg) = 0. Exact for a pre-buckling state
    that is linear in the load (a straight column in compression, up to its
    tiny axial shortening). Returns the ``num`` smallest positive factors.
    """
    model.setup()
    if model.load_factor != 0.0:
        raise ValueError("linear_buckling needs a model in its unloaded state")
    K0, free = dense_tangent(model)
    opts = dict(initial_step=probe, max_step=probe, min_step=probe / 16, verbose=False)
    opts.update(solver_options or {})
    Solver(model, opts).solve(probe)
    K1, _ = dense_tangent(model)
    real = None
    if model.comm.rank == 0:
        real = _critical_factors(K0, (K1 - K0) / probe)
    real = model.comm.bcast(real, root=0)
    if real.size == 0:
        raise RuntimeError("linear_buckling: no positive critical load factor found")
    return np.sort(real)[:num]


def _critical_factors(K0: np.ndarray, Kg: np.ndarray) -> np.ndarray:
    """Positive real mu with det(K0 + mu Kg) = 0."""
    # symmetric tangents: symmetrize away round-off; a repeated eigenvalue
    # (a round section buckles in two planes) still comes out as a complex
    # pair split by round-off (measured 1.6e-8 relative), hence the 1e-6
    mu = scipy.linalg.eigvals(0.5 * (K0 + K0.T), -0.5 * (Kg + Kg.T))
    mu = mu[np.isfinite(mu)]
    return mu[(np.abs(mu.imag) <= 1e-6 * np.abs(mu.real)) & (mu.real > 0)].real
