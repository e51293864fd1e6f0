"""Tests for textile.io.vtu (VTU polylines, written by meshio) and
textile.io.pvd (PVD collections)."""

import os
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

from textile.io.pvd import PVDSeries, SceneSeries
from textile.io.vtu import write_fibres_vtu


def two_fibres():
    """Fibre 0 with 3 points, fibre 1 with 2 points (5 points, 3 segments)."""
    a = np.array([[0.0, 0.0, 0.0], [1.0, 0.5, 0.0], [2.0, 0.25, -0.125]])
    b = np.array([[0.0, 1.0, 0.0], [0.1, 1.0, 3.0]])
    return [a, b]


def write_example(path):
    """Write the two-fibre example with point and cell data; return the data."""
    lines = two_fibres()
    point_data = {
        "displacement": np.arange(15, dtype=float).reshape(5, 3) / 7.0,
        "temperature": np.array([1.5, 2.5, 3.5, 4.5, 5.5]),
        "node_flag": np.array([1, 0, 1, 1, 0], dtype=np.int64),
    }
    cell_data = {
        "axial_force": np.array([-1.0e3, 2.0e-3, np.pi]),
        "material": np.array([7, 7, 9], dtype=np.int32),
    }
    write_fibres_vtu(path, lines, point_data, cell_data)
    return lines, point_data, cell_data


def test_roundtrip_with_meshio(tmp_path):
    path = tmp_path / "fibres.vtu"
    lines, point_data, cell_data = write_example(path)
    mesh = meshio.read(path)

    # points are the fibres' points concatenated in order, bit-exact (float64)
    np.testing.assert_array_equal(mesh.points, np.concatenate(lines))
    # one cell block of 2-node lines joining consecutive points within each fibre
    assert [c.type for c in mesh.cells] == ["line"]
    # no segment may join the last point of fibre 0 to the first of fibre 1
    np.testing.assert_array_equal(mesh.cells[0].data, [[0, 1], [1, 2], [3, 4]])
    for name, values in point_data.items():
        # user point data round-trips exactly, vectors keeping 3 components
        np.testing.assert_array_equal(mesh.point_data[name], values)
    # fibre_id point array tags each point with its fibre index
    np.testing.assert_array_equal(mesh.point_data["fibre_id"], [0, 0, 0, 1, 1])
    for name, values in cell_data.items():
        # user cell data round-trips exactly, one value per segment
        np.testing.assert_array_equal(mesh.cell_data[name][0], values)
    # fibre_id cell array tags each segment with its fibre index
    np.testing.assert_array_equal(mesh.cell_data["fibre_id"][0], [0, 0, 1])


def test_binary_encoding_and_types(tmp_path):
    path = tmp_path / "fibres.vtu"
    write_example(path)
    root = ET.parse(path).getroot()
    # header type is declared so readers decode the block-size prefix correctly
    assert root.get("header_type") == "UInt64"
    arrays = {a.get("Name"): a for a in root.iter("DataArray")}
    # every array is base64 binary, keeping files small
    assert {a.get("format") for a in arrays.values()} == {"binary"}
    # floats are stored in double precision
    assert arrays["Points"].get("type") == "Float64"
    # int64 user data keeps 64-bit width, int32 stays 32-bit
    assert (arrays["node_flag"].get("type"), arrays["material"].get("type")) == ("Int64", "Int32")
    # all cells are VTK_LINE (type 3)
    mesh = meshio.read(path)
    assert mesh.cells[0].data.shape == (3, 2)


def test_vector_has_three_components(tmp_path):
    path = tmp_path / "fibres.vtu"
    write_example(path)
    root = ET.parse(path).getroot()
    da = next(a for a in root.iter("DataArray") if a.get("Name") == "displacement")
    # ParaView shows (N,3) arrays as vectors only with NumberOfComponents=3
    assert da.get("NumberOfComponents") == "3"


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_nonfinite_coordinates_rejected(tmp_path, bad):
    lines = two_fibres()
    lines[1][1, 2] = bad
    with pytest.raises(ValueError, match=r"centrelines\[1\].*non-finite"):
        write_fibres_vtu(tmp_path / "bad.vtu", lines)
    # nothing is written for rejected input
    assert not (tmp_path / "bad.vtu").exists()


@pytest.mark.parametrize(
    "lines, pattern",
    [
        ([np.zeros((3, 2))], r"centrelines\[0\] must have shape \(n, 3\)"),
        ([np.zeros((1, 3))], r"centrelines\[0\] must have at least 2 points"),
        ([], r"centrelines must contain at least one fibre"),
        (np.zeros((4, 3)), r"centrelines must be a list"),
    ],
)
def test_bad_centreline_shapes(tmp_path, lines, pattern):
    # each malformed input gets a message naming the argument and the problem
    with pytest.raises(ValueError, match=pattern):
        write_fibres_vtu(tmp_path / "bad.vtu", lines)


def test_equal_length_lines_as_one_array(tmp_path):
    # contact segments come as one (n, 2, 3) array: the same file as the list
    rng = np.random.default_rng(3)
    lines = rng.random((4, 2, 3))
    force = rng.random(4)
    write_fibres_vtu(tmp_path / "array.vtu", lines, cell_data={"f": force})
    write_fibres_vtu(tmp_path / "list.vtu", list(lines), cell_data={"f": force})
    assert (tmp_path / "array.vtu").read_bytes() == (tmp_path / "list.vtu").read_bytes()
    mesh = meshio.read(tmp_path / "array.vtu")
    # each line its own segment, never joined to the next line
    np.testing.assert_array_equal(mesh.cells[0].data, [[0, 1], [2, 3], [4, 5], [6, 7]])
    # a non-finite coordinate is named by its line and point, nothing written
    lines[2, 1, 0] = np.nan
    with pytest.raises(ValueError, match=r"centrelines\[2\] .*non-finite.*point 1"):
        write_fibres_vtu(tmp_path / "bad.vtu", lines)
    assert not (tmp_path / "bad.vtu").exists()
    # the array form needs lines of at least 2 points of 3 coordinates
    with pytest.raises(ValueError, match=r"\(n_fibres, n >= 2, 3\)"):
        write_fibres_vtu(tmp_path / "bad.vtu", np.zeros((4, 1, 3)))


def test_bad_point_and_cell_data(tmp_path):
    lines = two_fibres()
    # point data must have one row per point (5), named in the message
    with pytest.raises(ValueError, match=r"point_data\['u'\].*\(5,\)"):
        write_fibres_vtu(tmp_path / "a.vtu", lines, point_data={"u": np.zeros((4, 3))})
    # cell data must have one row per segment (3), named in the message
    with pytest.raises(ValueError, match=r"cell_data\['N'\].*\(3,\)"):
        write_fibres_vtu(tmp_path / "a.vtu", lines, cell_data={"N": np.zeros(5)})
    # NaN in a field is rejected rather than silently written
    with pytest.raises(ValueError, match=r"point_data\['T'\].*non-finite"):
        write_fibres_vtu(tmp_path / "a.vtu", lines, point_data={"T": [0, 1, np.nan, 3, 4.0]})
    # fibre_id is reserved because it is added automatically
    with pytest.raises(ValueError, match=r"cell_data\['fibre_id'\].*reserved"):
        write_fibres_vtu(tmp_path / "a.vtu", lines, cell_data={"fibre_id": np.zeros(3)})


def test_atomic_write_keeps_old_file_on_failure(tmp_path, monkeypatch):
    path = tmp_path / "fibres.vtu"
    write_example(path)
    before = path.read_bytes()

    def fail(src, dst):
        raise OSError("simulated crash during rename")

    monkeypatch.setattr(os, "replace", fail)
    with pytest.raises(OSError, match="simulated crash"):
        write_fibres_vtu(path, [np.array([[0.0, 0, 0], [1, 1, 1]])])
    monkeypatch.undo()
    # an interrupted write leaves the previous complete file untouched
    assert path.read_bytes() == before
    # and no temporary file litters the output directory
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fibres.vtu"]


def test_pvd_series(tmp_path):
    out = tmp_path / "out"
    (out / "steps").mkdir(parents=True)
    pvd = out / "fibres.pvd"
    series = PVDSeries(pvd)
    # the index is valid XML even before any step is added
    assert ET.parse(pvd).getroot().find("Collection") is not None

    times = [0.0, 0.5, 1.25]
    for k, t in enumerate(times):
        vtu = out / "steps" / f"fibres_{k:06d}.vtu"
        write_fibres_vtu(vtu, two_fibres())
        series.add(t, vtu)
        # after each add the file is a valid index of the steps so far
        assert len(ET.parse(pvd).getroot().findall("Collection/DataSet")) == k + 1

    root = ET.parse(pvd).getroot()
    # ParaView recognises the file by the Collection type
    assert root.get("type") == "Collection"
    datasets = root.findall("Collection/DataSet")
    # entries keep insertion order and full time precision
    assert [float(d.get("timestep")) for d in datasets] == times
    expected = [f"steps/fibres_{k:06d}.vtu" for k in range(3)]
    # file paths are relative to the .pvd's directory so the folder can be moved
    assert [d.get("file") for d in datasets] == expected
    # the entries property mirrors the file
    assert series.entries == list(zip(times, expected))
    # each relative path resolves to a readable VTU
    assert all(meshio.read(out / f).points.shape == (5, 3) for f in expected)


def test_pvd_relative_path_from_cwd(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "results").mkdir()
    series = PVDSeries("results/run.pvd")
    series.add(1.0, "results/a.vtu")
    # a cwd-relative vtu path is re-expressed relative to the .pvd directory
    assert series.entries == [(1.0, "a.vtu")]


def test_pvd_rejects_bad_times(tmp_path):
    series = PVDSeries(tmp_path / "s.pvd")
    series.add(1.0, tmp_path / "a.vtu")
    # NaN time would make the collection unusable
    with pytest.raises(ValueError, match="time must be finite"):
        series.add(np.nan, tmp_path / "b.vtu")
    # going back in time is almost certainly a bug in the caller
    with pytest.raises(ValueError, match="non-decreasing"):
        series.add(0.5, tmp_path / "b.vtu")
    # rejected entries are not recorded
    assert len(series.entries) == 1


def test_scene_series_names_its_parts(tmp_path):
    scene = SceneSeries(tmp_path / "scene.pvd")
    scene.add(0.5, [("fibres", tmp_path / "fibres_1.vtu"), ("block", tmp_path / "b/b_1.pvtu")])
    datasets = ET.parse(tmp_path / "scene.pvd").getroot().findall("Collection/DataSet")
    # one step, its parts numbered in order and named, paths relative to the .pvd
    assert [(d.get("timestep"), d.get("part"), d.get("name"), d.get("file")) for d in datasets] \
        == [("0.5", "0", "fibres", "fibres_1.vtu"), ("0.5", "1", "block", "b/b_1.pvtu")]
