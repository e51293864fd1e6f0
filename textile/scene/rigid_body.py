"""Rigid bodies: what a body holds and how each of its components is driven.

A rigid body has six unknowns: the displacement (x, y, z) of its reference
centre and its rotation (rx, ry, rz), carried as an incremental rotation
vector on top of the rotation accumulated over the accepted steps (exact
for any total rotation; :mod:`textile.effects.rigid_bodies`). It holds

- fibre end *sections* (a fibre node whose position and section vectors
  follow the body exactly: the end is clamped to the body),
- *pins* (a fibre node whose position only follows the body),
- *member bodies* (nesting: e.g. a side of a sample gathers the bodies at
  the ends of the yarns on that side), and
- *block nodes* (nodes of an elastic matrix block, e.g. its end face, that
  follow the body in position: :class:`~textile.scene.block_nodes.BlockNodes`).

Nesting: when the model is assembled, a body takes over the sections, pins
and block nodes of its members (recursively) as if it held them directly.
The members get no unknowns and no multipliers of their own: a rigid body
inside a rigid body has no motion of its own, and coupling it rigidly to its
parent would only add six unknowns and six multipliers per member, and a
saddle point to the system, for the same solution. A member therefore
cannot be driven: giving it prescriptions or loads (before or after it is
gathered), gathering it twice or adding it to the model is an error; what a
member carries is still reported (``RigidBodies.reaction``).

Frictionless plate (``slide=normal``): a fully held face cannot contract by
Poisson's effect (a block pulled through fully held end faces is stiffer
than E A / L, and the fibres' ends are held against the matrix's
contraction). A sliding body holds only the components along its normal n
(fixed in the body, turning with it): block nodes and pins keep x0 . n
(they slide in the plate's plane); fibre sections keep x0 . n, g1 . n,
g2 . n and their twist about n (g1 along the turned G2): the end section
stays flat on the plate but may slide and contract. The body's
translations in the plate's plane (and its rotation about n when it holds
no sections) then act on nothing: prescribe them (an error is raised for
an axis-aligned normal otherwise). A node may be held by several bodies
only if they all slide (an edge shared by two plates, or a symmetry plane
crossing a face), each holding its own component.

Each component is either prescribed (a displacement, or a rotation angle
about the fixed global axis x, y or z, reached at the end of the first
stage or given as a callable of the load factor) or free and loaded by a
dead force or a moment fixed in space. Both live in schedules
(:mod:`textile.scene.loading`): later stages ramp, hold or release them through the
handles that ``prescribe``, ``add_force`` and ``add_moment`` return. Prescribed rotations are
accumulated as increments about the fixed global axes, step by step: exact
for rotations about one axis, of any size. The body's reaction (the force
and moment it exerts on what it holds, about its current centre) is
reported every step.

Units: lengths and forces as in the model; angles in radians.
"""
from __future__ import annotations

import numpy as np

from .block_nodes import BlockNodes
from .loading import Handle, Schedule

#: Names of a body's six components, in storage order.
BODY_DOFS = ("x", "y", "z", "rx", "ry", "rz")
#: Groups of components accepted wherever they are named.
BODY_GROUPS = {"translation": (0, 1, 2), "rotation": (3, 4, 5), "all": tuple(range(6))}


def body_dof_indices(dofs) -> tuple[int, ...]:
    """Indices (0..5) of component names or groups; ValueError otherwise."""
    if isinstance(dofs, str):
        dofs = [dofs]
    out = []
    for d in dofs:
        if isinstance(d, str) and d in BODY_GROUPS:
            out.extend(BODY_GROUPS[d])
        elif isinstance(d, str) and d in BODY_DOFS:
            out.append(BODY_DOFS.index(d))
        else:
            raise ValueError(f"unknown rigid-body component {d!r}; use one of {BODY_DOFS} or a "
                             f"group {tuple(BODY_GROUPS)}")
    return tuple(dict.fromkeys(out))


class RigidBody:
    """A rigid body (see the module docstring).

    Parameters
    ----------
    name:
        Label used in outputs (unique in a model).
    sections:
        (fibre, node) pairs whose sections the body clamps (fibre object or
        index; node index, negative from the end).
    pins:
        (fibre, node) pairs whose positions only the body carries.
    centre:
        Reference centre (3,); default: the mean reference position of what
        the body holds (its members' included; each block node counts once).
    bodies:
        Member bodies whose sections, pins and block nodes this body takes
        over when the model is assembled (they must have no prescriptions or
        loads of their own).
    block_nodes:
        A :class:`~textile.scene.block_nodes.BlockNodes` (or a list of them): nodes
        of an elastic block that follow the body in position.
    slide:
        None (hold fully), or the normal (3,) of a frictionless plate: hold
        only the components along it (module docstring).
    """

    def __init__(self, name: str, sections=(), pins=(), centre=None, bodies=(), block_nodes=(),
                 slide=None):
        if not isinstance(name, str) or not name:
            raise ValueError(f"RigidBody: name must be a non-empty string, got {name!r}")
        self.name = name
        self.sections = self._pairs(sections, "sections")
        self.pins = self._pairs(pins, "pins")
        self.bodies = list(bodies)
        for member in self.bodies:
            if not isinstance(member, RigidBody):
                raise TypeError(f"RigidBody {name!r}: bodies must be RigidBody objects, got "
                                f"{type(member).__name__}")
            if member.parent is not None:
                raise ValueError(f"RigidBody {member.name!r} is already gathered by "
                                 f"{member.parent.name!r}")
            member.check_member()
        if isinstance(block_nodes, BlockNodes):
            block_nodes = [block_nodes]
        self.block_nodes = list(block_nodes)
        if not all(isinstance(b, BlockNodes) for b in self.block_nodes):
            raise TypeError(f"RigidBody {name!r}: block_nodes must be textile.scene.block_nodes."
                            f"BlockNodes objects")
        if not (self.sections or self.pins or self.bodies or self.block_nodes):
            raise ValueError(f"RigidBody {name!r} holds nothing: give sections, pins, bodies "
                             f"or block_nodes")
        if centre is not None:
            c = np.asarray(centre, dtype=float)
            if c.shape != (3,) or not np.all(np.isfinite(c)):
                raise ValueError(f"RigidBody {name!r}: centre must be a finite 3-vector")
            centre = c
        self.centre = centre
        if slide is not None:
            n = np.asarray(slide, dtype=float)
            if n.shape != (3,) or not np.all(np.isfinite(n)) or np.linalg.norm(n) == 0:
                raise ValueError(f"RigidBody {name!r}: slide must be a non-zero finite "
                                 f"3-vector (the plate's normal)")
            slide = n / np.linalg.norm(n)
        self.slide = slide
        #: the body that gathers this one (None: a body of its own)
        self.parent: RigidBody | None = None
        for member in self.bodies:
            member.parent = self
        #: the six components' prescribed values (inactive: free)
        self.prescriptions = Schedule(f"body {name} prescribed")
        self._components = self.prescriptions.add(np.zeros(6), f"body {name}")
        self.prescriptions.active[:] = False
        #: force (3) and moment (3) applied to the body
        self.loads = Schedule(f"body {name} loads")
        self._loads = self.loads.add(np.zeros(6), f"body {name} loads")

    @staticmethod
    def _pairs(pairs, label: str) -> list:
        try:
            out = [(f, n) for f, n in pairs]
        except (TypeError, ValueError) as e:
            raise ValueError(f"RigidBody: {label} must be (fibre, node) pairs") from e
        return out

    # -- nesting ---------------------------------------------------------------
    def members(self) -> list["RigidBody"]:
        """Every body this one gathers, directly or through members."""
        out = []
        for m in self.bodies:
            out += [m] + m.members()
        return out

    def check_member(self) -> None:
        """ValueError if this body, gathered by another, has prescriptions or
        loads of its own (the gathering body is the one to drive)."""
        for b in [self] + self.members():
            if b.prescriptions.active.any() or b.has_load:
                raise ValueError(f"RigidBody {b.name!r} is gathered by another body and has "
                                 f"prescriptions or loads of its own: drive the gathering body "
                                 f"instead")

    def _check_drivable(self) -> None:
        if self.parent is not None:
            raise ValueError(f"RigidBody {self.name!r} is gathered by {self.parent.name!r}: "
                             f"it cannot be driven on its own; drive {self.parent.name!r}")

    def held(self, kind: str) -> list:
        """What the body holds once its members are taken over: ``kind`` is
        "sections", "pins" (lists of (fibre, node)) or "block_nodes"."""
        out = list(getattr(self, kind))
        for m in self.bodies:
            out += m.held(kind)
        return out

    def prescribe(self, dofs="all", value=0.0) -> Handle:
        """Prescribe components: displacement of the centre (x, y, z) or
        rotation angle about the global axis (rx, ry, rz), reached at the end
        of the first stage (scalar or one value per component), or a callable
        ``s -> values``. Returns the handle stages use to ramp or release
        them."""
        self._check_drivable()
        idx = np.array(body_dof_indices(dofs))
        handle = Handle(self.prescriptions, idx, f"body {self.name} {[BODY_DOFS[d] for d in idx]}")
        if callable(value):
            self.prescriptions.follow(handle, value)
        else:
            vals = np.broadcast_to(np.asarray(value, dtype=float), (len(idx),))
            if not np.all(np.isfinite(vals)):
                raise ValueError(f"RigidBody {self.name!r}: prescribed values must be finite")
            self.prescriptions.ramp(handle, vals)
        self.prescriptions.active[idx] = True
        return handle

    def fix(self, dofs="all") -> "RigidBody":
        """Hold components at their reference value (a clamp); returns the
        body (chainable; ``prescribe`` returns a handle)."""
        self.prescribe(dofs, 0.0)
        return self

    def add_force(self, force) -> Handle:
        """Dead force on the centre (reached at the end of the first stage);
        returns the handle of the body's force."""
        self._check_drivable()
        f = self._vector(force, "force")
        self.loads.target[0:3] += f
        return Handle(self.loads, np.arange(3), f"body {self.name} force")

    def add_moment(self, moment) -> Handle:
        """Moment fixed in space (reached at the end of the first stage);
        returns the handle of the body's moment."""
        self._check_drivable()
        m = self._vector(moment, "moment")
        self.loads.target[3:6] += m
        return Handle(self.loads, np.arange(3, 6), f"body {self.name} moment")

    @property
    def prescribed(self) -> np.ndarray:
        """Indices of the components prescribed now."""
        return np.flatnonzero(self.prescriptions.active)

    @property
    def has_load(self) -> bool:
        """True if a force or moment is (or will be) applied to the body."""
        return bool(np.any(self.loads.start) or np.any(self.loads.target)
                    or self.loads.has_callables())

    @property
    def has_moment(self) -> bool:
        return bool(np.any(self.loads.start[3:6]) or np.any(self.loads.target[3:6])
                    or self.loads.has_callables())

    def _vector(self, v, label) -> np.ndarray:
        a = np.asarray(v, dtype=float)
        if a.shape != (3,) or not np.all(np.isfinite(a)):
            raise ValueError(f"RigidBody {self.name!r}: {label} must be a finite 3-vector, "
                             f"got {v!r}")
        return a

    def __repr__(self) -> str:
        return (f"RigidBody({self.name!r}, {len(self.sections)} sections, {len(self.pins)} pins, "
                f"{len(self.bodies)} members, {len(self.block_nodes)} block node sets, "
                f"prescribed {[BODY_DOFS[d] for d in self.prescribed]})")
