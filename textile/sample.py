"""A woven sample driven through side rigid bodies: the scene of the virtual
tests (METHOD.md section 8), with or without a matrix.

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
  follow, the ends turn freely, as on the arms of a picture frame). Each
  body component is then prescribed or loaded by the caller
  (``sample.sides["xmax"].prescribe("y", u)``);
- the yarn ends no side body holds were held, in the weaving run, by the
  yarns' end bodies: here a force stands for each such body, equal to what
  it exerted in the saved state (so the sample starts in equilibrium), and
  :meth:`Sample.release_stage` lets those forces go.

:class:`~textile.composite.Composite` adds a matrix (and junctions) to this
scene; its side bodies also hold the matrix faces.

Units: those of the fabric (lengths of its spacing and radii, forces of its
materials' Young's modulus times an area); angles in radians.
"""
from __future__ import annotations

import numpy as np
from mpi4py import MPI

from . import fabric_measures
from .effects.fibre_contact import FibreContact
from .fabric import Fabric
from .io import fabric_labels
from .io.state_file import load_fibres, saved_configuration
from .loading import Stage
from .model import Model
from .output import Output
from .rigid_body import RigidBody

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
        slide over each other (a zero-stiffness mode).
    comm:
        MPI communicator.
    """

    def __init__(self, fabric: Fabric, woven: str | None, sides=("xmin", "xmax"), pins=(),
                 contact=None, comm=MPI.COMM_WORLD):
        name = type(self).__name__
        if not isinstance(fabric, Fabric):
            raise TypeError(f"{name}: fabric must be a textile.fabric.Fabric, got "
                            f"{type(fabric).__name__}")
        sides = _side_names(sides, f"{name}: sides")
        pins = _side_names(pins, f"{name}: pins", allow_empty=True)
        if not set(pins) <= set(sides):
            raise ValueError(f"{name}: pins {pins!r} must be among the sides {sides!r}")
        self.fabric, self.woven = fabric, woven
        fibres = fabric.fibres()
        # the configuration everything is built around: the woven one
        configuration = None
        if woven is not None:
            configuration = comm.bcast(saved_configuration(woven) if comm.rank == 0 else None,
                                       root=0)
        self.model = Model(fibres, comm=comm)
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
            self.contact = FibreContact(contact)
            self.model.add_effect(self.contact)
        self._add_matrix(configuration)
        self.sides: dict[str, RigidBody] = {}
        held = set()
        for side in sides:
            ends = self._yarn_ends(side)
            hold = dict(pins=ends) if side in pins else dict(sections=ends)
            body = RigidBody(side, **hold, **self._side_block(side))
            self.model.add_rigid_body(body)
            self.sides[side] = body
            held.update(ends)
        # the yarn ends no body holds: what held them in the weaving run
        # (its yarn-end bodies) is replaced by a force, released over the
        # first stage (release_stage)
        self._free_ends = [e for side in SIDES for e in self._yarn_ends(side) if e not in held]
        self._release = [self.model.add_force(f, k, np.zeros(9), dofs="all")
                         for f, k in self._free_ends] if woven is not None else []
        self.model.setup()
        if woven is not None:
            load_fibres(self.model, woven)
            self._hold_free_ends()

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

    def end_positions(self, side: str) -> np.ndarray:
        """(ends, 3) positions, in the starting configuration, of the yarn
        ends on ``side``."""
        mesh = self.model.mesh
        return self.configuration[[mesh.node(f, k) for f, k in self._yarn_ends(side)], 0:3]

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
    def _hold_free_ends(self) -> None:
        """Set the release forces to the generalized forces (9 a node) the
        loaded state is out of balance by at the free yarn ends, so that it
        starts in equilibrium (collective)."""
        model, mesh = self.model, self.model.mesh
        b = model.x.duplicate()
        model.residual(None, model.x, b)
        r = b.getArray(readonly=True)
        imbalance = np.zeros((len(self._free_ends), 9))
        local = mesh.global_to_local([mesh.node(f, k) for f, k in self._free_ends])
        mine = np.flatnonzero((local >= 0) & (local < mesh.num_owned))
        if len(mine):
            rows = model.layout.offset("beam") + 9 * local[mine][:, None] + np.arange(9)
            imbalance[mine] = r[model._owned_position(rows.ravel())].reshape(-1, 9)
        imbalance = model.comm.allreduce(imbalance)
        b.destroy()
        for h, f in zip(self._release, imbalance):
            h.schedule.start[h.index] = f
            h.schedule.target[h.index] = f

    def release_stage(self, steps: int = 2) -> Stage:
        """The first stage: the forces that stand for the weaving run's
        yarn-end bodies at the ends no side body holds go to zero (the
        sample is let go); the side bodies hold their components at zero."""
        return Stage("release", ramp={h: 0.0 for h in self._release},
                     solver=dict(initial_step=1.0 / steps, max_step=1.0 / steps))

    def output(self, directory: str, **options) -> Output:
        """An :class:`~textile.output.Output` writing fibres (with their yarn)
        (and the matrix) every step, and the fabric's figures."""
        return Output(directory, **fabric_labels(self.fabric),
                      extra=lambda model: fabric_measures.summary(self.fabric, model), **options)

    def side_reaction(self, side: str) -> np.ndarray:
        """(6,) force and moment the side body exerts on what it holds
        (fibre ends, and matrix face), about its current centre (collective)."""
        return np.asarray(self.model.rigid_bodies.reaction(self.sides[side]))

    def reaction_balance(self) -> np.ndarray:
        """(6,) sum of the forces and of the moments (about the origin) that
        the side bodies exert on the sample: zero in equilibrium once the
        free yarn ends are released (after :meth:`release_stage`; collective)."""
        bodies = self.model.rigid_bodies
        r = bodies.reactions()
        c = bodies.positions()
        return np.concatenate([r[:, 0:3].sum(axis=0),
                               (r[:, 3:6] + np.cross(c, r[:, 0:3])).sum(axis=0)])
