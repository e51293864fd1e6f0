"""Central differences of a model's assembled residual: what its assembled
tangent is checked against (one rank, dense matrices: small models only)."""
import numpy as np
from petsc4py import PETSc


def assembled_tangent_and_differences(model, x, h):
    """At the state ``x``: the assembled tangent ``J`` (dense, all columns),
    the central differences ``Jfd`` of the assembled residual with step ``h``
    in each unconstrained unknown, and those unknowns' positions ``free``.
    Compare ``J[:, free]`` with ``Jfd``: a constrained column is left out (its
    row is an identity row, u - u_prescribed, not a derivative to check)."""
    model.jacobian(None, x, model.A, model.A)
    J = model.A.convert("dense", PETSc.Mat()).getDenseArray()
    r = model.b.duplicate()
    v0 = x.getArray().copy()

    def residual(v):
        y = x.duplicate()
        y.setArray(v)
        model.residual(None, y, r)
        return r.getArray().copy()

    free = np.setdiff1d(np.arange(len(v0)), model.constrained_positions())
    Jfd = np.empty((len(v0), len(free)))
    for k, j in enumerate(free):
        e = np.zeros_like(v0)
        e[j] = h
        Jfd[:, k] = (residual(v0 + e) - residual(v0 - e)) / (2 * h)
    return J, Jfd, free
