"""A woven sample driven through side rigid bodies: the scene of the virtual
tests (docs/method.md §10), with or without a matrix.

The scene:

- the fibres of a :class:`~textile.fabric.Fabric`, in the state a weaving
  run saved (``woven``: :func:`textile.save_state`), so they keep their
  crimp, their pre-stress and their contact history; or straight if no
  state is given;
- fibre-fibre contact (:class:`~textile.effects.fibre_contact.FibreContact`);
- one rigid body per driven side of the sample (``sides``: names among
  xmin, xmax, ymin, ymax). Warp yarns run along x and end on xmin and
  xmax, weft yarns along y and end on ymin and ymax. A side body *clamps*
  the end sections of the yarns ending on its side (position and section
  directions follow the body), or only *pins* them (``pins``: positions
  follow, the ends turn freely, as on the arms of a picture frame, but do
  not spin about their own axis: :meth:`Sample._hold_spin`). Each
  body component is then prescribed or loaded by the caller
  (``sample.sides["xmax"].prescribe("y", u)``);
- the yarn ends no side body holds were held, in the weaving run, by the
  yarns' end bodies. Here (``free_ends="yarns"``, the default) each such
  yarn end keeps a rigid body of its own, free, loaded by the force and
  moment it exerted in the saved state (so the sample starts in
  equilibrium): the fibres of a yarn end stay together, as in a yarn whose
  tip is sealed; a lone fibre end of a small sample's yarn, resting on a
  crossing or two, would slide away. A body at a bundle's end keeps its
  woven orientation (its rotations held, ``turning_ends``): free to turn, it
  is a near-zero-stiffness mode (below). With ``free_ends="fibres"`` a
  force on each fibre end stands for it instead (a composite's matrix holds
  the fibres). :meth:`Sample.release_stage` lets those loads go.

Why a bundle's free end body must not turn: it holds its fibres' end
sections together, so turning it about an axis across the yarn makes the
fibres slide along each other over the yarn's tail. Once the friction
between them slips, only the fibres' own bending resists that: on a 2 x 2
sample of 3-fibre bundles in the shear test the tangent's smallest singular
values (1e-5 against 1e7) are those bodies turning with their fibres'
sections, Newton's updates turn them by radians and an element folds at
every step size. With their rotations held, the sample settles and shears
without a drag (benchmarks/README.md, "Yarn ends that keep their
orientation"). A real cut end has no such body; the held orientation is
the sample's boundary condition at the free sides, as if the yarns went on
straight beyond them.

:class:`~textile.composite.Composite` adds a matrix (and junctions) to this
scene; its side bodies also hold the matrix faces.

Units: those of the fabric (lengths of its spacing and radii, forces of its
materials' Young's modulus times an area); angles in radians.
"""
from __future__ import annotations

import math
import numbers
import os

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from . import measures
from .. import presets
from ..effects.fibre_contact import ContactOptions, FibreContact
from ..effects.nodal_loads import ReleasedForces
from ..effects.viscous_drag import ViscousDrag
from .fabric import Fabric
from ..io import fabric_labels
from ..io.state_file import load_fibres, saved_configuration
from ..scene.loading import Stage
from ..scene.model import Model
from ..io.output import Output
from ..scene.rigid_body import RigidBody

#: The sides a body can drive, with the yarn direction ending there and which end.
SIDES = {"xmin": ("warp", 0), "xmax": ("warp", -1), "ymin": ("weft", 0), "ymax": ("weft", -1)}


def _side_names(sides, label: str, allow_empty: bool = False) -> tuple[str, ...]:
    sides = (sides,) if isinstance(sides, str) else tuple(sides)
    unknown = [s for s in sides if s not in SIDES]
    if unknown or (not sides and not allow_empty) or len(set(sides)) != len(sides):
        raise ValueError(f"{label} must be distinct names among {tuple(SIDES)}, got {sides!r}")
    return sides


class Sample:
    """A woven sample with side bodies (module docstring).

    Parameters
    ----------
    fabric:
        The :class:`~textile.fabric.Fabric` (the same as the weaving run's).
    woven:
        Path of a saved woven state of that fabric, or None (straight yarns).
    sides:
        Names of the sides that get a rigid body (among xmin, xmax, ymin, ymax).
    pins:
        Those of ``sides`` whose body pins the yarn ends instead of clamping
        them.
    contact:
        :class:`~textile.effects.fibre_contact.ContactOptions` or a dict, or
        False for no fibre-fibre contact. A virtual test on a fabric without
        matrix needs friction: frictionless contacts leave yarns free to
        slide over each other (a zero-stiffness mode). Friction starts
        afresh in the woven state (every contact sticking, no tangential
        force: ``FibreContact.reset_friction``): the yarns got there
        slipping, at the friction limit. The friction forces the woven
        state carried (between the fibres of a bundle) are held as dead
        loads and released over the first stage (``released_friction``,
        :class:`~textile.effects.nodal_loads.ReleasedForces`): taken away
        at once, they let a bundle rearrange in one Newton solve, and an
        element folds.
    free_ends:
        "yarns" or "fibres": what stands for the weaving run's end bodies at
        the yarn ends no side body holds (module docstring).
    turning_ends:
        With ``free_ends="yarns"``: may those yarn-end bodies turn (True) or
        do they keep their woven orientation, moving freely (False: their
        three rotations held, a support outside the side bodies'
        reactions)? None (default): False at the ends of bundles
        (``Yarn.is_bundle``), True at flat yarns' and monofilaments' (module
        docstring).
    preset:
        Accuracy preset (:mod:`textile.presets`; None: "standard"): the
        contact options (a dict given overrides them key by key, a
        ContactOptions wholly) and the fibres' element are its.
    split:
        Those of ``sides`` whose yarn ends get one body per yarn instead of
        one for the side (``yarn_bodies[side][yarn]``), each driven on its
        own: e.g. spread with the sample in biaxial tension, where a rigid
        side would hold the ends of the other direction at their woven
        spacing.
    settle_drag:
        0 (default) or the coefficient c of a
        :class:`~textile.effects.ViscousDrag` on the fibres' centre lines
        through the first stage (``settle_drag_effects``), faded out as
        c (1 - s)^2, a viscosity (a cut step drags harder), so that the
        stage's last step has none: the state the loading starts from is
        the sample's own equilibrium. A path for bundles whose friction
        starts afresh and whose free end bodies turn (``turning_ends``
        True): without it the contact loop around Newton diverges in the
        first stage and an element folds at every step size (a 2 x 2
        sample of 3-fibre bundles, friction between the yarns too, settles
        with c = 0.1 and stopped at 0.0625 without; benchmarks/README.md,
        "The fading's last step is the relaxation"). With those bodies
        keeping their orientation (the default at bundles' ends) it settles
        without a drag.
    comm:
        MPI communicator.
    """

    #: load steps of a first stage with a ``settle_drag`` (the drag's
    #: viscosity step, as the weaving's fading stage's)
    SETTLE_DRAG_STEPS = 4

    def __init__(self, fabric: Fabric, woven: str | None, sides=("xmin", "xmax"), pins=(),
                 contact=None, free_ends: str = "yarns", split=(), preset: str | None = None,
                 settle_drag: float = 0.0, turning_ends: bool | None = None,
                 comm=MPI.COMM_WORLD):
        name = type(self).__name__
        self.preset = presets.checked(preset, name)
        if not isinstance(fabric, Fabric):
            raise TypeError(f"{name}: fabric must be a textile.fabric.Fabric, got "
                            f"{type(fabric).__name__}")
        if woven is not None and not isinstance(woven, (str, os.PathLike)):
            raise TypeError(f"{name}: woven must be the path of a saved woven state or None, "
                            f"got {type(woven).__name__}")
        if not (contact is None or contact is False or isinstance(contact, (dict,
                                                                            ContactOptions))):
            raise TypeError(f"{name}: contact must be a dict or ContactOptions of contact "
                            f"options, None (the defaults) or False (no contact), got "
                            f"{contact!r}")
        if not isinstance(comm, MPI.Comm):
            raise TypeError(f"{name}: comm must be an MPI communicator, got "
                            f"{type(comm).__name__}")
        sides = _side_names(sides, f"{name}: sides")
        pins = _side_names(pins, f"{name}: pins", allow_empty=True)
        if free_ends not in ("yarns", "fibres"):
            raise ValueError(f"{name}: free_ends must be 'yarns' or 'fibres', got {free_ends!r}")
        if turning_ends not in (None, True, False):
            raise ValueError(f"{name}: turning_ends must be True, False or None (bundles' "
                             f"ends keep their orientation), got {turning_ends!r}")
        if turning_ends is not None and free_ends != "yarns":
            raise ValueError(f"{name}: turning_ends is for free_ends='yarns' (the yarn-end "
                             f"bodies), got free_ends={free_ends!r}")
        split = _side_names(split, f"{name}: split", allow_empty=True)
        for label, subset in (("pins", pins), ("split", split)):
            if not set(subset) <= set(sides):
                raise ValueError(f"{name}: {label} {subset!r} must be among the sides {sides!r}")
        if isinstance(settle_drag, bool) or not isinstance(settle_drag, numbers.Real) \
                or not math.isfinite(settle_drag) or settle_drag < 0:
            raise ValueError(f"{name}: settle_drag must be a finite number >= 0, got "
                             f"{settle_drag!r}")
        self.fabric, self.woven = fabric, woven
        fibres = fabric.fibres()
        # the configuration everything is built around: the woven one
        configuration = None
        if woven is not None:
            found = comm.bcast(os.path.isfile(woven) if comm.rank == 0 else None, root=0)
            if not found:
                raise FileNotFoundError(f"{name}: no woven state file {str(woven)!r} (write one "
                                        f"with textile.save_state after a weaving run)")
            configuration = saved_configuration(woven, comm)
        self.model = Model(fibres, element=presets.element(self.preset), comm=comm)
        mesh = self.model.mesh
        if configuration is None:
            configuration = mesh.X_global
        if configuration.shape != mesh.X_global.shape:
            raise ValueError(f"{name}: the woven state has {len(configuration)} fibre nodes, "
                             f"this fabric {len(mesh.X_global)}: give the weaving run's fabric")
        #: (nodes, 9) nodal unknowns of the starting (woven) configuration
        self.configuration = configuration
        self.contact = None
        if contact is not False:
            self.contact = FibreContact(presets.contact(self.preset, contact),
                                        fibre_yarn=fabric.fibre_yarn,
                                        yarn_friction=fabric.yarn_friction())
            self.model.add_effect(self.contact)
        self._add_matrix(configuration)
        self.sides: dict[str, RigidBody] = {}
        self.yarn_bodies: dict[str, dict[int, RigidBody]] = {}
        held = set()
        for side in sides:
            ends = self._yarn_ends(side)
            if side in split:
                self.yarn_bodies[side] = {}
                for k, mine in self._ends_by_yarn(side).items():
                    hold = dict(pins=mine) if side in pins else dict(sections=mine)
                    body = RigidBody(f"{side} yarn {k}", **hold)
                    self.model.add_rigid_body(body)
                    self.yarn_bodies[side][k] = body
            else:
                hold = dict(pins=ends) if side in pins else dict(sections=ends)
                body = RigidBody(side, **hold, **self._side_block(side))
                self.model.add_rigid_body(body)
                self.sides[side] = body
            held.update(ends)
            if side in pins:
                self._hold_spin(ends, configuration)
        # the yarn ends no body holds: what held them in the weaving run
        # (its yarn-end bodies) is replaced by loads, released over the
        # first stage (release_stage)
        self._free_ends = [e for side in SIDES for e in self._yarn_ends(side) if e not in held]
        self._release = []          # handles of the loads that stand for the end bodies
        self.end_bodies: list[RigidBody] = []
        if woven is not None and free_ends == "fibres":
            self._release = [self.model.add_force(f, k, np.zeros(9), dofs="all")
                             for f, k in self._free_ends]
        elif woven is not None:
            for side in SIDES:
                if side in self.sides or side in self.yarn_bodies:
                    continue
                yarn = getattr(fabric, SIDES[side][0])
                turning = not yarn.is_bundle if turning_ends is None else turning_ends
                for k, ends in self._ends_by_yarn(side).items():
                    body = RigidBody(f"{side} end of yarn {k}", sections=ends)
                    self._release += [body.add_force(np.zeros(3)), body.add_moment(np.zeros(3))]
                    if not turning:
                        body.fix(("rx", "ry", "rz"))
                    self.model.add_rigid_body(body)
                    self.end_bodies.append(body)
        # the friction forces the woven state's contacts carry, released
        # over the first stage (ReleasedForces): friction starts afresh
        self.released_friction = None
        if woven is not None and self.contact is not None and self.contact.has_friction:
            self.released_friction = ReleasedForces("friction forces of the woven state")
            self.model.add_effect(self.released_friction)
        # off until the first stage switches it on (settle_drag_effects)
        self.settle_drag = float(settle_drag)
        self.drag = ViscousDrag(0.0) if settle_drag > 0 else None
        if self.drag is not None:
            self.model.add_effect(self.drag)
        self.model.setup()
        if woven is not None:
            load_fibres(self.model, woven)
            if self.contact is not None:
                removed = self.contact.reset_friction(self.model)
                if removed is not None:
                    self.released_friction.set(removed)
            self._hold_free_ends()

    def _hold_spin(self, ends, configuration: np.ndarray) -> None:
        """A pinned fibre end turns freely, but a round fibre pinned at both
        ends could then spin about its own centre line at no cost (its
        bending energy does not change, and friction acts on the centre
        lines): a zero-stiffness mode (Newton wanders, or fails with yarns
        of several fibres). Hold the out-of-plane component g1z of each
        pinned end's section vector g1 (across the yarn, in the fabric
        plane; a support fixed in space, outside the side body's reaction)
        at its woven value: the end can no longer spin, and stays free to
        turn about z (the pin's axis) and to tilt about g1. (Once the end
        has tilted, bending about its own tilted g2 needs a little spin
        too, so that bending is somewhat restrained: an end on a vertical
        pin.)"""
        mesh = self.model.mesh
        for f, k in ends:
            g = mesh.node(f, k)
            self.model.fix(f, k, "g1z", configuration[g, 5] - mesh.X_global[g, 5])

    # -- hooks of a sample with a matrix (Composite) --------------------------
    def _add_matrix(self, configuration: np.ndarray) -> None:
        """Add effects between contact and the side bodies (none here)."""

    def _side_block(self, side: str) -> dict:
        """Extra RigidBody arguments of the body of ``side`` (none here)."""
        return {}

    # -- geometry ---------------------------------------------------------------
    def _yarn_ends(self, side: str) -> list[tuple[int, int]]:
        """(fibre, node) of the yarn ends on ``side``."""
        direction, end = SIDES[side]
        fabric = self.fabric
        yarns = [k for k in range(fabric.num_yarns) if fabric.yarn_direction(k) == direction]
        return [(int(f), end) for f in np.flatnonzero(np.isin(fabric.fibre_yarn, yarns))]

    def _ends_by_yarn(self, side: str) -> dict[int, list[tuple[int, int]]]:
        """{yarn: its (fibre, node) ends on ``side``}."""
        out: dict[int, list] = {}
        for f, k in self._yarn_ends(side):
            out.setdefault(int(self.fabric.fibre_yarn[f]), []).append((f, k))
        return out

    def end_positions(self, side: str, yarn: int | None = None) -> np.ndarray:
        """(ends, 3) positions, in the starting configuration, of the yarn
        ends on ``side`` (of one ``yarn`` only if given)."""
        mesh = self.model.mesh
        ends = self._yarn_ends(side) if yarn is None else self._ends_by_yarn(side)[yarn]
        return self.configuration[[mesh.node(f, k) for f, k in ends], 0:3]

    def side_distance(self, axis: str = "x") -> float:
        """Distance between the yarn ends of the two sides across ``axis``
        ("x": xmin to xmax, "y": ymin to ymax) in the starting
        configuration: the sample's gauge length."""
        k = "xy".index(axis)
        lo, hi = (("xmin", "xmax"), ("ymin", "ymax"))[k]
        return float(self.end_positions(hi)[:, k].mean() - self.end_positions(lo)[:, k].mean())

    def side_width(self, axis: str = "x") -> float:
        """Width of the sample across the yarns that end on the sides
        normal to ``axis`` ("x": the warp yarns, their count times their
        spacing; "y": the weft yarns)."""
        fabric = self.fabric
        if axis == "x":
            return float(fabric.num_warp * fabric.spacing[0])
        return float(fabric.num_weft * fabric.spacing[1])

    # -- stages and results -----------------------------------------------------
    def _imbalance(self, ends: list) -> np.ndarray:
        """(len(ends), 9): what the current state is out of balance by at
        the fibre nodes ``ends`` ((fibre, node) pairs), their residual rows
        with the bodies' multipliers at zero (collective)."""
        model, mesh = self.model, self.model.mesh
        b = model.x.duplicate()
        # as the model's own residual vector: constrained rows (index -1) skipped
        b.setOption(PETSc.Vec.Option.IGNORE_NEGATIVE_INDICES, True)
        model.residual(None, model.x, b)
        r = b.getArray(readonly=True)
        imbalance = np.zeros((len(ends), 9))
        local = mesh.global_to_local([mesh.node(f, k) for f, k in ends])
        mine = np.flatnonzero((local >= 0) & (local < mesh.num_owned))
        if len(mine):
            rows = model.layout.offset("beam") + 9 * local[mine][:, None] + np.arange(9)
            imbalance[mine] = r[model.owned_positions(rows.ravel())].reshape(-1, 9)
        b.destroy()
        return model.comm.allreduce(imbalance)

    def _resultants(self, bodies: list, ends: list, imbalance: np.ndarray) -> list:
        """Per body, the (6,) force and moment about its centre of the
        generalized forces ``imbalance`` at its fibre nodes (``ends``: one
        list per body, ``imbalance`` their rows in that order; a nodal force
        f = (f_x, f_g1, f_g2) on (x0, g1, g2) has moment
        (x0 - c) x f_x + g1 x f_g1 + g2 x f_g2: the section vectors turn as
        dg = dtheta x g) (collective)."""
        model, mesh = self.model, self.model.mesh
        q, centres = model.nodal_unknowns(), model.rigid_bodies.positions()
        index = {id(t): i for i, t in enumerate(model.rigid_bodies.bodies)}
        out, k = [], 0
        for body, mine in zip(bodies, ends):
            f, k = imbalance[k:k + len(mine)], k + len(mine)
            x = q[[mesh.node(fi, n) for fi, n in mine]]
            moment = np.cross(x[:, 0:3] - centres[index[id(body)]], f[:, 0:3]).sum(axis=0) + sum(
                np.cross(x[:, 3 * j:3 * j + 3], f[:, 3 * j:3 * j + 3]).sum(axis=0)
                for j in (1, 2))
            out.append(np.concatenate([f[:, 0:3].sum(axis=0), moment]))
        return out

    def _hold_free_ends(self) -> None:
        """Set the loads at the free yarn ends to what the loaded state is
        out of balance by there, so that it starts in equilibrium
        (collective): per fibre end its generalized force (9 a node), or per
        end body the resultant force and moment about its centre."""
        imbalance = self._imbalance(self._free_ends)
        if not self.end_bodies:
            values = imbalance
        else:
            row = {e: i for i, e in enumerate(self._free_ends)}
            ends = [body.held("sections") for body in self.end_bodies]
            rows = [row[e] for mine in ends for e in mine]
            values = []
            for r in self._resultants(self.end_bodies, ends, imbalance[rows]):
                values += [r[0:3], r[3:6]]
        for h, v in zip(self._release, values):
            h.schedule.start[h.index] = v
            h.schedule.target[h.index] = v

    def hold_side_reactions(self) -> None:
        """Call once the side bodies are held or driven (a virtual test's
        ``drive``), before the first stage: the components a side body
        leaves free (e.g. the shear test's xmax along x) get, as a dead
        load, the reaction the woven state needs there (what held the yarn
        ends in the weaving run: the yarns' weaving tension), released over
        the first stage. Let go at once, the yarns' tension drops in one
        step; a yarn of several fibres then rearranges in one Newton solve,
        and an element folds (collective)."""
        bodies = list(self.sides.values()) + [
            b for yarns in self.yarn_bodies.values() for b in yarns.values()]
        bodies = [b for b in bodies if len(b.prescribed) < 6]
        ends = [b.held("sections") + b.held("pins") for b in bodies]
        if not any(ends):
            return
        imbalance = self._imbalance([e for mine in ends for e in mine])
        for body, r in zip(bodies, self._resultants(bodies, ends, imbalance)):
            free = np.setdiff1d(np.arange(6), body.prescribed)
            body.loads.start[free] = r[free]    # from there to the loads' own targets

    def settle_drag_effects(self, steps: int) -> dict:
        """The first stage's effect options of the ``settle_drag`` (faded
        out as c (1 - s)^2 over the stage, a viscosity of nominal step
        1/``steps``); {} without one."""
        if self.drag is None:
            return {}
        c = self.settle_drag
        return {self.drag: dict(coefficient=lambda s: c * (1 - s) ** 2, step=1.0 / steps)}

    def drag_off_effects(self) -> dict:
        """The stages after the first: the ``settle_drag`` off ({} without
        one; a stage that does not name the drag would keep the first
        stage's fading coefficient, evaluated at its own load factor)."""
        return {} if self.drag is None else {self.drag: dict(coefficient=0.0, step=None)}

    def release_stage(self, steps: int = 2) -> Stage:
        """The first stage: the forces that stand for the weaving run's
        yarn-end bodies at the ends no side body holds go to zero (the
        sample is let go); the side bodies hold their components at zero."""
        return Stage("release", ramp={h: 0.0 for h in self._release},
                     solver=dict(initial_step=1.0 / steps, max_step=1.0 / steps))

    def output(self, directory: str, **options) -> Output:
        """An :class:`~textile.io.output.Output` writing fibres (with their yarn)
        (and the matrix) every step, and the fabric's figures."""
        return Output(directory, **fabric_labels(self.fabric),
                      extra=lambda model: measures.summary(self.fabric, model), **options)

    def side_reaction(self, side: str) -> np.ndarray:
        """(6,) force and moment the side's body (or its yarn bodies
        together) exerts on what it holds (fibre ends, and matrix face),
        about its current centre (the mean of the yarn bodies' centres)
        (collective)."""
        bodies = self.model.rigid_bodies
        if side not in self.yarn_bodies:
            return np.asarray(bodies.reaction(self.sides[side]))
        index = [i for i, b in enumerate(bodies.bodies) if b in self.yarn_bodies[side].values()]
        r, c = bodies.reactions()[index], bodies.positions()[index]
        return np.concatenate([r[:, 0:3].sum(axis=0),
                               (r[:, 3:6] + np.cross(c - c.mean(axis=0), r[:, 0:3])).sum(axis=0)])

    def reaction_balance(self) -> np.ndarray:
        """(6,) sum of the forces, and of the moments about the origin, that
        act on the sample from outside: the reactions of the side bodies and
        of the free yarn ends' bodies, or the forces held at free fibre ends
        (zero once released). Zero in equilibrium, up to the couples of
        friction forces (applied on the centre lines, a radius or two from
        the surfaces where they act) and of woven contacts (their normal
        kept from weaving, not along the line between the contact points).
        Valid outside a release stage (collective)."""
        bodies = self.model.rigid_bodies
        r = bodies.reactions()
        c = bodies.positions()
        total = np.concatenate([r[:, 0:3].sum(axis=0),
                                (r[:, 3:6] + np.cross(c, r[:, 0:3])).sum(axis=0)])
        if self._release and not self.end_bodies:
            mesh = self.model.mesh
            q = self.model.nodal_unknowns()[[mesh.node(f, k) for f, k in self._free_ends]]
            f = np.array([h.value for h in self._release]).reshape(-1, 9)
            total[0:3] += f[:, 0:3].sum(axis=0)
            total[3:6] += sum(np.cross(q[:, 3 * i:3 * i + 3], f[:, 3 * i:3 * i + 3]).sum(axis=0)
                              for i in range(3))
        return total
