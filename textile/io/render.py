"""Pictures of a fibre sample a person would rather look at than read.

- :func:`render_fibres_png`: the fibres as tubes of their true radius,
  coloured by a per-fibre key (the yarn), from an oblique camera and
  optionally from the top; VTK, off-screen.
- :func:`sketch_fibres_png`: the same picture with matplotlib (lines whose
  width is the fibre's diameter at the picture's scale): the fallback when
  VTK cannot draw.
- :func:`render_cross_section_png`: a plane cut across the yarns (as
  Durville 2010, Fig. 10): each fibre's section drawn at its true radius.

**How VTK draws without a display.** Debian 12's VTK 9.1 renders through
X only (no EGL or OSMesa build), and aborts the whole process when it has
no X server. So the VTK scene (:mod:`textile.io.vtk_scene`) runs in a
child process, inside ``xvfb-run`` (a virtual X server; Mesa's llvmpipe
rasterizes) whenever ``xvfb-run`` exists, else on ``$DISPLAY``. A missing
VTK, X server or ``xvfb-run``, a crash or a timeout of that process raises
:class:`RenderingUnavailable` with the reason, never takes the caller
down; ``fallback=True`` draws the matplotlib sketch instead.

Conventions: lengths in model units; per-fibre arrays in fibre order;
colours from :func:`textile.io.palette.key_colours` (same yarn, same colour
in every picture). Serial: call on one MPI rank with gathered data. PNGs
are replaced atomically.
"""
from __future__ import annotations

import importlib.util
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import warnings
from collections.abc import Mapping

import numpy as np

from textile.io.cross_section import cut_fibres
from textile.io.palette import key_colours
from textile.io.vtu import check_centrelines

__all__ = ["RenderingUnavailable", "RenderingWarning", "read_fibres_vtu",
           "render_cross_section_png", "render_fibres_png", "sketch_fibres_png"]

_SCENE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "vtk_scene.py")
# a legend with more entries than this would hide the sample (fibre ids of a fabric)
_MAX_LEGEND = 12
# in-plane fibres of a cut: their colour mixed with white (a 1/2.2 share of colour)
_BAND_TINT = 2.2


class RenderingUnavailable(RuntimeError):
    """VTK cannot draw here: no VTK, no X server nor xvfb-run, or the
    rendering process failed. The message says which and what to install."""


class RenderingWarning(UserWarning):
    """A picture was drawn another way than asked (fallback), or not at all."""


# -- inputs ------------------------------------------------------------------------
def _per_fibre(values, n: int, name: str, positive: bool = False) -> np.ndarray:
    """A scalar broadcast, or an array of one value per fibre, checked."""
    a = np.asarray(values)
    if a.ndim == 0:
        a = np.full(n, a.item())
    if a.shape != (n,):
        raise ValueError(f"{name} must be one value per fibre ({n}), got shape {a.shape}")
    if a.dtype.kind not in "biuf":
        raise ValueError(f"{name} must be numbers, got dtype {a.dtype}")
    if a.dtype.kind == "f" and not np.all(np.isfinite(a)):
        raise ValueError(f"{name} contains non-finite values")
    if positive and not np.all(a > 0):
        raise ValueError(f"{name} must be positive")
    return a


def _fibres(centrelines, radii, fibre_key):
    """Checked (lines, radii, keys); keys default to the fibre index."""
    lines = check_centrelines(centrelines)
    n = len(lines)
    radii = _per_fibre(radii, n, "radii", positive=True).astype(float)
    keys = np.arange(n) if fibre_key is None else _per_fibre(fibre_key, n, "fibre_key")
    return lines, radii, keys


def _legend(keys: np.ndarray, labels: Mapping | None,
            shown: np.ndarray | None = None) -> list[tuple]:
    """[(key, text, rgb)] of the keys (of those ``shown``, default all), in key
    order; empty without labels or when there would be too many entries.
    Colours come from all ``keys``: a yarn keeps its colour in every picture."""
    colours = key_colours(keys)
    shown = set(np.asarray(keys if shown is None else shown).tolist())
    entries = [(k, str(labels.get(k, k)), rgb) for k, rgb in colours.items() if k in shown] \
        if labels is not None else []
    return entries if len(entries) <= _MAX_LEGEND else []


def read_fibres_vtu(path, key: str = "yarn"):
    """(centre lines, radius per fibre, key per fibre) of a fibres .vtu
    written by :func:`textile.io.vtu.write_fibres_vtu` with a ``radius``
    point array. ``key``: a point array colouring the fibres; the fibre id
    when the file has no such array."""
    import meshio

    mesh = meshio.read(path)
    data = mesh.point_data
    if "radius" not in data or "fibre_id" not in data:
        raise ValueError(f"{path}: needs the point arrays 'radius' and 'fibre_id' "
                         f"(has {sorted(data)})")
    fibre = np.asarray(data["fibre_id"]).ravel()
    starts = np.flatnonzero(np.r_[True, fibre[1:] != fibre[:-1]])
    lines = np.split(mesh.points, starts[1:])
    keys = np.asarray(data[key] if key in data else fibre).ravel()
    return lines, np.asarray(data["radius"]).ravel()[starts], keys[starts]


# -- VTK ---------------------------------------------------------------------------
def _scene_command(size) -> list[str]:
    """How to start the VTK scene process, or RenderingUnavailable."""
    if importlib.util.find_spec("vtkmodules") is None:
        raise RenderingUnavailable(f"{sys.executable} cannot import VTK: install python3-vtk9 "
                                   f"(Debian) and use Debian's python")
    command = [sys.executable, _SCENE]
    if shutil.which("xvfb-run") and shutil.which("xauth"):
        # the same software rasterizer everywhere, and no window on a desktop
        return ["xvfb-run", "-a", "-s", f"-screen 0 {size[0]}x{size[1]}x24 -nolisten tcp",
                *command]
    if os.environ.get("DISPLAY"):
        return command
    raise RenderingUnavailable("no X display for VTK: $DISPLAY is unset and xvfb-run (with "
                               "xauth) is not installed (apt-get install xvfb xauth); Debian's "
                               "VTK 9.1 renders through X only")


def _run_scene(command: list[str], job_path: str, timeout: float) -> None:
    # a session of its own: a timeout kills xvfb-run's X server with it
    process = subprocess.Popen([*command, job_path], stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, start_new_session=True)
    try:
        out, _ = process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        process.communicate()
        raise RenderingUnavailable(f"the VTK rendering process took more than {timeout:g} s "
                                   f"and was killed") from None
    if process.returncode != 0:
        # VTK's log colours its lines: no escape codes in a message
        text = re.sub(r"\x1b\[[0-9;]*m", "", out.decode(errors="replace")).strip()
        tail = "\n".join(text.splitlines()[-8:])
        code = process.returncode
        how = f"was killed by {signal.Signals(-code).name}" if code < 0 else f"exited with {code}"
        raise RenderingUnavailable(f"the VTK rendering process failed ({how}): {tail}")


def render_fibres_png(path, centrelines=None, radii=None, fibre_key=None, *, vtu=None,
                      key: str = "yarn", labels: Mapping | None = None, top_path=None,
                      size: tuple[int, int] = (1600, 1000), sides: int = 24,
                      fallback: bool = False, timeout: float = 180.0) -> str:
    """The fibres as tubes of their true radius, coloured by yarn, to PNG.

    Give either the fibres (``centrelines``: one (n_i, 3) array per fibre;
    ``radii``: one radius per fibre or one for all; ``fibre_key``: one
    integer or float per fibre choosing its colour, default the fibre
    index) or a written ``vtu`` (its point arrays ``radius`` and ``key``).

    ``path``: the oblique view; ``top_path``: also the view from +z (x to the
    right, y up, no perspective). ``labels``: {key: text} for a legend (e.g.
    {0: "warp 0"}). ``size``: pixels. ``sides``: of each tube.

    Returns the backend that drew: "vtk", or "matplotlib" when VTK could not
    and ``fallback`` is set (a :class:`RenderingWarning` says why).
    Raises :class:`RenderingUnavailable` when VTK cannot draw and
    ``fallback`` is not set; ValueError on bad input (either way, before any
    file is written).
    """
    if (vtu is None) == (centrelines is None):
        raise ValueError("give either centrelines (with radii) or vtu")
    if vtu is not None:
        centrelines, radii, fibre_key = read_fibres_vtu(vtu, key)
    elif radii is None:
        raise ValueError("radii are needed with centrelines (one per fibre, or one for all)")
    lines, radii, keys = _fibres(centrelines, radii, fibre_key)
    width, height = (int(v) for v in size)
    if width < 16 or height < 16:
        raise ValueError(f"size must be at least 16 x 16 pixels, got {size!r}")
    try:
        command = _scene_command((width, height))
        counts = np.array([len(x) for x in lines])
        colours = key_colours(keys)
        rgb = np.array([colours[k] for k in keys.tolist()])
        with tempfile.TemporaryDirectory(prefix="textile-render-") as tmp:
            arrays = os.path.join(tmp, "fibres.npz")
            np.savez(arrays, points=np.concatenate(lines), counts=counts,
                     radius=np.repeat(radii, counts),
                     rgb=np.repeat(np.rint(255 * rgb).astype(np.uint8), counts, axis=0))
            views = [["oblique", os.path.abspath(path)]]
            if top_path is not None:
                views.append(["top", os.path.abspath(top_path)])
            legend = [(text, rgb) for _, text, rgb in _legend(keys, labels)]
            job = dict(arrays=arrays, legend=legend, size=[width, height],
                       views=views, sides=int(sides))
            job_path = os.path.join(tmp, "job.json")
            with open(job_path, "w") as f:
                json.dump(job, f)
            _run_scene(command, job_path, timeout)
        return "vtk"
    except RenderingUnavailable as e:
        if not fallback:
            raise
        warnings.warn(f"{e}; drawing {os.path.basename(path)} with matplotlib instead",
                      RenderingWarning, stacklevel=2)
    sketch_fibres_png(path, lines, radii, keys, labels=labels, top_path=top_path, size=size)
    return "matplotlib"


# -- matplotlib --------------------------------------------------------------------
def _figure(size_px: tuple[int, int]):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from textile.io.plots import _DPI
    fig = Figure(figsize=(size_px[0] / _DPI, size_px[1] / _DPI), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _shade(rgb, factor: float) -> tuple:
    """``rgb`` darkened (factor < 1) or mixed with white (factor > 1)."""
    c = np.asarray(rgb, dtype=float)
    return tuple(c * factor if factor <= 1 else 1 - (1 - c) / factor)


def _legend_handles(legend: list) -> list:
    from matplotlib.lines import Line2D
    return [Line2D([], [], color=rgb, marker="o", linestyle="", markersize=8, label=text)
            for _, text, rgb in legend]


def _points_per_unit(fig, ax, view: str, centre: np.ndarray) -> float:
    """Typographic points per model length unit on the screen plane."""
    fig.canvas.draw()    # settles the layout, hence the axes' transforms
    if view == "top":
        ends = np.array([centre[:2], centre[:2] + [1.0, 0.0]])
    else:
        from mpl_toolkits.mplot3d.proj3d import proj_transform
        azim = np.radians(ax.azim)
        across = np.array([-np.sin(azim), np.cos(azim), 0.0])   # horizontal, normal to the view
        x, y, _ = proj_transform(*np.array([centre, centre + across]).T, ax.get_proj())
        ends = np.column_stack([x, y])
    pixels = ax.transData.transform(ends)
    return float(np.linalg.norm(pixels[1] - pixels[0])) * 72 / fig.dpi


def sketch_fibres_png(path, centrelines, radii, fibre_key=None, *, labels=None, top_path=None,
                      size: tuple[int, int] = (1600, 1000)) -> None:
    """Matplotlib stand-in for :func:`render_fibres_png` (same arguments):
    each centre line drawn as a line as wide as the fibre's diameter at the
    picture's scale (orthographic views: exact for a fibre across the line
    of sight), same colours and camera directions; no shading."""
    from matplotlib import patheffects

    from textile.io.plots import _equal_aspect_3d, _save_png

    lines, radii, keys = _fibres(centrelines, radii, fibre_key)
    colours = key_colours(keys)
    legend = _legend(keys, labels)
    points = np.concatenate(lines)
    lo, hi = points.min(axis=0) - radii.max(), points.max(axis=0) + radii.max()
    for view, target in (("oblique", path), ("top", top_path)):
        if target is None:
            continue
        fig = _figure(size)
        if view == "top":
            ax = fig.add_subplot()
            ax.set_xlim(lo[0], hi[0])
            ax.set_ylim(lo[1], hi[1])
            ax.set_aspect("equal")
            ax.set_xlabel("x")
            ax.set_ylabel("y")
        else:
            ax = fig.add_subplot(projection="3d", proj_type="ortho")
            ax.view_init(elev=32, azim=-55)     # vtk_scene's AZIMUTH, ELEVATION
            _equal_aspect_3d(ax, np.vstack([lo, hi]))
        scale = _points_per_unit(fig, ax, view, (lo + hi) / 2)
        for x, r, k in zip(lines, radii, keys.tolist()):
            xy = x[:, :2].T if view == "top" else x.T
            width = 2 * r * scale
            # a dark rim (the outer 10% of the width) tells neighbouring fibres apart
            rim = [patheffects.Stroke(linewidth=width, foreground=_shade(colours[k], 0.6)),
                   patheffects.Normal()]
            ax.plot(*xy, color=colours[k], linewidth=0.8 * width, solid_capstyle="butt",
                    path_effects=rim)
        if legend:
            ax.legend(handles=_legend_handles(legend), loc="upper right", frameon=False)
        _save_png(fig, target)


def render_cross_section_png(centrelines, radii, fibre_key, plane, path, *,
                             labels: Mapping | None = None, depth: float | None = None,
                             parallel: float = 0.25, title: str = "",
                             unit: str | None = None, width_px: int = 1600) -> None:
    """A cut across the yarns: every fibre's section where it crosses
    ``plane`` = (point, normal), to PNG (see :mod:`textile.io.cross_section`).

    Fibres crossing the plane are ellipses of their true radius (stretched
    by 1/|t . n| when oblique); fibres lying nearly in it (|t . n| <
    ``parallel``) are their projected bands within ``depth`` of the plane
    (default: each fibre's radius), drawn lighter and behind. Colours by
    ``fibre_key`` (default the fibre index), legend from ``labels``
    ({key: text}); equal axes labelled with the in-plane model coordinates
    and ``unit`` (default "model units").
    """
    from matplotlib.patches import Ellipse, Polygon

    from textile.io.plots import _save_png

    lines, radii, keys = _fibres(centrelines, radii, fibre_key)
    try:
        point, normal = plane
    except (TypeError, ValueError):
        raise ValueError(f"plane must be (point, normal), got {plane!r}") from None
    cut = cut_fibres(lines, radii, point, normal, parallel=parallel, depth=depth)
    colours = key_colours(keys)
    shapes = [e.centre + np.array([[-m, -m], [m, m]])
              for e in cut.ellipses for m in (max(e.semi_axes),)]
    shapes += [np.array([b.outline.min(axis=0), b.outline.max(axis=0)]) for b in cut.bands]
    if shapes:
        box = np.vstack(shapes)
        lo, hi = box.min(axis=0), box.max(axis=0)
    else:
        lo, hi = np.zeros(2), np.ones(2)
    span = np.maximum(hi - lo, 1e-12)
    aspect = span[1] / span[0]
    width_in = width_px / 150
    fig = _figure((width_px, int(150 * min(max(width_in * aspect + 1.4, 3.0), 9.0))))
    ax = fig.add_subplot()
    # bands first and lighter: they are the context the sections sit in;
    # the farthest (most negative depth) first so nearer ones cover them
    for band in sorted(cut.bands, key=lambda b: b.depth):
        colour = colours[keys[band.fibre].item()]
        ax.add_patch(Polygon(band.outline, closed=True, facecolor=_shade(colour, _BAND_TINT),
                             edgecolor=_shade(colour, 0.8), linewidth=0.4, zorder=1))
    for e in cut.ellipses:
        ax.add_patch(Ellipse(e.centre, 2 * e.semi_axes[0], 2 * e.semi_axes[1], angle=e.angle,
                             facecolor=colours[keys[e.fibre].item()], edgecolor="0.15",
                             linewidth=0.4, zorder=2))
    if not shapes:
        ax.text(0.5, 0.5, "no fibre crosses this plane", transform=ax.transAxes,
                ha="center", va="center")
    margin = 0.04 * span.max()
    ax.set_xlim(lo[0] - margin, hi[0] + margin)
    ax.set_ylim(lo[1] - margin, hi[1] + margin)
    ax.set_aspect("equal")
    units = unit or "model units"
    ax.set_xlabel(f"{cut.axis_names[0]} [{units}]")
    ax.set_ylabel(f"{cut.axis_names[1]} [{units}]")
    ax.grid(True, linewidth=0.3, alpha=0.5)
    ax.set_axisbelow(True)
    sections = set(keys[[e.fibre for e in cut.ellipses]].tolist())
    cut_keys = keys[[e.fibre for e in cut.ellipses] + [b.fibre for b in cut.bands]]
    # a yarn seen only as bands is named so, in the bands' tint
    legend = [(k, text, rgb) if k in sections else
              (k, f"{text} (in the plane)", _shade(rgb, _BAND_TINT))
              for k, text, rgb in _legend(keys, labels, shown=cut_keys)]
    if legend:
        ax.legend(handles=_legend_handles(legend), loc="upper left", bbox_to_anchor=(1.0, 1.0),
                  frameon=False)
    if title:
        ax.set_title(title)
    _save_png(fig, path)
