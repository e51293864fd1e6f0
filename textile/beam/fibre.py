"""Fibres: reference centre lines, section vectors, radius and material.

A fibre's reference configuration is given by the positions of its nodes
along the centre line and, at each node, two section vectors G1, G2: unit,
orthogonal to each other and to the centre line's tangent. The fibre's
section is a disk of radius ``radius`` spanned by them. Coordinates are in
the user's length unit throughout.
"""
from __future__ import annotations

import numbers

import numpy as np

from .material import Material


def _as_points(points, name: str) -> np.ndarray:
    try:
        p = np.array(points, dtype=float)
    except (TypeError, ValueError) as e:
        raise TypeError(f"{name} must be an array of 3D points") from e
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"{name} must have shape (n, 3), got {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError(f"{name} contains NaN or infinite coordinates")
    return p


def _check_positive(value, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {type(value).__name__}")
    if not np.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be positive and finite, got {value}")
    return float(value)


def node_tangents(points: np.ndarray) -> np.ndarray:
    """Unit tangents at the nodes of a polyline (one-sided at the ends,
    centred inside; second order on a uniformly spaced smooth curve)."""
    t = np.gradient(points, axis=0, edge_order=2 if len(points) > 2 else 1)
    return t / np.linalg.norm(t, axis=1)[:, None]


def transported_section_vectors(points: np.ndarray, first: np.ndarray | None = None) -> np.ndarray:
    """Section vector G1 at each node by parallel transport (rotation
    minimizing) of ``first`` along the centre line."""
    t = node_tangents(points)
    if first is None:
        # any unit vector orthogonal to the first tangent; prefer global z
        trial = np.array([0.0, 0.0, 1.0]) if abs(t[0, 2]) < 0.9 else np.array([1.0, 0.0, 0.0])
        first = np.cross(t[0], trial)
    g = np.array(first, dtype=float)
    g = g - g.dot(t[0]) * t[0]
    if np.linalg.norm(g) < 1e-8:
        raise ValueError("section_vector must not be parallel to the fibre's tangent")
    g1 = np.empty_like(points)
    g1[0] = g / np.linalg.norm(g)
    for i in range(1, len(points)):
        v = g1[i - 1] - g1[i - 1].dot(t[i]) * t[i]
        g1[i] = v / np.linalg.norm(v)
    return g1


class Fibre:
    """A fibre's reference geometry, section and material.

    Parameters
    ----------
    points:
        (n, 3) reference positions of the nodes along the centre line, in
        order. With quadratic elements n must be odd (elements take nodes
        2k, 2k+1, 2k+2).
    radius:
        Radius of the round section (length unit), > 0.
    material:
        :class:`~textile.Material` of the fibre.
    section_vectors:
        Optional (n, 3) G1 at each node, or a single 3-vector transported
        along the centre line; default: a vector orthogonal to the first
        tangent, transported. G2 = T x G1.
    name:
        Optional label used in outputs.
    """

    def __init__(self, points, radius, material: Material, section_vectors=None, name=None):
        p = _as_points(points, "points")
        if len(p) < 2:
            raise ValueError(f"points: a fibre needs at least two points, got {len(p)}")
        seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
        scale = max(np.max(np.abs(p)), seg.max())
        if np.any(seg <= 1e-12 * scale):
            i = int(np.argmin(seg))
            raise ValueError(f"points: repeated point at index {i + 1} (zero-length segment)")
        self.radius = _check_positive(radius, "radius")
        if not isinstance(material, Material):
            raise TypeError(f"material must be a textile.Material, got {type(material).__name__}")
        self.material = material
        self.points = p
        self.name = name
        t = node_tangents(p)
        if section_vectors is None:
            g1 = transported_section_vectors(p)
        else:
            sv = np.array(section_vectors, dtype=float)
            if not np.all(np.isfinite(sv)):
                raise ValueError("section_vectors contains NaN or infinite values")
            if sv.shape == (3,):
                g1 = transported_section_vectors(p, sv)
            elif sv.shape == p.shape:
                g1 = sv - np.sum(sv * t, axis=1)[:, None] * t
                n = np.linalg.norm(g1, axis=1)
                if np.any(n < 1e-8 * np.linalg.norm(sv, axis=1)):
                    raise ValueError("section_vectors: a vector is parallel to the fibre's "
                                     "tangent")
                g1 = g1 / n[:, None]
            else:
                raise ValueError(f"section_vectors must have shape (3,) or {p.shape}, "
                                 f"got {sv.shape}")
        self.g1 = g1
        self.g2 = np.cross(t, g1)

    @property
    def num_nodes(self) -> int:
        return len(self.points)

    @property
    def length(self) -> float:
        """Length of the reference polyline."""
        return float(np.linalg.norm(np.diff(self.points, axis=0), axis=1).sum())

    def reference_dofs(self) -> np.ndarray:
        """(n, 9) reference unknowns [X0, G1, G2] per node."""
        return np.hstack([self.points, self.g1, self.g2])

    def __repr__(self):
        return (f"Fibre(name={self.name!r}, nodes={self.num_nodes}, radius={self.radius}, "
                f"length={self.length:.6g})")


def _num_nodes(num_elements: int, order: int) -> int:
    if isinstance(num_elements, bool) or not isinstance(num_elements, numbers.Integral) \
            or num_elements < 1:
        raise ValueError(f"num_elements must be a positive integer, got {num_elements!r}")
    if order not in (1, 2):
        raise ValueError(f"order must be 1 or 2, got {order!r}")
    return order * int(num_elements) + 1


def straight_fibre(start, end, radius, material, num_elements=10, order=2,
                   section_vector=None, name=None) -> Fibre:
    """A straight fibre from ``start`` to ``end`` with ``num_elements``
    elements of polynomial ``order`` (1 or 2)."""
    a = _as_points([start], "start")[0]
    b = _as_points([end], "end")[0]
    n = _num_nodes(num_elements, order)
    s = np.linspace(0.0, 1.0, n)[:, None]
    return Fibre(a + s * (b - a), radius, material, section_vector, name)


def arc_fibre(centre, radius_of_curvature, angle, radius, material, num_elements=10, order=2,
              name=None) -> Fibre:
    """A fibre along a circular arc in the plane z = centre[2]: from angle 0
    to ``angle`` (radians) about ``centre``; G1 points to the centre, G2 = z."""
    c = _as_points([centre], "centre")[0]
    rc = _check_positive(radius_of_curvature, "radius_of_curvature")
    n = _num_nodes(num_elements, order)
    phi = np.linspace(0.0, float(angle), n)
    pts = c + rc * np.column_stack([np.cos(phi), np.sin(phi), np.zeros(n)])
    inward = -np.column_stack([np.cos(phi), np.sin(phi), np.zeros(n)])
    return Fibre(pts, radius, material, inward, name)
