"""Weave patterns: which yarn lies on top at each warp/weft crossing.

A pattern is a 0/1 *crossing-order matrix* ``order[i, j]`` for weft yarn i
(rows) and warp yarn j (columns): 1 where the warp yarn passes over the weft
yarn, 0 where it passes under. The matrix is one repeat of the weave; a
fabric of n_weft x n_warp yarns tiles it, so its shape must divide the yarn
counts. Named patterns:

- ``plain``: [[1, 0], [0, 1]];
- ``twill n/m``: each warp floats over n wefts and under m, the float moving
  by one weft from one warp to the next (period n + m), e.g. ``twill 2/2``;
- ``basket n``: the plain weave with every yarn replaced by n side by side
  (period 2n), e.g. ``basket 2``;
- ``satin n`` (n-harness, n >= 5, n != 6): each warp floats over n - 1 wefts
  and under one (warp-faced), the interlacings of successive warps n_s wefts
  apart, n_s the smallest move number coprime with n other than 1 and n - 1
  (2 for 5 and 7, 3 for 8), so that no two interlacings touch.
"""
from __future__ import annotations

import math
import re

import numpy as np


class WeavePattern:
    """A validated crossing-order matrix (see the module docstring).

    Parameters
    ----------
    order:
        Nested lists or an array of 0/1, one row per weft yarn of the repeat,
        one column per warp yarn.
    allow_floats:
        Accept a yarn that never changes side in the repeat (it then floats
        over or under the whole fabric); by default that is an error, since
        such a yarn is not interlaced.
    name:
        A label (the named constructors set it).
    """

    def __init__(self, order, allow_floats: bool = False, name: str = "custom"):
        self.order = self._validated(order, allow_floats)
        self.allow_floats = allow_floats
        self.name = name

    # -- construction ------------------------------------------------------
    @staticmethod
    def _validated(order, allow_floats: bool) -> np.ndarray:
        if isinstance(order, np.ndarray):
            rows = [list(r) for r in order] if order.ndim == 2 else None
            if rows is None:
                raise ValueError(f"weave pattern must be a 2D matrix, got {order.ndim} "
                                 f"dimension(s)")
        else:
            try:
                rows = [list(r) for r in order]
            except TypeError as e:
                raise ValueError("weave pattern must be a matrix (a list of rows) of 0/1") from e
        if not rows or not rows[0]:
            raise ValueError("weave pattern is empty")
        for i, r in enumerate(rows):
            if len(r) != len(rows[0]):
                raise ValueError(f"weave pattern row {i} has {len(r)} entries, row 0 has "
                                 f"{len(rows[0])}: the matrix is ragged")
            for j, v in enumerate(r):
                if isinstance(v, bool) or v not in (0, 1):
                    raise ValueError(f"weave pattern entry ({i}, {j}) is {v!r}: entries must be 0 "
                                     f"(warp under weft) or 1 (warp over weft)")
        m = np.array(rows, dtype=np.int8)
        if not allow_floats:
            for i in range(m.shape[0]):
                if m.shape[1] > 1 and len(set(m[i])) == 1:
                    raise ValueError(f"weft yarn {i} of the weave pattern never changes side "
                                     f"(always {'under' if m[i, 0] else 'over'}): pass "
                                     f"allow_floats=True if that is meant")
            for j in range(m.shape[1]):
                if m.shape[0] > 1 and len(set(m[:, j])) == 1:
                    raise ValueError(f"warp yarn {j} of the weave pattern never changes side "
                                     f"(always {'over' if m[0, j] else 'under'}): pass "
                                     f"allow_floats=True if that is meant")
            if m.shape == (1, 1):
                raise ValueError("a 1 x 1 weave pattern never interlaces: pass allow_floats=True "
                                 "if that is meant")
        return m

    @classmethod
    def plain(cls) -> "WeavePattern":
        return cls([[1, 0], [0, 1]], name="plain")

    @classmethod
    def twill(cls, over: int, under: int) -> "WeavePattern":
        """``over``/``under`` twill, e.g. twill(2, 2), twill(2, 1)."""
        for label, v in (("over", over), ("under", under)):
            if isinstance(v, bool) or not isinstance(v, int) or v < 1:
                raise ValueError(f"twill: {label} must be a positive integer, got {v!r}")
        n = over + under
        m = [[1 if (i - j) % n < over else 0 for j in range(n)] for i in range(n)]
        return cls(m, name=f"twill {over}/{under}")

    @classmethod
    def basket(cls, n: int) -> "WeavePattern":
        """n x n basket weave (plain weave of groups of n yarns)."""
        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise ValueError(f"basket: n must be a positive integer, got {n!r}")
        m = np.kron(np.array([[1, 0], [0, 1]]), np.ones((n, n), dtype=int))
        return cls(m, name=f"basket {n}x{n}")

    @classmethod
    def satin(cls, n: int) -> "WeavePattern":
        """n-harness warp-faced satin (n >= 5, n != 6)."""
        if isinstance(n, bool) or not isinstance(n, int) or n < 5 or n == 6:
            raise ValueError(f"satin: the number of harnesses must be an integer >= 5 other than "
                             f"6 (no regular 6-harness satin exists), got {n!r}")
        move = next(s for s in range(2, n - 1) if math.gcd(s, n) == 1)
        m = [[0 if (j * move - i) % n == 0 else 1 for j in range(n)] for i in range(n)]
        return cls(m, name=f"satin {n}")

    @classmethod
    def named(cls, name: str) -> "WeavePattern":
        """A pattern by name: "plain", "twill n/m", "basket n" (or "basket
        nxn"), "satin n"."""
        if not isinstance(name, str):
            raise ValueError(f"pattern name must be a string, got {name!r}")
        key = " ".join(name.lower().split())
        if key == "plain":
            return cls.plain()
        if m := re.fullmatch(r"twill (\d+)/(\d+)", key):
            return cls.twill(int(m[1]), int(m[2]))
        if m := re.fullmatch(r"basket (\d+)(?:x(\d+))?", key):
            if m[2] is not None and m[2] != m[1]:
                raise ValueError(f"basket weaves are n x n, got {name!r}")
            return cls.basket(int(m[1]))
        if m := re.fullmatch(r"satin (\d+)", key):
            return cls.satin(int(m[1]))
        raise ValueError(f"unknown weave pattern {name!r}: use 'plain', 'twill n/m', "
                         f"'basket n', 'satin n' or a 0/1 matrix")

    @classmethod
    def of(cls, pattern, allow_floats: bool = False) -> "WeavePattern":
        """A pattern from a WeavePattern, a name or a matrix."""
        if isinstance(pattern, WeavePattern):
            return pattern
        if isinstance(pattern, str):
            return cls.named(pattern)
        return cls(pattern, allow_floats=allow_floats)

    # -- use ---------------------------------------------------------------
    @property
    def shape(self) -> tuple[int, int]:
        """(weft yarns, warp yarns) of one repeat."""
        return tuple(self.order.shape)

    def tile(self, num_weft: int, num_warp: int) -> np.ndarray:
        """Crossing order of a fabric of num_weft x num_warp yarns: the
        repeat tiled, the last repeat cut where the yarns end (a fabric's
        width need not be a multiple of its repeat: a 3 x 3 plain weave is
        one). The pattern does not fit the counts when a yarn of the cut
        fabric never changes side (unless floats are allowed)."""
        for label, n in (("weft", num_weft), ("warp", num_warp)):
            if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
                raise ValueError(f"number of {label} yarns must be a positive integer, got {n!r}")
        reps = (-(-num_weft // self.shape[0]), -(-num_warp // self.shape[1]))
        order = np.tile(self.order, reps)[:num_weft, :num_warp]
        if not self.allow_floats:
            for label, lines, other in (("weft", order, "warp"), ("warp", order.T, "weft")):
                for k, line in enumerate(lines):
                    if len(line) > 1 and len(set(line)) == 1:
                        raise ValueError(
                            f"the {self.name} pattern does not fit {num_weft} weft x {num_warp} "
                            f"warp yarns: {label} yarn {k} would never change side over "
                            f"{len(line)} {other} yarns (the repeat is {self.shape[0]} weft x "
                            f"{self.shape[1]} warp yarns: use more yarns)")
        return order

    def __repr__(self) -> str:
        return f"WeavePattern({self.name!r}, {self.order.tolist()})"
