"""The weaving computation: straight, interpenetrating yarns become a fabric
that follows its pattern (docs/method.md §6)."""
import math

import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.fabric import Fabric, Weaving, Yarn, measures as fm
from tests.stability import guard

R = 0.1e-3
MAT = textile.Material(5.0e9, 0.35)
# Monofilament yarns (one fibre a yarn) and flat yarns of several fibres
# weave by ordered contact (the paper's); bundles (yarns more than one
# fibre high) by lifting (Weaving's docstring)


def woven(num, fibres, pattern="plain", spacing=6.0, comm=MPI.COMM_SELF, packing="hexagonal",
          free_length=None, **kwargs):
    yarn = Yarn(fibres, R, MAT, packing=packing)
    fab = Fabric(yarn, num_warp=num, num_weft=num, spacing=spacing * yarn.width,
                 pattern=pattern, elements_per_crossing=4,
                 free_length=None if free_length is None else free_length * spacing * yarn.width)
    w = Weaving(fab, comm=comm, **kwargs)
    solver = w.run(solver_options=dict(verbose=False))
    return w, solver


def check_woven(w):
    """Every crossing in pattern order, no deep penetration, crimp > 0."""
    s = w.summary()
    sep = fm.crossing_separation(w.fabric, w.model)
    # every fibre of the upper yarn above every fibre of the lower one, by
    # at least most of a fibre diameter (the centre lines; touching fibres
    # are 2 R apart)
    assert sep.min() > R, sep
    # the acceptance bound of the weaving issue: penetration <= 10% of R
    assert s["max penetration / radius"] <= 0.1
    c = fm.crimp(w.fabric, w.model)
    assert np.all(c > 0), c
    return s


def test_plain_weave_2x2_follows_its_pattern():
    w, solver = woven(2, 1)
    s = check_woven(w)
    stages = [h.stage for h in solver.history]
    assert stages.count("weaving") == 5 and stages[-1] == "relaxation"
    # a balanced plain weave: warp and weft crimp within 5%
    assert s["warp crimp"] == pytest.approx(s["weft crimp"], rel=0.05)


def test_flat_yarns_of_three_fibres_weave():
    # yarns of several fibres side by side (a flat yarn) weave through both
    # stages; stacked (hexagonal) ones do not settle yet
    w, solver = woven(2, 3, spacing=2.3, packing="layers 1")
    s = check_woven(w)
    assert s["warp crimp"] == pytest.approx(s["weft crimp"], rel=0.05)


def test_tight_flat_yarns_weave():
    # 3-fibre flat yarns only 1.5 widths apart: the relaxation's contact
    # loop cycled (effects unsettled) until the zones' kinds got their
    # hysteresis and crossings their blended tangents (detection.h;
    # measured 2026-12-01: penetration 0.066 R, crimp 4.4%, 10-13 s)
    w, solver = woven(2, 3, spacing=1.5, packing="layers 1")
    s = check_woven(w)
    assert s["crossings in pattern order"] == 4
    assert s["warp crimp"] == pytest.approx(s["weft crimp"], rel=0.05)


def test_plain_weave_of_seven_fibre_yarns():
    # the weaving issue's main case: 2 x 2 yarns of 7 fibres (flat), 2 widths
    # apart; every fibre of the upper yarn above every fibre of the lower
    # one at each crossing, penetration <= 10% R (check_woven)
    w, solver = woven(2, 7, spacing=2.0, packing="layers 1")
    s = check_woven(w)
    assert s["crossings in pattern order"] == 4
    assert s["warp crimp"] == pytest.approx(s["weft crimp"], rel=0.05)


def test_twill_2_2_follows_its_pattern():
    w, _ = woven(4, 1, pattern="twill 2/2")
    check_woven(w)


def test_plain_weave_3x3_follows_its_pattern():
    w, _ = woven(3, 1)
    check_woven(w)


def test_crimp_rises_as_the_spacing_shrinks():
    crimps = []
    for spacing in (8.0, 6.0, 4.0):
        w, _ = woven(2, 1, spacing=spacing)
        check_woven(w)
        crimps.append(fm.crimp(w.fabric, w.model).mean())
    assert crimps[0] < crimps[1] < crimps[2], crimps


def test_bundles_weave_by_lifting():
    """3-fibre hexagonal bundles, 2 widths apart (the ordered weave's
    relaxation fails on them: the vertical gap hid overlaps of 1.2 R on the
    yarns' flanks): every crossing in pattern order, penetration <= 0.1 R,
    and the bundles flatten where they cross (lens-shaped sections)."""
    w, solver = woven(2, 3, spacing=2.0, free_length=1.0)
    assert w.method == "lifting"
    s = check_woven(w)
    assert s["crossings in pattern order"] == 4
    assert [h.stage for h in solver.history][-1] == "relaxation"
    # balanced: warp and weft crimp within 5% (measured 2026-12-01: 3.45%
    # and 3.40%)
    assert s["warp crimp"] == pytest.approx(s["weft crimp"], rel=0.05)
    # flattened: 3.7 R high and 4 R wide at the start, 2.6 R x 5.8 R woven
    # (measured); a round bundle would keep height/width 0.93
    assert s["warp section height"] / s["warp section width"] < 0.6
    # Newton guard (measured 189 iterations, 3 failed attempts counted,
    # 2026-12-07, with at most 3 Newton iterations a contact pass and Newton
    # on the path to Weaving.PATH_RTOL of the step's first residual; 211 of
    # each solve's, 418 to the full tolerance (an older count), 571 with
    # every pass's solve run to convergence, 788 with the default
    # contact-loop tolerance in the settling stage): 1.5 x 189
    assert solver.counters["newton_iterations"] <= 283


def test_bad_weaving_options():
    fab = Fabric(Yarn(1, R, MAT), spacing=10 * R)
    with pytest.raises(ValueError, match="method must be one of"):
        Weaving(fab, method="jacquard", comm=MPI.COMM_SELF)
    with pytest.raises(ValueError, match="amplitude"):
        Weaving(fab, method="lifting", amplitude=0.2, comm=MPI.COMM_SELF)
    with pytest.raises(ValueError, match="tails of at least one spacing"):
        Weaving(fab, method="lifting", comm=MPI.COMM_SELF)   # free_length: half a spacing
    with pytest.raises(ValueError, match="steps must be an integer >= 1"):
        Weaving(fab, steps=0, comm=MPI.COMM_SELF)
    with pytest.raises(ValueError, match="tension is an axial strain"):
        Weaving(fab, tension=-1.0, comm=MPI.COMM_SELF)
    with pytest.raises(TypeError, match="fabric must be a textile.fabric.Fabric"):
        Weaving("plain", comm=MPI.COMM_SELF)
    bundles = Fabric(Yarn(3, R, MAT), spacing=20 * R, free_length=20 * R)
    for drag in (-0.1, float("nan"), True):
        with pytest.raises(ValueError, match="drag is a coefficient >= 0"):
            Weaving(bundles, drag=drag, comm=MPI.COMM_SELF)
        with pytest.raises(ValueError, match="lifting_drag is a coefficient >= 0"):
            Weaving(bundles, lifting_drag=drag, comm=MPI.COMM_SELF)
    with pytest.raises(ValueError, match="drag belongs to the lifting weave"):
        Weaving(fab, drag=0.1, comm=MPI.COMM_SELF)   # monofilaments: ordered
    lifted = Weaving(bundles, lifting_drag=0.1, comm=MPI.COMM_SELF)
    assert [st.name for st in lifted.stages()] == ["lifting", "settling", "relaxation"]
    assert lifted.stages()[0].effects[lifted.viscous_drag]["coefficient"] == 0.1
    assert lifted.stages()[1].effects[lifted.viscous_drag]["coefficient"] == 0.0
    with pytest.raises(ValueError, match="viscous_fading .* needs a drag > 0"):
        Weaving(bundles, viscous_fading=True, comm=MPI.COMM_SELF)
    with pytest.raises(ValueError, match="relaxation_steps has no stage to count with a drag"):
        Weaving(bundles, drag=0.1, relaxation_steps=2, comm=MPI.COMM_SELF)
    with pytest.raises(TypeError, match="viscous_fading is True or False"):
        Weaving(bundles, drag=0.1, viscous_fading=1, comm=MPI.COMM_SELF)
    viscous = Weaving(bundles, drag=0.1, viscous_fading=True, comm=MPI.COMM_SELF)
    fading = viscous.stages()[2]
    assert fading.name == "fading"
    assert fading.effects[viscous.viscous_drag]["step"] == 1.0 / Weaving.FADING_STEPS
    # a cut step drags harder: the stage may cut below the run's min_step
    assert fading.solver["min_step"] == Weaving.VISCOUS_FADING_MIN_STEP
    assert "min_step" not in Weaving(bundles, drag=0.1, comm=MPI.COMM_SELF).stages()[2].solver
    # the fading's path has the settling's loose contact loop, its last step
    # (the woven state) the contact's own tolerance
    tolerance = fading.effects[viscous.contact]["update_tolerance"]
    assert tolerance(0.99) == Weaving.PATH_UPDATE_TOLERANCE
    assert tolerance(1.0) == viscous.contact.options.update_tolerance < tolerance(0.99)
    # the settling's drag a viscosity on request only
    assert viscous.stages()[1].effects[viscous.viscous_drag]["step"] is None
    with pytest.raises(ValueError, match="viscous_settling .* needs a drag > 0"):
        Weaving(bundles, lifting_drag=0.1, viscous_settling=True, comm=MPI.COMM_SELF)
    with pytest.raises(TypeError, match="viscous_settling is True or False"):
        Weaving(bundles, drag=0.1, viscous_settling="yes", comm=MPI.COMM_SELF)
    settling = Weaving(bundles, drag=0.1, viscous_settling=True, settling_steps=8,
                       comm=MPI.COMM_SELF)
    assert settling.stages()[1].effects[settling.viscous_drag] == dict(coefficient=0.1,
                                                                       step=1.0 / 8)
    with pytest.raises(ValueError, match="pull must be one of"):
        Weaving(bundles, pull="fibres", comm=MPI.COMM_SELF)
    for n in (-1, 2.5):
        with pytest.raises(ValueError, match="newton_per_pass is an integer >= 0"):
            Weaving(bundles, newton_per_pass=n, comm=MPI.COMM_SELF)


def test_a_drag_is_faded_out_to_the_woven_state():
    """Weaving(drag=c): the settling stage with a ViscousDrag of
    coefficient c, then a fading stage taking it away as c (1 - s)^2 whose
    last step has none, so the woven state is the structure's own
    equilibrium (no relaxation follows: Weaving.stages): 3-fibre bundles
    as in test_bundles_weave_by_lifting end with the same crimp by this
    other path."""
    w, solver = woven(2, 3, spacing=2.0, free_length=1.0, drag=0.1)
    stages = w.stages()
    assert [st.name for st in stages] == ["lifting", "settling", "fading"]
    drag = w.viscous_drag
    assert stages[0].effects[drag]["coefficient"] == 0.0   # lifting_drag's
    assert stages[1].effects[drag]["coefficient"] == 0.1
    fade = stages[2].effects[drag]["coefficient"]
    assert fade(0.0) == pytest.approx(0.1) and fade(1.0) == 0.0
    assert all(st.solver["newton_per_pass"] == 0 for st in stages)   # the default with a drag
    last = solver.history[-1]
    assert last.stage == "fading" and last.load_factor == 1.0
    assert last.effects["drag_force"] == 0.0   # the woven state: no drag left
    s = check_woven(w)
    assert s["crossings in pattern order"] == 4
    # the drag-free weave's crimp (measured 3.47% by both paths, 2026-12-02;
    # friction within the bundles makes the end state path-dependent): 2%
    assert s["warp crimp"] == pytest.approx(0.0347, rel=0.02)
    # Newton guard (measured 251 iterations, 3 failed attempts, 2026-12-07,
    # Newton on the path to Weaving.PATH_RTOL of the step's first residual;
    # 262 of each solve's, 398 to the full tolerance, 757 with the fading's
    # path at the contact's own loop tolerance): 1.5 x
    assert solver.counters["newton_iterations"] <= 376
    # every stage regrows its steps after a cut (uncapped, no step is easy)
    assert all(st.solver["regrow_after"] == Weaving.REGROW_AFTER for st in stages)
    # the default drag: on every node's own motion
    assert len(drag.pairs) == 0 and drag.absolute_share == 1
    plain = Weaving(Fabric(Yarn(3, R, MAT), spacing=20 * R, free_length=20 * R),
                    comm=MPI.COMM_SELF)
    assert plain.viscous_drag is None and len(plain.stages()) == 3


def test_a_viscous_fading_weaves_the_same_state():
    """Weaving(drag=c, viscous_fading=True): the fading stage's drag a
    viscosity (a cut step drags harder); the 3-fibre bundles of
    test_a_drag_is_faded_out_to_the_woven_state end woven with the
    drag-free crimp, the relaxation without any drag."""
    w, solver = woven(2, 3, spacing=2.0, free_length=1.0, drag=0.1, viscous_fading=True)
    assert solver.history[-1].stage == "fading" and solver.history[-1].load_factor == 1.0
    assert solver.history[-1].effects["drag_force"] == 0.0
    # the fading's loose-then-tight loop tolerance ended with it: what follows
    # the weave takes the contact's own
    assert w.contact.update_tolerance(0.5) == w.contact.options.update_tolerance == 1e-3
    s = check_woven(w)
    assert s["crossings in pattern order"] == 4
    # measured 3.458% (2026-12-05) against 3.47% by the other paths: 2%
    assert s["warp crimp"] == pytest.approx(0.0347, rel=0.02)
    # capped Newton solves between contact updates (newton_per_pass), the
    # default on a viscous fading's path
    assert all(st.solver["newton_per_pass"] == Weaving.NEWTON_PER_PASS for st in w.stages())
    # Newton guard (measured 196 iterations, 2 failed attempts, 2026-12-07,
    # capped solves; 256 with solves to convergence; 272 with Newton to
    # each solve's own PATH_RTOL, 427 to the full tolerance, 531 with the
    # fading's path at the contact's own loop tolerance): 1.5 x
    assert solver.counters["newton_iterations"] <= 294


def test_a_contact_loop_that_lags_on_the_drags_path_weaves_the_same_state():
    """Weaving(drag=c, lagged_path=True): on the drag's path (the settling,
    the fading's steps before the last) a step is accepted after its first
    converged Newton solve, what its contact update finds acting from the
    next step; the woven state (the fading's last step) at the contact's
    own tolerance. The bundles of test_a_drag_is_faded_out_to_the_woven_state
    end woven with the same crimp, in fewer Newton iterations."""
    w, solver = woven(2, 3, spacing=2.0, free_length=1.0, drag=0.1, lagged_path=True)
    stages = w.stages()
    assert stages[0].effects[w.contact].get("update_tolerance") is None   # no lifting_drag
    assert stages[1].effects[w.contact]["update_tolerance"] == math.inf
    fading = stages[2].effects[w.contact]["update_tolerance"]
    assert fading(0.5) == math.inf and fading(1.0) == w.contact.options.update_tolerance
    # a step solves again only for contact forces where there were none (an
    # infinite change) or fibres that crossed: measured one pass a step
    path = [r for r in solver.history if r.stage == "settling"
            or (r.stage == "fading" and r.load_factor < 1)]
    assert path and all(c == math.inf for r in path for _, c in r.passes[:-1])
    # the woven state's loop solved again for finite changes (measured 4.3,
    # 2.2, 1.2 times its tolerance, then 0.63)
    last = solver.history[-1]
    assert last.stage == "fading" and last.load_factor == 1.0
    assert any(1 < c < math.inf for _, c in last.passes)
    assert w.contact.update_tolerance() == 1e-3
    s = check_woven(w)
    assert s["crossings in pattern order"] == 4
    # measured 3.473% (2026-12-06) against 3.472% with the loop at 1e-2: 2%
    assert s["warp crimp"] == pytest.approx(0.0347, rel=0.02)
    # Newton regression (measured 186 iterations, 3 failed attempts,
    # 2026-12-06 and -07, Newton on the path to Weaving.PATH_RTOL; 262 with
    # the path's loop at 1e-2): fails if the lag goes
    assert solver.counters["newton_iterations"] <= 214
    bundles = w.fabric
    with pytest.raises(ValueError, match="lagged_path lags the contact loop on a drag's path"):
        Weaving(bundles, lagged_path=True, comm=MPI.COMM_SELF)
    with pytest.raises(ValueError, match="lagged_path lags the contact loop on a drag's path"):
        Weaving(bundles, drag=0.1, newton_per_pass=3, lagged_path=True, comm=MPI.COMM_SELF)
    with pytest.raises(TypeError, match="lagged_path is True or False"):
        Weaving(bundles, drag=0.1, lagged_path=1, comm=MPI.COMM_SELF)
    lifted = Weaving(bundles, lifting_drag=0.1, lagged_path=True, comm=MPI.COMM_SELF)
    assert lifted.stages()[0].effects[lifted.contact]["update_tolerance"] == math.inf
    assert lifted.stages()[1].effects[lifted.contact]["update_tolerance"] \
        == Weaving.PATH_UPDATE_TOLERANCE   # no drag in its settling


def test_a_drag_within_the_yarns_weaves_the_same_state():
    """Weaving(drag=c, drag_within_yarns=True): the drag on the motion of
    each bundle's neighbouring fibres relative to each other (3 bonds a
    3-fibre bundle) and a hundredth of it on each node's own; the bundles
    of test_a_drag_is_faded_out_to_the_woven_state end woven with the
    drag-free crimp."""
    w, solver = woven(2, 3, spacing=2.0, free_length=1.0, drag=0.1, drag_within_yarns=True)
    drag = w.viscous_drag
    assert len(drag.pairs) == 4 * 3 and drag.absolute_share == Weaving.DRAG_ABSOLUTE_SHARE
    assert solver.history[-1].stage == "fading" and solver.history[-1].load_factor == 1.0
    assert solver.history[-1].effects["drag_force"] == 0.0
    s = check_woven(w)
    assert s["crossings in pattern order"] == 4
    # measured 3.479% (2026-12-05) against 3.47% by the other paths: 2%
    assert s["warp crimp"] == pytest.approx(0.0347, rel=0.02)
    # Newton guard (measured 353 iterations, 7 failed attempts, 2026-12-07,
    # Newton on the path to Weaving.PATH_RTOL of the step's first residual;
    # 370 of each solve's; 251 with the drag on every node's own motion):
    # 1.5 x
    assert solver.counters["newton_iterations"] <= 530
    with pytest.raises(TypeError, match="drag_within_yarns is True or False"):
        Weaving(w.fabric, drag=0.1, drag_within_yarns=1, comm=MPI.COMM_SELF)


def _end_slides(w) -> list[np.ndarray]:
    """Per yarn, how far each of its fibres' pulled ends moved along the yarn."""
    q = w.model.nodal_unknowns()
    out = []
    for k in range(w.fabric.num_yarns):
        axis = 0 if k < w.fabric.num_warp else 1
        ends = [w.model.mesh.fibre_nodes(f)[-1] for f in np.flatnonzero(w.fabric.fibre_yarn == k)]
        out.append(q[ends, axis] - w.fabric.yarn_axis(k)[1][axis])
    return out


def test_fibres_pulled_one_by_one_slip_at_the_yarn_end():
    """Weaving(pull="fibre"): a pull body per fibre, each loaded by its own
    tension, so the fibres of a bundle slip past each other where the yarn
    is pulled (one body per yarn moves them together). 3-fibre bundles as in
    test_bundles_weave_by_lifting weave with every crossing in order."""
    w, solver = woven(2, 3, spacing=2.0, free_length=1.0, pull="fibre")
    assert len(w.pulls) == 12   # a body per fibre
    ea = MAT.young * np.pi * R ** 2
    for body in w.pulls:
        assert np.linalg.norm(body.loads.target[0:3]) == pytest.approx(1e-4 * ea)
    s = check_woven(w)
    assert s["crossings in pattern order"] == 4
    # every fibre end slid in (the yarn crimps), the fibres of one yarn by
    # different amounts: measured 2026-12-02, slides of 0.70-1.15 R that
    # differ by 0.25-0.36 R within a yarn (a yarn-wide pull body moves them
    # together by 0.82-0.96 R); bounds 1.4 and 2.5 x inside those
    for slides in _end_slides(w):
        assert np.all(slides < -0.5 * R)
        assert np.ptp(slides) > 0.1 * R, slides
    together = _end_slides(woven(2, 3, spacing=2.0, free_length=1.0)[0])
    assert max(np.ptp(x) for x in together) < 1e-9 * R
    # the crimp (measured 3.69%; 3.47% with a pull body per yarn): 2%
    assert s["warp crimp"] == pytest.approx(0.0369, rel=0.02)
    # Newton guard (measured 198 iterations, 4 failed attempts, 2026-12-07,
    # Newton on the path to Weaving.PATH_RTOL of the step's first residual;
    # 218 of each solve's, 318 before): 1.5 x
    assert solver.counters["newton_iterations"] <= 297


@pytest.mark.mpi
def test_crimp_is_the_same_on_every_rank_count():
    # the 2 x 2 weave on COMM_WORLD (1 or 2 ranks) against one rank
    w1, _ = woven(2, 1, comm=MPI.COMM_SELF)
    wn, _ = woven(2, 1, comm=MPI.COMM_WORLD)
    assert np.abs(fm.crimp(wn.fabric, wn.model) - fm.crimp(w1.fabric, w1.model)).max() < 1e-8


@pytest.mark.mpi
def test_flat_yarns_weave_the_same_on_two_ranks():
    """The 2 x 2 weave of 3-fibre flat yarns on all ranks (on two, the warp
    on one and the weft on the other: every crossing couples them) ends where
    the one-rank weave does, through the same steps, to round-off (measured
    3e-15 R on positions, 4e-16 on section vectors; issue 22 asks 1e-8)."""
    (w1, s1), (wn, sn) = (woven(2, 3, spacing=2.3, packing="layers 1", comm=comm)
                          for comm in (MPI.COMM_SELF, MPI.COMM_WORLD))
    assert [(h.stage, h.load_factor) for h in s1.history] == \
        [(h.stage, h.load_factor) for h in sn.history]
    q1, qn = w1.model.nodal_unknowns(), wn.model.nodal_unknowns()
    assert np.abs(q1[:, 0:3] - qn[:, 0:3]).max() < 1e-13 * R
    assert np.abs(q1[:, 3:] - qn[:, 3:]).max() < 1e-13


@pytest.mark.mpi
def test_bundles_weave_the_same_on_two_ranks():
    """The lifting weave of 7-fibre bundles (the main demo's) on all ranks
    ends where the one-rank weave does, through the same steps (issue 20
    asks 1e-8 of the spacing; measured 7e-16; with contact passes capped at
    3 Newton iterations, answers taken from effects set at an unconverged
    iterate were 3.8e-8 apart: the contact loop accepts only effects set at
    a converged state). The 3-fibre weave does not:
    its path forks at a contact-loop decision taken on round-off (9e-5 of
    the spacing apart; see the weaving issue's note)."""
    (w1, s1), (wn, sn) = (woven(2, 7, spacing=2.0, free_length=1.0, comm=comm)
                          for comm in (MPI.COMM_SELF, MPI.COMM_WORLD))
    assert [(h.stage, h.load_factor, h.newton_iterations) for h in s1.history] == \
        [(h.stage, h.load_factor, h.newton_iterations) for h in sn.history]
    q1, qn = w1.model.nodal_unknowns(), wn.model.nodal_unknowns()
    assert np.abs(q1[:, 0:3] - qn[:, 0:3]).max() < 1e-8 * w1.fabric.spacing[0]
    # issue 20: the relaxation within 20 Newton iterations, all its contact
    # passes counted (measured 8; 10 before crossings were searched on the
    # smoothed centre lines), and every weaving step within 15 (the issue's;
    # measured 12 with Newton on the path to Weaving.PATH_RTOL, 15 to the
    # full tolerance: with the tangent floor in every solve after a contact
    # update, 21; with each pass's solve run to convergence, 46)
    relaxation = [h.newton_iterations for h in sn.history if h.stage == "relaxation"]
    assert max(relaxation) <= 20, relaxation
    weaving = [h.newton_iterations for h in sn.history if h.stage != "relaxation"]
    assert max(weaving) <= 15, weaving
    guard.newton_count("weave_bundles_7_lifting", sn)


def test_resumed_from_the_woven_state_equals_the_continuous_run(tmp_path):
    """Weave, save (unknowns, rigid bodies, contact history and mode, yarn
    ids), load into a fresh scene and relax: the same state as weaving and
    relaxing in one run, to the solver's tolerance."""
    def scene():
        yarn = Yarn(1, R, MAT)
        fab = Fabric(yarn, num_warp=2, num_weft=2, spacing=6.0 * yarn.width)
        w = Weaving(fab, comm=MPI.COMM_SELF)
        return w, textile.Solver(w.model, dict(verbose=False))

    w1, s1 = scene()
    s1.run(w1.stages())
    w2, s2 = scene()
    s2.run_stage(w2.stages()[0])
    path = str(tmp_path / "woven.h5")
    textile.save_state(w2.model, path, s2, fibre_data={"yarn": w2.fabric.fibre_yarn})
    w3, s3 = scene()
    attrs = textile.load_state(w3.model, path, s3)
    assert attrs["fibre_data"]["yarn"].tolist() == w3.fabric.fibre_yarn.tolist()
    s3.run_stage(w3.stages()[1])
    q1, q3 = w1.model.nodal_unknowns(), w3.model.nodal_unknowns()
    # the solver's tolerance (rtol 1e-10) on positions of order the spacing
    assert np.abs(q1[:, 0:3] - q3[:, 0:3]).max() < 1e-10 * w1.fabric.spacing[0]
    assert fm.crimp(w3.fabric, w3.model) == pytest.approx(fm.crimp(w1.fabric, w1.model),
                                                          rel=1e-9)
