"""Fibre-fibre contact and friction through intermediate geometries.

Detection, geometry, normals, laws and their tangents are in C++
(``cpp/textile/contact/``); this effect runs the algorithm of METHOD.md
section 4 around Newton:

- ``prepare`` (start of a step attempt): find proximity zones between the
  current centre lines, build the contact elements on their intermediate
  geometries, carry history (normal orientation, penalty, friction stick
  point) over from the elements of the previous pass by identity;
- Newton (the solver's SNES) with elements, particles and normals fixed;
- ``update`` (after each converged Newton): re-detect and re-normal; adapt
  each zone's penalty so that its largest penetration stays near the
  target; ask for another Newton if anything changed beyond tolerance;
- ``commit`` (step accepted): friction return mapping (stick points).

Units: lengths in the model's unit. Penalties are per unit length of
contact (force/length^2): a line contact of penetration p carries
k_c phi(p) per unit length, whatever the element spacing; a crossing stands
for the equivalent length r_i + r_j (``contact_set.h`` states this once for
the C++ side).
Sign conventions as in ``contact_element.h``: the normal points from fibre
j to fibre i, gap < 0 when they interpenetrate.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import _cpp
from ..options import Options
from .base import Effect, State


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
        Re-tune each zone's penalty towards the target penetration.
    penalty_range:
        (low, high) bounds of an adapted penalty, relative to the initial one.
    parallel_angle:
        Angle (degrees) below which two fibres are treated as parallel.
    friction:
        Coulomb coefficient mu (0: frictionless, no friction history kept).
    reversible_slip:
        u_T,rev as a fraction of the smallest radius.
    self_contact:
        Look for contact of a fibre with distant parts of itself.
    update_tolerance:
        After a converged Newton, the elements are re-detected and re-normaled
        at the new state; another Newton is run when the contact forces of the
        new set differ from the old set's, at that state, by more than this
        fraction of their norm (loops 1-2 of METHOD.md section 4).
    """

    search_factor: float = 2.0
    spacing: float | None = None
    regularization: float = 0.02
    target_penetration: float = 2.0
    penalty: float | None = None
    adapt_penalty: bool = True
    penalty_range: tuple = (1e-3, 1e3)
    parallel_angle: float = 10.0
    friction: float = 0.0
    reversible_slip: float = 0.01
    self_contact: bool = True
    update_tolerance: float = 1e-3

    kind = "contact"

    def __post_init__(self):
        self.require_positive("search_factor", "regularization", "target_penetration",
                              "reversible_slip", "update_tolerance")
        for name in ("spacing", "penalty"):
            v = getattr(self, name)
            if v is not None and (not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0):
                raise ValueError(f"ContactOptions.{name} must be positive (or None), got {v!r}")
        if not (isinstance(self.friction, (int, float)) and 0 <= self.friction < 10):
            raise ValueError(f"ContactOptions.friction must be in [0, 10), got {self.friction!r}")
        if not 0 < self.parallel_angle < 90:
            raise ValueError("ContactOptions.parallel_angle must be in (0, 90) degrees")
        lo, hi = self.penalty_range
        if not 0 < lo <= 1 <= hi:
            raise ValueError("ContactOptions.penalty_range must be (low <= 1 <= high), positive")


class FibreContact(Effect):
    """Contact (and optionally friction) between all fibres of a model."""

    fields = ("beam",)
    dynamic_sparsity = True

    def __init__(self, options: ContactOptions | dict | None = None):
        self.options = options if isinstance(options, ContactOptions) \
            else ContactOptions.from_dict(options)
        self.set = None
        self._committed = None

    # -- set-up ------------------------------------------------------------
    def setup(self, model) -> None:
        mesh, o = model.mesh, self.options
        self.model = model
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
        self.set = _cpp.ContactSet()
        self._committed = self.set.copy()
        self._pattern_pairs: set = set()
        # elements farther apart than this are left out of the matrix
        # pattern (they cannot close within one Newton solve)
        self.pattern_margin = 0.5 * rmin
        self.stats = {}

    # -- detection and history -----------------------------------------------
    def _detect(self, q: np.ndarray) -> dict:
        mesh = self.model.mesh
        return _cpp.detect_contacts(np.ascontiguousarray(q), mesh.first_node, mesh.order,
                                    self.radius, self.options.search_factor, self.self_exclusion,
                                    self.spacing, math.radians(self.options.parallel_angle))

    def _rebuild(self, q: np.ndarray) -> bool:
        """Detect, match history, set normals; True if the set changed."""
        o = self.options
        found = self._detect(q)
        self._num_zones = int(found["num_zones"])
        old = self.set.data()
        n = len(found["fibre_i"])
        # history by identity: same fibre pair and nearest sections
        match = np.full(n, -1)
        if len(old["fibre_i"]):
            key_old = old["fibre_i"] * 1_000_003 + old["fibre_j"]
            key_new = found["fibre_i"] * 1_000_003 + found["fibre_j"]
            for k in range(n):
                cand = np.flatnonzero(key_old == key_new[k])
                if len(cand):
                    d = np.abs(old["s_i"][cand] - found["s_i"][k]) + \
                        np.abs(old["s_j"][cand] - found["s_j"][k])
                    best = cand[np.argmin(d)]
                    if d.min() < 0.75:  # within one element on both fibres
                        match[k] = best
        previous = np.zeros((n, 3))
        penalty = np.full(n, self.k0)
        elastic_slip = np.zeros((n, 3))
        has = match >= 0
        previous[has] = old["normal"][match[has]]
        penalty[has] = old["penalty"][match[has]]
        elastic_slip[has] = old["elastic_slip"][match[has]]
        normals = _cpp.contact_normals(found["tangent_i"], found["tangent_j"], found["tangent"],
                                       found["centroid_gap"], previous,
                                       math.radians(o.parallel_angle))
        # one penalty per zone: the largest carried over (penalties only grow
        # within a step, so a zone never softens by re-detection)
        zone = found["zone"]
        zone_penalty = np.zeros(self._num_zones)
        np.maximum.at(zone_penalty, zone, np.where(has, penalty, 0.0))
        comm = self.model.comm
        if comm.size > 1:  # a zone's elements may live on several ranks
            from mpi4py import MPI
            comm.Allreduce(MPI.IN_PLACE, zone_penalty, op=MPI.MAX)
        penalty = np.where(zone_penalty[zone] > 0, zone_penalty[zone], self.k0)
        q = np.ascontiguousarray(q)
        before = self.set.nodal_forces(q)
        mu = self.options.friction
        mesh = self.model.mesh
        self.set.set_elements(found, normals, penalty, self.g_r, mu, self.u_rev, elastic_slip,
                              np.ascontiguousarray(q), mesh.first_node, mesh.order, self.radius,
                              mesh.owned)
        self.set.evaluate(q)
        # a coupling the matrix was not preallocated for: ask for a new one
        pairs = self._coupled_pairs(self.set.data())
        if not pairs <= self._pattern_pairs:
            self._pattern_pairs = self._pattern_pairs | pairs
            self.model.matrix_stale = True
        # what matters is what the elements do to the fibres at this state
        after = self.set.nodal_forces(q)
        comm = self.model.comm
        diff = comm.allreduce(float(np.sum((after - before) ** 2)))
        size = comm.allreduce(float(np.sum(before ** 2)))
        return diff > o.update_tolerance ** 2 * max(size, 1e-300) or (size == 0 and diff > 0)

    def _coupled_pairs(self, d) -> set:
        """(fibre, element) pairs of this rank's elements near contact (gap
        below the pattern margin): the matrix entries they may fill."""
        mesh = self.model.mesh
        near = d["gap"] <= self.pattern_margin
        ne = np.diff(mesh.first_node) // mesh.order
        fi, fj = d["fibre_i"][near], d["fibre_j"][near]
        ei = np.minimum(np.floor(d["s_i"][near]).astype(np.int64), ne[fi] - 1)
        ej = np.minimum(np.floor(d["s_j"][near]).astype(np.int64), ne[fj] - 1)
        return set(zip(fi.tolist(), ei.tolist(), fj.tolist(), ej.tolist()))

    def add_dynamic_pattern(self, model, preallocator) -> None:
        self.set.insert_pattern(preallocator, model.beam_global_dofs(model.state()),
                                self.pattern_margin)

    def _adapt_penalties(self) -> bool:
        o = self.options
        if not o.adapt_penalty:
            return False
        data = self.set.data()
        gap, zone, k = data["gap"], data["zone"], data["penalty"]
        target = o.target_penetration * self.g_r
        lo, hi = o.penalty_range[0] * self.k0, o.penalty_range[1] * self.k0
        # zone numbers come from the (replicated) detection pass, so every
        # rank agrees on them; each holds only its own elements
        comm = self.model.comm
        zones = np.arange(self._num_zones)
        pen = np.zeros(self._num_zones)
        np.maximum.at(pen, zone, np.maximum(-gap, 0.0))
        if comm.size > 1:
            from mpi4py import MPI
            comm.Allreduce(MPI.IN_PLACE, pen, op=MPI.MAX)
        changed = False
        for z, p in zip(zones, pen):
            sel = zone == z
            if not np.any(sel):
                continue
            kz = k[sel].max()
            # gentle steps (x2 at most): a large jump of the penalty moves
            # the equilibrium far and can throw Newton off
            if p > 2.0 * target:
                factor = min(p / target, 2.0)
            elif 0 < p < 0.1 * target:
                factor = 0.5
            else:
                continue
            new = float(np.clip(kz * factor, lo, hi))
            if abs(new - kz) > 1e-12 * kz:
                k[sel] = new
                changed = True
        if changed:
            self.set.set_penalties(k)
        return changed

    # -- load-step protocol ----------------------------------------------------
    def prepare(self, model) -> None:
        self._rebuild(model.beam_positions(model.state()))
        self.updates = 0

    def update(self, model) -> bool:
        self.updates += 1
        q = model.beam_positions(model.state())
        self.set.evaluate(q)
        changed = self._adapt_penalties()
        changed = self._rebuild(q) or changed
        return changed

    def commit(self, model) -> None:
        self.set.commit()
        self._committed = self.set.copy()
        self._statistics(model)

    def restore(self, model) -> None:
        self.set = self._committed.copy()

    # -- assembly --------------------------------------------------------------
    def residual_global(self, state: State, b) -> bool:
        q = self.model.beam_positions(state)
        self.set.assemble_vector(q, self.model.beam_global_dofs(state), b)
        return True

    def jacobian(self, state: State, A) -> None:
        q = self.model.beam_positions(state)
        self.set.assemble_matrix(q, self.model.beam_global_dofs(state), A)

    # -- reporting ----------------------------------------------------------------
    def _statistics(self, model) -> None:
        from mpi4py import MPI
        d = self.set.data()
        comm = model.comm
        active = d["normal_force"] > 0
        radius = np.minimum(self.radius[d["fibre_i"]], self.radius[d["fibre_j"]]) \
            if len(d["fibre_i"]) else np.zeros(0)
        pen = np.max(-d["gap"][active] / radius[active]) if np.any(active) else 0.0
        self.stats = dict(
            contact_zones=int(comm.allreduce(len(np.unique(d["zone"])), op=MPI.MAX)),
            contact_elements=int(comm.allreduce(len(d["gap"]))),
            active_contacts=int(comm.allreduce(int(active.sum()))),
            max_penetration_over_radius=float(comm.allreduce(pen, op=MPI.MAX)),
            contact_force_sum=float(comm.allreduce(float(d["normal_force"].sum()))),
            slipping_contacts=int(comm.allreduce(int(np.sum(d["slip"] & active)))),
            contact_updates=int(self.updates),
        )

    def statistics(self) -> dict:
        return dict(self.stats)

    def elements(self) -> dict:
        """This rank's contact elements: arrays of fibres, abscissas, normals,
        gaps, normal and tangential forces, slip flags."""
        return self.set.data()
