"""The weaving start of a 2x2 plain weave (docs/method.md §6): straight,
coplanar, interpenetrating yarns of 3 flat fibres are pushed over and under
each other in a weaving stage, then relax in ordinary contact; the crossing
order holds. The Output directory is checked and the Newton count guarded.
"""
import numpy as np
from mpi4py import MPI

import textile
from textile.effects.weaving_contact import weaving_mode, yarn_above
from tests.contact.test_weaving_mode import flat_fabric

from . import guard


def test_plain_weave_start(out):
    fab, model, contact = flat_fabric(2, "plain")
    solver = textile.Solver(model, dict(initial_step=0.2, max_step=0.2, verbose=False),
                            output=textile.Output(out))
    above = yarn_above(fab)
    yarn = np.asarray(fab.fibre_yarn)
    for stage in (textile.Stage("weave", effects={contact: weaving_mode(fab)}),
                  textile.Stage("relax", effects={contact: dict(mode="ordinary")})):
        solver.run_stage(stage)
        d = contact.elements()
        order = above[yarn[d["fibre_i"]], yarn[d["fibre_j"]]]
        ordered = (order != 0) & (d["normal_force"] > 0)
        assert ordered.sum() >= 36  # every fibre crossing of the 4 yarn crossings
        # the normal points from fibre j up to fibre i exactly when i's yarn
        # lies above: the order of the pattern holds
        assert np.all(order[ordered] * d["normal"][ordered, 2] > 0.9)
        assert solver.history[-1].effects["crossed_contacts"] == 0
        assert -d["gap"].min() <= 2 * contact.adaptation.target
    guard.clean_output(out, solver)
    assert len(solver.history) == 10
    guard.newton_count("contact_plain_weave_start", solver)


def test_bundle_lifting_weave(out):
    """A 2 x 2 plain weave of 3-fibre hexagonal bundles, 2 widths apart,
    woven by lifting (docs/method.md §6.4): every crossing in pattern order,
    penetration <= 0.1 R (issue 20's bound), clean output, Newton counts
    guarded."""
    from textile.fabric import Fabric, Weaving, Yarn
    R = 0.1e-3
    yarn = Yarn(3, R, textile.Material(5.0e9, 0.35), packing="hexagonal")
    p = 2.0 * yarn.width
    fab = Fabric(yarn, num_warp=2, num_weft=2, spacing=p, pattern="plain",
                 elements_per_crossing=4, free_length=p)
    w = Weaving(fab, comm=MPI.COMM_SELF)
    solver = textile.Solver(w.model, dict(verbose=False), output=textile.Output(out))
    solver.run(w.stages())
    s = w.summary()
    assert s["crossings in pattern order"] == s["crossings"] == 4
    assert s["max penetration / radius"] <= 0.1
    guard.clean_output(out, solver)
    guard.newton_count("weave_bundles_3_lifting", solver)
