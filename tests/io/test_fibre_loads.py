"""Fibre loads (textile.beam.fibre_loads) against closed forms, in ParaView, and
on 1 vs 2 ranks.

- a straight fibre pulled to a stretch 1 + eps: max_axial_strain is the
  Green-Lagrange strain eps + eps^2 / 2, max_stress = E times it, no curvature;
- a cantilever bent into a circular arc by an end moment M: curvature
  M / (E I), max_stress = E r kappa (the section-averaged S33 is second
  order, E r^2 kappa^2 / 4);
- two fibres, one pulled harder: it is ranked first;
- the fibres .vtu of an Output carries the per-segment and per-fibre fields
  (read back with VTK) and results.json the most loaded fibres of each step;
- the figures on 2 ranks (a fibre cut between them) equal those on one.
"""
import json
import os
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.beam.fibre_loads import (FIGURES, element_loads, fibre_loads,
                                      gathered_element_fields, ranked_table)

from tests.installed import import_installed

QUIET = {"verbose": False}


def pulled_fibre(eps, num_elements=4):
    E, nu, R, L = 2.0e9, 0.3, 1e-3, 0.05
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, nu),
                                 num_elements=num_elements, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    # node 0: centroid fixed, section vectors free to contract but not to turn
    model.fix(fib, 0, ["position", "g1x", "g1z", "g2x", "g2y"])
    model.fix(fib, -1, "x", eps * L)
    textile.Solver(model, dict(initial_step=1.0, max_step=1.0, **QUIET)).solve()
    return model, E, L


@pytest.mark.parametrize("eps", [1e-3, 1e-2])
def test_pulled_fibre_has_the_green_lagrange_strain(eps):
    model, E, L = pulled_fibre(eps)
    loads = fibre_loads(model)
    gl = eps + eps ** 2 / 2
    # uniform stretch is exact for this kinematics on any mesh (tests/beam/
    # test_tension.py): only Newton's tolerance and round-off remain
    # (measured 7e-14 and 3e-14 relative)
    assert loads["max_axial_strain"][0] == pytest.approx(gl, rel=3e-13)
    # the cured St Venant-Kirchhoff law in uniaxial stress: S33 = E E33
    # (measured 3e-14 and 5e-14 relative)
    assert loads["max_stress"][0] == pytest.approx(E * gl, rel=3e-13)
    # straight: curvature is round-off (measured kappa L = 3e-17, 1.3e-15)
    assert loads["max_curvature"][0] * L < 1e-12
    assert list(loads["most_loaded"]) == [0]


def bent_fibre(num_elements):
    """A cantilever along x bent by an end moment M about z into a quarter
    circle: kappa = M / (E I) = pi / (2 L)."""
    E, nu, R, L = 1.0e9, 0.3, 1e-3, 1.0
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, nu),
                                 num_elements=num_elements, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    I = np.pi * R ** 4 / 4
    M = np.pi / (2 * L) * E * I
    model.add_end_moment(fib, -1, [0, 0, M])
    textile.Solver(model, dict(initial_step=0.25, max_step=0.25, **QUIET)).solve()
    return model, M / (E * I), E, R


def test_arc_has_curvature_m_over_ei():
    errors = {}
    for n in (16, 32):
        model, kappa, E, R = bent_fibre(n)
        loads = fibre_loads(model)
        errors[n] = loads["max_curvature"][0] / kappa - 1
        # every element is bent alike (pure bending: uniform moment); the
        # largest error of an element is that of the maximum (below)
        el = element_loads(model.mesh, model.nodal_unknowns()[:, 0:3],
                           gathered_element_fields(model))
        assert el["curvature"] == pytest.approx(kappa, rel=1e-3 * (16 / n) ** 2)
        # surface stress: E r kappa; the S33 average adds E r^2 kappa^2 / 4
        # (r kappa / 4 = 3.9e-4 relative), the curvature its error (the
        # remainder measured equal to it: 3.0e-4, 7.8e-5)
        assert loads["max_stress"][0] == pytest.approx(E * R * kappa * (1 + R * kappa / 4),
                                                       rel=2 * abs(errors[n]))
    # the turning-angle curvature of the nodes is second order in the node
    # spacing: measured +3.0e-4 (16 elements) and +7.8e-5 (32) relative, the
    # mid-nodes of the quadratic elements lying ~1e-6 L off the exact circle
    assert 0 < errors[16] < 1e-3
    assert 0 < errors[32] < errors[16] / 3


def two_fibres(forces):
    """Parallel fibres along x, fibre k pulled at its end by forces[k]."""
    E, R, L = 2.0e9, 1e-3, 0.05
    fibres = [textile.straight_fibre([0, 4 * R * k, 0], [L, 4 * R * k, 0], R,
                                     textile.Material(E, 0.3), num_elements=4,
                                     section_vector=[0, 0, 1]) for k in range(len(forces))]
    model = textile.Model(fibres, comm=MPI.COMM_SELF)
    for fib, F in zip(fibres, forces):
        model.fix(fib, 0, ["position", "g1x", "g1y", "g2x", "g2z"])
        model.add_force(fib, -1, [F, 0, 0])
    textile.Solver(model, dict(initial_step=1.0, max_step=1.0, **QUIET)).solve()
    return model


def test_the_more_loaded_fibre_ranks_first():
    model = two_fibres([20.0, 60.0])
    loads = fibre_loads(model)
    assert list(loads["most_loaded"]) == [1, 0]
    # a dead force F: F / (E A) = lambda (lambda^2 - 1) / 2 = lambda E33,
    # exact for the model as a prescribed stretch (measured 1.4e-13, 1.1e-13)
    A, E = np.pi * 1e-6, 2.0e9
    for f, F in ((0, 20.0), (1, 60.0)):
        lam = max(np.roots([0.5, 0, -0.5, -F / (E * A)]).real)
        assert loads["max_axial_strain"][f] == pytest.approx((lam ** 2 - 1) / 2, rel=1e-12)
    table = ranked_table(loads, yarn=np.array([7, 8]))
    lines = table.splitlines()
    assert lines[0].startswith("2 most loaded of 2 fibres")
    assert lines[1].split()[:3] == ["rank", "fibre", "yarn"]
    for word in FIGURES.values():
        assert word in lines[1]
    assert lines[2].split()[:3] == ["1", "1", "8"] and lines[3].split()[:3] == ["2", "0", "7"]
    assert float(lines[2].split()[3]) == pytest.approx(loads["max_axial_strain"][1], rel=1e-3)
    assert len(ranked_table(loads, count=1).splitlines()) == 3        # title, head, 1 row
    assert "yarn" not in ranked_table(loads)
    with pytest.raises(ValueError, match="by must be"):
        ranked_table(loads, by="stress")
    with pytest.raises(ValueError, match="labels"):
        ranked_table(loads, yarn=[1])


# -- a scene on the communicator's ranks: ParaView fields, 1 vs 2 ranks ----

def scene(comm, directory=None):
    """Three fibres along x: 0 pulled, 1 bent by an end moment, 2 bent and
    pulled (on 2 ranks, each fibre is cut between them: the partition by place
    cuts across x)."""
    E, R, L = 1.0e9, 1e-3, 0.2
    mat = textile.Material(E, 0.3)
    fibres = [textile.straight_fibre([0, 0.05 * k, 0], [L, 0.05 * k, 0], R, mat, num_elements=8,
                                     section_vector=[0, 1, 0]) for k in range(3)]
    model = textile.Model(fibres, comm=comm)
    I = np.pi * R ** 4 / 4
    for k, fib in enumerate(fibres):
        model.clamp(fib, 0)
        if k != 1:
            model.add_force(fib, -1, [30.0 * k + 10.0, 0, 0])
        if k != 0:
            model.add_end_moment(fib, -1, [0, 0, 0.5 * k * E * I / L])
    output = None if directory is None else textile.Output(
        directory, fibre_data={"yarn": np.array([3, 4, 4])}, pictures=False)
    solver = textile.Solver(model, dict(initial_step=0.5, max_step=0.5, **QUIET), output=output)
    solver.solve()
    return model


def read_series(pvd):
    vtk_xml = import_installed("vtkmodules.vtkIOXML", "python3-vtk9 or python3-paraview")
    from vtkmodules.util.numpy_support import vtk_to_numpy
    out = []
    for ds in ET.parse(pvd).getroot().iter("DataSet"):
        reader = vtk_xml.vtkXMLUnstructuredGridReader()
        reader.SetFileName(os.path.join(os.path.dirname(pvd), ds.get("file")))
        reader.Update()
        grid = reader.GetOutput()
        out.append(tuple({d.GetArrayName(i): vtk_to_numpy(d.GetArray(i))
                          for i in range(d.GetNumberOfArrays())}
                         for d in (grid.GetPointData(), grid.GetCellData())))
    return out


@pytest.mark.mpi
def test_paraview_fields_and_results(tmp_path):
    comm = MPI.COMM_WORLD
    directory = comm.bcast(str(tmp_path), root=0)
    model = scene(comm, directory)
    loads = fibre_loads(model)
    comm.barrier()
    nodes = np.array([f.num_nodes for f in model.mesh.fibres])
    series = read_series(os.path.join(directory, "fibres.pvd"))
    assert len(series) == 2
    point, cell = series[-1]
    for name in FIGURES:    # per fibre, on points and cells, as fibre_data
        np.testing.assert_allclose(point[name], np.repeat(loads[name], nodes), rtol=1e-12)
        np.testing.assert_allclose(cell[name], np.repeat(loads[name], nodes - 1), rtol=1e-12)
    np.testing.assert_array_equal(cell["yarn"], np.repeat([3, 4, 4], nodes - 1))
    for name in ("curvature", "surface_stress"):
        assert cell[name].shape == (sum(nodes - 1),) and np.all(cell[name] >= 0)
    # the fibre's maxima are the largest of its segments'
    fibre_of = np.repeat(np.arange(3), nodes - 1)
    for f in range(3):
        assert cell["curvature"][fibre_of == f].max() == pytest.approx(loads["max_curvature"][f])
        assert cell["surface_stress"][fibre_of == f].max() == \
            pytest.approx(loads["max_stress"][f])
    assert loads["max_curvature"][0] < 1e-9 < loads["max_curvature"][1]
    steps = json.load(open(os.path.join(directory, "results.json")))["steps"]
    assert len(steps) == 2
    top = steps[-1]["most_loaded_fibres"]
    assert top["fibre"] == list(loads["most_loaded"])     # 3 fibres: all listed
    for name in FIGURES:
        np.testing.assert_allclose(top[name], loads[name][top["fibre"]], rtol=1e-12)


@pytest.mark.mpi
def test_two_ranks_give_the_figures_of_one():
    par_model = scene(MPI.COMM_WORLD)
    par = fibre_loads(par_model)
    ser = fibre_loads(scene(MPI.COMM_SELF))
    if MPI.COMM_WORLD.size > 1:       # fibre 1 really is cut between the ranks
        mesh = par_model.mesh
        assert set(mesh.node_owner[mesh.fibre_nodes(1)]) == {0, 1}
    # every rank has the same figures
    for name in FIGURES:
        assert np.array_equal(par[name], MPI.COMM_WORLD.bcast(par[name], root=0))
    # both Newton solves converge to round-off (positions within 1e-10,
    # tests/beam/test_parallel.py); curvature, a second difference of the
    # positions, amplifies that: 1e-9 of each figure's largest value
    # (measured 6e-14)
    for name in FIGURES:
        np.testing.assert_allclose(par[name], ser[name], rtol=0,
                                   atol=1e-9 * np.abs(ser[name]).max())
    assert list(par["most_loaded"]) == list(ser["most_loaded"])
