"""The matrix written for ParaView with the fibres of the same step:
scene.pvd lists per step the fibres' .vtu and the block's .pvtu (dolfinx's
VTKFile), read back here with VTK's own XML readers, as ParaView would."""
import os
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.elastic_block import ElasticBlock
from textile.effects.fibre_matrix_tie import FibreMatrixTie
from textile.composite.matrix_mesh import gmsh_box

from tests.installed import import_installed

vtk_xml = import_installed("vtkmodules.vtkIOXML", "python3-vtk9 or python3-paraview")
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402

pytestmark = pytest.mark.mpi
P = 20.0                        # N, pull on the fibre's far end
INSIDE = np.array([1.55, 0.45, 0.52])


def read(path):
    reader = (vtk_xml.vtkXMLPUnstructuredGridReader() if path.endswith(".pvtu")
              else vtk_xml.vtkXMLUnstructuredGridReader())
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


def arrays(data) -> dict:
    return {data.GetArrayName(i): vtk_to_numpy(data.GetArray(i))
            for i in range(data.GetNumberOfArrays())}


@pytest.mark.parametrize("degree", [1, 2])
def test_scene_series_has_fibres_and_matrix(tmp_path, degree):
    comm = MPI.COMM_WORLD
    directory = comm.bcast(str(tmp_path), root=0)
    mm = gmsh_box(comm, [0, 0, 0], [2, 1, 1], 0.4)
    block = ElasticBlock(mm, 1.0e3, 0.3, clamp="xmin", degree=degree)
    fibre = textile.straight_fibre(INSIDE, INSIDE + [2, 0, 0], 0.05, textile.Material(1e5, 0.3),
                                   num_elements=4)
    model = textile.Model(fibre, comm=comm)
    model.add_effect(block)
    model.add_effect(FibreMatrixTie(model, block, [(fibre, 0)], 1.0e4))
    model.fix(fibre, -1, ["y", "z", "section"])
    model.add_force(fibre, -1, [P, 0, 0])
    output = textile.Output(directory, pictures=False)
    textile.Solver(model, {"verbose": False, "initial_step": 0.5, "max_step": 0.5},
                   output=output).solve()
    cells_global = mm.mesh.topology.index_map(3).size_global
    nodes_global = block.V.dofmap.index_map.size_global
    vertices = np.vstack(comm.allgather(mm.mesh.geometry.x))   # reference, all ranks
    comm.barrier()
    if comm.rank != 0:
        return
    root = ET.parse(os.path.join(directory, "scene.pvd")).getroot()
    steps = {}
    for ds in root.iter("DataSet"):
        steps.setdefault(float(ds.get("timestep")), []).append((ds.get("part"), ds.get("name"),
                                                                ds.get("file")))
    assert sorted(steps) == [0.5, 1.0]              # two steps, each written
    for t, parts in steps.items():
        assert [(p, n) for p, n, _ in parts] == [("0", "fibres"), ("1", "matrix")], parts
        fibres, matrix = (read(os.path.join(directory, f)) for _, _, f in parts)
        assert fibres.GetNumberOfPoints() == fibre.num_nodes
        fibre_arrays = {**arrays(fibres.GetPointData()), **arrays(fibres.GetCellData())}
        assert {"displacement", "g1", "radius", "stress_33"} <= set(fibre_arrays)
        point, cell = arrays(matrix.GetPointData()), arrays(matrix.GetCellData())
        cell.pop("vtkOriginalCellIds", None)
        point.pop("vtkOriginalPointIds", None)
        assert {"displacement"} <= set(point) and {"J", "von_mises"} <= set(cell), (point, cell)
        # every cell once: the pieces' cells that are not ghosts (a rank's
        # piece also holds its ghost cells, flagged by vtkGhostType)
        ghost = cell.pop("vtkGhostType")
        assert np.count_nonzero(ghost == 0) == cells_global
        assert point["displacement"].shape[1] == 3 and len(point["displacement"]) >= nodes_global
        for a in (*point.values(), *cell.values()):
            assert np.all(np.isfinite(a))
        # the pulled block stretches (J > 1 somewhere), is nowhere inverted,
        # and its points sit at X + u: the clamped side x = 0 stays at x = 0,
        # where the displacement is zero
        assert cell["J"].min() > 0 and cell["J"].max() > 1
        x = vtk_to_numpy(matrix.GetPoints().GetData())
        at_clamp = np.abs(x[:, 0]) < 1e-12
        assert at_clamp.sum() >= 4
        np.testing.assert_allclose(point["displacement"][at_clamp], 0.0, atol=1e-14)
        # the matrix moves with the fibre at the tie: the displacement there
        # (largest near it) points along the pull
        assert point["displacement"][:, 0].max() > 1e-3
        if degree == 1:
            # each point is a vertex at X + u: x - u is a reference vertex
            from scipy.spatial import cKDTree
            gap, _ = cKDTree(vertices).query(x - point["displacement"])
            assert gap.max() < 1e-12
    # the block's own series indexes the same files
    own = ET.parse(os.path.join(directory, "matrix.pvd")).getroot()
    assert [ds.get("file") for ds in own.iter("DataSet")] == [
        parts[1][2] for _, parts in sorted(steps.items())]
