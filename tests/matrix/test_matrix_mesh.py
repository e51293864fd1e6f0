"""Matrix meshes from gmsh: a box with named sides, a box around fibres,
a user's .msh file, the command-line script, and gmsh imported only when a
matrix is made (a fibre-only scene never imports it nor builds a dolfinx mesh)."""
import os
import subprocess
import sys

import numpy as np
import pytest
import ufl
from dolfinx import fem
from mpi4py import MPI

import textile
from textile.composite.matrix_mesh import (SIDE_TAGS, MatrixMesh, box_around_fibres, fibre_box,
                                           gmsh_box, read_msh)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
P0, P1 = np.array([0.0, -0.5, 0.1]), np.array([2.0, 0.5, 0.4])


def measure(mm: MatrixMesh, form) -> float:
    return mm.mesh.comm.allreduce(fem.assemble_scalar(fem.form(form)), op=MPI.SUM)


def check_box(mm: MatrixMesh, p0, p1):
    """Volume and every named side's area equal the box's (a flat-faced box
    is meshed exactly: round-off only)."""
    d = p1 - p0
    assert mm.sides == SIDE_TAGS
    assert measure(mm, 1.0 * ufl.dx(domain=mm.mesh)) == pytest.approx(np.prod(d), rel=1e-12)
    ds = ufl.Measure("ds", domain=mm.mesh, subdomain_data=mm.facet_tags)
    x = ufl.SpatialCoordinate(mm.mesh)
    for name, tag in mm.sides.items():
        k = "xyz".index(name[0])
        area = np.prod(np.delete(d, k))
        assert measure(mm, 1.0 * ds(tag)) == pytest.approx(area, rel=1e-12), name
        # the side lies on its plane: the mean of x_k over it is the plane's value
        plane = p0[k] if name.endswith("min") else p1[k]
        assert measure(mm, x[k] * ds(tag)) / area == pytest.approx(plane, abs=1e-12), name


@pytest.mark.mpi
def test_gmsh_box_has_named_sides_and_size():
    size = 0.15
    mm = gmsh_box(MPI.COMM_WORLD, P0, P1, size)
    check_box(mm, P0, P1)
    # cells are about `size` across: the mean edge length (a regular tet of
    # edge a has volume a^3 / (6 sqrt 2)) within 30% of the target
    n = mm.mesh.topology.index_map(3).size_global
    edge = (6 * np.sqrt(2) * np.prod(P1 - P0) / n) ** (1 / 3)
    assert 0.7 * size < edge < 1.3 * size, edge
    assert mm.corners is not None and np.allclose(mm.corners, (P0, P1))


@pytest.mark.mpi
def test_msh_written_and_read_back(tmp_path):
    path = MPI.COMM_WORLD.bcast(str(tmp_path / "box.msh"), root=0)
    made = gmsh_box(MPI.COMM_WORLD, P0, P1, 0.2, msh_path=path)
    read = read_msh(MPI.COMM_WORLD, path)
    check_box(read, P0, P1)
    n = lambda mm: mm.mesh.topology.index_map(3).size_global  # noqa: E731
    assert n(read) == n(made)


def test_script_writes_a_msh(tmp_path):
    """meshes/matrix_box.py alone writes a file read_msh accepts."""
    out = tmp_path / "script.msh"
    run = subprocess.run([sys.executable, os.path.join(ROOT, "meshes", "matrix_box.py"),
                          "--corner0", *map(str, P0), "--corner1", *map(str, P1),
                          "--size", "0.2", "-o", str(out)], capture_output=True, text=True,
                         timeout=300)
    assert run.returncode == 0, run.stderr
    assert "tetrahedra" in run.stdout
    check_box(read_msh(MPI.COMM_SELF, str(out)), P0, P1)


def test_read_msh_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="no such file"):
        read_msh(MPI.COMM_SELF, str(tmp_path / "missing.msh"))
    # a mesh without physical groups: dolfinx would import nothing
    import gmsh
    from textile.composite.matrix_mesh import gmsh_session
    path = str(tmp_path / "untagged.msh")
    with gmsh_session():
        gmsh.model.add("untagged")
        gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
        gmsh.model.occ.synchronize()
        gmsh.model.mesh.generate(3)
        gmsh.write(path)
        gmsh.model.remove()
    with pytest.raises(ValueError, match="no physical volume group"):
        read_msh(MPI.COMM_SELF, path)


def test_fibre_box_encloses_fibres():
    """The documented choice: thickness from the lowest to the highest fibre
    surface plus the overlap, in-plane the centre lines' box plus the margin."""
    mat = textile.Material(1e9, 0.3)
    R = 0.01
    a = textile.straight_fibre([0, 0, 0.0], [1, 0, 0.0], R, mat, num_elements=2)
    b = textile.straight_fibre([0.2, -0.3, 0.015], [0.2, 0.4, 0.015], 2 * R, mat, num_elements=2)
    p0, p1 = fibre_box([a, b])
    np.testing.assert_allclose(p0, [0 - 2 * R, -0.3 - 2 * R, 0 - R - 0.5 * R], atol=1e-15)
    np.testing.assert_allclose(p1, [1 + 2 * R, 0.4 + 2 * R, 0.015 + 2 * R + 0.5 * R], atol=1e-15)
    p0, p1 = fibre_box([a, b], margin=0.0, overlap=0.0, axis="y")
    np.testing.assert_allclose(p0, [0, -0.3 - 2 * R, 0], atol=1e-15)
    np.testing.assert_allclose(p1, [1, 0.4 + 2 * R, 0.015], atol=1e-15)
    with pytest.raises(ValueError, match="axis"):
        fibre_box([a], axis="w")


@pytest.mark.mpi
def test_box_around_fibres_contains_their_surfaces():
    """Every point of the fibres' surfaces (centre line +- R along the
    section vectors) is found in a matrix cell."""
    from textile.effects.elastic_block import ElasticBlock
    mat = textile.Material(1e9, 0.3)
    R = 0.02
    fibres = [textile.straight_fibre([0, y, 0], [1, y, 0], R, mat, num_elements=4)
              for y in (0.0, 0.05, 0.1)]
    model = textile.Model(fibres)
    mm = box_around_fibres(MPI.COMM_WORLD, model)
    block = ElasticBlock(mm, 1.0, 0.3)
    pts = np.vstack([f.points + s * R * g for f in fibres for s in (-1, 1)
                     for g in (f.g1, f.g2)])
    cells, _ = block.point_basis(pts)          # raises if a point is outside
    assert MPI.COMM_WORLD.allreduce(int(np.sum(cells >= 0))) == len(pts)


LAZY_SCRIPT = r"""
import sys
import dolfinx.mesh
made = []
init = dolfinx.mesh.Mesh.__init__
def counting_init(self, *args, **kwargs):
    made.append(1)
    init(self, *args, **kwargs)
dolfinx.mesh.Mesh.__init__ = counting_init
import textile
fibre = textile.straight_fibre([0, 0, 0], [1, 0, 0], 0.01, textile.Material(1e9, 0.3),
                               num_elements=4)
model = textile.Model([fibre])
model.clamp(fibre, 0)
model.add_force(fibre, -1, [0, 0, -1e-3])
output = textile.Output(sys.argv[1], pictures=False)
history = textile.Solver(model, {"verbose": False}, output=output).solve()
assert model.load_factor == 1.0
import textile.composite.matrix_mesh  # importing the matrix-mesh module: no gmsh either
print("gmsh" in sys.modules, len(made), "textile.effects.elastic_block" in sys.modules)
"""


def test_fibre_only_scene_never_touches_gmsh_or_a_matrix_mesh(tmp_path):
    """A fibre-only solve with output: gmsh not imported, no dolfinx mesh
    built, the matrix block's module not loaded, no scene.pvd; importing
    textile.composite.matrix_mesh does not import gmsh either (a fresh
    interpreter, so nothing another test imported counts)."""
    run = subprocess.run([sys.executable, "-c", LAZY_SCRIPT, str(tmp_path)], capture_output=True,
                         text=True, cwd=ROOT, timeout=300)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split()[-3:] == ["False", "0", "False"], run.stdout
    assert (tmp_path / "fibres.pvd").exists() and not (tmp_path / "scene.pvd").exists()
