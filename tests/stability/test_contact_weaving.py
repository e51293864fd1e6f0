"""The weaving start of a 2x2 plain weave (docs/method.md §6): straight,
coplanar, interpenetrating yarns of 3 flat fibres are pushed over and under
each other in a weaving stage, then relax in ordinary contact; the crossing
order holds. The Output directory is checked and the Newton count guarded.
"""
import numpy as np

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
