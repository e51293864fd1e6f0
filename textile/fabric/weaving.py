"""The weaving computation (docs/method.md §6): from a fabric's straight,
coplanar, interpenetrating yarns to the woven state.

The scene:

- every fibre of the :class:`~textile.fabric.Fabric`, yarn after yarn;
- per yarn, two rigid bodies holding its end sections: the *clamp* at its
  start (all six components held) and the *pull* at its end, free to slide
  in the fabric plane along the yarn's direction and loaded by an axial
  tension; its other components are held (the yarn end neither tilts nor
  moves sideways: a yarn of a small sample has no lateral support but its
  own bending, and frictionless vertical contacts give it none, so a free
  sideways motion would be a near-zero-stiffness mode);
- fibre-fibre contact (:class:`~textile.effects.fibre_contact.FibreContact`).

Two stages:

1. ``weaving`` (``steps`` load steps): contacts between fibres of a warp
   and a weft yarn take the vertical as normal and the sign of their gap
   from the crossing order, so the yarns are pushed over and under each
   other; contacts within a yarn and between parallel yarns are ordinary.
   The yarn tensions ramp to their value.
2. ``relaxation`` (``relaxation_steps``): ordinary contact everywhere,
   tensions held: the woven state.

Units: as the fabric's (lengths of its spacing and radii, forces of its
materials' Young's modulus times an area).
"""
from __future__ import annotations

import math
import numbers

import numpy as np
from mpi4py import MPI

from . import measures
from .. import presets
from ..effects.base import stage_ended
from ..effects.fibre_contact import FibreContact
from ..effects.heddles import Heddles
from ..effects.viscous_drag import ViscousDrag
from ..effects.weaving_contact import weaving_mode
from .fabric import Fabric
from ..io import fabric_labels
from ..io.state_file import save_state
from ..scene.loading import Stage
from ..log import get_logger
from ..scene.model import Model
from ..io.output import Output
from ..scene.rigid_body import RigidBody
from ..solver import Solver


def _count(value, name: str, low: int = 1) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < low:
        raise ValueError(f"Weaving: {name} must be an integer >= {low}, got {value!r}")
    return int(value)


class Weaving:
    """The weaving scene of a fabric and its two stages (module docstring).

    Parameters
    ----------
    fabric:
        The :class:`~textile.fabric.Fabric` to weave.
    steps:
        Load steps of the weaving stage (about five, docs/method.md §6.3),
        or of the lifting stage.
    relaxation_steps:
        Load steps of the ordinary-contact stage that follows (default 1;
        with a ``drag`` there is none, and giving it is an error).
    tension:
        Axial tension of each fibre at the yarn's pull body, as a fraction
        of the fibre's axial stiffness E A (an axial strain; default 1e-4,
        small: the yarns crimp freely).
    contact:
        :class:`~textile.effects.fibre_contact.ContactOptions` or a dict.
    element:
        :class:`~textile.beam.element.BeamElement` of the fibres (default: the
        model's).
    method:
        ``"ordered"`` (the paper's: ordered contact, module docstring) or
        ``"lifting"`` (heddles, below). Default: ``"lifting"`` when a yarn
        is a bundle (``Fabric.has_bundles``), else ``"ordered"``.
    settling_steps:
        Lifting: load steps of the settling stage.
    amplitude:
        Lifting: how high the heddles lift a yarn over (and press it
        under) the yarn it crosses, from the starting plane, as a fraction
        of the mean height of a warp and a weft yarn (0.55: they clear each
        other at the crossing's middle by 0.1 of that height; fibres off
        the middle, where the yarns slope, may still overlap a little, and
        the settling stage makes that up progressively). Yarns closer
        than 2 widths slope more for the same lift: 7-fibre bundles 1.5
        widths apart weave with 0.45 and stop in the lifting stage with
        0.55 (benchmarks/README.md, "A line contact's point past its
        patch").
    drag:
        Lifting: the coefficient of a
        :class:`~textile.effects.ViscousDrag` (pseudo-time) through the
        settling stage, faded out as (1 - s)^2 over a ``fading`` stage
        (``FADING_STEPS`` steps, the heddles gone) that takes the
        relaxation's place: its last step, at s = 1, has no drag, so its
        state is the structure's own equilibrium (no relaxation stage
        follows, :meth:`stages` says why); the fading's steps before
        the last have the settling's loose contact loop
        (``PATH_UPDATE_TOLERANCE``, or one that lags: ``lagged_path``). A path
        through the instabilities where the heddles let go, where the
        contact loop otherwise alternates between two sets (twisted
        bundles). 0 (default): no drag, three stages.
    lifting_drag:
        Lifting: the same drag's coefficient in the lifting stage (default
        0), a path through the lifted bundles' instabilities (the 4 x 4
        twill's lifting stops at 0.86 without it); it ends with the
        lifting. On twisted bundles it stops the settling's first step.
    viscous_fading:
        Lifting with a ``drag``: in the fading stage the drag is a
        viscosity (:class:`~textile.effects.ViscousDrag`'s ``step``): a
        step cut after a failed attempt drags harder, and the stage may cut
        down to ``VISCOUS_FADING_MIN_STEP``. Default False. The
        28-fibre 2 x 2 weave (amplitude 0.45) fades through with it and
        stops without it (benchmarks/README.md, "28-fibre bundles: a
        viscous fading").
    viscous_settling:
        Lifting with a ``drag``: in the settling stage too the drag is a
        viscosity (over the settling's step, 1 / ``settling_steps``), so a
        cut step drags harder. Default False. After a lifting with a
        ``lifting_drag`` the 28-fibre 2 x 2 weave's settling folds an
        element in its first steps at every step size with the plain drag,
        and settles with it (benchmarks/README.md, "The paper's sample of
        28-fibre bundles").
    drag_within_yarns:
        With a ``drag`` or ``lifting_drag``: False (default), the drag acts
        on each node's own motion (:class:`~textile.effects.ViscousDrag`);
        True, on the motion of neighbouring fibres of a yarn relative to
        each other (:meth:`~textile.Fabric.neighbour_fibres`), and only
        ``DRAG_ABSOLUTE_SHARE`` of it on each node's own motion. True takes
        fewer Newton iterations on 3- and 7-fibre bundles (633 against 762,
        807 against 904 twisted) but the 28-fibre 2 x 2 weave then folds an
        element near the fading's end (s = 0.9984) where the default weaves
        (benchmarks/README.md, "A drag on the fibres' motion within their
        yarn").
    lagged_path:
        With a drag (``drag`` or ``lifting_drag``) and Newton solves run to
        convergence (``newton_per_pass`` 0, the default with it): the
        contact loop of the stages that hold a drag lags (``LAGGED_PATH``,
        :meth:`FibreContact.configure`): a step is accepted after its
        first converged Newton solve, what that solve's contact update
        finds (elements, normals, penalties) acts from the next step; the
        fading's last step, the woven state, at the contact's own
        tolerance. Default False. The 3-fibre 2 x 2 weave: 298 Newton
        iterations against 398, the same crimp to 0.01%; the twisted
        7-fibre weave stops in its fading with it (folded elements at
        every step size) and takes 765 against 693 when only the lifting
        and the settling lag (benchmarks/README.md, "A contact loop that
        lags on the drag's path").
    path_rtol:
        Lifting: Newton's tolerance before each stage's end
        (``SolverOptions.path_rtol``; default ``PATH_RTOL``; 0: every step to
        the full tolerance). Each stage's end, the woven state among them,
        meets the full tolerance.
    newton_per_pass:
        Lifting: Newton iterations between contact updates in its stages
        (``SolverOptions.newton_per_pass``; 0: each Newton solve to
        convergence). Default: ``NEWTON_PER_PASS``; 0 with a drag whose
        fading is not a viscosity (``viscous_fading`` False: capped solves
        fold an element in the fading of the 3-fibre weave, and folded
        them in the twisted 7-fibre weave's: benchmarks/README.md,
        "Twisted bundles", "Capped solves on a viscous fading's path") and
        with ``lagged_path``. With a viscous fading capped solves take
        fewer Newton iterations to the same woven state (the 3-, 7- and
        twisted 7-fibre 2 x 2 weaves: 196, 190, 477 against 256, 209, 560;
        the 6 x 6 weave of 7-fibre bundles: 799 against 973).
    pull:
        ``"yarn"`` (default): one pull body holds the end sections of all
        the fibres of a yarn (they slide in together); ``"fibre"``: a pull
        body per fibre, each loaded by its own share of the tension, so the
        fibres of a bundle slip past each other at the pulled end as the
        yarn bends (with ``"yarn"``, a 19-fibre bundle's fibres near the
        held end fold as the heddles let go; the 7-fibre weave takes more
        failed attempts with ``"fibre"``: benchmarks/README.md, "19-fibre
        bundles").
    preset:
        Accuracy preset (:mod:`textile.presets`: "draft", "standard" (None),
        "fine"): ``steps``, ``contact``, ``element`` and :meth:`run`'s solver
        options are its, except those given (a contact or solver dict
        overrides it key by key).
    comm:
        MPI communicator.
    partition:
        How the fibres are shared out over its ranks (:class:`~textile.Model`):
        ``"place"`` (default) or ``"numbers"``.

    The lifting weave (docs/method.md §6.4) has three stages:

    1. ``lifting`` (``steps``): contact within yarns only (the warps and
       wefts pass through each other, ``FibreContact`` mode
       ``"within_yarns"``); :class:`~textile.effects.heddles.Heddles` lift
       each yarn where it passes over another and press it where it passes
       under, to +-amplitude; the yarn tensions ramp to their value.
    2. ``settling`` (``settling_steps``): ordinary contact everywhere, the
       overlaps it starts with made up over the stage
       (``make_up_penetrations``); the heddles' stiffness fades as
       (1 - s)^2 to zero, and the yarns come to rest on each other,
       pressed by their tensions.
    3. ``relaxation`` (``relaxation_steps``): ordinary contact, no heddles:
       the woven state.

    With ``drag`` > 0 a ``fading`` stage after the settling takes the drag
    away, and is the last: its last step, drag-free, is the relaxation.

    Its yarns never interpenetrate once lifted, so ordinary contact never
    meets a hidden overlap; the ordered weave measures gaps along the
    vertical, which hides the overlap of a bundle's fibres running steeply
    down the flank of the yarn they cross (1.2 R found where the vertical
    gap said 0.05 R), and its relaxation then fails.
    """

    METHODS = ("ordered", "lifting")
    PULLS = ("yarn", "fibre")
    #: the heddles' springs while they hold the yarns, in units of each
    #: fibre's 12 E I / L^3 (Heddles): stiff enough that the yarns follow
    #: them (their fibres bend as the heddles ask) and soft enough not to
    #: dominate the tangent (30: each node's spring a few times its beam's)
    HEDDLE_STIFFNESS = 30.0
    #: the contact loop's tolerance on the lifting weave's artificial path,
    #: the settling (the heddles letting go) and a drag's fading before its
    #: last step: only the woven state is an answer (the relaxation, or the
    #: fading's drag-free last step, with the contact's own tolerance). The
    #: passes converge linearly as the crossings' normals turn, so 1e-2
    #: takes about half the passes of the default 1e-3 for the same woven
    #: state (measured: benchmarks/README.md, "Bundles"; in the fading,
    #: "A looser contact loop on the fading's path"); with ``lagged_path``
    #: the drag's path lags instead (LAGGED_PATH)
    PATH_UPDATE_TOLERANCE = 1e-2
    #: the contact loop's tolerance on the drag's path with ``lagged_path``
    #: (FibreContact.configure: math.inf, a loop that lags)
    LAGGED_PATH = math.inf
    #: Newton iterations between contact updates in the lifting weave's
    #: stages (SolverOptions.newton_per_pass): the passes' frozen normals
    #: are a fixed point that each solve need not settle first; 3 gave the
    #: fewest iterations on the 3- and 7-fibre weaves, 2 folds an element
    #: (measured: benchmarks/README.md, "Contact passes with capped Newton
    #: solves"; tests/weave/test_weaving.py holds the counts)
    NEWTON_PER_PASS = 3
    #: Newton's tolerance within the lifting weave's stages, before each
    #: stage's end (SolverOptions.path_rtol): a residual fallen 1000-fold
    #: in a step is enough on a path whose states are no answer; every
    #: stage's end, the woven state among them, to the full tolerance. 29%
    #: fewer Newton iterations on the 2 x 2 weave of 7-fibre bundles, 36%
    #: 1.5 widths apart, the same woven state to 0.1% of its crimp (1e-4
    #: relative to each solve's start: 13% and 18% fewer; 0.05 and 0.1
    #: fewer still on the first, but steps of 40 iterations on the second;
    #: benchmarks/README.md, "Newton on the weave's path to a looser
    #: tolerance" and "... relative to the step's start")
    PATH_RTOL = 1e-3
    #: with capped passes no step is easy (SolverOptions.easy_iterations):
    #: after a cut, steps grow again after this many in a row at one size
    #: (SolverOptions.regrow_after); without it a stage went on at its
    #: hardest step's size (the 19-fibre weave: 613 Newton iterations, 512
    #: with it; benchmarks/README.md, "Steps that grow again after a cut").
    #: Uncapped steps (with a drag: 5-25 iterations) are not easy either:
    #: every stage regrows (the 6 x 6 weave of 7-fibre bundles fades to the
    #: end with it, and stopped at 0.998 without; benchmarks/README.md, "A
    #: drag on the fibres' motion within their yarn"; the 6 x 6 sample of
    #: 28-fibre bundles, cut to 8e-4 of its lifting at 0.9, went on at that
    #: size: "The paper's sample of 28-fibre bundles")
    REGROW_AFTER = 3
    #: load steps of the stage that fades the drag out (``drag`` > 0): the
    #: twisted 7-fibre weave's (1 - s)^2 fade took 40-75 Newton iterations
    #: a step at first with 4 (benchmarks/README.md, "Twisted bundles")
    FADING_STEPS = 4
    #: the fading stage's smallest step with ``viscous_fading``: a cut step
    #: drags harder there (a viscosity over the step), so a shorter one
    #: always moves the state less and the stage may cut far below the
    #: run's min_step; the 6 x 6 2/2 twill of 7-fibre bundles cuts to
    #: 1.2e-5 near s = 0.998 and stopped there at the default 1e-4
    #: (benchmarks/README.md, "A weave resumed within its fading; the 6 x 6
    #: twill of 7-fibre bundles woven")
    VISCOUS_FADING_MIN_STEP = 1e-6
    #: with ``drag_within_yarns``, the share of the drag on each node's own
    #: motion (ViscousDrag's absolute_share): small, so that the yarns'
    #: long modes settle under their tension while the drag holds the
    #: fibres' rearrangements within the yarns (benchmarks/README.md, "A
    #: drag on the fibres' motion within their yarn")
    DRAG_ABSOLUTE_SHARE = 0.01

    def __init__(self, fabric: Fabric, steps: int | None = None,
                 relaxation_steps: int | None = None, tension: float = 1e-4, contact=None,
                 element=None, method: str | None = None, settling_steps: int = 16,
                 amplitude: float = 0.55, drag: float = 0.0, lifting_drag: float = 0.0,
                 viscous_fading: bool = False, viscous_settling: bool = False,
                 drag_within_yarns: bool = False, lagged_path: bool = False,
                 newton_per_pass: int | None = None, path_rtol: float | None = None,
                 pull: str = "yarn",
                 preset: str | None = None, comm=MPI.COMM_WORLD, partition: str = "place"):
        if not isinstance(fabric, Fabric):
            raise TypeError(f"Weaving: fabric must be a textile.fabric.Fabric, got "
                            f"{type(fabric).__name__}")
        self.preset = presets.checked(preset, "Weaving")
        steps = presets.knob(self.preset, "weaving", "steps", steps)
        contact = presets.contact(self.preset, contact)
        element = presets.element(self.preset) if element is None else element
        if method is None:
            method = "lifting" if fabric.has_bundles else "ordered"
        if method not in self.METHODS:
            raise ValueError(f"Weaving: method must be one of {self.METHODS}, got {method!r}")
        self.method = method
        self.steps = _count(steps, "steps")
        self.relaxation_steps = _count(1 if relaxation_steps is None else relaxation_steps,
                                       "relaxation_steps")
        self.settling_steps = _count(settling_steps, "settling_steps")
        if isinstance(amplitude, bool) or not isinstance(amplitude, numbers.Real) \
                or not 0.3 < amplitude < 5:
            raise ValueError(f"Weaving: amplitude is a fraction of the yarns' height in "
                             f"(0.3, 5) (below 0.3 the lifted yarns' fibres may still lie on the "
                             f"wrong side of each other), got "
                             f"{amplitude!r}")
        if isinstance(tension, bool) or not isinstance(tension, numbers.Real) \
                or not math.isfinite(tension) or tension <= 0 or tension >= 0.1:
            raise ValueError(f"Weaving: tension is an axial strain, in (0, 0.1); got {tension!r}")
        for name, value in (("drag", drag), ("lifting_drag", lifting_drag)):
            if isinstance(value, bool) or not isinstance(value, numbers.Real) \
                    or not math.isfinite(value) or value < 0:
                raise ValueError(f"Weaving: {name} is a coefficient >= 0, got {value!r}")
            if value > 0 and method != "lifting":
                raise ValueError(f"Weaving: {name} belongs to the lifting weave; this weave's "
                                 f"method is {method!r}")
        if pull not in self.PULLS:
            raise ValueError(f"Weaving: pull must be one of {self.PULLS}, got {pull!r}")
        for name, value in (("viscous_fading", viscous_fading),
                            ("viscous_settling", viscous_settling)):
            if not isinstance(value, bool):
                raise TypeError(f"Weaving: {name} is True or False, got {value!r}")
        if drag > 0 and relaxation_steps is not None:
            raise ValueError("Weaving: relaxation_steps has no stage to count with a drag: the "
                             "fading stage ends the weave (its last step is the relaxation); "
                             "leave relaxation_steps out")
        for name, value, stage in (("viscous_fading", viscous_fading, "fading"),
                                   ("viscous_settling", viscous_settling, "settling")):
            if value and not drag > 0:
                raise ValueError(f"Weaving: {name} makes the {stage} stage's drag a viscosity; "
                                 f"it needs a drag > 0")
        self.viscous_fading = viscous_fading
        self.viscous_settling = viscous_settling
        if not isinstance(drag_within_yarns, bool):
            raise TypeError(f"Weaving: drag_within_yarns is True or False, got "
                            f"{drag_within_yarns!r}")
        self.drag_within_yarns = drag_within_yarns
        self.fabric = fabric
        self.tension = float(tension)
        self.drag = float(drag)
        self.lifting_drag = float(lifting_drag)
        if newton_per_pass is None:
            # a drag's plain fading (not a viscosity) folds elements with
            # capped solves; a lagged path needs solves run to convergence
            newton_per_pass = 0 if lagged_path is True or (
                (self.drag > 0 or self.lifting_drag > 0) and not viscous_fading) \
                else self.NEWTON_PER_PASS
        if isinstance(newton_per_pass, bool) or not isinstance(newton_per_pass, numbers.Integral) \
                or newton_per_pass < 0:
            raise ValueError(f"Weaving: newton_per_pass is an integer >= 0 (0: Newton to "
                             f"convergence), got {newton_per_pass!r}")
        self.newton_per_pass = int(newton_per_pass)
        if not isinstance(lagged_path, bool):
            raise TypeError(f"Weaving: lagged_path is True or False, got {lagged_path!r}")
        if lagged_path and not (self.newton_per_pass == 0
                                and (self.drag > 0 or self.lifting_drag > 0)):
            raise ValueError("Weaving: lagged_path lags the contact loop on a drag's path, with "
                             "Newton solves run to convergence: it needs a drag or lifting_drag "
                             "> 0 and newton_per_pass 0")
        self.lagged_path = lagged_path
        if path_rtol is None:
            path_rtol = self.PATH_RTOL
        if isinstance(path_rtol, bool) or not isinstance(path_rtol, numbers.Real) \
                or not 0 <= path_rtol < 1:
            raise ValueError(f"Weaving: path_rtol is in [0, 1) (0: every step to the full "
                             f"tolerance), got {path_rtol!r}")
        self.path_rtol = float(path_rtol)
        fibres = fabric.fibres()
        self.model = Model(fibres, element=element, comm=comm, partition=partition)
        self.contact = FibreContact(contact, fibre_yarn=fabric.fibre_yarn,
                                    yarn_friction=fabric.yarn_friction())
        self.model.add_effect(self.contact)
        self._update_tolerance = self.contact.options.update_tolerance
        self._path_tolerance = max(self.PATH_UPDATE_TOLERANCE, self._update_tolerance)
        self.heddles = None
        if method == "lifting":
            height = 0.5 * (fabric.yarn(0).height + fabric.yarn(fabric.num_yarns - 1).height)
            shortest = min(fabric.spacing)
            if fabric.free_length < shortest * (1 - 1e-9):
                raise ValueError(
                    f"Weaving: the lifting weave needs yarn tails of at least one spacing "
                    f"beyond the outer crossings (Fabric free_length >= {shortest:.4g}, got "
                    f"{fabric.free_length:.4g}): lifted over and under each other, the yarns "
                    f"crimp by up to 20% before they settle, and their pulled ends slide in by "
                    f"that much (with tails of 0.8 spacing an end element folds)")
            self.heddles = Heddles(fabric, amplitude * height, stiffness=self.HEDDLE_STIFFNESS)
            self.model.add_effect(self.heddles)
        self.viscous_drag = None
        if self.drag > 0 or self.lifting_drag > 0:
            # switched on by the stages
            self.viscous_drag = ViscousDrag(0.0, pairs=fabric.neighbour_fibres(),
                                            absolute_share=self.DRAG_ABSOLUTE_SHARE) \
                if self.drag_within_yarns else ViscousDrag(0.0)
            self.model.add_effect(self.viscous_drag)
        self.pull = pull
        self.clamps, self.pulls = [], []
        for k in range(fabric.num_yarns):
            mine = np.flatnonzero(fabric.fibre_yarn == k)
            index = k if k < fabric.num_warp else k - fabric.num_warp
            label = f"{fabric.yarn_direction(k)} {index}"
            clamp = RigidBody(f"{label} clamp", sections=[(int(f), 0) for f in mine])
            clamp.fix("all")
            self.model.add_rigid_body(clamp)
            self.clamps.append(clamp)
            a, b = fabric.yarn_axis(k)
            axis = (b - a) / np.linalg.norm(b - a)
            groups = [mine] if pull == "yarn" else [[f] for f in mine]
            for n, group in enumerate(groups):
                name = f"{label} pull" if pull == "yarn" else f"{label} pull {n}"
                body = RigidBody(name, sections=[(int(f), -1) for f in group])
                body.fix(("z", "rotation", "y" if k < fabric.num_warp else "x"))
                ea = sum(fibres[f].material.young * math.pi * fibres[f].radius ** 2
                         for f in group)
                body.add_force(self.tension * ea * axis)
                self.model.add_rigid_body(body)
                self.pulls.append(body)

    def stages(self) -> list[Stage]:
        """The weaving stage, then the ordinary-contact relaxation (ordered
        method); lifting, settling, relaxation (lifting method; with a
        ``drag``, lifting, settling, fading).

        Why a fading stage ends the weave: its drag c (1 - s)^2 is 0 at its
        last step, so that step's converged state is already the
        drag-free equilibrium a relaxation would seek. A relaxation after it
        would solve the same equilibrium again from the fading's committed
        friction history, where every contact that slipped in the last step
        sits on the stick-slip cone (just inside it, ``stick_margin``); with
        no load increment to give their motion a direction, hundreds of
        them switch between stick and slip from one Newton iteration to the
        next (300-1400 of 5300 active contacts on the 6 x 6 weave of
        7-fibre bundles), and its Newton never converges (benchmarks/
        README.md, "The fading's last step is the relaxation")."""
        if self.method == "lifting":
            stiffness, passes = self.HEDDLE_STIFFNESS, self.newton_per_pass
            stepping = dict(newton_per_pass=passes, regrow_after=self.REGROW_AFTER,
                            path_rtol=self.path_rtol)
            lifting = weaving_mode(self.fabric, "within_yarns")
            if self._lags(self.lifting_drag):
                lifting["update_tolerance"] = self.LAGGED_PATH
            stages = [Stage("lifting", effects={self.contact: lifting,
                                                self.heddles: dict(lift=lambda s: s,
                                                                   stiffness=stiffness)},
                            solver=dict(initial_step=1.0 / self.steps, max_step=1.0 / self.steps,
                                        **stepping)),
                      Stage("settling", effects={
                          self.contact: dict(mode="ordinary", make_up_penetrations=True,
                                             update_tolerance=self.LAGGED_PATH
                                             if self._lags(self.drag) else self._path_tolerance),
                          self.heddles: dict(lift=1.0,
                                             stiffness=lambda s: stiffness * (1 - s) ** 2)},
                            solver=dict(initial_step=1.0 / self.settling_steps,
                                        max_step=1.0 / self.settling_steps,
                                        **stepping)),
                      Stage("relaxation", effects={
                          self.heddles: dict(stiffness=0.0),
                          self.contact: dict(update_tolerance=self._update_tolerance)},
                            solver=dict(initial_step=1.0 / self.relaxation_steps,
                                        max_step=1.0 / self.relaxation_steps,
                                        **stepping))]
            return self._with_drag(stages) if self.viscous_drag is not None else stages
        return [Stage("weaving", effects={self.contact: weaving_mode(self.fabric)},
                      solver=dict(initial_step=1.0 / self.steps, max_step=1.0 / self.steps)),
                Stage("relaxation", effects={self.contact: dict(mode="ordinary")},
                      solver=dict(initial_step=1.0 / self.relaxation_steps,
                                  max_step=1.0 / self.relaxation_steps))]

    def _with_drag(self, stages: list[Stage]) -> list[Stage]:
        """The lifting weave's stages with the drags on in the lifting
        (``lifting_drag``) and the settling (``drag``, then faded out in a
        ``fading`` stage that replaces the relaxation: :meth:`stages`); with
        only a ``lifting_drag``, off in the settling and the relaxation."""
        lifting, settling, relaxation = stages
        c, woven = self.drag, self._update_tolerance
        path = self.LAGGED_PATH if self._lags(c) else self._path_tolerance
        lifting.effects[self.viscous_drag] = dict(coefficient=self.lifting_drag)
        settling.effects[self.viscous_drag] = dict(
            coefficient=c, step=1.0 / self.settling_steps if self.viscous_settling else None)
        if c == 0:
            return [lifting, settling, relaxation]
        fading = Stage("fading", effects={**relaxation.effects,
                                          # the path loosely, the last step as the relaxation
                                          self.contact: dict(update_tolerance=lambda s: (
                                              woven if stage_ended(s) else path)),
                                          self.viscous_drag: dict(
                                              coefficient=lambda s: c * (1 - s) ** 2,
                                              step=1.0 / self.FADING_STEPS
                                              if self.viscous_fading else None)},
                       solver=dict(relaxation.solver, initial_step=1.0 / self.FADING_STEPS,
                                   max_step=1.0 / self.FADING_STEPS,
                                   regrow_after=self.REGROW_AFTER, path_rtol=self.path_rtol,
                                   **({"min_step": self.VISCOUS_FADING_MIN_STEP}
                                      if self.viscous_fading else {})))
        return [lifting, settling, fading]

    def _lags(self, drag: float) -> bool:
        """Does the contact loop lag in a stage with this drag
        (``lagged_path``)?"""
        return self.lagged_path and drag > 0

    def output(self, directory: str, **options) -> Output:
        """An :class:`~textile.io.output.Output` that also writes each fibre's
        yarn and the fabric's figures (crimp, shrinkage, ...) every step."""
        return Output(directory, **fabric_labels(self.fabric),
                      extra=lambda model: measures.summary(self.fabric, model), **options)

    def run(self, output: Output | None = None, solver_options=None) -> Solver:
        """Weave: run both stages; returns the solver (its ``history`` holds
        every step). Raises :class:`~textile.solver.ConvergenceError` with
        the last converged state kept (and written by ``output``)."""
        solver = Solver(self.model, presets.solver(self.preset, solver_options), output=output)
        solver.run(self.stages())
        return solver

    def summary(self) -> dict:
        """Crimp, shrinkage, section shapes and curvatures of the current
        state (:func:`textile.fabric.measures.summary`), the crossing order
        check and the contact figures."""
        out = measures.summary(self.fabric, self.model)
        sep = measures.crossing_separation(self.fabric, self.model)
        out["min crossing separation"] = float(sep.min())
        out["crossings in pattern order"] = int(np.count_nonzero(sep > 0))
        out["crossings"] = int(sep.size)
        stats = self.contact.statistics()
        out["max penetration / radius"] = stats.get("max_penetration_over_radius", 0.0)
        out["contact elements"] = stats.get("contact_elements", 0)
        return out


def woven_state(fabric: Fabric, path: str, solver_options=None, comm=MPI.COMM_WORLD,
                report: bool = True, **weaving_options) -> str:
    """Weave ``fabric`` (:class:`Weaving` with ``weaving_options``) and save
    the woven state to ``path`` (:func:`textile.save_state`, with each
    fibre's yarn), the start of composites and virtual tests; returns
    ``path``. ``report``: logs (rank 0) how many crossings are in pattern
    order. Collective."""
    weaving = Weaving(fabric, comm=comm, **weaving_options)
    weaving.run(solver_options=solver_options)
    save_state(weaving.model, path, fibre_data={"yarn": fabric.fibre_yarn})
    if report:
        summary = weaving.summary()   # collective
        get_logger(__name__).info(
            f"woven: {summary['crossings in pattern order']} of {summary['crossings']} "
            f"crossings in pattern order, saved to {path}")
    return path
