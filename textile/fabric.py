"""A woven fabric's yarns and the state weaving starts from.

Warp yarns run along x, weft yarns along y; the fabric plane is z = 0 and z
points up. Warp yarn j lies at y_j = (j - (n_warp - 1)/2) p_warp, weft yarn
i at x_i = (i - (n_weft - 1)/2) p_weft (p: the spacing between yarns of a
direction). Each yarn extends ``free_length`` beyond the last yarn it
crosses. The crossing order is the pattern tiled over the yarns
(:mod:`textile.weave_pattern`): ``order[i, j] = 1`` when warp j passes over
weft i.

The starting state (METHOD.md section 5): every yarn straight, all yarn axes
in the plane z = 0, so warp and weft yarns interpenetrate at every crossing;
the weaving computation pushes them over and under each other.

Numbering: fibres yarn after yarn, warps first (yarn k < n_warp is warp k,
yarn n_warp + i is weft i), fibres of a yarn in the order of its packing.
Section vectors: G1 across the yarn in the fabric plane, G2 = T x G1 = +z.
"""
from __future__ import annotations

import math
import numbers

import numpy as np

from .fibre import Fibre
from .weave_pattern import WeavePattern
from .yarn import Yarn


def _positive(value, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value) \
            or value <= 0:
        raise ValueError(f"Fabric: {name} must be positive and finite, got {value!r}")
    return float(value)


class Fabric:
    """Yarns, pattern and starting geometry of a woven fabric.

    Parameters
    ----------
    warp, weft:
        :class:`~textile.yarn.Yarn` of each direction (weft defaults to the
        warp's).
    num_warp, num_weft:
        Yarn counts (>= 1; the last repeat may be cut, as long as every
        yarn still changes side).
    spacing:
        Distance between neighbouring yarns (length): one number, or
        (warp spacing, weft spacing).
    pattern:
        A :class:`~textile.weave_pattern.WeavePattern`, a name ("plain",
        "twill 2/2", ...) or a 0/1 matrix.
    free_length:
        Yarn length beyond the last crossing (default: half the spacing).
    elements_per_crossing:
        Fibre elements between two neighbouring crossings (and over a free
        length of half a spacing).
    order:
        Element order of the fibres (1 or 2).
    """

    def __init__(self, warp: Yarn, weft: Yarn | None = None, num_warp: int = 2,
                 num_weft: int = 2, spacing=1.0, pattern="plain", free_length=None,
                 elements_per_crossing: int = 4, order: int = 2):
        weft = warp if weft is None else weft
        for name, y in (("warp", warp), ("weft", weft)):
            if not isinstance(y, Yarn):
                raise TypeError(f"Fabric: {name} must be a textile.yarn.Yarn, got "
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
            if y.width >= p:
                raise ValueError(f"Fabric: {name} yarns are {y.width:.4g} wide ({y.count} fibres of "
                                 f"radius {y.radius:.4g}) but only {p:.4g} apart: neighbouring "
                                 f"{name} yarns would overlap (larger spacing, fewer or thinner "
                                 f"fibres)")
        if isinstance(elements_per_crossing, bool) or not isinstance(
                elements_per_crossing, numbers.Integral) or elements_per_crossing < 1:
            raise ValueError(f"Fabric: elements_per_crossing must be a positive integer, got "
                             f"{elements_per_crossing!r}")
        self.warp, self.weft = warp, weft
        self.num_warp, self.num_weft = int(num_warp), int(num_weft)
        self.pattern = WeavePattern.of(pattern)
        self.order = self.pattern.tile(self.num_weft, self.num_warp)
        self.free_length = 0.5 * min(self.spacing) if free_length is None \
            else _positive(free_length, "free_length")
        self.elements_per_crossing = int(elements_per_crossing)
        self.element_order = order
        self._fibres = None

    # -- yarns -------------------------------------------------------------------
    @property
    def num_yarns(self) -> int:
        return self.num_warp + self.num_weft

    def yarn(self, k: int) -> Yarn:
        return self.warp if k < self.num_warp else self.weft

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
