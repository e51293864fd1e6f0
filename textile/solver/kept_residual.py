"""A residual evaluation kept for reuse: :class:`KeptResidual`."""
from __future__ import annotations

import numpy as np
from petsc4py import PETSc


class KeptResidual:
    """A residual evaluation made by :meth:`Newton.residual_norm` (the
    predictor's choice): the iterate, the residual and what the model
    recorded with it (group norms, force scale, support reactions), for
    SNES's first evaluation of the step when it is at the same iterate,
    load factor and constraints. Only the last evaluation is kept: the
    effects' state is then that of this iterate, as after a new
    evaluation."""

    def __init__(self, m, y: PETSc.Vec, r: PETSc.Vec):
        self.x = y.getArray(readonly=True).copy()
        self.r = r.getArray(readonly=True).copy()
        self.recorded = m.residual_record()

    def matches(self, m, x: PETSc.Vec) -> bool:
        return (m.domain_error is None and m.residual_record_current(self.recorded)
                and np.array_equal(x.getArray(readonly=True), self.x))

    def restore(self, m, b: PETSc.Vec) -> None:
        b.getArray()[:] = self.r
        m.restore_residual_record(self.recorded)
