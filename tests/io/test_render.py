"""Pictures: tubes rendered by VTK off-screen, the matplotlib fallback, and
plane cuts (geometry checked against closed forms, then drawn)."""
import os
import shutil
import sys
import warnings

import numpy as np
import pytest
from matplotlib.image import imread

from textile.io import render
from textile.io.cross_section import cut_fibres, plane_frame
from textile.io.palette import PALETTE
from textile.io.render import (RenderingUnavailable, RenderingWarning, render_cross_section_png,
                               render_fibres_png, sketch_fibres_png)
from textile.io.sample_pictures import cut_planes, draw_sample_pictures, yarn_axes

from tests.installed import needs

R = 0.05


def two_yarns():
    """Two 3-fibre yarns crossing: yarn 0 along x (above), yarn 1 along y."""
    s = np.linspace(-1, 1, 9)
    lines, yarn = [], []
    for k, d in enumerate((-2 * R, 0, 2 * R)):
        lines.append(np.column_stack([s, np.full_like(s, d), np.full_like(s, R)]))
        yarn.append(0)
    for k, d in enumerate((-2 * R, 0, 2 * R)):
        lines.append(np.column_stack([np.full_like(s, d), s, np.full_like(s, -R)]))
        yarn.append(1)
    return lines, np.full(6, R), np.array(yarn)


def colour_share(image: np.ndarray, rgb) -> float:
    """Share of the pixels whose chromaticity is that of ``rgb`` (shading
    scales a colour's brightness, not its chromaticity)."""
    pixels = image[..., :3].reshape(-1, 3).astype(float)
    lit = pixels.sum(axis=1) > 0.05
    chroma = pixels[lit] / pixels[lit].sum(axis=1)[:, None]
    target = np.asarray(rgb) / np.sum(rgb)
    return float(np.mean(np.linalg.norm(chroma - target, axis=1) < 0.03) * lit.mean())


def vtk_can_draw() -> bool:
    try:
        render._scene_command((64, 64))
        return True
    except RenderingUnavailable:
        return False


needs_vtk = needs(vtk_can_draw(), "VTK cannot draw here (python3-vtk9 or "
                  "python3-paraview, and xvfb)")


@needs_vtk
def test_tubes_png_size_content_and_colours(tmp_path):
    lines, radii, yarn = two_yarns()
    path, top = tmp_path / "s.png", tmp_path / "t.png"
    assert render_fibres_png(path, lines, radii, yarn, top_path=top, size=(320, 200),
                             labels={0: "warp", 1: "weft"}) == "vtk"
    for p in (path, top):
        image = imread(p)
        assert image.shape[:2] == (200, 320)           # rows, columns
        assert image[..., :3].std() > 0.1               # not blank
        for k in (0, 1):
            # each yarn's colour covers a visible part of the picture (the
            # yarns cover about 10% of it; 1% leaves room for shading)
            assert colour_share(image, PALETTE[k]) > 0.01, (p, k)
    # the background is white: the corners are
    assert np.all(imread(path)[0, -1, :3] > 0.99)


@needs_vtk
def test_tubes_from_a_written_vtu(tmp_path):
    from textile.io.vtu import write_fibres_vtu
    lines, radii, yarn = two_yarns()
    counts = [len(x) for x in lines]
    vtu = tmp_path / "f.vtu"
    write_fibres_vtu(vtu, lines, point_data={"radius": np.repeat(radii, counts),
                                             "yarn": np.repeat(yarn, counts)})
    assert render_fibres_png(tmp_path / "s.png", vtu=vtu, size=(160, 100)) == "vtk"
    assert colour_share(imread(tmp_path / "s.png"), PALETTE[1]) > 0.01


def test_no_display_is_a_clear_error_and_the_fallback_draws(tmp_path, monkeypatch):
    lines, radii, yarn = two_yarns()
    monkeypatch.setattr(shutil, "which", lambda name: None)
    monkeypatch.delenv("DISPLAY", raising=False)
    with pytest.raises(RenderingUnavailable, match="xvfb"):
        render_fibres_png(tmp_path / "s.png", lines, radii, yarn)
    assert not (tmp_path / "s.png").exists()
    with pytest.warns(RenderingWarning, match="matplotlib instead"):
        backend = render_fibres_png(tmp_path / "s.png", lines, radii, yarn, size=(320, 200),
                                    top_path=tmp_path / "t.png", fallback=True)
    assert backend == "matplotlib"
    for p in ("s.png", "t.png"):
        image = imread(tmp_path / p)
        assert image.shape[:2] == (200, 320)
        assert colour_share(image, PALETTE[0]) > 0.005, p   # thinner than tubes, still there


def test_a_crashing_renderer_is_an_error_not_a_crash(tmp_path, monkeypatch):
    crash = tmp_path / "crash.py"
    crash.write_text("import os\nos.abort()\n")      # what VTK 9.1 does without X
    monkeypatch.setattr(render, "_scene_command", lambda size: [sys.executable, str(crash)])
    lines, radii, yarn = two_yarns()
    with pytest.raises(RenderingUnavailable, match="failed"):
        render_fibres_png(tmp_path / "s.png", lines, radii, yarn)


def test_bad_input_is_named(tmp_path):
    lines, radii, yarn = two_yarns()
    with pytest.raises(ValueError, match="radii must be one value per fibre"):
        render_fibres_png(tmp_path / "s.png", lines, radii[:2], yarn)
    with pytest.raises(ValueError, match="radii must be positive"):
        sketch_fibres_png(tmp_path / "s.png", lines, -1.0, yarn)
    with pytest.raises(ValueError, match="either centrelines"):
        render_fibres_png(tmp_path / "s.png")
    assert not (tmp_path / "s.png").exists()


# -- cuts -----------------------------------------------------------------------------------
def test_plane_frame_reads_in_model_coordinates():
    # (normal, the in-plane coordinates a picture shows)
    for normal, names in (((1, 0, 0), ("y", "z")), ((0, -2, 0), ("x", "z")),
                          ((0, 0, 1), ("x", "y")), ((1, 1, 0), ("s1", "s2"))):
        n, e1, e2, found = plane_frame(normal)
        assert found == names
        assert np.allclose([e1 @ n, e2 @ n, e1 @ e2], 0, atol=1e-15)
    n, e1, e2, _ = plane_frame((1, 0, 0))
    assert np.allclose(e1, [0, 1, 0]) and np.allclose(e2, [0, 0, 1])    # y right, z up


@pytest.mark.parametrize("angle", [0.0, 30.0, 60.0])
def test_oblique_fibre_cuts_in_an_ellipse(angle):
    a = np.radians(angle)
    t = np.array([np.cos(a), np.sin(a), 0.0])       # in the xy plane, at `angle` from x
    line = np.outer(np.linspace(-1, 1, 5), t) + [0.0, 0.3, 0.2]
    cut = cut_fibres([line], [R], (0.1, 0, 0), (1, 0, 0))
    assert not cut.bands and len(cut.ellipses) == 1
    e = cut.ellipses[0]
    # the centre line meets x = 0.1 at y = 0.3 + 0.1 tan(a), z = 0.2 (exact for a straight line)
    assert np.allclose(e.centre, [0.3 + 0.1 * np.tan(a), 0.2], rtol=0, atol=1e-14)
    assert e.semi_axes == pytest.approx((R / np.cos(a), R), rel=1e-14)   # stretched by 1/|t.n|
    # the long axis along the fibre's in-plane projection, y (e1): angle 0
    assert e.angle == pytest.approx(0.0, abs=1e-12)


def test_fibre_in_the_plane_is_a_band_and_far_ones_are_not_drawn():
    s = np.linspace(-1, 1, 5)
    near = np.column_stack([np.full(5, 0.5 * R), s, np.zeros(5)])    # half a radius off x = 0
    far = np.column_stack([np.full(5, 3 * R), s, np.zeros(5)])
    cut = cut_fibres([near, far], [R, R], (0, 0, 0), (1, 0, 0))
    assert not cut.ellipses
    assert [b.fibre for b in cut.bands] == [0]
    outline = cut.bands[0].outline
    # its projection: y over the fibre's length, z over its diameter
    assert np.allclose(outline.min(axis=0), [-1, -R]) and np.allclose(outline.max(axis=0), [1, R])
    assert cut.bands[0].depth == pytest.approx(0.5 * R)
    # a deeper slab takes the far fibre too
    assert len(cut_fibres([near, far], [R, R], (0, 0, 0), (1, 0, 0), depth=4 * R).bands) == 2


def test_wavy_fibre_crossing_twice():
    s = np.linspace(0, 2 * np.pi, 81)
    line = np.column_stack([0.5 * np.sin(s), s, np.zeros_like(s)])   # crosses x = 0 at s = pi
    cut = cut_fibres([line], [R], (0, 0, 0), (1, 0, 0))
    # the ends lie on the plane (d = 0 counts as the positive side): only the middle crossing
    assert len(cut.ellipses) == 1
    assert cut.ellipses[0].centre[0] == pytest.approx(np.pi, abs=1e-3)


def test_cut_planes_of_two_yarns_and_the_picture(tmp_path):
    lines, radii, yarn = two_yarns()
    axes = yarn_axes(["warp", "weft"])
    planes = {p.name: p for p in cut_planes(lines, radii, yarn, axes)}
    assert set(planes) == {"warp", "weft"}
    warp = planes["warp"]
    assert np.allclose(warp.normal, [1, 0, 0])
    # through the weft yarn lying across (its fibres at x = -2R, 0, 2R: mean 0),
    # deep enough for all of them
    assert warp.point[0] == pytest.approx(0, abs=1e-15)
    assert warp.depth == pytest.approx(3 * R)
    path = tmp_path / "cut.png"
    render_cross_section_png(lines, radii, yarn, (warp.point, warp.normal), path,
                             labels={0: "warp 0", 1: "weft 0"}, depth=warp.depth, title="cut")
    image = imread(path)
    # the warp's sections in its colour, the weft's band in a light tint of
    # its own (0.2%: a few thousand pixels; the legend's dots make a few hundred)
    assert colour_share(image, PALETTE[0]) > 0.002
    assert colour_share(image, render._shade(PALETTE[1], render._BAND_TINT)) > 0.002
    # a mean-direction cut when no directions are known
    (plane,) = cut_planes(lines, radii, None, None)
    assert plane.name == "" and np.allclose(np.abs(plane.normal), np.sqrt([0.5, 0.5, 0]))


def test_sample_pictures_fall_back_and_report(tmp_path, monkeypatch):
    def unavailable(size):
        raise RenderingUnavailable("no GL here")
    monkeypatch.setattr(render, "_scene_command", unavailable)
    lines, radii, yarn = two_yarns()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RenderingWarning)
        drawn, errors = draw_sample_pictures(str(tmp_path), lines, radii, yarn,
                                             yarn_axes(["warp", "weft"]), size=(320, 200))
    assert errors == []
    assert drawn == {"sample.png": "matplotlib", "sample_top.png": "matplotlib",
                     "cut_warp.png": "matplotlib", "cut_weft.png": "matplotlib"}
    assert sorted(os.listdir(tmp_path)) == sorted(drawn)


@needs_vtk
def test_the_scene_process_runs_on_every_core():
    # started from an MPI rank bound to one core, the VTK process would
    # share that core with its rank (llvmpipe rasterizes with a thread per
    # core): the demo's 3D pictures took 3.5 s instead of 2.8 s
    import subprocess
    cores = os.cpu_count() or 1
    if cores < 2:
        pytest.skip("one core: nothing to widen")
    # the child binds itself to core 0 first, as mpirun binds a rank
    code = ("import os, sys; os.sched_setaffinity(0, {0}); sys.path.insert(0, sys.argv[1]); "
            "import vtk_scene; vtk_scene.use_every_core(); print(sorted(os.sched_getaffinity(0)))")
    out = subprocess.run([sys.executable, "-c", code, os.path.dirname(render.__file__)],
                         capture_output=True, text=True, check=True).stdout
    assert out.strip() == str(list(range(cores)))
