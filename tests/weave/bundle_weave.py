"""A bundle weave as the bundle-weave tests run it: every crossing in
pattern order, penetration <= 0.1 R (the issue's bound), every step
converged, the crimp of the measured run within 2% (the spread of the
2 x 2 weave's crimp over settling schedules, 3.62-3.65%), the Newton
counts guarded."""
import pytest
from mpi4py import MPI

import textile
from textile.fabric import Fabric, Weaving, Yarn
from tests.stability import guard

R = 0.1e-3
MAT = textile.Material(5.0e9, 0.35)


def weave(num: int, widths: float, crimp: float, name: str, fibres: int = 7, **weaving):
    """Weave num x num hexagonal bundles of `fibres` fibres, `widths` yarn
    widths apart, tails of one spacing, and check what every bundle weave
    must hold (module docstring); the solver."""
    yarn = Yarn(fibres, R, MAT, packing="hexagonal")
    spacing = widths * yarn.width
    fabric = Fabric(yarn, num_warp=num, num_weft=num, spacing=spacing, pattern="plain",
                    elements_per_crossing=4, free_length=spacing)
    woven = Weaving(fabric, tension=1e-4, comm=MPI.COMM_SELF, **weaving)
    solver = woven.run(solver_options=dict(verbose=False))
    assert [h.stage for h in solver.history][-1] == "relaxation"
    s = woven.summary()
    assert s["crossings in pattern order"] == s["crossings"] == num * num
    assert s["max penetration / radius"] <= 0.1
    assert s["warp crimp"] == pytest.approx(crimp, rel=0.02)
    assert s["weft crimp"] == pytest.approx(crimp, rel=0.02)
    guard.newton_count(name, solver)
    return solver
