"""Bad input to the composite's entry points (project issue 22, item 4):
each a named error (the class and the argument in the message), raised
before anything is meshed or solved, so nothing computed is lost.

`Composite` and `Sample` arguments, `ElasticBlock` modulus, Poisson ratio,
law and degree. The weave pattern's are in tests/weave/test_weave_pattern.py,
the stages' in tests/solver/test_stages.py, the contact options' in
tests/contact/test_contact_options.py.
"""
import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.composite import Composite
from textile.effects.elastic_block import ElasticBlock
from textile.composite.matrix_mesh import box_mesh
from textile.fabric import Sample

from tests.woven_states import plain_weave, woven_once

R = 0.1e-3
FIBRE = textile.Material(5.0e9, 0.35)
MATRIX = textile.Material(3.0e9, 0.35)
NAN = float("nan")


@pytest.fixture(scope="module")
def woven(tmp_path_factory):
    return woven_once(tmp_path_factory, plain_weave(FIBRE, R), dict(verbose=False))


@pytest.mark.parametrize("kwargs,error,message", [
    (dict(degree=3), ValueError, r"Composite: degree must be one of \(1, 2\), got 3"),
    (dict(degree=2.0), ValueError, "Composite: degree must be one of"),
    (dict(degree=True), ValueError, "Composite: degree must be one of"),
    (dict(law="linear"), ValueError, "Composite: law must be one of"),
    (dict(junction_stiffness=-1.0), ValueError, "Composite: junction_stiffness must be a "
                                                "positive number"),
    (dict(junction_stiffness=NAN), ValueError, "Composite: junction_stiffness"),
    (dict(junction_stiffness="stiff"), ValueError, "Composite: junction_stiffness"),
    (dict(junction_spacing=0.0), ValueError, "Composite: junction_spacing must be a "
                                             "positive length"),
    (dict(junction_spacing=-R), ValueError, "Composite: junction_spacing"),
    (dict(junction_spacing=NAN), ValueError, "Composite: junction_spacing"),
    (dict(junction_spacing=True), ValueError, "Composite: junction_spacing"),
    (dict(junction_spacing="1"), ValueError, "Composite: junction_spacing"),
    # elements 3 R long: 30 stations an element, over the 20 allowed
    (dict(junction_spacing=0.1 * R), ValueError,
     r"Composite: junction_spacing 1e-05 asks for 30 junction stations on fibre elements "
     r"0.0003\d* long \(at most 20\)"),
    (dict(size=0.0), ValueError, "Composite: size must be a positive length"),
    (dict(size=NAN), ValueError, "Composite: size"),
    (dict(overlap=-R), ValueError, "Composite: overlap must be a positive length"),
    (dict(sides=("xmin", "zmax")), ValueError, "Composite: sides must be distinct names"),
    (dict(sides=("xmin", "xmin")), ValueError, "Composite: sides must be distinct names"),
    (dict(contact=True), TypeError, "Composite: contact must be a dict or ContactOptions"),
    (dict(contact=dict(frction=0.1)), ValueError, r"unknown contact option\(s\) \['frction'\]"),
    (dict(comm="world"), TypeError, "Composite: comm must be an MPI communicator"),
])
def test_composite_arguments(woven, kwargs, error, message):
    kwargs = dict(comm=MPI.COMM_SELF) | kwargs
    with pytest.raises(error, match=message):
        Composite(plain_weave(FIBRE, R), woven, MATRIX, **kwargs)


def test_composite_positional_arguments(woven, tmp_path):
    with pytest.raises(TypeError, match="Composite: fabric must be a textile.fabric.Fabric"):
        Composite("plain", woven, MATRIX, comm=MPI.COMM_SELF)
    with pytest.raises(TypeError, match="Composite: matrix must be a textile.Material"):
        Composite(plain_weave(FIBRE, R), woven, "epoxy", comm=MPI.COMM_SELF)
    with pytest.raises(TypeError, match="Composite: woven must be the path"):
        Composite(plain_weave(FIBRE, R), 3, MATRIX, comm=MPI.COMM_SELF)
    missing = str(tmp_path / "nowhere.h5")
    with pytest.raises(FileNotFoundError, match="Composite: no woven state file"):
        Composite(plain_weave(FIBRE, R), missing, MATRIX, comm=MPI.COMM_SELF)


@pytest.mark.parametrize("kwargs,error,message", [
    (dict(sides=("xmin", "top")), ValueError, "Sample: sides must be distinct names"),
    (dict(sides=()), ValueError, "Sample: sides must be distinct names"),
    (dict(pins=("ymin",)), ValueError, r"Sample: pins \('ymin',\) must be among the sides"),
    (dict(split=("xmax", "ymax")), ValueError, "Sample: split .* must be among the sides"),
    (dict(free_ends="none"), ValueError, "Sample: free_ends must be 'yarns' or 'fibres'"),
    (dict(contact=3), TypeError, "Sample: contact must be a dict or ContactOptions"),
    (dict(contact=dict(friction=-0.2)), ValueError, "ContactOptions.friction"),
    (dict(comm=None), TypeError, "Sample: comm must be an MPI communicator"),
])
def test_sample_arguments(woven, kwargs, error, message):
    kwargs = dict(comm=MPI.COMM_SELF) | kwargs
    with pytest.raises(error, match=message):
        Sample(plain_weave(FIBRE, R), woven, **kwargs)


def test_sample_fabric_and_woven_state(woven, tmp_path):
    with pytest.raises(TypeError, match="Sample: fabric must be a textile.fabric.Fabric"):
        Sample(None, woven, comm=MPI.COMM_SELF)
    with pytest.raises(TypeError, match="Sample: woven must be the path"):
        Sample(plain_weave(FIBRE, R), ["woven.h5"], comm=MPI.COMM_SELF)
    with pytest.raises(FileNotFoundError, match="Sample: no woven state file"):
        Sample(plain_weave(FIBRE, R), str(tmp_path / "nowhere.h5"), comm=MPI.COMM_SELF)
    # a woven state of another fabric
    with pytest.raises(ValueError, match="Sample: the woven state has 68 fibre nodes, this "
                                         "fabric 134"):
        Sample(plain_weave(FIBRE, R, num_weft=4), woven, comm=MPI.COMM_SELF)


@pytest.fixture(scope="module")
def box():
    return box_mesh(MPI.COMM_SELF, [0, 0, 0], [1, 1, 1], [1, 1, 1])


@pytest.mark.parametrize("young,poisson,law,message", [
    (-1.0, 0.3, "svk", "ElasticBlock: young must be positive, got -1.0"),
    (0.0, 0.3, "svk", "ElasticBlock: young must be positive"),
    (NAN, 0.3, "svk", "ElasticBlock: young must be a finite real number"),
    (np.inf, 0.3, "svk", "ElasticBlock: young must be a finite real number"),
    ("3e9", 0.3, "svk", "ElasticBlock: young must be a finite real number"),
    (True, 0.3, "svk", "ElasticBlock: young must be a finite real number"),
    (1.0, 0.5, "svk", r"ElasticBlock: poisson must lie in \(-1, 0.5\), got 0.5"),
    (1.0, -1.0, "svk", "ElasticBlock: poisson must lie in"),
    (1.0, NAN, "svk", "ElasticBlock: poisson must be a finite real number"),
    (1.0, None, "svk", "ElasticBlock: poisson must be a finite real number"),
    (1.0, 0.3, "hooke", r"ElasticBlock: law must be one of \('neo-hookean', 'svk'\)"),
    (1.0, 0.3, None, "ElasticBlock: law must be one of"),
])
def test_elastic_block_material(box, young, poisson, law, message):
    with pytest.raises(ValueError, match=message):
        ElasticBlock(box, young, poisson, law=law)
