"""Tests for textile.io.plots: headless PNG output."""

import numpy as np
import pytest

from textile.io.plots import plot_curve, plot_fibres

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def helix_fibres():
    """Two helical fibres and their straight (undeformed) reference."""
    s = np.linspace(0.0, 1.0, 40)
    fibres = [
        np.column_stack((s, 0.05 * np.cos(8 * s + phase), 0.05 * np.sin(8 * s + phase)))
        for phase in (0.0, np.pi)
    ]
    reference = [np.column_stack((s, np.zeros_like(s), np.zeros_like(s)))] * 2
    return fibres, reference


def assert_png(path):
    data = path.read_bytes()
    # the file is a PNG image
    assert data[:8] == PNG_MAGIC
    # and not an empty/degenerate one
    assert len(data) > 1024


@pytest.mark.parametrize("view", ["3d", "xy", "xz", "yz"])
def test_plot_fibres_views(tmp_path, view):
    fibres, reference = helix_fibres()
    path = tmp_path / f"fibres_{view}.png"
    plot_fibres(path, fibres, title=f"view {view}", reference=reference, view=view)
    assert_png(path)


def test_plot_fibres_planar_3d(tmp_path):
    # z-extent is zero: the equal-aspect box must not collapse to zero height
    s = np.linspace(0.0, 2.0, 10)
    flat = [np.column_stack((s, s**2, np.zeros_like(s)))]
    path = tmp_path / "flat.png"
    plot_fibres(path, flat)
    assert_png(path)


def test_plot_fibres_bad_input(tmp_path):
    fibres, reference = helix_fibres()
    # unknown projections are refused with the valid options listed
    with pytest.raises(ValueError, match="view must be one of"):
        plot_fibres(tmp_path / "a.png", fibres, view="zx")
    fibres[0][3, 1] = np.nan
    # NaN coordinates are named rather than plotted as silent gaps
    with pytest.raises(ValueError, match=r"centrelines\[0\]"):
        plot_fibres(tmp_path / "a.png", fibres)
    # the reference is validated too and named as such
    with pytest.raises(ValueError, match=r"reference\[0\]"):
        plot_fibres(tmp_path / "a.png", reference, reference=[np.zeros((2, 2))])
    # nothing is written for rejected input
    assert not (tmp_path / "a.png").exists()


def test_plot_curve_single_with_reference(tmp_path):
    u = np.linspace(0.0, 1.0, 11)
    path = tmp_path / "curve.png"
    plot_curve(path, u, 3.0 * u, "u [mm]", "F [N]", title="load curve", label="FE",
               reference=(u, 3.0 * u + 0.01, "analytical"))
    assert_png(path)


def test_plot_curve_multiple(tmp_path):
    u = np.linspace(0.0, 1.0, 11)
    path = tmp_path / "curves.png"
    # several curves sharing one x array, one label each
    plot_curve(path, u, [u, 2 * u, u**2], "u [mm]", "F [N]", label=["a", "b", None])
    assert_png(path)
    path2 = tmp_path / "curves2.png"
    # several curves with their own x arrays of different lengths
    plot_curve(path2, [u, u[:5]], [u, u[:5] ** 2], "u", "F", label=["a", "b"])
    assert_png(path2)


def test_plot_curve_bad_input(tmp_path):
    u = np.linspace(0.0, 1.0, 11)
    # mismatched x/y lengths name both arguments
    with pytest.raises(ValueError, match="x and y must have the same length"):
        plot_curve(tmp_path / "a.png", u, u[:-1], "u", "F")
    # the failing curve of a multi-curve plot is identified by index
    with pytest.raises(ValueError, match=r"y\[1\] contains non-finite"):
        plot_curve(tmp_path / "a.png", u, [u, np.full(11, np.nan)], "u", "F", label=["a", "b"])
    # one label per curve is required when y is a list
    with pytest.raises(ValueError, match="label must be a list of 2"):
        plot_curve(tmp_path / "a.png", u, [u, u], "u", "F", label=["only one"])
    # reference must be (x_ref, y_ref, label)
    with pytest.raises(ValueError, match="reference must be a tuple"):
        plot_curve(tmp_path / "a.png", u, u, "u", "F", reference=(u, u))
    # nothing is written for rejected input
    assert not (tmp_path / "a.png").exists()


def test_an_empty_load_curve_writes_its_header_and_no_picture(tmp_path):
    """A virtual test stopped before its first loading step has an empty
    curve: its CSV (header only) is written, no PNG, no error."""
    from textile.virtual_tests.load_curve import LoadCurve

    curve = LoadCurve("u [mm]", "F [N]")
    paths = curve.write(str(tmp_path), "stopped")
    assert paths == [str(tmp_path / "stopped.csv")]
    assert (tmp_path / "stopped.csv").read_text().strip() == "u [mm],F [N]"
    assert not (tmp_path / "stopped.png").exists()
    curve.add(0.0, 0.0)
    assert len(curve.write(str(tmp_path), "stopped")) == 2
    assert_png(tmp_path / "stopped.png")


def test_a_test_stopped_before_its_first_step_writes_its_record(tmp_path):
    """A virtual test's result with no loading step (IncompleteTest.result
    of a test whose settling stopped): write() gives the CSV header, the
    JSON record and a fibre table saying there is none, no error."""
    import json

    from textile.virtual_tests.load_curve import LoadCurve
    from textile.virtual_tests.virtual_test import VirtualTestResult

    result = VirtualTestResult("shear", LoadCurve("angle [rad]", "force [N]"))
    paths = result.write(str(tmp_path))
    assert [p.rsplit("/", 1)[1] for p in paths] == ["shear.csv", "shear.json"]
    assert json.loads((tmp_path / "shear.json").read_text())["steps"] == []
    assert (tmp_path / "shear_fibres.txt").read_text().startswith("no loading step")
