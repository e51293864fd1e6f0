"""Fibre-fibre contact and friction through intermediate geometries.

Detection, geometry, normals, history transfer, laws, penalty adaptation
and assembly are in C++ (``cpp/textile/contact/``); this effect runs the
algorithm of docs/method.md §9.2 around Newton and does the few MPI
reductions, all on per-zone arrays. On several ranks each rank detects
among its own fibres and those near them (detection_view.py), and the
ranks agree on the zone numbers (:meth:`FibreContact._number_zones`):

- ``prepare`` (start of a step attempt, at the last converged state):
  retune the zone penalties for this step (between steps: no Newton solve
  is added), find proximity zones, build the contact elements on their
  intermediate geometries, carry history (normal orientation, zone penalty,
  friction stick point) over from the elements of the previous pass;
- Newton (the solver's SNES) with elements, particles, normals and
  penalties fixed;
- ``update`` (after each converged Newton): re-detect and re-normal; ask
  for another Newton if the contact forces changed beyond tolerance, or if
  a zone penetrates beyond the band (emergency retune, counted);
- ``commit`` (step accepted): friction return mapping (stick points).

Modes (``configure``, e.g. from a :class:`textile.Stage`): ``"ordinary"``
(the default) and ``"weaving"`` (docs/method.md §6.2): elements between
fibres of two yarns with a crossing order take the vertical as normal,
oriented by that order (``weaving_order.h``; build the order of a fabric
with :func:`textile.effects.weaving_contact.weaving_mode`). When the mode
changes, the next step sets every normal from the geometry (or the order)
again; zone penalties and stick points carry over.

Units: lengths in the model's unit. Penalties are per unit length of
contact (force/length^2): a line contact of penetration p carries
k_c phi(p) per unit length, whatever the element spacing; a crossing stands
for the equivalent length r_i + r_j (``contact_set.h`` states this once for
the C++ side). Sign conventions as in ``contact_element.h``: the normal
points from fibre j to fibre i, gap < 0 when they interpenetrate.
"""
from __future__ import annotations

import dataclasses

import math
import numbers
import time
from dataclasses import dataclass

import numpy as np
from mpi4py import MPI

from .. import _cpp
from ..options import Options
from .base import Effect, State, stage_ended
from .detection_view import DetectionView


@dataclass(frozen=True)
class ContactOptions(Options):
    """Parameters of fibre-fibre contact (unknown names raise ValueError).

    Attributes
    ----------
    search_factor:
        Proximity criterion delta = search_factor * (r_i + r_j) between centre lines.
    spacing:
        Distance between contact elements along an intermediate geometry
        (length); default half the smallest reference element length. It
        sets how finely a line contact is sampled, not its stiffness.
    regularization:
        g_r = regularization * min(r_i, r_j) (regularization depth).
    target_penetration:
        Target of a zone's largest penetration, in units of g_r.
    penalty:
        Initial penalty k_c of a zone, per unit length of contact: force per
        unit length per unit penetration (force/length^2, a pressure). A
        line contact of penetration p carries k_c phi(p) per unit length
        (phi(p) = p^2 / (2 g_r) below g_r, p - g_r / 2 beyond), whatever the
        spacing; a crossing's single element stands for the length
        r_i + r_j (stiffness k_c (r_i + r_j)). Default: young / 8 (the
        smallest Young's modulus), the order of the elastic stiffness per
        length of two round fibres pressed side by side (2D Hertz:
        pi E* / (2 ln(...)), about E / 8 to E / 4).
    adapt_penalty:
        Re-tune each zone's penalty towards the target penetration: between
        steps for zones outside penalty_band (no Newton solve added), within
        a step only for a zone beyond the band's top (an emergency: one more
        Newton solve, counted in the statistics as ``emergency_retunes``).
    penalty_band:
        (low, high), in units of the target: zones below low * target are
        softened and zones above 3/4 high * target stiffened between steps;
        above high * target, in the step. Zones inside keep their penalty.
    max_penalty_change:
        Bound on the factor by which a zone's penalty changes in one retune.
    penalty_range:
        (low, high) bounds of an adapted penalty, relative to the initial one.
    parallel_angle:
        Angle (degrees) below which two fibres are treated as parallel
        (line contacts; above it, point crossings). 20: the fibres of a
        bundle, rearranged in a weave, cross each other at 10-20 degrees, and
        as point crossings their relocation from pass to pass ran away into
        deeper overlaps (a 3 x 3 bundle weave stopped at 10 degrees,
        tests/weave/test_close_bundles.py).
    friction:
        Coulomb coefficient mu between fibres (of different yarns when the
        contact knows the fibres' yarns, FibreContact ``fibre_yarn``; 0:
        frictionless, no friction history kept).
    yarn_friction:
        Coulomb coefficient between two fibres of one yarn, for every yarn
        (None: each yarn's own, ``Yarn.friction``, given to FibreContact
        with ``fibre_yarn``; without yarns, ``friction``).
    reversible_slip:
        u_T,rev as a fraction of the smallest radius.
    self_contact:
        Look for contact of a fibre with distant parts of itself.
    tangent_floor:
        First-contact safeguard (stability issue item 5): the n-th tangent
        (n = 0, 1, ...) of a load-step attempt's first Newton solve keeps
        at least tangent_floor x 0.1^n times the penalty for contact
        elements closed by less than
        g_r (the law's quadratic part, whose stiffness vanishes at gap = 0)
        or open by less than g_r. A fibre pushed by a dead force onto
        another it just touches then moves by about the linear law's
        penetration in Newton's first iterate, not as far as the rest of the
        structure lets it (a residual of 1e13 after 3e-3). The floor fades
        within a few iterations (quadratic convergence again); the residual
        is the law's, so the converged answer does not change. The solves
        after a contact update start near the contacts it found and have no
        floor (with it, the weave's capped contact passes converge only
        linearly: benchmarks/README.md, "Matrix rebuilds as compressed rows,
        and the contact loop's last passes"). 0: off.
    crossing_patch:
        How far a crossing's contact point may move within one Newton solve
        (docs/method.md §4.2, *facing*): 2 (default) over its element and the
        neighbour across the nearer node, so it passes a node smoothly; 1
        over its own element (the next detection pass moves it on). A
        crossing then couples 3 nodes a side instead of 5: on fabrics of
        wide flat yarns, where each crossing couples every fibre of one yarn
        with every fibre of the other, the tangent has about half the
        entries and its factorization costs about a quarter (measured in
        benchmarks/README.md, "Crossing patches").
    update_tolerance:
        After a converged Newton, the elements are re-detected and re-normaled
        at the new state; another Newton is run when the contact forces of the
        new set differ from the old set's, at that state, by more than this
        fraction of their norm (loops 1-2 of docs/method.md §9.2); math.inf:
        the loop lags (:meth:`FibreContact.configure`; its states are not
        answers).
    """

    search_factor: float = 2.0
    spacing: float | None = None
    regularization: float = 0.02
    target_penetration: float = 2.0
    penalty: float | None = None
    adapt_penalty: bool = True
    penalty_band: tuple = (0.5, 2.0)
    max_penalty_change: float = 4.0
    penalty_range: tuple = (1e-3, 1e3)
    parallel_angle: float = 20.0
    friction: float = 0.0
    yarn_friction: float | None = None
    reversible_slip: float = 0.01
    self_contact: bool = True
    tangent_floor: float = 1.0
    update_tolerance: float = 1e-3
    crossing_patch: int = 2

    kind = "contact"

    def __post_init__(self):
        # every value checked for its type too: a string, a bool for a
        # number (True == 1) or a number for a bool would pass the C++
        # conversion or a comparison silently, or fail there unnamed
        self.require_positive("search_factor", "regularization", "target_penetration",
                              "reversible_slip", "max_penalty_change")
        v = self.update_tolerance
        if not _is_loop_tolerance(v):
            raise ValueError(f"ContactOptions.update_tolerance must be a positive number or "
                             f"math.inf, got {v!r}")
        for name in ("spacing", "penalty"):
            v = getattr(self, name)
            if v is not None and not (_real(v) and 0 < v < math.inf):
                raise ValueError(f"ContactOptions.{name} must be positive (a finite number > 0) "
                                 f"or None (the default), got {v!r}")
        for name in ("adapt_penalty", "self_contact"):
            v = getattr(self, name)
            if not isinstance(v, bool):
                raise ValueError(f"ContactOptions.{name} must be True or False, got {v!r}")
        if not (_real(self.friction) and 0 <= self.friction < 10):
            raise ValueError(f"ContactOptions.friction must be in [0, 10), got {self.friction!r}")
        if not (_real(self.parallel_angle) and 0 < self.parallel_angle < 90):
            raise ValueError(f"ContactOptions.parallel_angle must be in (0, 90) degrees, got "
                             f"{self.parallel_angle!r}")
        lo, hi = _pair(self, "penalty_range", "0 < low <= 1 <= high")
        if not 0 < lo <= 1 <= hi:
            raise ValueError(f"ContactOptions.penalty_range must be (low, high) with "
                             f"0 < low <= 1 <= high, got {self.penalty_range!r}")
        lo, hi = _pair(self, "penalty_band", "0 < low <= 1 <= 3/4 high")
        if not 0 < lo <= 1 <= 0.75 * hi:
            raise ValueError(f"ContactOptions.penalty_band must be (low, high) with "
                             f"0 < low <= 1 <= 3/4 high, got {self.penalty_band!r}")
        if self.crossing_patch not in (1, 2) or isinstance(self.crossing_patch, bool):
            raise ValueError(f"ContactOptions.crossing_patch must be 1 or 2 (elements), got "
                             f"{self.crossing_patch!r}")
        if not (_real(self.tangent_floor) and 0 <= self.tangent_floor <= 1):
            raise ValueError(f"ContactOptions.tangent_floor must be in [0, 1], got "
                             f"{self.tangent_floor!r}")
        if self.max_penalty_change < 1:
            raise ValueError(f"ContactOptions.max_penalty_change must be >= 1, got "
                             f"{self.max_penalty_change!r}")
        v = self.yarn_friction
        if v is not None and not (_real(v) and 0 <= v < 10):
            raise ValueError(f"ContactOptions.yarn_friction must be in [0, 10) or None, got {v!r}")


def _real(v) -> bool:
    """A finite real number that is not a bool."""
    return not isinstance(v, bool) and isinstance(v, numbers.Real) and math.isfinite(v)


def _is_loop_tolerance(v) -> bool:
    """Is ``v`` a contact loop's tolerance: a number > 0, or math.inf (a
    loop that lags, FibreContact.configure)?"""
    return (_real(v) or v == math.inf) and v > 0


def _loop_tolerance(v) -> float:
    """The stage option update_tolerance's value (_is_loop_tolerance), or a
    ValueError."""
    if not _is_loop_tolerance(v):
        raise ValueError(f"FibreContact: update_tolerance must be a number > 0 or math.inf (or "
                         f"a callable of the stage's load factor giving one), got {v!r}")
    return float(v)


def _pair(options, name: str, expected: str) -> tuple[float, float]:
    """The two finite numbers of the (low, high) option ``name``, or a
    ValueError naming it."""
    v = getattr(options, name)
    if not (isinstance(v, (tuple, list)) and len(v) == 2 and all(_real(x) for x in v)):
        raise ValueError(f"ContactOptions.{name} must be a pair of finite numbers (low, high) "
                         f"with {expected}, got {v!r}")
    return v[0], v[1]


def _friction_groups(o: ContactOptions, fibre_yarn, yarn_friction):
    """(each fibre's yarn or None, each yarn's friction coefficient)."""
    if fibre_yarn is None:
        if yarn_friction is not None:
            raise ValueError("FibreContact: yarn_friction needs fibre_yarn (each fibre's yarn)")
        return None, np.zeros(0)
    groups = np.asarray(fibre_yarn)
    if groups.ndim != 1 or groups.dtype.kind not in "iu" or (groups.size and groups.min() < -1):
        raise ValueError("FibreContact: fibre_yarn must hold one yarn index (>= 0, or -1 for "
                         "none) per fibre")
    num_yarns = int(groups.max(initial=-1)) + 1
    if o.yarn_friction is not None:
        mu = np.full(num_yarns, float(o.yarn_friction))
    elif yarn_friction is not None:
        mu = np.array(yarn_friction, dtype=float)
        if mu.shape != (num_yarns,) or not np.all(np.isnan(mu) | ((mu >= 0) & (mu < 10))):
            raise ValueError(f"FibreContact: yarn_friction must hold one coefficient in [0, 10) "
                             f"(or NaN: friction) per yarn ({num_yarns}), got {yarn_friction!r}")
        mu[np.isnan(mu)] = o.friction
    else:
        mu = np.full(num_yarns, float(o.friction))
    return groups.astype(np.intc), mu


#: Factor by which the tangent floor decays from one Newton iteration to the
#: next (ContactOptions.tangent_floor). Measured on a fibre pressed by dead
#: forces onto another it touches (tests/contact/test_first_contact.py): 0.1
#: needs the fewest iterations; a floor kept for the first iteration only
#: lets the second explode, a slower decay (0.3, 0.5) converges slowly.
FLOOR_DECAY = 0.1


def _reduce(comm, values: np.ndarray, op) -> np.ndarray:
    """Element-wise reduction of an array (per zone, per unknown) over all ranks."""
    values = np.ascontiguousarray(values)
    if comm.size > 1:
        comm.Allreduce(MPI.IN_PLACE, values, op=op)
    return values


class FibreContact(Effect):
    """Contact (and optionally friction) between all fibres of a model."""

    fields = ("beam",)
    dynamic_sparsity = True
    smooth_path = False

    @property
    def symmetric_tangent(self) -> bool:
        """Frictionless contact derives from a potential at fixed normals:
        symmetric without friction coefficients, or in a stage with friction
        switched off (the solver chooses the factorization at each stage's
        start)."""
        return not (self.has_friction and self._friction_on)

    @property
    def yarn_friction(self) -> np.ndarray | None:
        """Each yarn's coefficient between its own fibres (None: the
        contact was not given the fibres' yarns)."""
        return None if self._fibre_groups is None else self._yarn_mu.copy()

    @property
    def has_friction(self) -> bool:
        """Some pair of fibres has friction (between or within yarns), in
        the stages where friction is on."""
        return self.options.friction > 0 or bool(np.any(self._yarn_mu > 0))

    @property
    def friction_on(self) -> bool:
        """The current stage's ``friction`` switch (True unless a stage set
        it False): off, every pair is frictionless and no contact element
        has a friction law or history (a stick point to follow)."""
        return self._friction_on

    def _mu(self) -> float:
        """The coefficient between yarns (or of every pair) in this stage."""
        return self.options.friction if self._friction_on else 0.0

    MODES = ("ordinary", "weaving", "within_yarns")

    def __init__(self, options: ContactOptions | dict | None = None, fibre_yarn=None,
                 yarn_friction=None):
        """``fibre_yarn``: each fibre's yarn (model fibre order; -1: none),
        so that fibres of one yarn take their yarn's friction coefficient,
        ``yarn_friction[yarn]`` (NaN: ContactOptions.friction;
        ContactOptions.yarn_friction overrides them all)."""
        if not (options is None or isinstance(options, (ContactOptions, dict))):
            raise TypeError(f"FibreContact: options must be a ContactOptions, a dict of contact "
                            f"options or None (the defaults), got {options!r}")
        self.options = options if isinstance(options, ContactOptions) \
            else ContactOptions.from_dict(options)
        self._fibre_groups, self._yarn_mu = _friction_groups(self.options, fibre_yarn,
                                                             yarn_friction)
        self.set = None
        self._committed = None
        self.mode = "ordinary"
        self._order = None           # _cpp.WeavingOrder of the weaving mode
        self._weaving = None         # its arrays (saved states)
        self._reset_normals = False  # the mode changed: normals from the geometry again
        self._fibre_yarn = self._yarn_above = None
        self._woven = None           # the order of a woven fabric, after its weaving stage
        self._woven_arrays = None    # ... as fibre_yarn and yarn_above (saved states)
        self._weaving_done = False   # the weaving stage reached its end (depths made up)
        self._friction_on = True     # the stage option friction
        self._make_up = False        # the stage option make_up_penetrations
        self._make_up_reference = None  # ... its stage's starting positions
        self._tolerance_schedule = None  # the stage option update_tolerance, a callable of s

    # -- stage options ---------------------------------------------------------
    def configure(self, mode: str | None = None, fibre_yarn=None, yarn_above=None,
                  friction: bool | None = None, make_up_penetrations: bool | None = None,
                  update_tolerance=None, **unknown) -> None:
        """Stage options: ``mode="ordinary"``, or ``mode="weaving"`` with
        ``fibre_yarn`` (yarn of each fibre, in the model's fibre order) and
        ``yarn_above`` ((yarns, yarns): +1 if yarn a lies above yarn b at
        their crossing, -1 below, 0 no order; antisymmetric). In weaving
        mode a contact element between fibres of two ordered yarns has the
        normal sign * e_z (from fibre j to fibre i), so a fibre of the upper
        yarn below one of the lower yarn has a negative gap wherever it is.
        ``mode="within_yarns"`` (same arrays): fibres of two ordered yarns
        get no contact at all, they pass through each other (while
        :class:`~textile.effects.heddles.Heddles` lift the yarns apart);
        contacts within a yarn and between parallel yarns are ordinary.

        The yarns' interpenetration in the reference (straight, coplanar)
        state is made up progressively over the stage: an ordered element's
        gap is shifted by (1 - s) times its pair's reference penetration at
        stage progress s (``ContactSet.set_depth_scale``), so each load step
        pushes the yarns apart by its share, and a cut step pushes less.

        ``friction=False``: the stage is frictionless (every pair, whatever
        the coefficients): its contact elements get no friction law and no
        history; ``friction=True`` turns the contact's coefficients back on,
        every contact sticking where it is (``reset_friction``). None (or
        not given): as in the previous stage. Only ``friction`` given:
        the mode stays as it is.

        ``make_up_penetrations=True`` (ordinary mode, this stage only): the
        penetrations the contact elements find at the stage's start are
        made up over the stage as the weaving stage makes up the yarns'
        interpenetration: an element's gap is shifted by (1 - s) times its
        penetration in the stage's starting state (evaluated there with the
        element's particles and normal). The stage's end (s = 1) is the
        structure's equilibrium. What it is for: after the weaving stage,
        ordinary contact measures gaps where the ordered one did not (fibres
        bent around each other at a crossing: 0.44 R found at once), and the
        relaxation would take that jump in one step.

        ``update_tolerance`` (a number > 0, or a callable of the stage's
        load factor s giving one): the contact loop's tolerance
        (``ContactOptions.update_tolerance``) from this stage on; a stage
        whose path is artificial (the lifting weave's settling, its drag's
        fading before the last step) may take a looser one than the states
        that are answers. ``math.inf``: the loop *lags*: a step is accepted
        after its first converged Newton solve unless contact forces appear
        where there were none or fibres crossed; the elements, normals and
        penalties that update found act from the next step, and penalties
        are retuned within the step only where fibres crossed. A lagged
        step's state is not an answer (a zone pressed beyond its target
        penetration is retuned only at the next step; tests/contact/
        test_tunnelling.py): end with a finite tolerance (Weaving's fading
        does at its last step). A callable is
        evaluated at each update, at the
        load factor of the step being solved; the stages after its own go
        on with its value at s = 1."""
        if unknown:
            raise ValueError(f"FibreContact.configure: unknown option(s) {sorted(unknown)}; "
                             f"allowed: mode, fibre_yarn, yarn_above, friction, "
                             f"make_up_penetrations, update_tolerance")
        if callable(update_tolerance):
            for s in (0.0, 1.0):    # a bad schedule named now, not mid-run
                _loop_tolerance(update_tolerance(s))
            self._tolerance_schedule = update_tolerance
        elif update_tolerance is not None:
            # a copy: the options a user passed stay theirs
            self.options = dataclasses.replace(
                self.options, update_tolerance=_loop_tolerance(update_tolerance))
            self._tolerance_schedule = None
        if friction is not None and not isinstance(friction, (bool, np.bool_)):
            raise ValueError(f"FibreContact: friction must be True or False, got {friction!r}")
        if make_up_penetrations is not None:
            if not isinstance(make_up_penetrations, (bool, np.bool_)):
                raise ValueError(f"FibreContact: make_up_penetrations must be True or False, "
                                 f"got {make_up_penetrations!r}")
            if make_up_penetrations and mode == "weaving":
                raise ValueError("FibreContact: make_up_penetrations goes with the ordinary "
                                 "mode (the weaving mode makes up its own)")
        self._make_up, self._make_up_reference = bool(make_up_penetrations), None
        if mode is None and fibre_yarn is None and yarn_above is None:
            self._switch_friction(friction)   # only friction (or tolerances) given
            return
        mode = self.mode if mode is None else mode
        if mode not in self.MODES:
            raise ValueError(f"FibreContact: mode must be one of {self.MODES}, got {mode!r}")
        if mode in ("weaving", "within_yarns"):
            if fibre_yarn is None or yarn_above is None:
                raise ValueError(f"FibreContact: mode={mode!r} needs fibre_yarn and yarn_above "
                                 f"(textile.effects.weaving_contact.weaving_mode(fabric))")
            self._order = _cpp.WeavingOrder(np.asarray(fibre_yarn, dtype=np.intc),
                                            np.asarray(yarn_above, dtype=np.int8),
                                            pass_through=mode == "within_yarns")
            self._fibre_yarn = np.asarray(fibre_yarn, dtype=np.intc)
            self._yarn_above = np.asarray(yarn_above, dtype=np.int8)
            self._weaving_done = False
            self._weaving = dict(fibre_yarn=np.asarray(fibre_yarn, dtype=np.int64),
                                 yarn_above=np.asarray(yarn_above, dtype=np.int8))
            self._check_order()
        elif fibre_yarn is not None or yarn_above is not None:
            raise ValueError("FibreContact: fibre_yarn and yarn_above go with mode='weaving' "
                             "or 'within_yarns'")
        else:
            if self.mode in ("weaving", "within_yarns"):
                # the fabric's yarns stay bent around each other
                self._woven, self._woven_arrays = self._order, self._weaving
            self._order = self._weaving = None
        if mode != self.mode:
            self._reset_normals = True
        self.mode = mode
        self._switch_friction(friction)

    def _switch_friction(self, on: bool | None) -> None:
        if on is None or bool(on) == self._friction_on:
            return
        self._friction_on = bool(on)
        if self._friction_on and self._committed is not None:
            # the stick points are those of the last stage with friction:
            # start afresh from here
            self.reset_friction(self.model)

    def _check_order(self) -> None:
        model = getattr(self, "model", None)
        if self._order is not None and model is not None \
                and self._order.num_fibres != len(model.mesh.fibres):
            raise ValueError(f"FibreContact: fibre_yarn names {self._order.num_fibres} fibres, "
                             f"the model has {len(model.mesh.fibres)}")

    # -- set-up ------------------------------------------------------------
    def setup(self, model) -> None:
        mesh, o = model.mesh, self.options
        self.model = model
        if self._fibre_groups is not None and len(self._fibre_groups) != len(mesh.fibres):
            raise ValueError(f"FibreContact: fibre_yarn names {len(self._fibre_groups)} "
                             f"fibres, the model has {len(mesh.fibres)}")
        self.radius = np.array([f.radius for f in mesh.fibres])
        young = min(f.material.young for f in mesh.fibres)
        rmin = self.radius.min()
        self.k0 = o.penalty if o.penalty is not None else young / 8
        self.g_r = o.regularization * rmin
        self.u_rev = o.reversible_slip * rmin
        # contact elements about two per fibre element, consistent with the mesh
        element_length = min(f.length / ((f.num_nodes - 1) // mesh.order) for f in mesh.fibres)
        self.spacing = o.spacing if o.spacing is not None else 0.5 * element_length
        # a fibre's own neighbourhood is never "in contact" with itself
        self.self_exclusion = (4 * o.search_factor * 2 * self.radius.max() + 2 * self.spacing
                               if o.self_contact else math.inf)
        low, high = o.penalty_band
        self.adaptation = _cpp.PenaltyAdaptation(
            target=o.target_penetration * self.g_r, regularization=self.g_r, band_low=low,
            retune_high=0.75 * high, band_high=high, max_change=o.max_penalty_change,
            k_min=o.penalty_range[0] * self.k0, k_max=o.penalty_range[1] * self.k0)
        self.set = _cpp.ContactSet()
        self._committed = self.set.copy()
        # the pairs of fibre elements the system matrix has room for; the
        # first pass always rebuilds the matrix (the base one refuses new
        # entries), later ones only for new couplings
        self.coverage = _cpp.CouplingPattern()
        self._committed_coverage = self.coverage.copy()
        self._matrix_has_contact = False
        # the matrix pattern holds the elements whose tangent may be
        # non-zero: closed, or open by less than g_r (tangent_floor); one
        # closing within Newton gets a rebuilt matrix (Newton._converged),
        # kept until the next converged state. A wider margin (0.5 R)
        # preallocated open neighbours: 45% of a bundle weave's stored
        # entries were zero and its factorizations did 2.7 times the work
        # (benchmarks/README.md, "A contact pattern of the contacts that
        # carry force")
        self.pattern_margin = self.g_r
        self.stats = {}
        self._timing = dict(kernel=0.0, total=0.0, kernel_calls=0, off_rank_sent=0,
                            off_rank_stashed=0, history_bytes_received=0,
                            gathered_values=0, evaluations=0, zone_keys_received=0,
                            detection_passes=0, detection_seconds=0.0)
        self.updates = 0
        self.emergency_retunes = 0
        self.retuned_zones = 0
        self.penalty_conversions = 0
        self.held_contacts = 0
        self._first_solve = False  # the attempt's first Newton solve follows (tangent_floor)
        self._change = 0.0  # the last update's (update_change)
        self._node_gather, self._node_gather_set = None, None   # (_positions)
        self._view = None   # on several ranks, at the first pass (_pass_positions)
        self._check_order()

    # -- detection and history -----------------------------------------------
    def _detect(self, q: np.ndarray, held: dict | None = None,
                zones: np.ndarray | None = None, keep_kinds: bool = False,
                present: np.ndarray | None = None):
        mesh = self.model.mesh
        return _cpp.detect_contacts(q, mesh.first_node, mesh.order, self.radius,
                                    self.options.search_factor, self.self_exclusion,
                                    self.spacing, math.radians(self.options.parallel_angle),
                                    held, self._order,
                                    np.zeros((0, 5)) if zones is None else zones,
                                    keep_kinds, present)

    def _pass_positions(self, state: State, old, history) -> tuple[np.ndarray, dict, object]:
        """q for a detection pass (on several ranks: the fibres this rank
        detects among, NaN elsewhere, see detection_view.py), the held
        contacts of every rank, and which fibres q holds (None: all).
        ``old`` is evaluated at q."""
        comm = self.model.comm
        if comm.size == 1:
            q = self.model.beam_positions(state)
            old.evaluate(q)
            return q, self._contacts_to_hold(q), None
        if self._view is None:
            self._view = DetectionView(self.model, self.radius, self.options.search_factor)
        view, x = self._view, state.vector
        fibre_of_node = view.fibre_of_node
        # its last elements (evaluated here) and the history handed to it:
        # the zones they match into are found here, as on one rank
        extra = np.unique(fibre_of_node[history.nodes()])
        present = view.present(x, extra)
        q = view.positions(x, present)
        old.evaluate(q)
        held = self._contacts_to_hold(q)
        # a held contact on a fibre of this rank's: both its fibres
        own = np.zeros_like(present)
        own[view.own_fibres] = True
        touching = own[held["fibre_i"]] | own[held["fibre_j"]]
        more = np.zeros_like(present)
        more[held["fibre_i"][touching]] = more[held["fibre_j"][touching]] = True
        more &= ~present
        if comm.allreduce(bool(more.any()), op=MPI.LOR):   # a new scatter: collective
            present |= more
            q = view.positions(x, present)
        return q, held, present

    def _number_zones(self, found, present: np.ndarray) -> None:
        """Zone numbers every rank agrees on, for one rank's detection
        among the fibres it holds (``present``). A zone between two fibres
        that several ranks hold is found by each of them alike (the same
        fibres, whole, give the same zone, bit for bit): these *shared*
        zones are numbered last, by their keys (Detection.zone_keys), which
        the ranks exchange. Every other zone is found by one rank only and
        takes a number in that rank's block. What travels is the fibres
        each rank holds (a bit a fibre) and the shared zones' keys, not
        every zone."""
        comm = self.model.comm
        keys = found.zone_keys()
        bits = comm.allgather(np.packbits(present))
        held_by = np.unpackbits(np.vstack(bits), axis=1, count=len(present)).astype(bool)
        fibre_i, fibre_j = keys[:, 0].astype(np.int64), keys[:, 1].astype(np.int64)
        shared = np.count_nonzero(held_by[:, fibre_i] & held_by[:, fibre_j], axis=0) > 1
        parts = comm.allgather((int(np.count_nonzero(~shared)), keys[shared]))
        counts = [p[0] for p in parts]
        self._timing["zone_keys_received"] += sum(len(p[1]) for p in parts) - int(shared.sum())
        own_block, start = sum(counts), sum(counts[:comm.rank])
        number = np.empty(len(keys), dtype=np.intc)
        number[~shared] = start + np.arange(counts[comm.rank], dtype=np.intc)
        offsets = np.cumsum([0] + [len(p[1]) for p in parts])
        unique, inverse = np.unique(np.vstack([p[1] for p in parts]).reshape(-1, 9), axis=0,
                                    return_inverse=True)
        inverse = inverse.reshape(-1)[offsets[comm.rank]:offsets[comm.rank + 1]]
        number[shared] = own_block + inverse
        found.renumber_zones(number, own_block + len(unique))

    def _friction_args(self) -> dict:
        """The fibres' yarns and the yarns' coefficients (ContactSet.next),
        zero in a stage with friction off."""
        if self._fibre_groups is None:
            return {}
        return dict(group=self._fibre_groups,
                    group_mu=self._yarn_mu if self._friction_on else np.zeros_like(self._yarn_mu))

    def _contacts_to_hold(self, q: np.ndarray) -> dict:
        """The closed elements of every rank (at the set's last evaluation)
        that the next detection might lose (``held_contact.h``): each rank
        gets all of them, in rank order (a held contact's place in this list
        is part of its zone's key), and keeps those between fibres it holds."""
        mesh, comm = self.model.mesh, self.model.comm
        mine = self.set.contacts_to_hold(q, mesh.first_node, mesh.order, self.radius,
                                         self.options.search_factor)
        if comm.size == 1:
            return mine
        parts = comm.allgather(mine)
        return {k: np.concatenate([p[k] for p in parts]) for k in mine}

    def _zone_marks(self) -> np.ndarray:
        """One element of each zone of the last pass and its kind, from
        every rank: the hysteresis of the wrap and crossing criteria
        (detection.h)."""
        mine = self.set.zone_marks()
        comm = self.model.comm
        return mine if comm.size == 1 else np.concatenate(comm.allgather(mine))

    def _history(self, old):
        """``old`` plus the other ranks' elements whose successor this rank
        may evaluate (history_handover.h): the history a new pass inherits
        from. One exchange between ranks per detection pass."""
        mesh, comm = self.model.mesh, self.model.comm
        if comm.size == 1:
            return old
        parts = comm.alltoall(old.handover(mesh.node_owner, mesh.rank, mesh.first_node,
                                           mesh.order, comm.size))
        received = [p for p in parts if p]
        self._timing["history_bytes_received"] += sum(len(p) for p in received)
        return old.with_history(received) if received else old

    def _replace_set(self, new) -> None:
        for k, v in self.set.timing().items():
            self._timing[k] += v
        self.set = new

    def _rebuild(self, state: State, reset_normals: bool = False,
                 persist: bool = False) -> bool:
        """Detect, carry history, set normals and zone penalties; True if
        the contact forces at the state changed beyond update_tolerance.
        ``persist`` (the passes within a step): zones keep their kind
        (detection.h, keep_kinds) and line contacts found again keep their
        elements (ElementParameters::persist in history_transfer.h)."""
        self._timing["detection_passes"] += 1
        start = time.perf_counter()
        try:
            return self._pass(state, reset_normals, persist)
        finally:
            self._timing["detection_seconds"] += time.perf_counter() - start

    def _pass(self, state: State, reset_normals: bool, persist: bool) -> bool:
        o, mesh, comm = self.options, self.model.mesh, self.model.comm
        old = self.set
        history = self._history(old)
        # old evaluated there: elastic slips, zone forces and held contacts
        q, held, present = self._pass_positions(state, old, history)
        found = self._detect(q, held, self._zone_marks(), persist, present)
        if present is not None:
            self._number_zones(found, present)
        self.held_contacts += found.held
        before = old.nodal_forces(q)
        new, inherited = history.next(
            found, q, mesh.first_node, mesh.order, self.radius, self.k0, self.g_r, self._mu(),
            self.u_rev, math.radians(o.parallel_angle), mesh.node_owner, mesh.rank, self._order,
            reset_normals, self._woven, persist, **self._friction_args(),
            crossing_patch=o.crossing_patch)
        self._set_depths(new)
        self._carry_zone_penalties(new, old, inherited, q)
        new.evaluate(q)
        new.take_layout(old)  # usually the same nodes: no new assembly layout
        self._replace_set(new)
        # a coupling the matrix was not preallocated for: ask for a new one
        if not self._matrix_has_contact or not self.coverage.covers(new, self.pattern_margin):
            self.coverage.add(new, self.pattern_margin)
            self._matrix_has_contact = True
            self.model.request_matrix_rebuild()
        # what matters is what the elements do to the fibres at this state
        # (summed over the ranks first: an element that moved to another
        # rank changes both ranks' forces, not the fibres')
        after = new.nodal_forces(q)
        change, before = _reduce(comm, after - before, MPI.SUM), _reduce(comm, before, MPI.SUM)
        diff, size = float(np.sum(change ** 2)), float(np.sum(before ** 2))
        # the change relative to the forces, in units of the tolerance
        # (contacts appearing where there was no force: infinitely large)
        self._change = (math.sqrt(diff / size) / self.update_tolerance() if size > 0 else
                        (math.inf if diff > 0 else 0.0))
        return self._change > 1.0

    def _depth_scale(self) -> float:
        """1 - s during the weaving stage and a stage that makes up its
        starting penetrations (s: its load factor), else 0."""
        if (self.mode != "weaving" or self._weaving_done) and self._make_up_reference is None:
            return 0.0
        return float(np.clip(1.0 - self.model.load_factor, 0.0, 1.0))

    def _set_depths(self, new) -> None:
        """Weaving: each element between ordered yarns takes its pair's
        penetration in the reference state (evaluated there, with the
        element's particles and normal) as the depth to make up."""
        if self._depth_scale() == 0.0 or new.size == 0:
            new.set_depth_scale(0.0)
            return
        new.set_depth_scale(0.0)
        if self._make_up_reference is not None:
            # every element: its penetration where the stage started, beyond
            # the depth the penalty law works at (what it held the fabric by)
            new.evaluate(self._make_up_reference)
            new.set_depths(np.maximum(-new.data()["gap"] - self.adaptation.target, 0.0))
            new.set_depth_scale(self._depth_scale())
            return
        new.evaluate(self.model.mesh.X_global.ravel())
        d = new.data()
        yarn = self._fibre_yarn
        ordered = self._yarn_above[yarn[d["fibre_i"]], yarn[d["fibre_j"]]] != 0
        new.set_depths(np.where(ordered, np.maximum(-d["gap"], 0.0), 0.0))
        new.set_depth_scale(self._depth_scale())

    def _carry_zone_penalties(self, new, old, inherited: dict, q: np.ndarray) -> None:
        """One penalty per zone of the new pass: the largest of the elements
        it inherits from (penalties never soften by re-detection), k0 for a
        new zone. A zone that changed kind (crossing <-> line contact) has
        its penalty scaled so that its force at q is the old zone's: the
        same penalty per length gives different forces to one element of
        equivalent length and to a line of elements (R_N is linear in k)."""
        comm = self.model.comm
        k = _reduce(comm, inherited["penalty"], MPI.MAX)
        k = np.where(k > 0, k, self.k0)
        new.set_zone_penalties(k)
        changed = _reduce(comm, inherited["changed_kind"], MPI.MAX) > 0
        if not np.any(changed):
            return
        lo = _reduce(comm, inherited["previous_zone_min"], MPI.MIN)
        hi = _reduce(comm, inherited["previous_zone_max"], MPI.MAX)
        f_old = _reduce(comm, old.zone_force(), MPI.SUM)
        new.evaluate(q)
        f_new = _reduce(comm, new.zone_force(), MPI.SUM)
        previous = np.where(changed & (lo == hi) & (hi >= 0), hi, -1)
        convert = (previous >= 0) & (f_new > 0)
        convert[convert] &= f_old[previous[convert]] > 0
        k[convert] *= f_old[previous[convert]] / f_new[convert]
        new.set_zone_penalties(k)
        self.penalty_conversions += int(convert.sum())

    def add_dynamic_pattern(self, model, pattern) -> None:
        self.coverage.insert(pattern, model.beam_global_dofs())

    def _zone_state(self) -> tuple[np.ndarray, np.ndarray]:
        """(penalty, largest penetration) of every zone, over all ranks."""
        comm = self.model.comm
        return (_reduce(comm, self.set.zone_penalty(), MPI.MAX),
                _reduce(comm, self.set.zone_max_penetration(), MPI.MAX))

    def _retune(self, in_step: bool, zones: np.ndarray | None = None) -> int:
        """Apply the penalty rule (see PenaltyAdaptation in C++) to every
        zone (or to those where ``zones`` is True) at the set's last
        evaluation; the number of zones changed."""
        if not self.options.adapt_penalty or self.set.num_zones == 0:
            return 0
        k, p = self._zone_state()
        rule = self.adaptation.in_step if in_step else self.adaptation.between_steps
        new = rule(k, p)
        if zones is not None:
            new = np.where(zones, new, k)
        changed = int(np.count_nonzero(new != k))
        if changed:
            self.set.set_zone_penalties(new)
        return changed

    # -- load-step protocol ----------------------------------------------------
    def prepare(self, model) -> None:
        # the set holds the last converged state's evaluation: retune for
        # this step there, then re-detect
        self.retuned_zones = self._retune(in_step=False)
        self.updates = 0
        self.emergency_retunes = 0
        self.penalty_conversions = 0
        state = model.state()
        if self._make_up and self._make_up_reference is None:
            # the stage's start, whole: its elements are not yet known
            self._make_up_reference = model.beam_positions(state).copy()
        self.set.set_depth_scale(self._depth_scale())
        self.held_contacts = 0
        # after a mode change, every attempt's first pass sets normals anew
        self._rebuild(state, reset_normals=self._reset_normals)
        self._first_solve = True

    def _check_crossed(self) -> np.ndarray:
        """After a converged Newton solve, at the set's evaluation: fibres
        whose centre lines lie on the wrong side of each other along the
        normal have passed through each other. Their zone's penalty is
        raised by the in-step retune when it can be; when it cannot
        (adapt_penalty off, or at the top of penalty_range), the state is
        refused: GeometryError, the step is cut. Returns, per zone, whether
        its fibres crossed."""
        comm = self.model.comm
        crossed = _reduce(comm, self.set.zone_crossed(), MPI.SUM) > 0
        if not np.any(crossed):
            return crossed
        k, _ = self._zone_state()
        stuck = crossed & ~(self.options.adapt_penalty
                            & (k < self.adaptation.k_max * (1 - 1e-12)))
        if not np.any(stuck):
            return crossed
        d = self.set.data()
        mine = np.flatnonzero(stuck[d["zone"]] & (d["separation"] < 0)) \
            if len(d["zone"]) else np.zeros(0, dtype=int)
        words = ""
        if len(mine):
            e = mine[np.argmin(d["separation"][mine])]
            i, j = d["fibre_i"][e], d["fibre_j"][e]
            words = (f"fibres {i} and {j} have passed through each other (centre lines "
                     f"{-d['separation'][e] / self.radius[[i, j]].min():.3g} radii past each "
                     f"other along the contact normal, at abscissas {d['s_i'][e]:.4g} and "
                     f"{d['s_j'][e]:.4g})")
        words = "; ".join(w for w in comm.allgather(words) if w)
        why = "adapt_penalty is off" if not self.options.adapt_penalty else \
            "their penalty is at the top of penalty_range"
        raise _cpp.GeometryError(f"{words}, and {why}: the contact cannot push them back "
                                 f"(a stiffer penalty or smaller steps)")

    def update(self, model) -> bool:
        self.updates += 1
        state = model.state()
        self.set.evaluate(self._positions(state, count=False))
        crossed = self._check_crossed()
        # a loop that lags (update_tolerance inf): within the step, only
        # zones whose fibres crossed are retuned (and solved again)
        lagged = self.update_tolerance() == math.inf
        emergency = self._retune(in_step=True, zones=crossed if lagged else None)
        self.emergency_retunes += emergency
        changed = self._rebuild(state, persist=True) or emergency > 0
        if emergency and not self._change > 1.0:
            self._change = math.inf  # penalties retuned: Newton must run again
        # the solves after an update start from an iterate near the contacts
        # it found: no floor there (ContactOptions.tangent_floor)
        self._first_solve = False
        return changed

    def update_tolerance(self, s: float | None = None) -> float:
        """The contact loop's tolerance at the stage's load factor ``s``
        (default: the model's; the stage option ``update_tolerance``,
        :meth:`configure`)."""
        if self._tolerance_schedule is None:
            return self.options.update_tolerance
        return _loop_tolerance(self._tolerance_schedule(
            self.model.load_factor if s is None else s))

    def configure_resumed(self, update_tolerance=None, **options) -> None:
        """Resumed within a stage: a loop tolerance that is a callable of s
        again (it cannot be saved: the saved value is its value where the
        state was saved); the rest of the stage's options is saved."""
        if callable(update_tolerance):
            self._tolerance_schedule = update_tolerance

    def update_change(self) -> float:
        """The contact forces' change at the last update relative to their
        size, in units of ``update_tolerance`` (inf: new contact forces, or
        penalties retuned)."""
        return self._change

    def commit(self, model) -> None:
        self._reset_normals = False
        ended = stage_ended(model.load_factor)
        if self.mode == "weaving" and ended:
            self._weaving_done = True  # a later weaving stage has nothing to make up
        if self._make_up and ended:
            self._make_up, self._make_up_reference = False, None   # made up
        if self._tolerance_schedule is not None and ended:
            # a schedule of its stage's s: the stages after it go on with
            # its value at the end (unless they set their own)
            self.options = dataclasses.replace(self.options,
                                               update_tolerance=self.update_tolerance(1.0))
            self._tolerance_schedule = None
        self.set.commit()
        self._committed = self.set.copy()
        # couplings that no element comes near at the converged state (the
        # yarns moved on): a matrix without their zero blocks factorizes
        # faster (benchmarks/README.md, "A contact pattern of the contacts
        # that carry force")
        now = _cpp.CouplingPattern()
        now.add(self.set, self.pattern_margin)
        if now.size < self.coverage.size:
            self.coverage = now
            model.request_matrix_rebuild()
        self._committed_coverage = self.coverage.copy()
        self._statistics(model)

    def restore(self, model) -> None:
        self._replace_set(self._committed.copy())
        if self.coverage.size != self._committed_coverage.size:
            # couplings of a failed attempt's iterates (far from any
            # solution, often many): a matrix without them factorizes faster
            self.coverage = self._committed_coverage.copy()
            model.request_matrix_rebuild()

    # -- assembly --------------------------------------------------------------
    def _positions(self, state: State, count: bool = True) -> np.ndarray:
        """Current q of the nodes this rank's elements read (on several
        ranks, NaN at the others): the elements are fixed within a Newton
        solve, so one NodeGather a set moves just their nodes, where
        gathering the whole fibre state cost every rank the whole problem."""
        system = self.model
        if system.comm.size == 1 or state.vector is None:
            return system.beam_positions(state)
        if self._node_gather_set is not self.set:   # a new set: on every rank at once
            if self._node_gather is not None:
                self._node_gather.destroy()
            self._node_gather = system.node_gather(self.set.nodes())
            self._node_gather_set = self.set
        if count:
            self._timing["gathered_values"] += self._node_gather.num_remote
            self._timing["evaluations"] += 1
        return self._node_gather.positions(state.vector)

    def residual_global(self, state: State, b) -> bool:
        q = self._positions(state)
        self.set.set_depth_scale(self._depth_scale())  # the load factor of this evaluation
        # constrained rows too: the model reads them as support reactions
        self.set.assemble_vector(q, self.model.beam_global_dofs(state, constrained=True), b)
        # an element closing, within Newton, on fibre elements the matrix
        # has no room for: Newton rebuilds the matrix before its tangent
        # (Newton._converged), PETSc does not reallocate entry by entry
        if self._matrix_has_contact and not self.coverage.covers(self.set, self.pattern_margin):
            self.coverage.add(self.set, self.pattern_margin)
            self.model.request_matrix_rebuild()
        return True

    def jacobian(self, state: State, A) -> None:
        q = self._positions(state)
        self.set.set_depth_scale(self._depth_scale())
        # the first tangents of a Newton solve keep a floor that decays by
        # FLOOR_DECAY an iteration (first contact at zero gap, see
        # ContactOptions.tangent_floor); the model counts the iterations
        floor = self.options.tangent_floor * FLOOR_DECAY ** state.tangent_index \
            if self._first_solve else 0.0
        self.set.set_tangent_floor(floor)
        # penetrations beyond the adaptation band: the tangent of held
        # points (ContactSet.set_motion_depth)
        self.set.set_motion_depth(self.options.penalty_band[1] * self.adaptation.target)
        self.set.assemble_matrix(q, self.model.beam_global_dofs(state), A)

    # -- saved states (textile.io.state_file) ----------------------------------------
    state_name = "fibre contact"
    #: element columns of a saved state (ContactSet.data() / from_saved)
    SAVED = ("fibre_i", "fibre_j", "s_i", "s_j", "xi1_i", "xi2_i", "xi1_j", "xi2_j", "zone",
             "crossing", "wrap", "normal", "length", "penalty", "stick", "gap_kind",
             "tangent_i", "tangent_j")
    #: columns states saved before them lack (from_saved derives them from
    #: the geometry)
    SAVED_SINCE = ("gap_kind", "tangent_i", "tangent_j")

    def save_state(self, model) -> dict:
        """The committed contact elements with their history (normal
        orientation, zone penalty, stick point), keyed by fibre pair and
        abscissas and sorted by them, so the file does not depend on the
        partition; the contact mode and weaving order. Collective; complete
        on rank 0."""
        d = self._committed.data()
        parts = model.comm.gather({k: d[k] for k in self.SAVED}, root=0)
        if model.comm.rank != 0:
            return {}
        out = {k: np.concatenate([p[k] for p in parts]) for k in self.SAVED}
        order = np.lexsort((out["s_j"], out["s_i"], out["fibre_j"], out["fibre_i"]))
        out = {k: v[order] for k, v in out.items()}
        # zones numbered by their first element in this order: the numbers
        # the ranks agreed on depend on the partition, the file must not
        _, first, inverse = np.unique(out["zone"], return_index=True, return_inverse=True)
        out["zone"] = np.argsort(np.argsort(first))[inverse.reshape(-1)].astype(
            out["zone"].dtype)
        out.update(num_zones=np.int64(len(first)),
                   mode=np.int64(self.MODES.index(self.mode)),
                   reset_normals=np.int64(self._reset_normals))
        if self._order is not None:
            out.update(fibre_yarn=np.asarray(self._weaving["fibre_yarn"]),
                       yarn_above=np.asarray(self._weaving["yarn_above"]))
        if self._woven is not None:
            out.update(woven_fibre_yarn=np.asarray(self._woven_arrays["fibre_yarn"]),
                       woven_yarn_above=np.asarray(self._woven_arrays["yarn_above"]))
        out.update(weaving_done=np.int64(self._weaving_done),
                   friction_on=np.int64(self._friction_on),
                   # a stage's options that shape the rest of it (a state
                   # saved within the stage goes on with them)
                   update_tolerance=np.float64(self.update_tolerance()),
                   make_up=np.int64(self._make_up))
        if self._make_up_reference is not None:
            out["make_up_reference"] = np.asarray(self._make_up_reference)
        return out

    def check_state(self, model, data: dict) -> None:
        if not data:
            raise ValueError("the state file holds no fibre contact history, the model has "
                             "FibreContact: save the state with the contact in the scene")
        missing = [k for k in self.SAVED + ("num_zones", "mode")
                   if k not in data and k not in self.SAVED_SINCE]
        if missing:
            raise ValueError(f"the state file's fibre contact history lacks {missing}")
        n = len(model.mesh.fibres)
        fibres = np.concatenate([np.asarray(data["fibre_i"]), np.asarray(data["fibre_j"])])
        if len(fibres) and (fibres.min() < 0 or fibres.max() >= n):
            raise ValueError(f"the state file's contacts name fibre {int(fibres.max())}, this "
                             f"model has {n} fibres")

    def load_state(self, model, data: dict) -> None:
        """Restore what save_state wrote: this rank's elements (its owned
        range, whatever the partition that saved them), evaluated at the
        loaded unknowns, as the committed set; mode and order; the stage's
        loop tolerance and penetrations to make up."""
        self._load(model, data, stage_options=True)

    def _load(self, model, data: dict, stage_options: bool) -> None:
        """load_state's work; ``stage_options`` False (a new scene from saved
        fibres): the scene keeps its own loop tolerance and makes up
        nothing of the saved stage's."""
        self.check_state(model, data)
        mode = self.MODES[int(data["mode"])]
        if mode in ("weaving", "within_yarns"):
            self.configure(mode=mode, fibre_yarn=data["fibre_yarn"],
                           yarn_above=data["yarn_above"])
        else:
            self.configure(mode=mode)
        self._reset_normals = bool(data["reset_normals"])
        if stage_options and "update_tolerance" in data:
            self.options = dataclasses.replace(
                self.options, update_tolerance=float(data["update_tolerance"]))
            self._tolerance_schedule = None
        if stage_options:
            self._make_up = bool(data.get("make_up", False))
            self._make_up_reference = np.array(data["make_up_reference"]) \
                if "make_up_reference" in data else None
        self._weaving_done = bool(data.get("weaving_done", False))
        self._friction_on = bool(data.get("friction_on", True))
        if "woven_fibre_yarn" in data:
            self._woven_arrays = dict(fibre_yarn=np.asarray(data["woven_fibre_yarn"]),
                                      yarn_above=np.asarray(data["woven_yarn_above"]))
            self._woven = _cpp.WeavingOrder(
                np.asarray(data["woven_fibre_yarn"], dtype=np.intc),
                np.asarray(data["woven_yarn_above"], dtype=np.int8))
        self._restore(model, {k: data[k] for k in self.SAVED if k in data},
                      int(data["num_zones"]))

    def _restore(self, model, columns: dict, num_zones: int) -> None:
        """Elements from saved columns (ContactSet.data() of all ranks or of
        this one), evaluated at the model's unknowns, as the committed set."""
        mesh = model.mesh
        q = model.beam_positions(model.state())
        self.set = _cpp.ContactSet.from_saved(columns, num_zones, q, mesh.first_node,
                                              mesh.order, self.radius, self.g_r, self._mu(),
                                              self.u_rev, mesh.node_owner, mesh.rank,
                                              **self._friction_args(),
                                              crossing_patch=self.options.crossing_patch)
        # the weaving stage's depths (not saved: from the reference state);
        # without them a state saved within that stage read the yarns'
        # remaining interpenetration as penetration, and the resumed run
        # retuned every zone's penalty (a crimp 2% off the continuous run's)
        self._set_depths(self.set)
        self.set.evaluate(q)  # results at the loaded state, as after a commit
        self._committed = self.set.copy()
        self.coverage = _cpp.CouplingPattern()
        self._committed_coverage = self.coverage.copy()
        self._matrix_has_contact = False

    def reset_friction(self, model) -> np.ndarray | None:
        """Start friction afresh at the current state: every contact sticks
        where it is, with no tangential force (its stick point moved by its
        elastic slip). A test starting from a woven state: the yarns reached
        their places slipping, at the friction limit, where a free yarn has
        no tangential stiffness. Returns the friction forces removed (this
        rank's share, 9 per global node, in the residual's sign: what
        :class:`~textile.effects.nodal_loads.ReleasedForces` hands back over
        a stage), or None without friction (or with the stage's friction
        off): then nothing changes."""
        if not (self.has_friction and self._friction_on):
            return None
        q = model.beam_positions(model.state())
        before = self._committed.nodal_forces(q)
        d = self._committed.data()
        columns = {k: np.asarray(d[k]) for k in self.SAVED}
        columns["stick"] = columns["stick"] + np.asarray(d["elastic_slip"]).reshape(
            columns["stick"].shape)
        self._restore(model, columns, self._committed.num_zones)
        return before - self._committed.nodal_forces(q)

    def load_fibres(self, model, data: dict) -> None:
        """A new scene starts from saved fibres (textile.load_fibres): take
        their contact history if the file has one (not its stage's loop
        tolerance nor make-up: the new scene's own), else start afresh."""
        if data:
            self._load(model, data, stage_options=False)

    # -- reporting ----------------------------------------------------------------
    def _statistics(self, model) -> None:
        d = self.set.data()
        comm = model.comm
        active = d["normal_force"] > 0
        radius = np.minimum(self.radius[d["fibre_i"]], self.radius[d["fibre_j"]]) \
            if len(d["fibre_i"]) else np.zeros(0)
        pen = np.max(-d["gap"][active] / radius[active]) if np.any(active) else 0.0
        # centre lines on the wrong side of each other along the normal
        crossed = d["separation"] < 0
        # penetration band: each active zone's largest penetration / target
        _, zone_pen = self._zone_state() if self.set.num_zones else (None, np.zeros(0))
        ratio = zone_pen[zone_pen > 0] / self.adaptation.target
        low, high = self.options.penalty_band
        self.stats = dict(
            contact_zones=int(np.count_nonzero(_reduce(comm, np.bincount(
                d["zone"], minlength=self.set.num_zones).astype(float), MPI.SUM))),
            contact_elements=int(comm.allreduce(len(d["gap"]))),
            active_contacts=int(comm.allreduce(int(active.sum()))),
            max_penetration_over_radius=float(comm.allreduce(pen, op=MPI.MAX)),
            contact_force_sum=float(comm.allreduce(float(d["normal_force"].sum()))),
            slipping_contacts=int(comm.allreduce(int(np.sum(d["slip"] & active)))),
            contact_updates=int(self.updates),
            active_zones=int(len(ratio)),
            zone_penetration_min=float(ratio.min()) if len(ratio) else 0.0,
            zone_penetration_median=float(np.median(ratio)) if len(ratio) else 0.0,
            zone_penetration_max=float(ratio.max()) if len(ratio) else 0.0,
            zones_below_band=int(np.count_nonzero(ratio < low)),
            zones_above_band=int(np.count_nonzero(ratio > high)),
            retuned_zones=int(self.retuned_zones),
            emergency_retunes=int(self.emergency_retunes),
            penalty_conversions=int(self.penalty_conversions),
            crossed_contacts=int(comm.allreduce(int(crossed.sum()))),
            held_contacts=int(self.held_contacts),
        )

    def statistics(self) -> dict:
        return dict(self.stats)

    def assembly_timing(self) -> dict:
        """Seconds spent by this effect's C++ assembly (residual + tangent)
        since setup: in the element kernels ("kernel") and in all ("total",
        which adds the gap checks of open elements, the node-block sums and
        the PETSc insertion); "kernel_calls" counts kernel evaluations,
        "off_rank_sent" the node blocks of other ranks' rows this rank sent
        to their owners (added in place there) and "off_rank_stashed" those
        that went through PETSc's stash instead (MatSetValues);
        "history_bytes_received" the other ranks' contact history this rank
        received at detection passes (:meth:`_history`); on several ranks,
        "gathered_values" the unknowns of other ranks' nodes moved to this
        rank for its elements, summed over the "evaluations" (residuals and
        tangents) that moved them (:meth:`_positions`); "detection_values"
        the unknowns of other ranks' nodes moved for detection passes,
        "detection_pieces" the other ranks' fibre pieces received,
        "own_fibres" the fibres with elements of this rank's and
        "ghost_fibres" the others the last pass held (detection_view.py),
        "zone_keys_received" the other ranks' zones that numbered this
        rank's (:meth:`_number_zones`), over "detection_passes", which
        took "detection_seconds" (all of each pass: exchanges, detection,
        history, new elements)."""
        out = dict(self._timing, detection_values=0, detection_pieces=0, ghost_fibres=0,
                   own_fibres=len(self.radius))
        if self._view is not None:
            out.update(self._view.counts)
        for k, v in self.set.timing().items():
            out[k] += v
        return out

    def detection_fibres(self) -> np.ndarray:
        """One flag per fibre: the fibres this rank's last detection pass
        held (its own and its ghosts, detection_view.py; on one rank all)."""
        if self._view is None:
            return np.ones(len(self.radius), dtype=bool)
        return self._view.last_present.copy()

    def nodal_forces(self) -> np.ndarray:
        """(nodes, 9): this rank's contact elements' generalized forces on
        every fibre node's [x0, g1, g2] at the current state (the residual's
        contact part: internal force, so minus what the contact pushes
        with), in the global node numbering."""
        q = self.model.beam_positions(self.model.state())
        return np.asarray(self.set.nodal_forces(q)).reshape(-1, 9)

    def elements(self) -> dict:
        """This rank's contact elements: arrays of fibres, abscissas, normals,
        gaps, normal and tangential forces, slip flags, penalty per unit
        length and the contact length each element stands for."""
        return self.set.data()

    def contact_elements(self) -> dict:
        """The output's contact elements (Effect.contact_elements): :meth:`elements`."""
        return self.elements()
