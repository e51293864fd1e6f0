"""Yarns: bundles of fibres, how they are packed in the yarn's section, twist.

A yarn is ``count`` identical fibres (radius R, material) whose centre lines
sit at fixed offsets (d, h) in the yarn's section: d across the fabric (in
the fabric plane, orthogonal to the yarn) and h vertical (out of the fabric
plane), both lengths, centred on the yarn's axis (the offsets' mean is 0).

Packings. The lattice packings place neighbouring fibres ``pitch`` =
2 R (1 + clearance/2) apart, centre to centre (clearance 0: touching):

- ``"hexagonal"``: sites of a hexagonal lattice: 1, 7, 19, 37 fibres fill
  whole rings about a fibre (outer radius R, 3R, 5R, 7R at clearance 0);
- ``"round"``: concentric rings filling a circle: a core (a centre fibre, or
  2 to 5 fibres touching on a ring), then rings one pitch further out each,
  each holding as many evenly spaced fibres as fit on it without overlap
  (:func:`round_rings`). Full rings of 1 + 6 + 12 + 18 (7, 19, 37 fibres),
  and 28 = 3 + 9 + 16 (outer radius (2/sqrt(3) + 5) R = 6.155 R at
  clearance 0, every ring full; the hexagonal 28 is 6.292 R). Rings touch
  where their fibres line up radially (on the +d axis, and wherever the
  rings' angles coincide); round a ring the fibres spread over the whole
  circle, so ring neighbours are 2 r sin(pi/n) - pitch apart (28: 0.158 R
  on the ring of 9, 0.011 R on the ring of 16): the core and the lined-up
  fibres touch, the others nearly (a hexagonal bundle touches everywhere);
- ``"layers n"``: a flat yarn of n staggered rows of the hexagonal lattice,
  their lengths differing by at most one fibre (e.g. ``"layers 2"`` for 28
  fibres: 2 rows of 14);
- a (count, 2) array of offsets (no clearance: the offsets are the spacing).

When ``count`` does not fill whole shells of a hexagonal or round packing,
the last shell or ring is filled partially, its fibres spread evenly, and of
the candidate bundles (hexagonal: about a lattice site, a triangle's centre
or a bond's middle; round: each core) the most compact is kept: the smallest
outer diameter, then the smallest polar moment of the fibres' centres.

Twist. ``twist`` tau (turns per unit length, its sign the hand) turns the
section rigidly about the yarn's axis along the yarn: fibre m, at offset a_m
= r_m (cos phi_m, sin phi_m), has the centre line

    c_m(s) = s t + r_m (cos(phi_m + k s) e_d + sin(phi_m + k s) e_h),
    k = 2 pi tau,

a helix of radius r_m, pitch 1/|tau| and helix angle alpha_m = atan(k r_m)
(t the yarn's direction, e_d across, e_h up).

Twist and overlap. The yarn is unchanged by the screw motion (s -> s + u/k,
section turned by u), so the distance between the centre lines of fibres i
and j is

    d_ij^2 = min over u of  (u/k)^2 + |a_i - Rot(u) a_j|^2
           = min over u of  (u/k)^2 + r_i^2 + r_j^2 - 2 r_i r_j cos(D_ij + u),

D_ij = phi_j - phi_i. At u = 0 this is the distance in the yarn's section;
it is smaller whenever the pair has a tangential component. Neighbours on
one ring (r_i = r_j = r, section distance d = 2 r sin(D/2), D small):
expanding to second order in u, d_ij^2 = d^2 - (k r^2 sin D)^2 / (1 + k^2
r^2 cos D) -> d^2 / (1 + k^2 r^2), so d_ij = d cos(alpha): cut normal to the
fibres, the sections of ring neighbours come closer by the cosine of the
helix angle. Radial neighbours (D = 0) keep their distance. Hence fibres
touching side by side in the section overlap as soon as tau != 0: a twisted
yarn needs a clearance of about 2 / cos(alpha_outer) - 2 when its outer ring
holds many fibres, less when neighbours are far round the ring (7 fibres
with clearance 0.1, 60 deg apart: up to alpha = 20.0 deg, not acos(2/2.1) =
17.8 deg).

The yarn refuses a twist for which two centre lines come closer than 2 R
(:func:`helix_distances` computes d_ij exactly: the minimum lies in |u| <=
pi, since beyond it (u/k)^2 exceeds its value at u = -D_ij; it is found on
each interval where the function is convex), and a pitch 1/|tau| shorter
than 4 R: points of one fibre more than half a turn apart are then more
than 2 R apart along the yarn, closer points are farther apart the farther
along the helix (r^2 (1 - cos u) grows on |u| < pi), and the helix's
curvature radius r + 1/(k^2 r) >= 2/k = pitch/pi exceeds R: no fibre meets
itself.
"""
from __future__ import annotations

import math
import numbers
import re
from dataclasses import dataclass, field

import numpy as np

from ..beam.material import Material

ROUND_OFF = 1e-9
"""Relative round-off below which two fibres count as touching, not
overlapping: centres at least 2 R (1 - ROUND_OFF) apart. The packings come
out touching to about 1e-15 relative
(tests/weave/test_yarn_fabric.py::test_packings_touch_without_overlap);
offsets typed or computed by a user carry their own round-off."""

#: Default Coulomb coefficient between the fibres of a bundle (Yarn.friction):
#: the low end of measured fibre-on-fibre friction of polyester and glass
#: filaments (0.2-0.3), and what the virtual tests take between yarns.
BUNDLE_FRICTION = 0.2

#: Fibres of a yarn whose centres are closer than this many times the
#: packing's closest centre distance are neighbours (Yarn.neighbours): a
#: hexagonal lattice's nearest sites (1) and not its second ones (sqrt 3);
#: the round packings' neighbours on a ring and across rings (up to 1.31
#: on 37 fibres, tests/weave/test_yarn_fabric.py)
NEIGHBOUR_DISTANCE = 1.5

# a lattice site, the centre of a triangle of sites, the middle of a bond
# (in pitches): the centres a compact hexagonal bundle can have
_HEX_CENTRES = ((0.0, 0.0), (0.5, math.sqrt(3) / 6), (0.5, 0.0))


def _outer_and_moment(p: np.ndarray) -> tuple[float, float]:
    r2 = np.sum(p * p, axis=1)
    return float(np.sqrt(r2.max())), float(r2.sum())


def _most_compact(candidates: list[np.ndarray]) -> int:
    """Index of the candidate, re-centred on its mean, with the smallest
    outer radius, then the smallest polar moment (ties: the first)."""
    keys = [_outer_and_moment(c - c.mean(axis=0)) for c in candidates]
    outer = min(k[0] for k in keys)
    near = [i for i, k in enumerate(keys) if k[0] <= outer * (1 + ROUND_OFF)]
    moment = min(keys[i][1] for i in near)
    return next(i for i in near if keys[i][1] <= moment * (1 + ROUND_OFF))


def _centred(p: np.ndarray) -> np.ndarray:
    return p - p.mean(axis=0)


def _shell_choices(points: np.ndarray, k: int) -> list[np.ndarray]:
    """Ways to take k of the points of one shell: spread evenly in angle, or
    side by side (which can make a bundle rounder once re-centred), from
    every first point, starting from angle 0."""
    points = points[np.argsort(np.mod(np.arctan2(points[:, 1], points[:, 0]), 2 * math.pi))]
    m = len(points)
    spread = np.floor(np.arange(k) * m / k).astype(int)
    return [points[(start + step) % m] for step in (spread, np.arange(k)) for start in range(m)]


def hexagonal_sites(count: int, pitch: float) -> np.ndarray:
    """The most compact ``count`` sites of a hexagonal lattice of spacing
    ``pitch``, re-centred on their mean (see the module docstring)."""
    n = int(math.ceil(math.sqrt(count))) + 2
    i, j = np.meshgrid(np.arange(-n, n + 1), np.arange(-n, n + 1))
    lattice = np.column_stack([(i + 0.5 * j).ravel(), (math.sqrt(3) / 2 * j).ravel()])
    candidates = []
    for centre in _HEX_CENTRES:
        q = lattice - centre
        # 12 |q|^2 is an integer for the three centres: exact shells
        shell = np.rint(12 * np.sum(q * q, axis=1)).astype(np.int64)
        values = np.unique(shell)
        inside = np.cumsum([np.count_nonzero(shell == v) for v in values])
        last = int(np.searchsorted(inside, count))  # the shell holding the count-th site
        full = q[shell < values[last]]
        k = count - len(full)
        if k == 0:
            candidates.append(full)
            continue
        for chosen in _shell_choices(q[shell == values[last]], k):
            candidates.append(np.vstack([full, chosen]))
    return pitch * _centred(candidates[_most_compact(candidates)])


def round_rings(count: int) -> list[tuple[int, float]]:
    """Rings of the round packing of ``count`` fibres, from the inside: (fibres
    on the ring, ring radius in pitches). The core is a centre fibre (radius 0)
    or c = 2..5 fibres touching on a ring of radius 1/(2 sin(pi/c)); each
    further ring lies one pitch out and holds the floor(pi / asin(1/(2 r)))
    fibres that fit on radius r, the last one only what is left; the most
    compact of the cores (module docstring). E.g. 28 -> [(3, 0.577), (9,
    1.577), (16, 2.577)]."""
    sites, rings = _round_candidates(count)
    return rings[_most_compact(sites)]


def _round_candidates(count: int) -> tuple[list[np.ndarray], list[list[tuple[int, float]]]]:
    sites, rings = [], []
    # a core of 6 or more would leave room for a centre fibre; the centre comes
    # last so that the one tie (2 fibres: a centre and a ring of 1) is the core 2
    for core in (2, 3, 4, 5, 1):
        if core > count:
            continue
        radius = 0.0 if core == 1 else 0.5 / math.sin(math.pi / core)
        ring, left = [(core, radius)], count - core
        while left > 0:
            radius += 1.0
            # as many as fit: chords of 2 r sin(pi/n) >= 1 pitch (to round-off)
            fit = int(math.floor(math.pi / math.asin(0.5 / radius) * (1 + ROUND_OFF)))
            ring.append((min(fit, left), radius))
            left -= ring[-1][0]
        p = [np.zeros((1, 2)) if r == 0 else
             r * np.column_stack([np.cos(2 * np.pi * np.arange(n) / n),
                                  np.sin(2 * np.pi * np.arange(n) / n)]) for n, r in ring]
        sites.append(np.vstack(p))
        rings.append(ring)
    return sites, rings


def round_sites(count: int, pitch: float) -> np.ndarray:
    """The ``count`` fibre centres of the round packing (:func:`round_rings`),
    ``pitch`` apart where they touch, re-centred on their mean."""
    sites = _round_candidates(count)[0]
    return pitch * _centred(sites[_most_compact(sites)])


def layered_sites(count: int, layers: int, pitch: float) -> np.ndarray:
    """``count`` sites in ``layers`` staggered rows of the hexagonal lattice,
    the first ``count % layers`` rows one site longer, re-centred."""
    base, longer = divmod(count, layers)
    sites = [((col + 0.5 * (row % 2)) * pitch, row * math.sqrt(3) / 2 * pitch)
             for row in range(layers) for col in range(base + (row < longer))]
    p = np.array(sites)
    return p - p.mean(axis=0)


def _turned(b: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Offsets b turned by angles u about the yarn's axis."""
    cu, su = np.cos(u), np.sin(u)
    return np.column_stack([cu * b[:, 0] - su * b[:, 1], su * b[:, 0] + cu * b[:, 1]])


def _pair_value(a, b, k, u):
    """d_ij^2(u) of the module docstring for offsets a (fibre i), b (j)."""
    return (u / k) ** 2 + np.sum((a - _turned(b, u)) ** 2, axis=1)


def _pair_slope(a, b, k, u):
    """Half the derivative of :func:`_pair_value` in u."""
    w = _turned(b, u)
    return u / k ** 2 + a[:, 0] * w[:, 1] - a[:, 1] * w[:, 0]


def _convex_minimum(a, b, k, lo, hi):
    """Minimum of d^2(u) on [lo, hi], where it is convex: an end, or where
    the derivative vanishes (bisection down to neighbouring floats)."""
    s_lo, s_hi = _pair_slope(a, b, k, lo), _pair_slope(a, b, k, hi)
    u = np.where(s_lo >= 0, lo, hi)
    inner = (s_lo < 0) & (s_hi > 0)
    left, right, a, b = lo[inner], hi[inner], a[inner], b[inner]
    while len(left):
        mid = 0.5 * (left + right)
        moving = (mid != left) & (mid != right)
        if not moving.any():
            break
        up = _pair_slope(a, b, k, mid) > 0
        right = np.where(moving & up, mid, right)
        left = np.where(moving & ~up, mid, left)
    u[inner] = np.where(_pair_value(a, b, k, left) <= _pair_value(a, b, k, right), left, right)
    return u


def helix_distances(offsets, twist: float) -> np.ndarray:
    """(count, count) distances between the centre lines of fibres at
    ``offsets`` (count, 2) of a yarn twisted by ``twist`` turns per unit
    length (diagonal: inf). Exact to round-off: the minimum over |u| <= pi
    of the module docstring's d_ij^2(u), taken on each interval where it is
    convex."""
    a = np.asarray(offsets, dtype=float)
    n = len(a)
    out = np.full((n, n), np.inf)
    i, j = np.triu_indices(n, 1)
    ai, aj = a[i], a[j]
    section = np.hypot(*(ai - aj).T)
    if twist == 0 or n < 2:
        out[i, j] = out[j, i] = section
        return out
    k = 2 * math.pi * abs(float(twist))  # the distances do not depend on the hand
    skew = np.arctan2(ai[:, 0] * aj[:, 1] - ai[:, 1] * aj[:, 0], np.sum(ai * aj, axis=1))
    # d^2'' / 2 = 1/k^2 + r_i r_j cos(skew + u): concave only where cos(skew + u) < -1/c,
    # c = r_i r_j k^2, i.e. within beta of skew + u = pi (mod 2 pi)
    c = np.hypot(*ai.T) * np.hypot(*aj.T) * k * k
    beta = np.arccos(np.minimum(1.0, np.divide(1.0, c, out=np.full_like(c, np.inf), where=c > 0)))
    # the convex intervals about skew + u = 2 pi m, m = -1, 0, 1, within |u| <= pi
    m = 2 * math.pi * np.repeat([-1.0, 0.0, 1.0], len(c))
    lo = np.maximum(np.tile(-math.pi + beta - skew, 3) + m, -math.pi)
    hi = np.minimum(np.tile(math.pi - beta - skew, 3) + m, math.pi)
    held = lo <= hi  # the m = 0 interval always is: it holds u = -skew
    A, B = np.tile(ai, (3, 1))[held], np.tile(aj, (3, 1))[held]
    d2 = np.full(len(lo), np.inf)
    d2[held] = _pair_value(A, B, k, _convex_minimum(A, B, k, lo[held], hi[held]))
    d = np.sqrt(np.maximum(d2.reshape(3, -1).min(axis=0), 0.0))
    out[i, j] = out[j, i] = np.minimum(d, section)  # u = 0 is a value of d^2 too
    return out


def _closest_pair(distances: np.ndarray) -> tuple[int, int, float]:
    i, j = np.unravel_index(np.argmin(distances), distances.shape)
    return int(i), int(j), float(distances[i, j])


@dataclass(frozen=True)
class Yarn:
    """A bundle of ``count`` fibres (see the module docstring).

    Parameters
    ----------
    count:
        Number of fibres, an integer >= 1.
    radius:
        Fibre radius R (length), > 0.
    material:
        Fibre :class:`~textile.Material`.
    packing:
        "hexagonal", "round", "layers n" (1 <= n <= count), or a (count, 2)
        array of (d, h) offsets (lengths) at least 2 R apart.
    clearance:
        Gap between neighbouring fibres of a lattice packing, in fibre radii,
        >= 0 (0: touching). Not for offsets.
    twist:
        Turns per unit length about the yarn's axis, finite (0: parallel
        fibres; the sign is the hand). Refused when two fibres' helices would
        come closer than 2 R or the pitch 1/|twist| is shorter than 4 R.
    friction:
        Coulomb coefficient between two fibres of this yarn, in [0, 10), or
        None: the contact's ``friction`` (as between yarns). Default:
        BUNDLE_FRICTION for a bundle (fibres stacked over each other, or
        twisted), None for a single row or a monofilament. A frictionless
        stack is unstable: pressed by a crossing yarn, a fibre resting on
        two others rolls off them as they spread (a negative eigenvalue of
        the tangent, tests/contact/test_stacked_fibres.py), which a
        quasi-static solve cannot pass, and the weaving stage is
        frictionless between yarns; fibres side by side in one row cannot
        roll off each other.
    """

    count: int
    radius: float
    material: Material
    packing: object = "hexagonal"
    clearance: float = 0.0
    twist: float = 0.0
    friction: float | None = None
    _offsets: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        if isinstance(self.count, bool) or not isinstance(self.count, numbers.Integral) \
                or self.count < 1:
            raise ValueError(f"Yarn.count must be a positive integer, got {self.count!r}")
        v = self.radius
        if (isinstance(v, bool) or not isinstance(v, numbers.Real) or not math.isfinite(v)
                or v <= 0):
            raise ValueError(f"Yarn.radius must be positive and finite, got {v!r}")
        for name in ("clearance", "twist"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, numbers.Real) or not math.isfinite(v):
                raise ValueError(f"Yarn.{name} must be a finite number, got {v!r}")
        if self.clearance < 0:
            raise ValueError(f"Yarn.clearance must be >= 0, got {self.clearance!r}")
        if not isinstance(self.material, Material):
            raise TypeError(f"Yarn.material must be a textile.Material, got "
                            f"{type(self.material).__name__}")
        object.__setattr__(self, "_offsets", self._make_offsets())
        self._check_twist()
        v = self.friction
        if v is None and self.is_bundle:
            v = BUNDLE_FRICTION
        if v is not None and (isinstance(v, bool) or not isinstance(v, numbers.Real)
                              or not 0 <= v < 10):
            raise ValueError(f"Yarn.friction must be in [0, 10) (or None), got {v!r}")
        object.__setattr__(self, "friction", None if v is None else float(v))

    @property
    def is_bundle(self) -> bool:
        """Fibres stacked over each other in the section (more than one
        row), or a twisted yarn of several fibres."""
        h = self._offsets[:, 1]
        return bool(np.ptp(h) > ROUND_OFF * self.radius) or (self.count > 1 and self.twist != 0)

    def _make_offsets(self) -> np.ndarray:
        pitch = 2 * self.radius * (1 + 0.5 * self.clearance)
        p = self.packing
        if isinstance(p, str):
            key = " ".join(p.lower().split())
            if key == "hexagonal":
                return hexagonal_sites(self.count, pitch)
            if key == "round":
                return round_sites(self.count, pitch)
            if m := re.fullmatch(r"layers (\d+)", key):
                layers = int(m[1])
                if not 1 <= layers <= self.count:
                    raise ValueError(f"Yarn.packing {p!r}: the number of layers must be in "
                                     f"1..{self.count} (the count)")
                return layered_sites(self.count, layers, pitch)
            raise ValueError(f"unknown Yarn.packing {p!r}: use 'hexagonal', 'round', 'layers n' "
                             f"or a ({self.count}, 2) array of offsets")
        if self.clearance != 0:
            raise ValueError(f"Yarn.clearance applies to the lattice packings; offsets given as "
                             f"an array carry their own spacing (got clearance "
                             f"{self.clearance!r})")
        try:
            offsets = np.array(p, dtype=float)
        except (TypeError, ValueError) as e:
            raise TypeError(f"Yarn.packing must be 'hexagonal', 'round', 'layers n' or a "
                            f"({self.count}, 2) array of offsets, got {p!r}") from e
        if offsets.shape != (self.count, 2) or not np.all(np.isfinite(offsets)):
            raise ValueError(f"Yarn.packing offsets must be a finite ({self.count}, 2) array, "
                             f"got shape {offsets.shape}")
        d = helix_distances(offsets, 0.0)
        i, j, dij = _closest_pair(d)
        if dij < 2 * self.radius * (1 - ROUND_OFF):
            raise ValueError(f"Yarn.packing: fibres {i} and {j} overlap (centres {dij:.4g} "
                             f"apart, less than a diameter {2 * self.radius:.4g})")
        return offsets

    def _check_twist(self):
        if self.twist == 0:
            return
        R, tau = self.radius, abs(self.twist)
        if 1 / tau < 4 * R:
            raise ValueError(f"Yarn.twist {self.twist!r}: the pitch 1/|twist| = {1 / tau:.4g} is "
                             f"shorter than two fibre diameters {4 * R:.4g}; |twist| must be <= "
                             f"{1 / (4 * R):.4g} turns per unit length")
        i, j, dij = _closest_pair(helix_distances(self._offsets, tau))
        if dij >= 2 * R * (1 - ROUND_OFF):
            return
        lo, hi = 0.0, tau  # the distances shrink as |twist| grows: bisect
        for _ in range(40):  # to 1e-12 of the twist asked for
            mid = 0.5 * (lo + hi)
            if helix_distances(self._offsets, mid).min() >= 2 * R * (1 - ROUND_OFF):
                lo = mid
            else:
                hi = mid
        alpha = math.degrees(math.atan(2 * math.pi * tau * self.outer_radius_of_centres))
        allowed = (f"|twist| <= {lo:.4g}" if lo > 0 else
                   "no twist (fibres touch side by side: give a clearance)")
        raise ValueError(f"Yarn.twist {self.twist!r}: the helices of fibres {i} and {j} come "
                         f"{dij:.4g} apart, less than a fibre diameter {2 * R:.4g} (helix angle "
                         f"{alpha:.3g} deg at the outer fibres); this packing admits {allowed}, "
                         f"a larger clearance admits more")

    @property
    def offsets(self) -> np.ndarray:
        """(count, 2) offsets (d across, h vertical) of the fibres' centres."""
        return self._offsets.copy()

    def neighbours(self) -> np.ndarray:
        """(n, 2) pairs (i < j) of this yarn's fibres next to each other in
        its section: centres closer than NEIGHBOUR_DISTANCE times the
        closest two (none for a monofilament). A twisted yarn's fibres turn
        together, so they stay neighbours along it."""
        o = self._offsets
        if len(o) < 2:
            return np.zeros((0, 2), dtype=np.int64)
        i, j = np.triu_indices(len(o), 1)
        d = np.linalg.norm(o[i] - o[j], axis=1)
        near = d < NEIGHBOUR_DISTANCE * d.min()
        return np.column_stack([i[near], j[near]]).astype(np.int64)

    @property
    def outer_radius_of_centres(self) -> float:
        """Largest distance of a fibre's centre from the yarn's axis."""
        return float(np.hypot(*self._offsets.T).max())

    @property
    def diameter(self) -> float:
        """Diameter of the circle about the yarn's axis holding every fibre's
        section, 2 (max |offset| + R): a twisted yarn stays inside the
        cylinder of this diameter."""
        return 2 * (self.outer_radius_of_centres + self.radius)

    @property
    def width(self) -> float:
        """Extent of the bundle across the fabric (fibres included)."""
        return float(np.ptp(self._offsets[:, 0]) + 2 * self.radius)

    @property
    def height(self) -> float:
        """Extent of the bundle out of the fabric plane (fibres included)."""
        return float(np.ptp(self._offsets[:, 1]) + 2 * self.radius)
