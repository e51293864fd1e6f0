"""The written ParaView series, opened with VTK's own XML reader.

A tiny contact scene (three crossing fibres as two yarns, four steps) is
solved with an Output that labels the fibres by yarn; every .vtu named in
fibres.pvd and contacts.pvd is read back with vtkXMLUnstructuredGridReader,
as ParaView would, and the pictures of the final state are checked.
"""
import json
import os
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.fibre_contact import FibreContact
from textile.io.sample_pictures import fabric_labels

from tests.installed import import_installed

vtk_xml = import_installed("vtkmodules.vtkIOXML", "python3-vtk9 or python3-paraview")
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402

R, L, S, DELTA = 1e-3, 0.1, 0.02, 2e-4
YARN = np.array([2, 0, 1])               # A is the weft, B and C two warp yarns
DIRECTIONS = ["warp", "warp", "weft"]
POINT_ARRAYS = {"radius": 1, "displacement": 3, "g1": 3, "g2": 3, "yarn": 1, "fibre_id": 1}
CELL_ARRAYS = {**{f"{k}_{c}": 1 for k in ("strain", "stress")
                  for c in ("11", "22", "33", "23", "13", "12")}, "yarn": 1, "fibre_id": 1}
CONTACT_ARRAYS = {"normal_force": 1, "gap": 1, "normal": 3, "tangential_force": 3, "slip": 1,
                  "penalty": 1, "fibre_i": 1, "fibre_j": 1}


def shared_directory(tmp_path) -> str:
    """Rank 0's tmp_path on every rank (Output writes on rank 0)."""
    return MPI.COMM_WORLD.bcast(str(tmp_path), root=0)


def run_scene(directory, comm, **output_options):
    """A plain-weave crossing in miniature: weft fibre A along y, clamped at
    its ends; warp fibre B along x passes over it at y = -S and is lowered
    by DELTA at its ends, warp fibre C passes under it at y = +S and is
    raised by DELTA: A is crimped into an S between them."""
    mat = textile.Material(1.0e9, 0.3)
    A = textile.straight_fibre([0, -L / 2, 0], [0, L / 2, 0], R, mat, num_elements=8)
    B = textile.straight_fibre([-L / 4, -S, 2 * R], [L / 4, -S, 2 * R], R, mat, num_elements=4)
    C = textile.straight_fibre([-L / 4, S, -2 * R], [L / 4, S, -2 * R], R, mat, num_elements=4)
    model = textile.Model([A, B, C], comm=comm)
    for end in (0, -1):
        model.fix(A, end, "all")
    for fibre, sign in ((B, -1), (C, 1)):
        model.fix(fibre, 0, ["position", "g1x"], [0, 0, sign * DELTA, 0])
        model.fix(fibre, -1, ["y", "z"], [0, sign * DELTA])
    model.add_effect(FibreContact(dict(friction=0.2)))
    output = textile.Output(directory, fibre_data={"yarn": YARN},
                            yarn_directions=DIRECTIONS, **output_options)
    solver = textile.Solver(model, dict(initial_step=0.25, max_step=0.25, verbose=False),
                            output=output)
    solver.solve()
    return model


def read_series(pvd):
    """[(time, vtk unstructured grid)] of a .pvd, read with VTK."""
    out = []
    for ds in ET.parse(pvd).getroot().iter("DataSet"):
        reader = vtk_xml.vtkXMLUnstructuredGridReader()
        reader.SetFileName(os.path.join(os.path.dirname(pvd), ds.get("file")))
        reader.Update()
        out.append((float(ds.get("timestep")), reader.GetOutput()))
    return out


def arrays(data) -> dict:
    """{name: numpy array} of a vtkPointData / vtkCellData."""
    return {data.GetArrayName(i): vtk_to_numpy(data.GetArray(i))
            for i in range(data.GetNumberOfArrays())}


def check_arrays(found: dict, expected: dict, count: int, where: str):
    for name, components in expected.items():
        assert name in found, f"{where}: no array {name!r} (has {sorted(found)})"
        a = found[name]
        assert a.shape == ((count,) if components == 1 else (count, components)), (where, name)
        assert np.all(np.isfinite(a)), (where, name)


@pytest.mark.mpi
def test_series_reads_back_in_vtk(tmp_path):
    directory = shared_directory(tmp_path)
    model = run_scene(directory, MPI.COMM_WORLD)
    MPI.COMM_WORLD.barrier()
    nodes = [f.num_nodes for f in model.mesh.fibres]
    series = read_series(os.path.join(directory, "fibres.pvd"))
    assert len(series) == 4                  # 4 steps of 0.25, each written
    times = [t for t, _ in series]
    assert np.all(np.diff(times) > 0), times
    for t, grid in series:
        where = f"fibres at t={t}"
        assert grid.GetNumberOfPoints() == sum(nodes), where
        assert grid.GetNumberOfCells() == sum(n - 1 for n in nodes), where   # one per segment
        point, cell = arrays(grid.GetPointData()), arrays(grid.GetCellData())
        check_arrays(point, POINT_ARRAYS, sum(nodes), where)
        check_arrays(cell, CELL_ARRAYS, sum(n - 1 for n in nodes), where)
        np.testing.assert_array_equal(point["yarn"], np.repeat(YARN, nodes))
        np.testing.assert_array_equal(cell["yarn"], np.repeat(YARN, np.array(nodes) - 1))
        np.testing.assert_array_equal(point["radius"], R)
    # the last state is the prescribed one: B's first node lowered by DELTA,
    # C's raised (a prescribed value is met exactly, to round-off)
    u = arrays(series[-1][1].GetPointData())["displacement"]
    assert u[nodes[0], 2] == pytest.approx(-DELTA, rel=1e-12)
    assert u[nodes[0] + nodes[1], 2] == pytest.approx(DELTA, rel=1e-12)
    # and A, pushed down under B and up over C, is crimped into an S
    a = u[:nodes[0]]
    y = np.linspace(-L / 2, L / 2, nodes[0])
    assert a[np.argmin(abs(y + S)), 2] < 0 < a[np.argmin(abs(y - S)), 2]

    contacts = read_series(os.path.join(directory, "contacts.pvd"))
    assert [t for t, _ in contacts] == times     # contact in every step
    for t, grid in contacts:
        where = f"contacts at t={t}"
        n = grid.GetNumberOfCells()
        assert n >= 1 and grid.GetNumberOfPoints() == 2 * n, where    # a line per element
        data = arrays(grid.GetCellData())
        check_arrays(data, CONTACT_ARRAYS, n, where)
        assert np.all(data["fibre_i"] != data["fibre_j"]), where
        assert set(data["fibre_i"]) | set(data["fibre_j"]) <= {0, 1, 2}, where
    # the pictures of the final state, drawn once after the results
    meta = json.load(open(os.path.join(directory, "results.json")))["meta"]
    names = {"sample.png", "sample_top.png", "cut_warp.png", "cut_weft.png"}
    assert set(meta["pictures"]) == names
    assert all(p["step"] == 4 for p in meta["pictures"].values())
    assert "warnings" not in meta, meta.get("warnings")
    for name in names:
        assert os.path.getsize(os.path.join(directory, name)) > 1000, name


def test_fibre_data_is_checked(tmp_path):
    with pytest.raises(ValueError, match="one Output writes itself"):
        textile.Output(str(tmp_path), fibre_data={"radius": [1, 2]})
    with pytest.raises(ValueError, match="1-D integer or float"):
        textile.Output(str(tmp_path), fibre_data={"yarn": ["a", "b"]})
    with pytest.raises(ValueError, match="non-finite"):
        textile.Output(str(tmp_path), fibre_data={"w": [1.0, np.nan]})
    with pytest.raises(ValueError, match="missing: \\[2\\]"):
        textile.Output(str(tmp_path), fibre_data={"yarn": [0, 2]}, yarn_directions=["warp"])
    with pytest.raises(ValueError, match="pictures must be"):
        textile.Output(str(tmp_path), pictures="first")
    fibre = textile.straight_fibre([0, 0, 0], [1, 0, 0], 0.01, textile.Material(1e9, 0.3),
                                   num_elements=2)
    model = textile.Model([fibre], comm=MPI.COMM_SELF)
    output = textile.Output(str(tmp_path), fibre_data={"yarn": [0, 1]}, pictures=False)
    with pytest.raises(ValueError, match="has 2 values but the model has 1 fibres"):
        output.finish(model)


def test_fabric_labels():
    from textile.fabric import Fabric
    from textile.fabric import Yarn
    fabric = Fabric(Yarn(7, 0.05, textile.Material(1e9, 0.3)), num_warp=2, num_weft=4,
                    spacing=1.0)
    labels = fabric_labels(fabric)
    np.testing.assert_array_equal(labels["fibre_data"]["yarn"], np.repeat(np.arange(6), 7))
    assert labels["yarn_directions"] == ["warp"] * 2 + ["weft"] * 4
