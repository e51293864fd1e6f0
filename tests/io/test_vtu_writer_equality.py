"""The meshio-written .vtu files hold what the hand-written writer they
replaced wrote: tests/io/data/old_writer_{fibres,contacts}.vtu were written
by that writer (commit f1a754d) from the last step of test_vtk_reader's
contact scene, and old_writer_*.npz hold the arrays textile.Output handed
it (points per fibre, point and cell data). The same arrays written now and
read back, by meshio and by VTK's own XML reader (as ParaView reads them),
give the same cells, array names, types, components and values, bit for
bit."""
import os

import meshio
import numpy as np
import pytest

from textile.io.vtu import write_fibres_vtu

from tests.installed import import_installed

DATA = os.path.join(os.path.dirname(__file__), "data")


def rewrite(kind: str, directory) -> tuple[str, str]:
    """(old file, the same state written now)."""
    saved = np.load(os.path.join(DATA, f"old_writer_{kind}.npz"))
    lines = np.split(saved["points"], np.cumsum(saved["counts"])[:-1])
    point_data = {k[6:]: saved[k] for k in saved.files if k.startswith("point/")}
    cell_data = {k[5:]: saved[k] for k in saved.files if k.startswith("cell/")}
    new = os.path.join(directory, f"{kind}.vtu")
    write_fibres_vtu(new, lines, point_data=point_data, cell_data=cell_data)
    return os.path.join(DATA, f"old_writer_{kind}.vtu"), new


def assert_same_arrays(old: dict, new: dict, where: str):
    assert list(old) == list(new), where          # same names, same order
    for name in old:
        a, b = old[name], new[name]
        assert (a.dtype, a.shape) == (b.dtype, b.shape), (where, name)
        np.testing.assert_array_equal(a, b, err_msg=f"{where} {name}")


@pytest.mark.parametrize("kind", ["fibres", "contacts"])
def test_meshio_reads_the_same_fields(tmp_path, kind):
    old, new = (meshio.read(p) for p in rewrite(kind, tmp_path))
    np.testing.assert_array_equal(old.points, new.points)
    assert [c.type for c in old.cells] == [c.type for c in new.cells] == ["line"]
    np.testing.assert_array_equal(old.cells[0].data, new.cells[0].data)
    assert_same_arrays(old.point_data, new.point_data, "point data")
    assert_same_arrays({k: v[0] for k, v in old.cell_data.items()},
                       {k: v[0] for k, v in new.cell_data.items()}, "cell data")
    assert kind == "contacts" or len(old.point_data) > 5     # the fibres' arrays are all there


@pytest.mark.parametrize("kind", ["fibres", "contacts"])
def test_vtk_reads_the_same_grid(tmp_path, kind):
    vtk_xml = import_installed("vtkmodules.vtkIOXML", "python3-vtk9 or python3-paraview")
    from vtkmodules.util.numpy_support import vtk_to_numpy

    def read(path):
        reader = vtk_xml.vtkXMLUnstructuredGridReader()
        reader.SetFileName(path)
        reader.Update()
        grid = reader.GetOutput()

        def arrays(data):
            return {data.GetArrayName(i): vtk_to_numpy(data.GetArray(i))
                    for i in range(data.GetNumberOfArrays())}
        cells = vtk_to_numpy(grid.GetCells().GetConnectivityArray())
        types = [grid.GetCellType(i) for i in range(grid.GetNumberOfCells())]
        return (vtk_to_numpy(grid.GetPoints().GetData()), cells, types,
                arrays(grid.GetPointData()), arrays(grid.GetCellData()))

    old, new = (read(p) for p in rewrite(kind, tmp_path))
    np.testing.assert_array_equal(old[0], new[0])                 # points
    np.testing.assert_array_equal(old[1], new[1])                 # connectivity
    assert old[2] == new[2] and set(new[2]) == {3}                # all VTK_LINE
    assert_same_arrays(old[3], new[3], "point data")
    assert_same_arrays(old[4], new[4], "cell data")
