"""Where fibres cross a plane: the shapes of a cut through a sample.

The plane is a point p and a normal n (normalised here). Shapes are given
in in-plane model coordinates (s1, s2) = (x . e1, x . e2), not relative to
p, so a cut normal to x reads in the model's y and z:

- e2, "up" in a picture: z projected on the plane (y when n is along z);
- e1: the coordinate axis most orthogonal to n and e2, made orthogonal to
  both (sign kept, so the horizontal axis reads increasing model values).

A fibre crossing the plane with unit tangent t, |t . n| >= ``parallel``,
is cut by it in an **ellipse**: a cylinder of radius r cut obliquely has
semi-axes r across and r / |t . n| along the in-plane projection of t.

A fibre lying nearly in the plane (|t . n| < ``parallel``) is drawn as a
**band**: the part of its centre line within ``depth`` of the plane (by
default its radius: exactly the part the plane touches), projected on the
plane and widened to the fibre's diameter 2 r.

Lengths are model units; the geometry is serial numpy (call it on one rank).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Band", "Cut", "Ellipse", "cut_fibres", "plane_frame"]

_AXES = np.eye(3)
_NAMES = "xyz"


@dataclass(frozen=True)
class Ellipse:
    """A fibre's section where it crosses the plane."""

    fibre: int
    centre: np.ndarray        # (2,) in-plane coordinates
    semi_axes: tuple          # (along the fibre's in-plane direction, across)
    angle: float              # degrees from e1 to the first semi-axis


@dataclass(frozen=True)
class Band:
    """A fibre piece lying nearly in the plane, projected on it."""

    fibre: int
    outline: np.ndarray       # (m, 2) closed polygon, in-plane coordinates
    depth: float              # mean signed distance of the piece from the plane


@dataclass
class Cut:
    """The shapes of a plane cut and the plane's frame."""

    point: np.ndarray
    normal: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    axis_names: tuple         # e.g. ("y", "z"), or ("s1", "s2") for a skew plane
    ellipses: list = field(default_factory=list)
    bands: list = field(default_factory=list)


def plane_frame(normal) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple]:
    """(n, e1, e2, axis names) of a plane of normal ``normal`` (see module)."""
    n = np.asarray(normal, dtype=float)
    if n.shape != (3,) or not np.all(np.isfinite(n)) or np.linalg.norm(n) == 0:
        raise ValueError(f"the plane's normal must be a finite non-zero 3-vector, got {normal!r}")
    n = n / np.linalg.norm(n)
    up = 2 if abs(n[2]) < 0.9 else 1
    e2 = _AXES[up] - n[up] * n
    e2 /= np.linalg.norm(e2)
    others = [a for a in range(3) if a != up]
    side = min(others, key=lambda a: abs(n[a]))
    e1 = _AXES[side] - n[side] * n - np.dot(_AXES[side], e2) * e2
    e1 /= np.linalg.norm(e1)
    aligned = abs(e1[side]) > 1 - 1e-9 and abs(e2[up]) > 1 - 1e-9
    names = (_NAMES[side], _NAMES[up]) if aligned else ("s1", "s2")
    return n, e1, e2, names


def _clip_to_slab(d0: float, d1: float, depth: float) -> tuple[float, float] | None:
    """Parameter interval [s0, s1] of a segment (signed distances d0 -> d1)
    where |d| <= depth, or None."""
    if d0 == d1:
        return (0.0, 1.0) if abs(d0) <= depth else None
    lo, hi = sorted(((-depth - d0) / (d1 - d0), (depth - d0) / (d1 - d0)))
    s0, s1 = max(lo, 0.0), min(hi, 1.0)
    return (s0, s1) if s0 < s1 else None


def _band_outline(points: np.ndarray, half_width: float) -> np.ndarray | None:
    """Polygon of a 2D polyline widened by ``half_width`` on both sides."""
    keep = np.r_[True, np.linalg.norm(np.diff(points, axis=0), axis=1) > 1e-12 * half_width]
    p = points[keep]
    if len(p) < 2:
        return None
    seg = np.diff(p, axis=0)
    seg /= np.linalg.norm(seg, axis=1)[:, None]
    normal = np.column_stack([-seg[:, 1], seg[:, 0]])
    # a vertex's offset direction: the mean of its segments' normals
    vertex = np.vstack([normal[:1], normal[:-1] + normal[1:], normal[-1:]])
    vertex /= np.linalg.norm(vertex, axis=1)[:, None]
    return np.vstack([p + half_width * vertex, (p - half_width * vertex)[::-1]])


def cut_fibres(centrelines, radii, point, normal, parallel: float = 0.25,
               depth: float | None = None) -> Cut:
    """Ellipses and bands of the fibres cut by the plane (see module).

    ``centrelines``: one (n_i, 3) array per fibre; ``radii``: one radius per
    fibre; ``parallel``: |t . n| below which a fibre piece counts as lying in
    the plane; ``depth``: half thickness of the slab whose in-plane fibre
    pieces are drawn (default: each fibre's radius).
    """
    n, e1, e2, names = plane_frame(normal)
    p = np.asarray(point, dtype=float)
    cut = Cut(p, n, e1, e2, names)
    in_plane = np.column_stack([e1, e2])
    for f, (x, r) in enumerate(zip(centrelines, radii)):
        x = np.asarray(x, dtype=float)
        d = (x - p) @ n
        chord = np.diff(x, axis=0)
        t = chord / np.linalg.norm(chord, axis=1)[:, None]
        c = np.abs(t @ n)
        slab = r if depth is None else depth
        piece: list[np.ndarray] = []
        piece_depths: list[float] = []
        for k in range(len(chord)):
            if c[k] >= parallel:
                if (d[k] < 0) != (d[k + 1] < 0):
                    s = d[k] / (d[k] - d[k + 1])
                    centre = (x[k] + s * chord[k]) @ in_plane
                    along = t[k] @ in_plane
                    angle = np.degrees(np.arctan2(along[1], along[0])) \
                        if np.linalg.norm(along) > 1e-12 else 0.0
                    cut.ellipses.append(Ellipse(f, centre, (r / c[k], r), float(angle)))
                interval = None
            else:
                interval = _clip_to_slab(d[k], d[k + 1], slab)
            if interval is not None:
                a, b = x[k] + interval[0] * chord[k], x[k] + interval[1] * chord[k]
                if piece and interval[0] == 0.0:
                    piece.append(b)                 # continues the previous segment's piece
                else:
                    _close_band(cut, f, piece, piece_depths, r, in_plane)
                    piece, piece_depths = [a, b], []
                piece_depths.append(float(((a + b) / 2 - p) @ n))
                if interval[1] < 1.0:
                    _close_band(cut, f, piece, piece_depths, r, in_plane)
                    piece, piece_depths = [], []
            else:
                _close_band(cut, f, piece, piece_depths, r, in_plane)
                piece, piece_depths = [], []
        _close_band(cut, f, piece, piece_depths, r, in_plane)
    return cut


def _close_band(cut: Cut, fibre: int, piece: list, depths: list, radius: float,
                in_plane: np.ndarray) -> None:
    """Add the band of a finished fibre piece (points in 3D) to ``cut``."""
    if len(piece) < 2:
        return
    outline = _band_outline(np.array(piece) @ in_plane, radius)
    if outline is not None:
        cut.bands.append(Band(fibre, outline, float(np.mean(depths))))
