"""The weaving contact mode (docs/method.md §6.2).

Weaving starts from straight, coplanar, interpenetrating yarns; while it
lasts, contact between fibres of two yarns with a crossing order uses the
vertical as its normal, oriented by the order (not by where the fibres
are), so the yarns are pushed over and under each other; then ordinary
contact everywhere.
"""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import ContactOptions, FibreContact
from textile.effects.weaving_contact import weaving_mode, yarn_above
from textile.fabric import Fabric, WeavePattern, Yarn

E, R = 1.0e9, 1e-3
MAT = textile.Material(E, 0.3)


def test_yarn_above_of_a_plain_2x2_fabric():
    """Yarns 0, 1 warps, 2, 3 wefts; plain: warp 0 over weft 0 and under
    weft 1, warp 1 the opposite; yarns of one direction have no order."""
    fab = Fabric(Yarn(3, R, MAT), num_warp=2, num_weft=2, spacing=10 * R, pattern="plain")
    above = yarn_above(fab)
    assert above.tolist() == [[0, 0, 1, -1],
                              [0, 0, -1, 1],
                              [-1, 1, 0, 0],
                              [1, -1, 0, 0]]
    options = weaving_mode(fab)
    assert options["mode"] == "weaving"
    assert options["fibre_yarn"].tolist() == [0] * 3 + [1] * 3 + [2] * 3 + [3] * 3


def flat_fabric(num_yarns: int, pattern):
    """num_yarns warps (along x) and as many wefts (along y) of 3 fibres side
    by side, 14 radii apart, straight, in the plane z = 0, interpenetrating
    at their crossings; each fibre clamped at its start and pinned at its
    end. Returns (fabric, model, contact)."""
    fab = Fabric(Yarn(3, R, MAT, packing="layers 1"), num_warp=num_yarns, num_weft=num_yarns,
                 spacing=14 * R, pattern=pattern)
    fibres = fab.fibres()
    model = textile.Model(fibres, comm=MPI.COMM_SELF)
    for f in fibres:
        model.fix(f, 0, "all")
        model.fix(f, -1, "position")
    contact = FibreContact()
    model.add_effect(contact)
    return fab, model, contact


def two_yarns(warp_on_top: bool):
    """One warp and one weft crossing in the given order."""
    return flat_fabric(1, WeavePattern([[int(warp_on_top)]], allow_floats=True))


def crossing_heights(model, fibres):
    """Height of each fibre's middle node (where the yarns cross)."""
    return np.array([model.centreline(f)[len(f.points) // 2, 2] for f in fibres])


def test_upper_yarn_below_has_a_negative_gap():
    """Weft over warp, but the weft starts 1.5 R *below* the warp (within
    the search distance): the weaving normal is +z from warp to weft, and
    the gap is about -1.5 R - 2R, whatever the current positions say."""
    fab, model, contact = two_yarns(warp_on_top=False)
    model.setup()
    q = model.nodal_unknowns()
    weft = [k for k, y in enumerate(fab.fibre_yarn) if y == 1]
    warp = [k for k, y in enumerate(fab.fibre_yarn) if y == 0]
    for k in weft:
        q[model.mesh.fibre_nodes(k), 2] -= 1.5 * R
    u = q - model.mesh.X_global
    arrays = model.layout.get_local(model.x)
    arrays[model.layout.index("beam")][:] = u.ravel()
    model.layout.scatter(model.x, arrays)
    contact.configure(**weaving_mode(fab))
    model.load_factor = 1.0  # the end of the weaving stage: the whole order applies
    contact.prepare(model)
    d = contact.elements()
    between = np.isin(d["fibre_i"], warp) & np.isin(d["fibre_j"], weft)
    assert between.any() and not np.any(np.isin(d["fibre_i"], weft) & np.isin(d["fibre_j"], warp))
    # i is the warp (lower yarn): N points from the weft down to the warp
    assert np.allclose(d["normal"][between], [0, 0, -1])
    # centre lines 1.5 R apart on the wrong side: gap -1.5 R - 2 R
    assert d["gap"][between].max() == pytest.approx(-3.5 * R, rel=1e-9)
    # at the stage's start the reference interpenetration (coplanar centre
    # lines: -2 R) is not yet asked for: -3.5 R + 2 R
    model.load_factor = 0.0
    contact.prepare(model)
    d = contact.elements()
    between = np.isin(d["fibre_i"], warp) & np.isin(d["fibre_j"], weft)
    assert d["gap"][between].max() == pytest.approx(-1.5 * R, rel=1e-9)
    # within a yarn: the ordinary (in-plane) normal
    within = ~between
    assert np.all(np.abs(d["normal"][within, 2]) < 1e-12)


@pytest.mark.parametrize("warp_on_top", [False, True])
def test_two_yarns_weave_to_the_order_and_keep_it(warp_on_top):
    """Coplanar and interpenetrating, the yarns separate to the prescribed
    order in five weaving steps, and keep it in an ordinary stage."""
    fab, model, contact = two_yarns(warp_on_top)
    fibres = fab.fibres()
    upper = np.array(fab.fibre_yarn) == (0 if warp_on_top else 1)
    solver = textile.Solver(model, dict(initial_step=0.2, max_step=0.2, verbose=False))
    target = contact.adaptation.target
    for stage in (textile.Stage("weave", effects={contact: weaving_mode(fab)}),
                  textile.Stage("relax", effects={contact: dict(mode="ordinary")})):
        solver.run_stage(stage)
        z = crossing_heights(model, fibres)
        # every upper fibre above every lower one by two radii, up to the
        # penetration the penalty allows (the band's top), read at the
        # middle nodes: the contacts sit where each pair of fibres crosses,
        # up to 2 R off the middle, where the bent fibres are a little
        # closer, and they measure the centre lines smoothed across the
        # kinked middle nodes (particle.h), up to about kink x window / 8
        # off the fibres (measured 5.3e-6 m = 0.13 target beyond the band's
        # top; 3.3e-7 m with crossings held at their particles)
        assert z[upper].min() - z[~upper].max() > 2 * R - 2.3 * target
        d = contact.elements()
        active = d["normal_force"] > 0
        assert -d["gap"][active].min() <= 2 * target
        assert solver.history[-1].effects["crossed_contacts"] == 0
        between = upper[d["fibre_i"]] != upper[d["fibre_j"]]
        # the normals point from the lower fibre up to the upper one
        up = np.where(upper[d["fibre_i"][between]], 1.0, -1.0)
        assert np.all(up * d["normal"][between, 2] > 0.9)
    assert contact.mode == "ordinary"
    assert len(solver.history) == 10 and all(h.attempts == 1 for h in solver.history)


def test_configure_checks_its_options():
    fab, model, contact = two_yarns(False)
    with pytest.raises(ValueError, match="mode must be one of"):
        contact.configure(mode="knitting")
    with pytest.raises(ValueError, match="needs fibre_yarn and yarn_above"):
        contact.configure(mode="weaving")
    with pytest.raises(ValueError, match="unknown option"):
        contact.configure(order=1)
    with pytest.raises(ValueError, match="antisymmetric"):
        contact.configure(mode="weaving", fibre_yarn=[0] * 3 + [1] * 3,
                          yarn_above=[[0, 1], [1, 0]])
    with pytest.raises(ValueError, match="go with mode='weaving'"):
        contact.configure(mode="ordinary", yarn_above=[[0, 1], [-1, 0]])
    contact.configure(mode="weaving", fibre_yarn=[0] * 4, yarn_above=[[0]])
    with pytest.raises(ValueError, match="names 4 fibres, the model has 6"):
        model.setup()


def test_within_yarns_mode_leaves_crossing_yarns_without_contact():
    """``mode="within_yarns"`` (the lifting weave's first stage): the warp
    and the weft pass through each other, no element between them, while
    the fibres of each yarn keep their contacts (the control: the weaving
    mode, same state, has elements between the yarns)."""
    fab, model, contact = two_yarns(warp_on_top=True)
    model.setup()
    yarn = np.asarray(fab.fibre_yarn)
    contact.configure(**weaving_mode(fab, "within_yarns"))
    contact.prepare(model)
    d = contact.elements()
    assert len(d["fibre_i"]) > 0
    assert np.all(yarn[d["fibre_i"]] == yarn[d["fibre_j"]])
    contact.configure(**weaving_mode(fab))
    contact.prepare(model)
    d = contact.elements()
    assert np.any(yarn[d["fibre_i"]] != yarn[d["fibre_j"]])


def test_update_tolerance_is_a_stage_option():
    """A stage may loosen the contact loop's tolerance (the lifting weave's
    settling does); a bad value is named; the options a user passed are
    not changed."""
    options = ContactOptions()
    contact = FibreContact(options)
    contact.configure(update_tolerance=1e-2)
    assert contact.options.update_tolerance == 1e-2
    assert options.update_tolerance == 1e-3
    for bad in (0.0, -1.0, float("nan"), -float("inf"), True, "1e-2"):
        with pytest.raises(ValueError, match="update_tolerance must be a number > 0"):
            contact.configure(update_tolerance=bad)
    # inf: a loop that lags (the lifting weave's path with a drag)
    contact.configure(update_tolerance=float("inf"))
    assert contact.update_tolerance() == float("inf")
    # a callable of the stage's load factor (a drag's fading: its path loose,
    # its last step as the relaxation)
    contact.configure(update_tolerance=lambda s: 1e-3 if s >= 1 else 1e-2)
    assert contact.update_tolerance(0.5) == 1e-2
    assert contact.update_tolerance(1.0) == 1e-3
    # a bad schedule is named when the stage is configured, not mid-run
    for bad in (lambda s: 0.0, lambda s: "1e-2", lambda s: 1e-2 if s < 1 else float("nan")):
        with pytest.raises(ValueError, match="update_tolerance must be a number > 0"):
            contact.configure(update_tolerance=bad)
    contact.configure(update_tolerance=2e-3)    # a number again: the schedule gone
    assert contact.update_tolerance(0.5) == 2e-3
