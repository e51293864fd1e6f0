"""Fibres as tubes of their true radius, rendered to PNG with VTK.

This file is a stand-alone script, run in its own process by
:func:`textile.io.render.render_fibres_png`:

    python3 vtk_scene.py job.json

It imports neither textile nor MPI, so it can run from inside an
``mpirun`` rank, and a crash of the OpenGL stack (Debian's VTK 9.1 aborts
the whole process when it has no X display) costs this process only.

``job.json`` holds:

- ``arrays``: an .npz with ``points`` (N, 3) (the fibres' centre-line
  points, fibre after fibre), ``counts`` (points of each fibre),
  ``radius`` (N,) and ``rgb`` (N, 3) uint8 colours;
- ``legend``: [[text, [r, g, b]], ...] (components 0..1; empty: no legend);
- ``size``: [width, height] in pixels;
- ``views``: [[view, png path], ...], view ``"oblique"`` or ``"top"``;
- ``sides``: number of sides of the tubes.

Model length units throughout; the camera only looks, it never scales.
"""
from __future__ import annotations

import json
import math
import os
import sys

# Only the modules used: `import vtk` would load every VTK module (MPI ones too).
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
from vtkmodules.vtkFiltersCore import vtkTubeFilter
from vtkmodules.vtkFiltersSources import vtkRegularPolygonSource
from vtkmodules.vtkIOImage import vtkPNGWriter
from vtkmodules.vtkRenderingAnnotation import vtkAxesActor, vtkLegendBoxActor
from vtkmodules.vtkRenderingCore import (vtkActor, vtkLightKit, vtkPolyDataMapper, vtkRenderer,
                                         vtkRenderWindow, vtkWindowToImageFilter)
import vtkmodules.vtkRenderingFreeType  # noqa: F401  (text of the legend and the axes)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the OpenGL render window)

import numpy as np

# Oblique view: looking down at ELEVATION degrees from the fabric plane, from
# AZIMUTH degrees about z measured from the -y axis: both yarn directions of
# a fabric (x and y) stay visible, and the crossings' relief shows.
AZIMUTH, ELEVATION = 35.0, 32.0
VIEW_ANGLE = 20.0   # degrees: a long lens, little perspective distortion
MARGIN = 1.06       # white space around the sample


def fibre_polylines(points: np.ndarray, counts: np.ndarray) -> vtkPolyData:
    """One polyline per fibre: a tube filter given one cell per segment
    would cap and seam every segment."""
    cells = vtkCellArray()
    start = 0
    for n in counts.tolist():
        cells.InsertNextCell(n, list(range(start, start + n)))
        start += n
    vtk_points = vtkPoints()
    vtk_points.SetData(numpy_to_vtk(np.ascontiguousarray(points, dtype=np.float64), deep=True))
    poly = vtkPolyData()
    poly.SetPoints(vtk_points)
    poly.SetLines(cells)
    return poly


def tubes(arrays, sides: int) -> vtkTubeFilter:
    """Tubes of radius ``arrays["radius"]`` around the fibres' centre lines."""
    poly = fibre_polylines(arrays["points"], arrays["counts"])
    radius = numpy_to_vtk(np.ascontiguousarray(arrays["radius"], dtype=np.float64), deep=True)
    radius.SetName("radius")
    rgb = numpy_to_vtk(np.ascontiguousarray(arrays["rgb"], dtype=np.uint8), deep=True)
    rgb.SetName("colours")
    poly.GetPointData().SetScalars(radius)      # the tube filter's radius
    poly.GetPointData().AddArray(rgb)
    tube = vtkTubeFilter()
    tube.SetInputData(poly)
    tube.SetVaryRadiusToVaryRadiusByAbsoluteScalar()
    tube.SetNumberOfSides(sides)
    tube.CappingOn()
    tube.Update()
    return tube


def fibre_actor(tube: vtkTubeFilter) -> vtkActor:
    mapper = vtkPolyDataMapper()
    mapper.SetInputConnection(tube.GetOutputPort())
    mapper.SetScalarModeToUsePointFieldData()
    mapper.SelectColorArray("colours")
    mapper.SetColorModeToDirectScalars()
    mapper.ScalarVisibilityOn()
    actor = vtkActor()
    actor.SetMapper(mapper)
    prop = actor.GetProperty()
    prop.SetInterpolationToPhong()
    # little ambient light: the screen-space ambient occlusion darkens the
    # grooves between fibres, which shows how they are packed
    prop.SetAmbient(0.1)
    prop.SetDiffuse(0.9)
    prop.SetSpecular(0.3)
    prop.SetSpecularPower(40)
    return actor


def place_camera(renderer: vtkRenderer, view: str, bounds: np.ndarray, width: int,
                 height: int) -> None:
    """Frame the whole sample from the oblique or the top view."""
    centre = bounds.mean(axis=0)
    camera = renderer.GetActiveCamera()
    if view == "top":
        direction, up = np.array([0.0, 0.0, 1.0]), (0.0, 1.0, 0.0)
        camera.ParallelProjectionOn()
    elif view == "oblique":
        az, el = math.radians(AZIMUTH), math.radians(ELEVATION)
        # from the focal point towards the camera: in front (-y), to the right (+x), above (+z)
        direction = np.array([math.sin(az) * math.cos(el), -math.cos(az) * math.cos(el),
                              math.sin(el)])
        up = (0.0, 0.0, 1.0)
        camera.ParallelProjectionOff()
        camera.SetViewAngle(VIEW_ANGLE)
    else:
        raise ValueError(f"unknown view {view!r}: 'oblique' or 'top'")
    # the box's corners in the camera's frame (right, up, towards the camera)
    w = direction / np.linalg.norm(direction)
    v = np.asarray(up) - np.dot(up, w) * w
    v /= np.linalg.norm(v)
    u = np.cross(v, w)
    corners = np.array([[bounds[i, 0], bounds[j, 1], bounds[k, 2]]
                        for i in (0, 1) for j in (0, 1) for k in (0, 1)]) - centre
    half_width = np.abs(corners @ u).max()
    half_height = np.abs(corners @ v).max()
    aspect = width / height
    visible = MARGIN * max(half_height, half_width / aspect)   # half of the picture's height
    if view == "top":
        camera.SetParallelScale(visible)
        distance = 2 * np.abs(corners @ w).max() + visible
    else:
        # the nearest corners look largest: step back by the box's depth too
        distance = visible / math.tan(math.radians(VIEW_ANGLE) / 2) + np.abs(corners @ w).max()
    camera.SetFocalPoint(*centre)
    camera.SetPosition(*(centre + distance * w))
    camera.SetViewUp(*v)
    renderer.ResetCameraClippingRange()


def axes_renderer(font_size: int) -> vtkRenderer:
    """A small x, y, z triad for the lower left corner (see follow_camera)."""
    axes = vtkAxesActor()
    axes.SetShaftTypeToCylinder()
    axes.SetCylinderRadius(0.03)
    axes.SetConeRadius(0.5)
    axes.SetTotalLength(1.0, 1.0, 1.0)
    for caption in (axes.GetXAxisCaptionActor2D(), axes.GetYAxisCaptionActor2D(),
                    axes.GetZAxisCaptionActor2D()):
        caption.GetTextActor().SetTextScaleModeToNone()    # a fixed, readable size
        caption.SetWidth(0.4)
        caption.SetHeight(0.2)
        text = caption.GetCaptionTextProperty()
        text.SetFontSize(font_size)
        text.SetColor(0.1, 0.1, 0.1)
        text.ShadowOff()
        text.ItalicOff()
        text.BoldOff()
    corner = vtkRenderer()
    corner.SetViewport(0.0, 0.0, 0.16, 0.24)
    corner.SetLayer(1)
    corner.InteractiveOff()
    corner.AddActor(axes)
    return corner


def follow_camera(corner: vtkRenderer, main: vtkRenderer) -> None:
    """Turn the corner's triad as the main view is turned."""
    camera, main_camera = corner.GetActiveCamera(), main.GetActiveCamera()
    d = np.array(main_camera.GetPosition()) - np.array(main_camera.GetFocalPoint())
    camera.SetFocalPoint(0, 0, 0)
    camera.SetPosition(*(5 * d / np.linalg.norm(d)))
    camera.SetViewUp(*main_camera.GetViewUp())
    camera.SetParallelProjection(main_camera.GetParallelProjection())
    corner.ResetCamera()


def legend(entries: list, height: int) -> vtkLegendBoxActor:
    """Coloured discs (a fibre's section) and their texts, top right."""
    box = vtkLegendBoxActor()
    box.SetNumberOfEntries(len(entries))
    disc = vtkRegularPolygonSource()
    disc.SetNumberOfSides(32)
    disc.Update()
    for i, (text, rgb) in enumerate(entries):
        box.SetEntry(i, disc.GetOutput(), str(text), rgb)
    box.BorderOff()
    box.GetEntryTextProperty().ShadowOff()
    rows = 0.038 * len(entries)     # the box's size sets the text's
    box.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
    box.GetPositionCoordinate().SetValue(0.87, 0.96 - rows)
    box.GetPosition2Coordinate().SetCoordinateSystemToNormalizedViewport()
    box.GetPosition2Coordinate().SetValue(0.11, rows)
    return box


def write_png(window: vtkRenderWindow, path: str) -> None:
    grab = vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    grab.Update()
    tmp = f"{path}.{os.getpid()}.tmp.png"
    writer = vtkPNGWriter()
    writer.SetFileName(tmp)
    writer.SetInputConnection(grab.GetOutputPort())
    writer.Write()
    os.replace(tmp, path)     # readers never see a half-written picture


def render(job: dict) -> None:
    with np.load(job["arrays"]) as data:
        arrays = {k: data[k] for k in data.files}
    r = arrays["radius"].max()
    bounds = np.array([arrays["points"].min(axis=0) - r, arrays["points"].max(axis=0) + r])
    width, height = (int(v) for v in job["size"])
    window = vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(width, height)
    window.SetNumberOfLayers(2)
    window.SetMultiSamples(8)     # anti-aliasing (VTK 9.1: adding FXAA gives a black image)
    renderer = vtkRenderer()
    renderer.SetBackground(1.0, 1.0, 1.0)
    renderer.AddActor(fibre_actor(tubes(arrays, int(job["sides"]))))
    # key, fill and back lights: the tubes' roundness shows (a headlight flattens it)
    vtkLightKit().AddLightsToRenderer(renderer)
    renderer.UseSSAOOn()
    renderer.SetSSAORadius(r)         # occlusion felt over about a fibre radius
    renderer.SetSSAOKernelSize(32)    # 128 (the default) doubles the time for little
    renderer.SSAOBlurOn()
    if job["legend"]:
        renderer.AddActor2D(legend(job["legend"], height))
    corner = axes_renderer(max(10, height // 45))
    window.AddRenderer(renderer)
    window.AddRenderer(corner)
    for view, path in job["views"]:
        place_camera(renderer, view, bounds, width, height)
        follow_camera(corner, renderer)
        window.Render()
        write_png(window, path)
    window.Finalize()


def use_every_core() -> None:
    """Let this process run on every core: started from an MPI rank, it
    inherits the rank's binding to one core (Open MPI binds ranks to
    cores), where llvmpipe's rasterizing threads would share that core with
    the rank while the other ranks' cores wait idle."""
    try:
        os.sched_setaffinity(0, range(os.cpu_count() or 1))
    except (AttributeError, OSError):
        pass     # no affinity on this system, or a core we may not use


if __name__ == "__main__":
    use_every_core()
    with open(sys.argv[1]) as f:
        render(json.load(f))
