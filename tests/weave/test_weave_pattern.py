"""Weave patterns: named constructors, custom matrices, clear errors."""
import numpy as np
import pytest

from textile.fabric import WeavePattern


def test_plain_and_its_tiling():
    p = WeavePattern.named("plain")
    assert p.order.tolist() == [[1, 0], [0, 1]]
    t = p.tile(4, 6)
    assert t.shape == (4, 6)
    # every yarn alternates over/under: a checkerboard
    assert np.all(t[:, 1:] != t[:, :-1]) and np.all(t[1:] != t[:-1])


@pytest.mark.parametrize("over,under", [(2, 2), (2, 1), (3, 1)])
def test_twill_floats_and_diagonal(over, under):
    p = WeavePattern.named(f"twill {over}/{under}")
    n = over + under
    assert p.shape == (n, n)
    # each warp floats over `over` wefts, each weft under `over` warps
    assert np.all(p.order.sum(axis=0) == over) and np.all(p.order.sum(axis=1) == over)
    # the float moves by one from one warp to the next: the twill line
    assert np.array_equal(np.roll(p.order[:, 0], 1), p.order[:, 1])


def test_basket():
    p = WeavePattern.named("basket 2x2")
    assert p.shape == (4, 4)
    assert p.order[:2, :2].tolist() == [[1, 1], [1, 1]]
    assert p.order[:2, 2:].tolist() == [[0, 0], [0, 0]]


@pytest.mark.parametrize("n,move", [(5, 2), (7, 2), (8, 3)])
def test_satin_interlaces_once_per_yarn_and_never_adjacent(n, move):
    p = WeavePattern.satin(n)
    under = 1 - p.order
    assert np.all(under.sum(axis=0) == 1) and np.all(under.sum(axis=1) == 1)
    rows = [int(np.flatnonzero(under[:, j])[0]) for j in range(n)]
    # successive warps interlace `move` wefts apart, never on adjacent wefts
    steps = {(rows[j + 1] - rows[j]) % n for j in range(n - 1)}
    assert steps == {move}
    assert move not in (1, n - 1)


def test_custom_matrix():
    p = WeavePattern.of([[1, 0, 0], [0, 1, 0], [0, 0, 1]])
    assert p.name == "custom" and p.shape == (3, 3)


@pytest.mark.parametrize("order,match", [
    ([], "empty"),
    ([[]], "empty"),
    ([[1, 0], [1]], "row 1 has 1 entries.*ragged"),
    ([[1, 2], [0, 1]], r"entry \(0, 1\) is 2"),
    ([[1, 0.5], [0, 1]], r"entry \(0, 1\)"),
    ([[1, 1], [0, 1]], "weft yarn 0 .*never changes side"),
    ([[1, 0], [1, 0]], "warp yarn 0 .*never changes side"),
    (np.zeros((2, 2, 2)), "2D matrix"),
    (7, "matrix"),
])
def test_bad_matrices_are_named(order, match):
    with pytest.raises(ValueError, match=match):
        WeavePattern.of(order)


def test_floats_on_request():
    p = WeavePattern.of([[1, 1], [0, 1]], allow_floats=True)
    assert p.order.tolist() == [[1, 1], [0, 1]]


@pytest.mark.parametrize("name,match", [("satin 6", "6-harness"), ("satin 4", ">= 5"),
                                        ("twill 0/2", "positive"), ("basket 2x3", "n x n"),
                                        ("herringbone", "unknown weave pattern"), (3, "string")])
def test_bad_names(name, match):
    with pytest.raises(ValueError, match=match):
        WeavePattern.named(name)


def test_partial_repeats_fit_when_every_yarn_interlaces():
    # a fabric's width need not be a multiple of the repeat
    assert WeavePattern.plain().tile(3, 3).tolist() == [[1, 0, 1], [0, 1, 0], [1, 0, 1]]
    t = WeavePattern.named("twill 2/2").tile(4, 6)
    assert t.shape == (4, 6) and np.array_equal(t[:, 4:], t[:, :2])
    # two wefts of a 2/2 twill: a warp floats over both and never changes side
    with pytest.raises(ValueError, match="does not fit 2 weft x 4 warp yarns: warp yarn 0 would "
                                         "never change side"):
        WeavePattern.named("twill 2/2").tile(2, 4)
    with pytest.raises(ValueError, match="number of weft yarns must be a positive integer"):
        WeavePattern.plain().tile(0, 2)
