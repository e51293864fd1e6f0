"""The fibre nodes' partitions (textile.beam.node_partition), computed for
several ranks on one process: every rank gets a share, an element's first
node is its rank's, and by place a woven fabric's warp-weft contacts stay
on one rank where by number they cross."""
import numpy as np
import pytest

import textile
from textile.beam.node_partition import bisection, node_owners


def fabric_mesh():
    """A 4 x 4 plain weave of 3-fibre flat yarns (24 fibres), one process."""
    from mpi4py import MPI
    from textile.beam.fibre_mesh import FibreMesh
    from textile.fabric import Fabric, Yarn
    yarn = Yarn(3, 0.1e-3, textile.Material(5e9, 0.35), packing="layers 1")
    fabric = Fabric(yarn, num_warp=4, num_weft=4, spacing=2 * yarn.width, pattern="plain",
                    elements_per_crossing=4)
    return FibreMesh(MPI.COMM_SELF, fabric.fibres(), 2), fabric


@pytest.mark.parametrize("size", [1, 2, 3, 8])
def test_bisection_shares_points_evenly(size):
    points = np.random.default_rng(1).random((1001, 3)) * [5, 2, 1]
    owner = bisection(points, size)
    counts = np.bincount(owner, minlength=size)
    assert len(counts) == size and counts.max() - counts.min() <= 1
    assert np.array_equal(owner, bisection(points, size))   # the same on every rank


@pytest.mark.parametrize("partition", ["place", "numbers"])
@pytest.mark.parametrize("size", [2, 5])
def test_every_node_has_an_owner_and_nodes_follow_their_elements(partition, size):
    mesh, _ = fabric_mesh()
    e = mesh.elements_global
    owner = node_owners(partition, size, mesh.X_global, e)
    assert owner.shape == (mesh.num_nodes_global,) and owner.min() >= 0 and owner.max() < size
    element_owner = owner[e[:, 0]]
    # a rank owns its elements' first and inner nodes, plus the last node of
    # each fibre whose last element it owns
    last = np.r_[mesh.element_fibre[1:] != mesh.element_fibre[:-1], True]
    expected = np.bincount(element_owner, minlength=size) * 2 \
        + np.bincount(element_owner[last], minlength=size)
    assert np.array_equal(np.bincount(owner, minlength=size), expected)
    assert np.all(owner[e[:, 1]] == element_owner)   # inner (quadratic) nodes
    if partition == "place":    # the elements are shared out evenly
        counts = np.bincount(element_owner, minlength=size)
        assert counts.max() - counts.min() <= 1
    else:                       # node ranges, fibre after fibre
        assert np.all(np.diff(owner) >= 0)


def test_by_place_the_crossings_stay_on_one_rank():
    """2 ranks: of the 64 pairs of a warp and a weft fibre element that
    cross (reference midpoints within half an element length), none couples
    two ranks by place (the cut runs between crossings), all of them by
    number (warp on one rank, weft on the other). Measured 0 and 1; the
    limits leave room for a cut through a crossing column (0.1)."""
    mesh, fabric = fabric_mesh()
    e = mesh.elements_global
    mid = mesh.X_global[e, :3].mean(axis=1)
    warp = np.isin(mesh.element_fibre, np.flatnonzero(np.asarray(fabric.fibre_yarn) < 4))
    length = np.linalg.norm(mesh.X_global[e[:, -1], :3] - mesh.X_global[e[:, 0], :3],
                            axis=1).max()
    w, f = np.flatnonzero(warp), np.flatnonzero(~warp)
    d = np.linalg.norm(mid[w][:, None, :2] - mid[f][None, :, :2], axis=2)
    i, j = np.nonzero(d < 0.5 * length)
    pairs = np.c_[w[i], f[j]]
    assert len(pairs) > 50
    shares = {}
    for partition in ("place", "numbers"):
        owner = node_owners(partition, 2, mesh.X_global, e)[e[:, 0]]
        shares[partition] = float(np.mean(owner[pairs[:, 0]] != owner[pairs[:, 1]]))
    assert shares["place"] < 0.10 and shares["numbers"] > 0.9


def test_an_unknown_partition_is_named():
    mesh, _ = fabric_mesh()
    with pytest.raises(ValueError, match="unknown partition 'spatial'"):
        node_owners("spatial", 2, mesh.X_global, mesh.elements_global)
    with pytest.raises(ValueError, match="unknown partition"):
        textile.Model(mesh.fibres, partition="spatial")
