"""The pictures :class:`textile.Output` draws of a sample's state.

- ``sample.png`` (oblique) and ``sample_top.png``: the fibres as tubes of
  their true radius, coloured by yarn (:func:`textile.io.render.render_fibres_png`,
  with the matplotlib sketch as fallback);
- ``cut_<direction>.png``: one cut per yarn direction, normal to it
  (``cut_warp.png`` cuts across the warp yarns), through the yarn of
  another direction nearest the sample's middle, so that yarn lies in the
  picture as a band with the sections above and below it; that yarn's
  fibres are drawn as bands over its whole thickness;
- ``cut.png`` when no yarn directions are known: normal to the mean fibre
  direction, through the middle of the sample.

Yarn directions: one per yarn id (the values of ``fibre_data["yarn"]``),
``"warp"`` (x) or ``"weft"`` (y) as :mod:`textile.fabric` lays them, or a
3-vector. :func:`fabric_labels` gives both arguments for a
:class:`~textile.fabric.Fabric`. Lengths in model units; serial (rank 0).

:func:`draw_vtu_pictures` draws them from a written ``fibres_<step>.vtu``
(its centre lines, ``radius`` and ``yarn`` arrays): what Output does at a
stage's end, and what can be done after a run for any written step.
"""
from __future__ import annotations

import os
import warnings
from collections.abc import Mapping
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from textile.io.render import (RenderingUnavailable, RenderingWarning, render_cross_section_png,
                               render_fibres_png, sketch_fibres_png)

__all__ = ["CutPlane", "cut_planes", "draw_sample_pictures", "draw_state_pictures",
           "draw_vtu_pictures",
           "fabric_labels", "read_fibres_vtu", "yarn_axes", "yarn_labels"]

#: :mod:`textile.fabric`'s convention: warp yarns along x, weft yarns along y.
NAMED_DIRECTIONS = {"warp": (1.0, 0.0, 0.0), "weft": (0.0, 1.0, 0.0)}


def fabric_labels(fabric) -> dict:
    """``fibre_data`` and ``yarn_directions`` of a :class:`~textile.fabric.Fabric`,
    for ``textile.Output(directory, **fabric_labels(fabric))``."""
    fabric.fibres()      # sets fabric.fibre_yarn
    return dict(fibre_data={"yarn": np.asarray(fabric.fibre_yarn)},
                yarn_directions=[fabric.yarn_direction(k) for k in range(fabric.num_yarns)])


def yarn_axes(yarn_directions) -> dict:
    """{yarn: (name, unit vector)} from a sequence (index = yarn id) or a
    mapping of "warp", "weft" or 3-vectors. A vector along a coordinate
    axis is named after it ("x"), any other "dir<i>"."""
    items = yarn_directions.items() if isinstance(yarn_directions, Mapping) \
        else enumerate(yarn_directions)
    out, skew = {}, []
    for yarn, d in items:
        if isinstance(d, str):
            if d not in NAMED_DIRECTIONS:
                raise ValueError(f"yarn {yarn}: direction {d!r} is not one of "
                                 f"{sorted(NAMED_DIRECTIONS)} nor a 3-vector")
            out[yarn] = (d, np.array(NAMED_DIRECTIONS[d]))
            continue
        v = np.asarray(d, dtype=float)
        if v.shape != (3,) or not np.all(np.isfinite(v)) or not np.linalg.norm(v) > 0:
            raise ValueError(f"yarn {yarn}: direction must be 'warp', 'weft' or a non-zero "
                             f"3-vector, got {d!r}")
        v = v / np.linalg.norm(v)
        axis = int(np.argmax(np.abs(v)))
        if abs(v[axis]) > 1 - 1e-9:
            name = "xyz"[axis]
        else:
            known = [i for i, w in enumerate(skew) if abs(np.dot(w, v)) > 1 - 1e-9]
            if not known:
                skew.append(v)
            name = f"dir{known[0] if known else len(skew) - 1}"
        out[yarn] = (name, v)
    return out


def yarn_labels(yarns, axes: dict | None) -> dict:
    """{yarn: "warp 0", ...}: each direction's yarns counted in id order
    (as Fabric numbers them); "yarn <id>" without directions."""
    yarns = sorted(set(np.asarray(yarns).tolist()))
    if not axes:
        return {k: f"yarn {k}" for k in yarns}
    count: dict = {}
    labels = {}
    for k in yarns:
        name = axes[k][0]
        labels[k] = f"{name} {count.get(name, 0)}"
        count[name] = count.get(name, 0) + 1
    return labels


@dataclass(frozen=True)
class CutPlane:
    name: str            # the picture is cut_<name>.png ("cut.png" for name "")
    point: np.ndarray
    normal: np.ndarray
    depth: float | None  # slab of the in-plane fibres drawn as bands (None: radius)
    title: str


def _coordinate(normal: np.ndarray) -> str:
    """How the plane's position reads: "x" for a plane normal to x."""
    axis = int(np.argmax(np.abs(normal)))
    return "xyz"[axis] if abs(normal[axis]) > 1 - 1e-9 else "s"


def _reads(value: float, decimals: int) -> float:
    """``value`` rounded for a title (+ 0.0 turns -0.0 into 0.0)."""
    return round(float(value), decimals) + 0.0


def cut_planes(lines, radii, yarn, axes: dict | None) -> list[CutPlane]:
    """The cuts of the module docstring for fibres ``lines`` (one (n, 3)
    array each), ``radii`` and ``yarn`` (per fibre; None: no yarns)."""
    points = np.concatenate(lines)
    radii = np.asarray(radii, dtype=float)
    if not axes or yarn is None:
        chords = np.array([x[-1] - x[0] for x in lines])
        # fibres running against the first one count in its direction
        chords *= np.where(chords @ chords[0] < 0, -1.0, 1.0)[:, None]
        normal = chords.sum(axis=0)
        normal = normal / np.linalg.norm(normal) if np.linalg.norm(normal) > 0 \
            else np.array([1.0, 0.0, 0.0])
        middle = (points.min(axis=0) + points.max(axis=0)) / 2
        return [CutPlane("", middle, normal, None,
                         "cut normal to the mean fibre direction, through the sample's middle")]
    yarn = np.asarray(yarn)
    labels = yarn_labels(yarn, axes)
    # a position is written to 1e-4 of the sample's size: "x = 0", not "x = -2.1e-07"
    decimals = 4 - int(np.ceil(np.log10(np.ptp(points, axis=0).max())))
    planes = []
    for name in dict.fromkeys(n for n, _ in axes.values()):
        normal = next(v for n, v in axes.values() if n == name)
        s = points @ normal
        middle = (s.min() + s.max()) / 2
        across = [k for k in np.unique(yarn).tolist() if abs(np.dot(axes[k][1], normal)) < 0.5]
        coordinate = _coordinate(normal)
        if not across:
            planes.append(CutPlane(name, middle * normal, normal, None,
                                   f"{name} yarns cut at {coordinate} = "
                                   f"{_reads(middle, decimals):.4g}"))
            continue
        # each fibre's mean position along the normal, per yarn lying across
        fibre_s = {f: float(np.mean(lines[f] @ normal)) for f in range(len(lines))}
        yarn_s = {k: np.mean([fibre_s[f] for f in np.flatnonzero(yarn == k)]) for k in across}
        through = min(across, key=lambda k: abs(yarn_s[k] - middle))
        position = yarn_s[through]
        depth = max(abs(fibre_s[f] - position) + radii[f] for f in np.flatnonzero(yarn == through))
        planes.append(CutPlane(name, position * normal, normal, depth,
                               f"{name} yarns cut at {coordinate} = "
                               f"{_reads(position, decimals):.4g}, "
                               f"through {labels[through]}"))
    return planes


def draw_sample_pictures(directory: str, lines, radii, yarn=None, axes: dict | None = None,
                         suffix: str = "", size=(1600, 1000),
                         unit: str | None = None) -> tuple[dict, list[str]]:
    """Draw sample<suffix>.png, sample_top<suffix>.png and the cuts in
    ``directory`` (``yarn``: per fibre; ``axes``: :func:`yarn_axes`;
    ``size``: of the 3D pictures, pixels; ``unit``: of length, on the cuts'
    axes). Each picture on its own: one
    failing does not stop the others. Returns ({file: "vtk" |
    "matplotlib"}, [error messages])."""
    key = np.arange(len(lines)) if yarn is None else np.asarray(yarn)
    labels = yarn_labels(key, axes) if yarn is not None \
        else {f: f"fibre {f}" for f in range(len(lines))}
    drawn, errors = {}, []
    sample = os.path.join(directory, f"sample{suffix}.png")
    top = os.path.join(directory, f"sample_top{suffix}.png")
    with ThreadPoolExecutor(max_workers=1) as pool:
        # VTK draws the 3D views in its own process while matplotlib draws
        # the cuts here (the thread only waits for that process)
        views = pool.submit(render_fibres_png, sample, lines, radii, key, labels=labels,
                            top_path=top, size=size)
        cuts = _draw_cuts(directory, lines, radii, yarn, key, labels, axes, suffix, unit,
                          errors)
        try:
            try:
                backend = views.result()
            except RenderingUnavailable as e:
                # matplotlib stands in, here (not beside the cuts' figures)
                warnings.warn(f"{e}; drawing {os.path.basename(sample)} with matplotlib "
                              f"instead", RenderingWarning, stacklevel=2)
                sketch_fibres_png(sample, lines, radii, key, labels=labels, top_path=top,
                                  size=size)
                backend = "matplotlib"
            drawn.update({os.path.basename(sample): backend, os.path.basename(top): backend})
        except Exception as e:     # a picture must never cost the results
            errors.insert(0, f"{os.path.basename(sample)}: {type(e).__name__}: {e}")
    drawn.update(cuts)
    return drawn, errors


def _draw_cuts(directory, lines, radii, yarn, key, labels, axes, suffix, unit,
               errors: list) -> dict:
    """The cuts of :func:`draw_sample_pictures` ({file: "matplotlib"});
    failures are appended to ``errors``."""
    drawn = {}
    try:
        planes = cut_planes(lines, radii, yarn, axes)
    except Exception as e:
        errors.append(f"cut planes: {type(e).__name__}: {e}")
        planes = []
    for plane in planes:
        name = f"cut_{plane.name}{suffix}.png" if plane.name else f"cut{suffix}.png"
        try:
            render_cross_section_png(lines, radii, key, (plane.point, plane.normal),
                                     os.path.join(directory, name), labels=labels,
                                     depth=plane.depth, title=plane.title, unit=unit)
            drawn[name] = "matplotlib"
        except Exception as e:
            errors.append(f"{name}: {type(e).__name__}: {e}")
    return drawn


def read_fibres_vtu(path: str) -> tuple[list[np.ndarray], np.ndarray, np.ndarray | None]:
    """(centre lines, radius per fibre, yarn per fibre or None) of a fibres
    .vtu written by :func:`textile.io.vtu.write_fibres_vtu` with a
    ``radius`` point array (as :class:`textile.Output` writes them)."""
    import meshio

    mesh = meshio.read(path)
    data = mesh.point_data
    if "fibre_id" not in data or "radius" not in data:
        raise ValueError(f"{path}: not a fibres file (needs point arrays fibre_id and radius)")
    fibre = np.asarray(data["fibre_id"])
    first = np.flatnonzero(np.r_[True, np.diff(fibre) != 0])
    lines = np.split(np.asarray(mesh.points, dtype=float), first[1:])
    yarn = np.asarray(data["yarn"])[first] if "yarn" in data else None
    return lines, np.asarray(data["radius"], dtype=float)[first], yarn


def draw_vtu_pictures(vtu: str, directory: str | None = None, axes: dict | None = None,
                      suffix: str = "", size=(1600, 1000),
                      unit: str | None = None) -> tuple[dict, list[str]]:
    """:func:`draw_sample_pictures` of the state in the fibres file ``vtu``
    (in ``directory``, default the file's); fibres coloured by its ``yarn``
    array when it has one."""
    lines, radii, yarn = read_fibres_vtu(vtu)
    return draw_sample_pictures(os.path.dirname(os.path.abspath(vtu)) if directory is None
                                else directory, lines, radii, yarn, axes, suffix, size, unit)


def draw_state_pictures(state: str, directory: str, axes: dict | None = None,
                        suffix: str = "", size=(1600, 1000),
                        unit: str | None = None, yarn=None) -> tuple[dict, list[str]]:
    """:func:`draw_sample_pictures` of the fibres of a saved state
    (:func:`textile.save_state`), in ``directory``; fibres coloured by
    ``yarn`` (one yarn number per fibre), else by the state's ``yarn``
    fibre data when it has one (``axes``: :func:`yarn_axes` of the yarns'
    directions, for cuts across each)."""
    from .state_file import saved_fibres

    lines, radii, data = saved_fibres(state)
    if yarn is None:
        yarn = data.get("yarn")
    elif len(yarn) != len(lines):
        raise ValueError(f"draw_state_pictures: {len(yarn)} yarn numbers for the "
                         f"{len(lines)} fibres of {state}")
    os.makedirs(directory, exist_ok=True)
    return draw_sample_pictures(directory, lines, radii, yarn, axes, suffix, size, unit)
