"""Headless PNG plots of fibre geometry and load curves.

Figures are rendered with matplotlib's Agg canvas
(:class:`matplotlib.backends.backend_agg.FigureCanvasAgg`) attached explicitly
to a stand-alone :class:`matplotlib.figure.Figure`. This never opens a
display and, unlike ``matplotlib.use("Agg")``, does not switch the global
backend of an interactive session that happens to import this module; no
pyplot state is created, so figures cannot leak between calls.

PNG files are written atomically. These functions are serial: call them on
one MPI rank with gathered data.
"""

from __future__ import annotations

import io
import os
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from textile.io.vtu import atomic_write_bytes, check_centrelines

__all__ = ["plot_curve", "plot_fibres"]

# Axis indices shown by each 2D projection.
_PROJECTIONS = {"xy": (0, 1), "xz": (0, 2), "yz": (1, 2)}
_AXIS_NAMES = "xyz"
_REFERENCE_STYLE = {"color": "0.6", "linestyle": "--", "linewidth": 1.0, "zorder": 1}
_DPI = 150


def _new_figure() -> Figure:
    """A stand-alone figure bound to an Agg canvas."""
    fig = Figure(figsize=(6.4, 4.8), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _save_png(fig: Figure, path: str | os.PathLike) -> None:
    """Render ``fig`` to PNG and write it atomically to ``path``."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=_DPI)
    atomic_write_bytes(path, buf.getvalue())


def _equal_aspect_3d(ax, points: np.ndarray) -> None:
    """Give a 3D axes equal scaling on x, y and z around ``points`` (m, 3).

    The box is shaped like the data (not a cube) so long, thin fibre bundles
    stay readable, but each side is at least 20% of the largest extent so
    flat (e.g. planar) geometry does not collapse the box.
    """
    lo, hi = points.min(axis=0), points.max(axis=0)
    largest = float(np.max(hi - lo))
    span = np.maximum(hi - lo, 0.2 * largest if largest > 0 else 1.0) * 1.05
    centre = 0.5 * (lo + hi)
    ax.set_xlim(centre[0] - span[0] / 2, centre[0] + span[0] / 2)
    ax.set_ylim(centre[1] - span[1] / 2, centre[1] + span[1] / 2)
    ax.set_zlim(centre[2] - span[2] / 2, centre[2] + span[2] / 2)
    # Box side lengths proportional to the axis ranges -> equal unit lengths.
    ax.set_box_aspect(tuple(span))
    # Fewer ticks on short sides, whose tick labels would otherwise overlap.
    for axis, s in zip((ax.xaxis, ax.yaxis, ax.zaxis), span):
        axis.set_major_locator(MaxNLocator(nbins=max(2, round(6 * s / span.max()))))


def plot_fibres(
    path: str | os.PathLike,
    centrelines: Sequence[npt.ArrayLike],
    title: str = "",
    reference: Sequence[npt.ArrayLike] | None = None,
    view: str = "3d",
) -> None:
    """Plot fibre centre lines to a PNG file.

    Args:
        path: Output PNG file; its directory must exist.
        centrelines: One array of shape ``(n_i, 3)`` per fibre, ``n_i >= 2``
            (model length units); each fibre gets its own colour.
        title: Figure title.
        reference: Optional centre lines in the same format drawn as dashed
            grey lines underneath, e.g. the undeformed configuration.
        view: ``"3d"`` for a 3D view, or ``"xy"``, ``"xz"``, ``"yz"`` for the
            projection onto that coordinate plane. All views use equal
            scaling of the axes.

    Raises:
        ValueError: On an unknown ``view`` or malformed/non-finite
            ``centrelines`` or ``reference`` (the argument is named).
    """
    if view != "3d" and view not in _PROJECTIONS:
        raise ValueError(f"view must be one of '3d', 'xy', 'xz', 'yz'; got {view!r}")
    lines = check_centrelines(centrelines, "centrelines")
    ref = check_centrelines(reference, "reference") if reference is not None else []
    axes_idx = (0, 1, 2) if view == "3d" else _PROJECTIONS[view]

    fig = _new_figure()
    ax = fig.add_subplot(projection="3d" if view == "3d" else None)
    for i, x in enumerate(ref):
        ax.plot(*x[:, axes_idx].T, label="reference" if i == 0 else None, **_REFERENCE_STYLE)
    for x in lines:
        ax.plot(*x[:, axes_idx].T, linewidth=1.5, zorder=2)

    ax.set_xlabel(_AXIS_NAMES[axes_idx[0]])
    ax.set_ylabel(_AXIS_NAMES[axes_idx[1]])
    if view == "3d":
        ax.set_zlabel("z")
        _equal_aspect_3d(ax, np.concatenate(lines + ref))
    else:
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, linewidth=0.3)
    if ref:
        ax.legend(loc="best")
    if title:
        ax.set_title(title)
    _save_png(fig, path)


def _check_curve(x: npt.ArrayLike, y: npt.ArrayLike, xname: str, yname: str):
    """Validate one curve: 1-D, equal lengths, finite. Returns float arrays."""
    xa = np.asarray(x, dtype=np.float64)
    ya = np.asarray(y, dtype=np.float64)
    for a, name in ((xa, xname), (ya, yname)):
        if a.ndim != 1 or a.size == 0:
            raise ValueError(f"{name} must be a non-empty 1-D array; got shape {a.shape}")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"{name} contains non-finite (NaN/inf) values")
    if xa.shape != ya.shape:
        raise ValueError(
            f"{xname} and {yname} must have the same length; got {xa.size} and {ya.size}"
        )
    return xa, ya


def _is_list_of_arrays(v) -> bool:
    """True if ``v`` is a list/tuple whose items are themselves array-like."""
    return isinstance(v, (list, tuple)) and len(v) > 0 and all(np.ndim(e) >= 1 for e in v)


def _curves(x, y, label) -> list[tuple[np.ndarray, np.ndarray, str | None]]:
    """Normalise single- or multi-curve arguments to ``[(x, y, label), ...]``."""
    if not _is_list_of_arrays(y):
        if label is not None and not isinstance(label, str):
            raise ValueError(f"label must be a string for a single curve; got {label!r}")
        return [(*_check_curve(x, y, "x", "y"), label)]

    n = len(y)
    shared_x = not _is_list_of_arrays(x)
    xs = [x] * n if shared_x else list(x)
    if len(xs) != n:
        raise ValueError(
            f"x must be one array or a list of {n} arrays (one per curve); got {len(xs)}"
        )
    labels = [None] * n if label is None else label
    if isinstance(labels, str) or len(labels) != n:
        raise ValueError(f"label must be a list of {n} labels (one per curve in y); got {label!r}")
    xnames = ["x" if shared_x else f"x[{i}]" for i in range(n)]
    return [
        (*_check_curve(xi, yi, xn, f"y[{i}]"), lab)
        for i, (xi, yi, xn, lab) in enumerate(zip(xs, y, xnames, labels))
    ]


def plot_curve(
    path: str | os.PathLike,
    x: npt.ArrayLike | Sequence[npt.ArrayLike],
    y: npt.ArrayLike | Sequence[npt.ArrayLike],
    xlabel: str,
    ylabel: str,
    title: str = "",
    label: str | Sequence[str | None] | None = None,
    reference: tuple | None = None,
) -> None:
    """Plot one or several curves (e.g. load-displacement) to a PNG file.

    Args:
        path: Output PNG file; its directory must exist.
        x: Abscissae, shape ``(n,)``. With several curves, either one array
            shared by all curves or a list with one array per curve.
        y: Ordinates, shape ``(n,)``, or a list of such arrays for several
            curves (drawn with solid lines and markers).
        xlabel: Label of the x axis (include units, e.g. ``"u [mm]"``).
        ylabel: Label of the y axis (include units).
        title: Figure title.
        label: Legend label of the curve, or a list with one label (or None)
            per curve when ``y`` is a list.
        reference: Optional ``(x_ref, y_ref, label)`` drawn as a dashed
            line, e.g. an analytical solution; ``label`` may be None.

    Raises:
        ValueError: On mismatched lengths, non-1-D or non-finite data, or a
            wrong number of labels (the argument is named).
    """
    curves = _curves(x, y, label)
    ref = None
    if reference is not None:
        if not isinstance(reference, (list, tuple)) or len(reference) != 3:
            raise ValueError("reference must be a tuple (x_ref, y_ref, label)")
        x_ref, y_ref = _check_curve(reference[0], reference[1], "reference x", "reference y")
        ref = (x_ref, y_ref, reference[2])

    fig = _new_figure()
    ax = fig.add_subplot()
    for xc, yc, lab in curves:
        ax.plot(xc, yc, marker="o", markersize=3, linewidth=1.5, label=lab)
    if ref is not None:
        ax.plot(ref[0], ref[1], color="k", linestyle="--", linewidth=1.0, label=ref[2])

    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, linewidth=0.3)
    if title:
        ax.set_title(title)
    if any(lab is not None for *_, lab in curves) or (ref is not None and ref[2] is not None):
        ax.legend(loc="best")
    _save_png(fig, path)
