"""A scene: fibres, their prescribed unknowns and loads, effects, stages.

:class:`Model` is what the user builds. Set up (by the solver, or by a
query of the current state), it closes and assembles its effects into one
monolithic :class:`~textile.system.system.System` (layout, vectors, matrix,
constraints, residual and tangent), which the solver drives. The model
keeps the scene (its schedules move with the stages) and answers the user's
queries of the solved state (centre lines, section vectors, reactions).
"""
from __future__ import annotations

import numpy as np
from mpi4py import MPI

from ..beam.element import BeamElement
from ..beam.fibre import Fibre
from ..beam.fibre_mesh import FibreMesh, dof_indices
from ..effects import BeamElasticity, EndMoments, NodalForces
from ..effects.base import Effect
from ..effects.prescribed_displacements import PrescribedDisplacements
from ..system.system import System
from .loading import Handle, Schedule


def _forwarded(name: str, writable: bool = True) -> property:
    """The attribute (or method) ``name`` of the model's system."""
    return property(lambda self: getattr(self.system, name),
                    (lambda self, value: setattr(self.system, name, value)) if writable else None,
                    doc=f"``{name}`` of the scene's :class:`~textile.system.system.System`.")


class Model:
    """Fibres plus everything acting on them: the scene, assembled into one system.

    Parameters
    ----------
    fibres:
        List of :class:`~textile.Fibre`.
    element:
        :class:`~textile.BeamElement` (order, quadratures); default quadratic.
    comm:
        MPI communicator (default ``MPI.COMM_WORLD``).
    partition:
        How the fibres' nodes are shared out over the ranks: ``"place"``
        (default: boxes of the fabric) or ``"numbers"`` (node ranges, fibre
        after fibre); :mod:`textile.beam.node_partition`.
    """

    def __init__(self, fibres, element: BeamElement | None = None, comm=MPI.COMM_WORLD,
                 partition: str = "place"):
        if isinstance(fibres, Fibre):
            fibres = [fibres]
        self.comm = comm
        self.element = element if element is not None else BeamElement()
        if not isinstance(self.element, BeamElement):
            raise TypeError("element must be a textile.BeamElement")
        self.mesh = FibreMesh(comm, list(fibres), self.element.order, partition)
        self.beam = BeamElasticity()
        self._forces = NodalForces()
        self._moments = EndMoments()
        self._effects: list[Effect] = []
        self._rigid = None
        self._prescribed = PrescribedDisplacements()
        self._ready = False
        #: the assembled system (built by setup)
        self._system: System | None = None
        self._load_factor = 0.0

    # -- scene definition ------------------------------------------------
    def _check_open(self):
        if self._ready:
            raise RuntimeError("the model is already assembled: define the scene before solving")

    def fix(self, fibre, node: int, dofs="all", value=0.0) -> Handle:
        """Prescribe node unknowns' displacement.

        ``dofs``: names ("x", "g1y", ...), groups ("position", "g1", "g2",
        "section", "all") or indices 0..8. ``value``: displacement reached at
        the end of the first stage, ramped from 0 (scalar or one per dof), or
        a callable ``s -> values`` of the load factor. Returns the handle
        with which stages ramp or release the prescription
        (:mod:`textile.scene.loading`). Fixing a dof again replaces its value.
        """
        self._check_open()
        idx = dof_indices(dofs)
        if not callable(value):
            vals = np.broadcast_to(np.asarray(value, dtype=float), (len(idx),))
            if not np.all(np.isfinite(vals)):
                raise ValueError("value contains NaN or infinite numbers")
        handle = self._prescribed.add(self.mesh.node(fibre, node), idx,
                                      f"fibre {fibre} node {node} {idx}")
        if callable(value):
            self._prescribed.schedule.follow(handle, value)
        else:
            self._prescribed.schedule.ramp(handle, vals)
        return handle

    def clamp(self, fibre, node: int) -> Handle:
        """Fix position and section vectors of a node (a clamped end)."""
        return self.fix(fibre, node, "all", 0.0)

    def add_force(self, fibre, node: int, force, dofs="position") -> Handle:
        """Dead force on a node: a 3-vector on its position by default, or
        one value per named dof, reached at the end of the first stage.
        Returns its handle (stages ramp or hold it)."""
        self._check_open()
        idx = dof_indices(dofs)
        f = np.asarray(force, dtype=float).ravel()
        if f.shape != (len(idx),) or not np.all(np.isfinite(f)):
            raise ValueError(f"force must hold {len(idx)} finite values, got {force!r}")
        g = self.mesh.node(fibre, node)
        return self._forces.add(g, idx, f, f"force on fibre {fibre} node {node}")

    def add_end_moment(self, fibre, node: int, moment) -> Handle:
        """Moment vector (fixed in space) on a node's section, reached at the
        end of the first stage; returns its handle."""
        self._check_open()
        m = np.asarray(moment, dtype=float)
        if m.shape != (3,) or not np.all(np.isfinite(m)):
            raise ValueError(f"moment must be a finite 3-vector, got {moment!r}")
        return self._moments.add(self.mesh.node(fibre, node), m,
                                 f"moment on fibre {fibre} node {node}")

    def add_rigid_body(self, body) -> None:
        """Add a :class:`textile.RigidBody` (its unknowns, couplings, loads)."""
        self._check_open()
        if self._rigid is None:
            from ..effects.rigid_bodies import RigidBodies

            self._rigid = RigidBodies()
            self._effects.append(self._rigid)
        self._rigid.add(body)

    @property
    def rigid_bodies(self):
        """The scene's :class:`~textile.effects.rigid_bodies.RigidBodies`, or None."""
        return self._rigid

    def schedules(self) -> list[Schedule]:
        """Every schedule of the scene: prescribed displacements, nodal
        forces, end moments and the effects' own (rigid bodies, ...). The
        prescribed displacements' schedule comes first even when empty (a
        state file lists it)."""
        out = [self._prescribed.schedule]
        for e in self.effects:
            if e is not self._prescribed:
                out += e.schedules()
        return out

    @property
    def saddle_point_rows(self) -> int:
        """Negative eigenvalues the scene's multipliers add to the tangent."""
        return sum(e.saddle_point_rows() for e in self.effects)

    def add_effect(self, effect: Effect) -> None:
        """Add a physics term (e.g. an elastic matrix block, a junction)."""
        self._check_open()
        if not isinstance(effect, Effect):
            raise TypeError("effect must be a textile.effects.Effect")
        self._effects.append(effect)

    @property
    def force_scale(self) -> float:
        """Largest fibre axial stiffness E*A (force unit): the scale of the
        internal forces, used for absolute solver tolerances."""
        return max(f.material.young * np.pi * f.radius ** 2 for f in self.mesh.fibres)

    @property
    def effects(self) -> list[Effect]:
        """Effects assembled in this scene (loads only when present)."""
        out: list[Effect] = [self.beam]
        if len(self._prescribed):
            out.append(self._prescribed)
        if len(self._forces.schedule):
            out.append(self._forces)
        if len(self._moments.schedule):
            out.append(self._moments)
        return out + self._effects

    # -- stages ------------------------------------------------------------
    def begin_stage(self, stage) -> bool:
        """Apply a :class:`textile.loading.Stage` (targets, releases, effect
        options) at the current state, load factor 0. Returns True when the
        set of prescribed unknowns changed (the system matrix is then new)."""
        system = self.system
        system.load_factor = 0.0
        stage.apply()
        return system.update_constraints()

    def finish_stage(self) -> None:
        """The stage is complete: every quantity's end value becomes the
        start of the next stage (held unless that stage says otherwise)."""
        for s in self.schedules():
            s.finish_stage()
        self.system.invalidate_constraints()
        self.system.load_factor = 0.0

    # -- the assembled system ------------------------------------------------
    def setup(self) -> None:
        """Close the scene and assemble its system (called by the solver and
        by the first query of the state; a second call does nothing)."""
        if self._ready:
            return
        self._system = System(self.comm, self.mesh, self.element, self.effects, self.force_scale,
                              self._load_factor)
        self._ready = True

    @property
    def system(self) -> System:
        """The scene's assembled :class:`~textile.system.system.System`
        (built on first use)."""
        self.setup()
        return self._system

    @property
    def load_factor(self) -> float:
        """Where the scene's schedules stand in the current stage (0 to 1)."""
        return self._load_factor if self._system is None else self._system.load_factor

    @load_factor.setter
    def load_factor(self, value: float) -> None:
        if self._system is None:
            self._load_factor = value
        else:
            self._system.load_factor = value

    # The system's own API, reached through the scene by scripts and tests
    # that hold the model (the solver and the effects work on the System).
    x = _forwarded("x")
    b = _forwarded("b")
    A = _forwarded("A")
    layout = _forwarded("layout")
    constraint_set = _forwarded("constraint_set")
    residual_groups = _forwarded("residual_groups")
    residual_norms = _forwarded("residual_norms")
    force_reference = _forwarded("force_reference")
    domain_error = _forwarded("domain_error")
    matrix_stale = _forwarded("matrix_stale")
    effect_seconds = _forwarded("effect_seconds")
    newton = _forwarded("newton")
    last_tangent_update = _forwarded("last_tangent_update")
    constraint_version = _forwarded("constraint_version")
    state = _forwarded("state", writable=False)
    residual = _forwarded("residual", writable=False)
    jacobian = _forwarded("jacobian", writable=False)
    apply_constraints = _forwarded("apply_constraints", writable=False)
    rebuild_matrix = _forwarded("rebuild_matrix", writable=False)
    update_constraints = _forwarded("update_constraints", writable=False)
    invalidate_constraints = _forwarded("invalidate_constraints", writable=False)
    request_matrix_rebuild = _forwarded("request_matrix_rebuild", writable=False)
    start_newton = _forwarded("start_newton", writable=False)
    set_linearization_point = _forwarded("set_linearization_point", writable=False)
    floors = _forwarded("floors", writable=False)
    reference_values = _forwarded("reference_values", writable=False)
    reference_norm = _forwarded("reference_norm", writable=False)
    set_field_values = _forwarded("set_field_values", writable=False)
    block_keys = _forwarded("block_keys", writable=False)
    field_owner = _forwarded("field_owner", writable=False)
    constrained_positions = _forwarded("constrained_positions", writable=False)
    owned_positions = _forwarded("owned_positions", writable=False)
    beam_values = _forwarded("beam_values", writable=False)
    beam_positions = _forwarded("beam_positions", writable=False)
    beam_global_dofs = _forwarded("beam_global_dofs", writable=False)
    residual_record = _forwarded("residual_record", writable=False)
    residual_record_current = _forwarded("residual_record_current", writable=False)
    restore_residual_record = _forwarded("restore_residual_record", writable=False)

    # -- results -------------------------------------------------------------
    def nodal_unknowns(self) -> np.ndarray:
        """Current (global nodes, 9) values [x0, g1, g2] (positions, not
        displacements), identical on every rank. Collective: call it on
        every rank (not inside a rank-0 block), as centreline,
        section_vectors and reaction, which use it or an allreduce."""
        return self.system.nodal_unknowns()

    def centreline(self, fibre) -> np.ndarray:
        """Current (n, 3) centre-line node positions of ``fibre``."""
        return self.nodal_unknowns()[self.mesh.fibre_nodes(fibre), 0:3]

    def section_vectors(self, fibre) -> tuple[np.ndarray, np.ndarray]:
        """Current (n, 3) section vectors g1, g2 of ``fibre``."""
        q = self.nodal_unknowns()[self.mesh.fibre_nodes(fibre)]
        return q[:, 3:6], q[:, 6:9]

    def reaction(self, fibre, node: int, dofs="position") -> np.ndarray:
        """Support reaction on the named constrained dofs of a node, from the
        last residual evaluation: internal minus external generalized force,
        i.e. the force the support exerts on the fibre (a bar pulled by +P at
        its free end has reaction -P at its clamp)."""
        return self.system.reaction_values(self.mesh.node(fibre, node), dof_indices(dofs))
