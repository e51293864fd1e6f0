"""Yarns: bundles of fibres and how they are packed in the yarn's section.

A yarn is ``count`` identical fibres (radius, material) whose centre lines
sit at fixed offsets (d, h) in the yarn's section: d across the fabric (in
the fabric plane, orthogonal to the yarn) and h vertical (out of the fabric
plane), both lengths, centred on the yarn's axis.

Packings:

- ``"hexagonal"``: the ``count`` sites of a hexagonal lattice (fibres
  touching, or ``clearance`` radii apart) nearest a centre: 1, 7, 19, 37
  fibres fill whole rings; other counts give the most compact bundle;
- ``"layers n"``: a flat yarn, n staggered rows of the hexagonal lattice,
  as wide as needed (e.g. ``"layers 2"`` for 28 fibres: 2 rows of 14);
- an (count, 2) array of offsets.

``twist`` (turns per unit length) rotates the offsets about the yarn axis
along its length.
"""
from __future__ import annotations

import math
import numbers
import re
from dataclasses import dataclass, field

import numpy as np

from .material import Material


def hexagonal_sites(count: int, pitch: float) -> np.ndarray:
    """The ``count`` hexagonal lattice sites (spacing ``pitch``) nearest the
    origin, sorted by distance then angle, re-centred on their mean."""
    rings = int(math.ceil(math.sqrt(count))) + 1
    i, j = np.meshgrid(np.arange(-rings, rings + 1), np.arange(-rings, rings + 1))
    p = np.column_stack([(i + 0.5 * j).ravel(), (math.sqrt(3) / 2 * j).ravel()]) * pitch
    r = np.round(np.hypot(p[:, 0], p[:, 1]) / pitch, 9)
    a = np.round(np.mod(np.arctan2(p[:, 1], p[:, 0]), 2 * math.pi), 9)
    p = p[np.lexsort((a, r))][:count]
    return p - p.mean(axis=0)


def layered_sites(count: int, layers: int, pitch: float) -> np.ndarray:
    """``count`` sites in ``layers`` staggered rows (hexagonal lattice),
    filled row by row, re-centred."""
    per_row = int(math.ceil(count / layers))
    sites = []
    for k in range(count):
        row, col = divmod(k, per_row)
        sites.append(((col + 0.5 * (row % 2)) * pitch, row * math.sqrt(3) / 2 * pitch))
    p = np.array(sites)
    return p - p.mean(axis=0)


@dataclass(frozen=True)
class Yarn:
    """A bundle of ``count`` fibres (see the module docstring).

    Parameters
    ----------
    count:
        Number of fibres, >= 1.
    radius:
        Fibre radius (length), > 0.
    material:
        Fibre :class:`~textile.Material`.
    packing:
        "hexagonal", "layers n", or an (count, 2) array of (d, h) offsets.
    clearance:
        Gap between neighbouring fibres of a lattice packing, in fibre radii
        (0: touching).
    twist:
        Turns per unit length about the yarn's axis (0: parallel fibres).
    """

    count: int
    radius: float
    material: Material
    packing: object = "hexagonal"
    clearance: float = 0.0
    twist: float = 0.0
    _offsets: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        if isinstance(self.count, bool) or not isinstance(self.count, numbers.Integral) \
                or self.count < 1:
            raise ValueError(f"Yarn.count must be a positive integer, got {self.count!r}")
        for name in ("radius",):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, numbers.Real) or not math.isfinite(v) \
                    or v <= 0:
                raise ValueError(f"Yarn.{name} must be positive and finite, got {v!r}")
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

    def _make_offsets(self) -> np.ndarray:
        pitch = 2 * self.radius * (1 + 0.5 * self.clearance)
        p = self.packing
        if isinstance(p, str):
            key = " ".join(p.lower().split())
            if key == "hexagonal":
                return hexagonal_sites(self.count, pitch)
            if m := re.fullmatch(r"layers (\d+)", key):
                layers = int(m[1])
                if not 1 <= layers <= self.count:
                    raise ValueError(f"Yarn.packing {p!r}: the number of layers must be in "
                                     f"1..{self.count}")
                return layered_sites(self.count, layers, pitch)
            raise ValueError(f"unknown Yarn.packing {p!r}: use 'hexagonal', 'layers n' or an "
                             f"array of offsets")
        offsets = np.array(p, dtype=float)
        if offsets.shape != (self.count, 2) or not np.all(np.isfinite(offsets)):
            raise ValueError(f"Yarn.packing offsets must be a finite ({self.count}, 2) array, "
                             f"got shape {offsets.shape}")
        d = np.hypot(*(offsets[:, None, :] - offsets[None, :, :]).transpose(2, 0, 1))
        d[np.diag_indices(self.count)] = np.inf
        if self.count > 1 and d.min() < 2 * self.radius * (1 - 1e-9):
            i, j = np.unravel_index(np.argmin(d), d.shape)
            raise ValueError(f"Yarn.packing: fibres {i} and {j} overlap (centres {d[i, j]:.4g} "
                             f"apart, less than a diameter {2 * self.radius:.4g})")
        return offsets

    @property
    def offsets(self) -> np.ndarray:
        """(count, 2) offsets (d across, h vertical) of the fibres' centres."""
        return self._offsets.copy()

    @property
    def width(self) -> float:
        """Extent of the bundle across the fabric (fibres included)."""
        return float(np.ptp(self._offsets[:, 0]) + 2 * self.radius)

    @property
    def height(self) -> float:
        """Extent of the bundle out of the fabric plane (fibres included)."""
        return float(np.ptp(self._offsets[:, 1]) + 2 * self.radius)
