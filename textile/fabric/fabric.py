"""A woven fabric's yarns and the state weaving starts from.

Warp yarns run along x, weft yarns along y; the fabric plane is z = 0 and z
points up. Warp yarn j lies at y_j = (j - (n_warp - 1)/2) p_warp, weft yarn
i at x_i = (i - (n_weft - 1)/2) p_weft (p: the spacing between yarns of a
direction). Each yarn extends ``free_length`` beyond the last yarn it
crosses. The crossing order is the pattern tiled over the yarns
(:mod:`textile.fabric.weave_pattern`): ``order[i, j] = 1`` when warp j passes over
weft i.

The starting state (docs/method.md §6.1): every yarn straight, all yarn axes
in the plane z = 0, so warp and weft yarns interpenetrate at every crossing;
the weaving computation pushes them over and under each other.

Numbering: fibres yarn after yarn, warps first (yarn k < n_warp is warp k,
yarn n_warp + i is weft i), fibres of a yarn in the order of its packing.
Section vectors: G1 across the yarn in the fabric plane, G2 = T x G1 = +z
(transported along a twisted fibre).

Neighbouring yarns of one direction must not overlap: a yarn's width across
the fabric (a twisted yarn's diameter, which its turning section sweeps)
may reach the spacing (yarns touching side by side) but not exceed it.

Twisted yarns. A yarn of length L cut into n elements (n = elements_per_
crossing L / p rounded, p the spacing of the yarns it crosses) gets N =
n / (|twist| L), about elements_per_crossing / (|twist| p), elements per
turn (:meth:`Fabric.elements_per_turn`); each element turns the section by
2 pi / N. Its nodes lie on the helices; between them an element of order q
interpolates every fibre of the yarn with the same shape functions, so at
each point of the element the interpolated section is the yarn's section
turned and scaled by |P(x)|, P the interpolant of the unit circle. Over an
element turning by 2 phi (phi = pi / N), with x in [-1, 1]:

    q = 1: P = cos(phi) + i x sin(phi),          min |P| = cos(phi)            (x = 0),
    q = 2: P = 1 + i x sin(phi) - x^2 (1 - cos(phi)),
           |P|^2 = 1 - (1 - cos(phi))^2 x^2 (1 - x^2),
           min |P| = sqrt(1 - (1 - cos(phi))^2 / 4)                           (x^2 = 1/2).

The fabric refuses a twisted yarn whose fibres come closer than 2 R once
its section is shrunk by that minimum (the helix distances of
:func:`~textile.fabric.yarn.helix_distances`: exact in every section, an estimate
between them) and one whose node interval turns by pi or more (the nodes
would describe the opposite hand, or no twist at all). E.g. 10 elements a
turn shrink the section to cos(18 deg) = 0.9511 (order 1: radial
neighbours need a clearance of 0.103 or more) or to 0.9997 (order 2).
"""
from __future__ import annotations

import math
import numbers

import numpy as np

from .. import presets
from ..beam.fibre import Fibre
from .weave_pattern import WeavePattern
from .yarn import ROUND_OFF, Yarn, helix_distances


def _positive(value, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value) \
            or value <= 0:
        raise ValueError(f"Fabric: {name} must be positive and finite, got {value!r}")
    return float(value)


def interpolated_section_scale(order: int, turn) -> np.ndarray:
    """Smallest scale of a yarn's section interpolated by an element of
    ``order`` (1 or 2) whose nodes turn by ``turn`` (radians) from its first
    to its last (module docstring)."""
    phi = 0.5 * np.asarray(turn, dtype=float)
    if order == 1:
        return np.cos(phi)
    return np.sqrt(1 - 0.25 * (1 - np.cos(phi)) ** 2)


class Fabric:
    """Yarns, pattern and starting geometry of a woven fabric.

    Parameters
    ----------
    warp, weft:
        :class:`~textile.fabric.Yarn` of each direction (weft defaults to the
        warp's).
    num_warp, num_weft:
        Yarn counts (>= 1; the last repeat may be cut, as long as every
        yarn still changes side).
    spacing:
        Distance between neighbouring yarns (length): one number, or
        (warp spacing, weft spacing).
    pattern:
        A :class:`~textile.fabric.weave_pattern.WeavePattern`, a name ("plain",
        "twill 2/2", ...) or a 0/1 matrix.
    free_length:
        Yarn length beyond the last crossing (default: one spacing for
        bundles, which weave by lifting and need it
        (:class:`~textile.fabric.weaving.Weaving`); half a spacing for yarns
        one fibre high).
    elements_per_crossing:
        Fibre elements between two neighbouring crossings (and over a free
        length of half a spacing), an integer >= 1; a twisted yarn needs
        enough per turn (module docstring).
    order:
        Element order of the fibres (1 or 2).
    preset:
        Accuracy preset (:mod:`textile.presets`; None: "standard"): sets
        ``elements_per_crossing`` unless it is given (draft 2, standard 4,
        fine 8).
    """

    def __init__(self, warp: Yarn, weft: Yarn | None = None, num_warp: int = 2,
                 num_weft: int = 2, spacing=1.0, pattern="plain", free_length=None,
                 elements_per_crossing: int | None = None, order: int = 2,
                 preset: str | None = None):
        weft = warp if weft is None else weft
        for name, y in (("warp", warp), ("weft", weft)):
            if not isinstance(y, Yarn):
                raise TypeError(f"Fabric: {name} must be a textile.fabric.Yarn, got "
                                f"{type(y).__name__}")
        for name, n in (("num_warp", num_warp), ("num_weft", num_weft)):
            if isinstance(n, bool) or not isinstance(n, numbers.Integral) or n < 1:
                raise ValueError(f"Fabric: {name} must be a positive integer, got {n!r}")
        if isinstance(spacing, numbers.Real) and not isinstance(spacing, bool):
            spacing = (spacing, spacing)
        try:
            p_warp, p_weft = spacing
        except (TypeError, ValueError) as e:
            raise ValueError(f"Fabric: spacing must be a number or a pair, got {spacing!r}") from e
        self.spacing = (_positive(p_warp, "warp spacing"), _positive(p_weft, "weft spacing"))
        for name, y, p in (("warp", warp, self.spacing[0]), ("weft", weft, self.spacing[1])):
            across = y.diameter if y.twist else y.width
            if across > p * (1 + ROUND_OFF):
                what = (f"sweep a diameter of {across:.4g} as they turn" if y.twist else
                        f"are {across:.4g} wide")
                raise ValueError(f"Fabric: {name} yarns {what} ({y.count} fibres of "
                                 f"radius {y.radius:.4g}) but only {p:.4g} apart: neighbouring "
                                 f"{name} yarns would overlap (larger spacing, fewer or thinner "
                                 f"fibres)")
        self.preset = presets.checked(preset, "Fabric")
        elements_per_crossing = presets.knob(self.preset, "fabric", "elements_per_crossing",
                                             elements_per_crossing)
        if isinstance(elements_per_crossing, bool) or not isinstance(
                elements_per_crossing, numbers.Integral) or elements_per_crossing < 1:
            raise ValueError(f"Fabric: elements_per_crossing must be a positive integer, got "
                             f"{elements_per_crossing!r}")
        if isinstance(order, bool) or not isinstance(order, numbers.Integral) \
                or order not in (1, 2):
            raise ValueError(f"Fabric: order (of the fibres' elements) must be 1 or 2, got "
                             f"{order!r}")
        self.warp, self.weft = warp, weft
        self.num_warp, self.num_weft = int(num_warp), int(num_weft)
        self.pattern = WeavePattern.of(pattern)
        self.order = self.pattern.tile(self.num_weft, self.num_warp)
        if free_length is None:
            free_length = (1.0 if self.has_bundles else 0.5) * min(self.spacing)
        self.free_length = _positive(free_length, "free_length")
        self.elements_per_crossing = int(elements_per_crossing)
        self.element_order = int(order)
        self._fibres = None
        for k in sorted({0, self.num_warp}):
            self._check_twist_resolved(k)

    # -- yarns -------------------------------------------------------------------
    @property
    def num_yarns(self) -> int:
        return self.num_warp + self.num_weft

    def yarn(self, k: int) -> Yarn:
        return self.warp if k < self.num_warp else self.weft

    @property
    def has_bundles(self) -> bool:
        """Whether the warp or the weft is a bundle (``Yarn.is_bundle``:
        fibres stacked in the section, or twisted): such a fabric weaves by
        lifting, with longer free ends, and its loadings cap their Newton
        solves."""
        return self.warp.is_bundle or self.weft.is_bundle

    def yarn_friction(self) -> np.ndarray:
        """Each yarn's friction coefficient between its own fibres
        (Yarn.friction; NaN: the contact's), for FibreContact's
        ``yarn_friction``."""
        return np.array([math.nan if self.yarn(k).friction is None else self.yarn(k).friction
                         for k in range(self.num_yarns)])

    def yarn_direction(self, k: int) -> str:
        """"warp" (along x) or "weft" (along y)."""
        if not 0 <= k < self.num_yarns:
            raise ValueError(f"yarn {k} out of range 0..{self.num_yarns - 1}")
        return "warp" if k < self.num_warp else "weft"

    def yarn_axis(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """(start, end) of yarn k's axis in the starting state."""
        p_warp, p_weft = self.spacing
        if k < self.num_warp:
            y = (k - (self.num_warp - 1) / 2) * p_warp
            half = (self.num_weft - 1) / 2 * p_weft + self.free_length
            return np.array([-half, y, 0.0]), np.array([half, y, 0.0])
        i = k - self.num_warp
        x = (i - (self.num_weft - 1) / 2) * p_weft
        half = (self.num_warp - 1) / 2 * p_warp + self.free_length
        return np.array([x, -half, 0.0]), np.array([x, half, 0.0])

    def crossings(self) -> list[tuple[int, int, np.ndarray, bool]]:
        """(weft i, warp j, point of the crossing in the plane, warp on top)."""
        out = []
        for i in range(self.num_weft):
            x = self.yarn_axis(self.num_warp + i)[0][0]
            for j in range(self.num_warp):
                y = self.yarn_axis(j)[0][1]
                out.append((i, j, np.array([x, y, 0.0]), bool(self.order[i, j])))
        return out

    # -- fibres ------------------------------------------------------------------
    def _num_elements(self, k: int) -> int:
        a, b = self.yarn_axis(k)
        p = self.spacing[1] if k < self.num_warp else self.spacing[0]
        return max(1, int(round(self.elements_per_crossing * np.linalg.norm(b - a) / p)))

    def elements_per_turn(self, k: int) -> float:
        """Elements of yarn k per turn of its twist (inf if untwisted)."""
        yarn = self.yarn(k)
        if yarn.twist == 0:
            return math.inf
        a, b = self.yarn_axis(k)
        return self._num_elements(k) / (abs(yarn.twist) * float(np.linalg.norm(b - a)))

    def _check_twist_resolved(self, k: int):
        """Refuse a twist yarn k's elements cannot follow (module docstring)."""
        yarn, name = self.yarn(k), self.yarn_direction(k)
        if yarn.twist == 0:
            return
        q, per_turn = self.element_order, self.elements_per_turn(k)
        if q * per_turn <= 2:
            raise ValueError(f"Fabric: {name} yarns twisted {yarn.twist:.4g} turns per unit "
                             f"length get {per_turn:.3g} elements of order {q} per turn: a node "
                             f"interval turns by pi or more and cannot describe the helix (more "
                             f"elements_per_crossing)")
        scale = float(interpolated_section_scale(q, 2 * math.pi / per_turn))
        limit = 2 * yarn.radius * (1 - ROUND_OFF)

        def closest(s):
            return helix_distances(s * yarn.offsets, yarn.twist).min()

        d = closest(scale)
        if d >= limit:
            return
        lo, hi = scale, 1.0  # the distances grow with the scale: bisect for the least
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if closest(mid) >= limit else (mid, hi)
        # the elements per turn whose interpolated section scale reaches hi
        phi = math.acos(hi) if q == 1 else math.acos(max(-1.0, 1 - 2 * math.sqrt(1 - hi * hi)))
        need = (f"at least {math.pi / phi:.3g} elements per turn" if phi > 0 else
                "more clearance (its helices touch: no element follows them without overlap)")
        raise ValueError(f"Fabric: {name} yarns twisted {yarn.twist:.4g} turns per unit length "
                         f"get {per_turn:.3g} elements of order {q} per turn: interpolated "
                         f"between nodes their section shrinks to {scale:.6f} and fibres come "
                         f"{d:.4g} apart, less than a diameter {2 * yarn.radius:.4g}; this "
                         f"needs {need}")

    def fibres(self) -> list[Fibre]:
        """The fibres of the starting state, yarn after yarn (built once)."""
        if self._fibres is None:
            self._fibres, self.fibre_yarn = [], []
            for k in range(self.num_yarns):
                for f in self._yarn_fibres(k):
                    self._fibres.append(f)
                    self.fibre_yarn.append(k)
            self.fibre_yarn = np.array(self.fibre_yarn)
        return list(self._fibres)

    def neighbour_fibres(self) -> np.ndarray:
        """(n, 2) fibre numbers (those of :meth:`fibres`) of the pairs of
        fibres next to each other within a yarn (Yarn.neighbours), yarn
        after yarn."""
        self.fibres()
        first = np.searchsorted(self.fibre_yarn, np.arange(self.num_yarns))
        pairs = [first[k] + self.yarn(k).neighbours() for k in range(self.num_yarns)]
        return np.vstack(pairs).astype(np.int64)

    def _yarn_fibres(self, k: int) -> list[Fibre]:
        yarn = self.yarn(k)
        a, b = self.yarn_axis(k)
        length = float(np.linalg.norm(b - a))
        t = (b - a) / length
        across = np.array([-t[1], t[0], 0.0])  # in the plane, left of the yarn
        up = np.array([0.0, 0.0, 1.0])
        n = self.element_order * self._num_elements(k) + 1
        s = np.linspace(0.0, length, n)
        angle = 2 * math.pi * yarn.twist * s
        out = []
        for m, (d, h) in enumerate(yarn.offsets):
            # the offset turns about the yarn axis with the twist
            dd = d * np.cos(angle) - h * np.sin(angle)
            hh = d * np.sin(angle) + h * np.cos(angle)
            pts = a + s[:, None] * t + dd[:, None] * across + hh[:, None] * up
            name = f"{self.yarn_direction(k)} {k if k < self.num_warp else k - self.num_warp}" \
                   f" fibre {m}"
            out.append(Fibre(pts, yarn.radius, yarn.material, across, name=name))
        return out

    def __repr__(self) -> str:
        return (f"Fabric({self.pattern.name}, {self.num_warp} warp x {self.num_weft} weft yarns "
                f"of {self.warp.count}/{self.weft.count} fibres, spacing {self.spacing})")
