"""The interface every physics term implements.

Sign convention (whole project): the residual is internal minus external
generalized force, r(u) = dPi_int/du - f_ext, so equilibrium is r = 0 and
the tangent is dr/du. Unknowns are displacements u = x - X of every field.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from petsc4py import PETSc

#: Relative difference (to the largest value of the quantity) within which a
#: saved scene's reference values (fibre and matrix node coordinates,
#: junction points, body centres) are this model's: a scene built again,
#: on any number of ranks, gives them to round-off (measured 2e-16 for the
#: matrix nodes of 1 and 2 ranks, tests/io/test_state_file.py); another
#: scene differs by far more.
SAME_SCENE_RTOL = 1e-12


def stage_ended(s: float) -> bool:
    """Is load factor ``s`` its stage's end (s = 1, up to the round-off of
    summed steps)? The one test for it (effects' commits, stage schedules,
    the output's last-step pictures)."""
    return s >= 1.0 - 1e-12


@dataclass
class State:
    """What an effect sees during one evaluation.

    Attributes
    ----------
    load_factor:
        Current load factor t (external loads and prescribed values scale
        with it).
    u:
        Field name -> local displacement array (owned + ghost, unrolled).
    dofs:
        Field name -> stacked local index of each local unrolled dof in the
        global matrix, -1 where the dof is constrained (PETSc skips it).
    du:
        Field name -> local array of the last Newton update (the iterate
        minus the previous linearization point), set only for the tangent
        that SNES asks for; empty otherwise. Effects may use it for a
        mixed-integration-point (MIP) tangent; with du empty (or zero) the
        tangent must be the exact derivative of the residual. At a predicted
        state (System.set_predicted_stress) it holds k differences of
        states one after another (k times the field's local size).
    du_weights:
        Field name -> the k weights of du's differences, set with them
        (absent: one update of weight 1).
    tangent_index:
        For a tangent (Effect.jacobian): how many tangents the model has
        assembled since the solver last ran the effects' ``prepare`` or
        ``update`` (0: the first tangent of the Newton solve that follows;
        1, 2, ...: the next iterations, counted on across the linear
        solver's retries of that solve). Effects read the Newton iteration
        from it instead of counting their own calls. 0 otherwise.
    vector:
        The global PETSc vector the local arrays view, for effects that
        read unknowns of other ranks (:class:`~textile.system.node_gather.NodeGather`).
    """

    load_factor: float
    u: dict[str, np.ndarray] = field(default_factory=dict)
    dofs: dict[str, np.ndarray] = field(default_factory=dict)
    du: dict[str, np.ndarray] = field(default_factory=dict)
    du_weights: dict[str, np.ndarray] = field(default_factory=dict)
    tangent_index: int = 0
    vector: object = None


class Effect:
    """A physics term: residual and tangent contributions to the global system.

    Subclasses override what they need. ``fields`` names the fields whose
    blocks the effect writes into.

    Every hook the system, the solver, saved states and the output call is
    declared here with its contract and a neutral default (they call it on
    every effect, never asking whether an effect has it): an effect that
    overrides nothing adds nothing to the system, has no schedules, no
    multipliers, no saved state and no output of its own. The hooks' ``model``
    argument is the scene's assembled :class:`~textile.system.system.System`
    (its mesh, communicator, element, layout, unknowns); an effect changes
    it only through its public methods (e.g.
    ``System.request_matrix_rebuild``, ``System.set_field_values``).
    """

    #: Field names the effect couples (rows and columns).
    fields: tuple[str, ...] = ()
    #: True if the effect's couplings change during a run (contact): the
    #: matrix then accepts entries outside the initial sparsity pattern.
    dynamic_sparsity: bool = False
    #: True if the effect's tangent is symmetric (it derives from a potential
    #: and nothing follows the deformation): when every effect of a scene
    #: says so, the solver may factorize with LDL^T.
    symmetric_tangent: bool = False
    #: True if the effect's tangent does not depend on the state (a
    #: quadratic energy): the model then calls its jacobian first, while the
    #: matrix still has its final pattern and is assembled, so the effect
    #: can add a cached copy in one pass instead of inserting it again.
    constant_tangent: bool = False
    #: True if ``external`` depends on nothing but the values of the
    #: effect's schedules (dead loads): the model then computes the force
    #: scale of the convergence test again only when those values change.
    external_from_schedules: bool = False
    #: False if the effect's forces switch along a load path (contacts
    #: opening, closing and sliding): the "auto" predictor then chooses each
    #: step between the secant's start and the plain one instead of
    #: extrapolating the path (SolverOptions.predictor).
    smooth_path: bool = True

    def fibre_ghosts(self, mesh) -> np.ndarray:
        """Global fibre nodes this effect couples on this rank without
        owning them (they become ghosts: :meth:`FibreMesh.add_ghosts`).
        Called once, before the numbering is final (before add_fields)."""
        return np.zeros(0, dtype=np.int64)

    def add_fields(self, model) -> list:
        """New fields this effect brings (e.g. the matrix's function space)."""
        return []

    def setup(self, model) -> None:
        """Called once the layout exists, before any assembly."""

    def reference_values(self) -> dict[str, np.ndarray]:
        """Per field this effect brings: the reference values its kernels
        add to the unknowns (owned then ghost, unrolled; e.g. node
        coordinates under displacements). They set the size of the terms a
        residual is made of, hence its round-off floor (Model.floors): a
        coupling row computing X + u carries round-off of eps |X|, however
        small u is. Called after setup; fields not listed count as zero."""
        return {}

    def block_keys(self, field: str) -> np.ndarray:
        """For a field this effect brings: (local blocks, k) int64 rows, one
        per block (owned then ghost), naming the block the same way whatever
        the partition (a matrix node by its mesh input vertices, a rigid
        body by its index, ...). A saved state writes and reads the field by
        these keys (:mod:`textile.io.state_file`)."""
        raise NotImplementedError(f"{type(self).__name__} brings field {field!r} but no "
                                  f"block_keys for saved states")

    def add_sparsity(self, sparsity) -> None:
        """Insert the blocks this effect will fill."""

    def add_dynamic_pattern(self, model, pattern) -> None:
        """For effects with dynamic_sparsity: declare the matrix entries the
        effect can fill now, by global index (``pattern.add(rows, cols)``;
        ``pattern`` is a ``_cpp.SparsityPattern``). Called when the model
        rebuilds its matrix, after an effect asked for it with
        ``model.request_matrix_rebuild()`` in its prepare or update."""

    def constraints(self, load_factor: float) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Field name -> (local unrolled dofs, prescribed values) the effect
        constrains (e.g. Dirichlet conditions of its own field)."""
        return {}

    def residual(self, state: State, b: dict[str, np.ndarray]) -> None:
        """Add the residual into the local arrays ``b[field]`` (owned+ghost)."""

    def external(self, state: State, b: dict[str, np.ndarray]) -> None:
        """Add the external generalized forces the effect applies (loads,
        positive along the load) into ``b[field]``: the force scale of the
        Newton convergence test. Only effects that apply loads override it."""

    def jacobian(self, state: State, A: PETSc.Mat) -> None:
        """Add the tangent into A using ``state.dofs`` (local numbering)."""

    def residual_global(self, state: State, b: PETSc.Vec) -> bool:
        """Add residual entries by *global* index (``b.setValues`` with ADD),
        for couplings between unknowns that are not all local on this rank.
        Return True if anything was added (the model then assembles b)."""
        return False

    def configure(self, **options) -> None:
        """Options set by a stage (:class:`textile.scene.loading.Stage`), e.g. the
        contact mode; effects without stage options refuse any."""
        if options:
            raise ValueError(f"{type(self).__name__} takes no stage options, got "
                             f"{sorted(options)}")

    def configure_resumed(self, **options) -> None:
        """A stage resumed from a saved state within it
        (:meth:`textile.solver.stages.Stages.resume_stage`) gives the effect
        its options again: an effect sets here those it does not save
        (callables of s cannot be saved), and keeps what its
        :meth:`load_state` restored (history, and the options that shape
        it). Default: nothing, the effect saved all it needs."""

    # -- load-step protocol (docs/method.md §9.2) ------------------------
    def prepare(self, model) -> None:
        """Start of a load-step attempt, at the predicted state: set up what
        Newton holds fixed (e.g. contact elements and normals)."""

    def update(self, model) -> bool:
        """After a converged Newton solve: update what Newton held fixed;
        True if it changed enough that Newton must run again."""
        return False

    def update_change(self) -> float:
        """How much the last ``update`` changed what it acts on, in units of
        the effect's own tolerance for it (> 1: ``update`` said changed;
        the same on every rank): the contact loop records it per pass and
        names it when the loop does not settle. 0 for an effect that holds
        nothing fixed."""
        return 0.0

    def commit(self, model) -> None:
        """The step is accepted: move history forward (e.g. stick points)."""

    def restore(self, model) -> None:
        """The step attempt failed: return to the state of the last commit."""

    def statistics(self) -> dict:
        """Scalars worth logging per step (merged into results.json)."""
        return {}

    # -- loading and stability ---------------------------------------------
    def schedules(self) -> list:
        """The effect's loading schedules (:class:`textile.scene.loading.Schedule`:
        its prescriptions and loads), which stages ramp, hold and release
        and saved states write. The model lists them after its own
        prescribed displacements (Model.schedules), whenever it needs them:
        the same schedules, in the same order, at every call."""
        return []

    def saddle_point_rows(self) -> int:
        """Negative eigenvalues the effect's Lagrange multiplier rows add to
        the tangent (one per constraint row, by Sylvester's law), the same
        on every rank: the stability check discounts them. Called after
        setup."""
        return 0

    # -- saved states (textile.io.state_file) ------------------------------
    #: Name of the effect's group in a state file, None if it saves nothing
    #: beyond its fields' unknowns (which the state file writes by block key).
    state_name: str | None = None

    def save_state(self, model) -> dict:
        """Name -> array of what the effect needs, besides its fields'
        unknowns, to continue exactly (history) and to recognize its scene
        (e.g. its material, its bodies' names), independent of the
        partition. Collective; the result counts on rank 0 only."""
        return {}

    def check_state(self, model, data: dict) -> None:
        """Raise ValueError naming what differs if ``data`` (save_state's
        output read back; empty if the file has none) is not this effect's
        scene. Called before anything is loaded, so a refused file leaves
        the model as it was. Every rank sees the same data."""

    def load_state(self, model, data: dict) -> None:
        """Restore the history saved by save_state (after check_state, with
        the unknowns already loaded)."""

    def load_fibres(self, model, data: dict) -> None:
        """A new scene starts from the fibres of a saved state
        (:func:`textile.load_fibres`): the fibre unknowns are already set;
        ``data`` is the file's group of this effect's ``state_name`` (empty
        when the file has none, or state_name is None). Collective. Default:
        nothing, the effect starts afresh."""

    # -- output (textile.io.output.Output) ------------------------------------
    #: Name of the effect's own ParaView part (``<vtk_name>/`` and
    #: ``<vtk_name>.pvd`` next to the fibres, a part of ``scene.pvd``),
    #: None if it writes none; then write_vtk is never called.
    vtk_name: str | None = None

    def write_vtk(self, directory: str, stem: str, time: float) -> str:
        """For an effect with a vtk_name: write its part at the model's
        current state into ``directory`` (which exists), file names starting
        with ``stem``, at ``time`` (collective); return the path of the file
        to index (on rank 0)."""
        raise NotImplementedError(f"{type(self).__name__} has a vtk_name but no write_vtk")

    def contact_elements(self) -> dict | None:
        """This rank's contact elements for the output's ``contacts_<step>.vtu``
        (collective call: every rank gets its own), or None if the effect has
        none to show. Arrays, one row per element: ``position_i``,
        ``position_j`` (n, 3), ``normal_force``, ``gap``, ``normal``,
        ``tangential_force``, ``slip``, ``penalty``, ``fibre_i``,
        ``fibre_j``; every effect that returns them gives the same keys."""
        return None
