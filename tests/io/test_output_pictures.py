"""When Output draws its pictures, and that a picture never costs a result."""
import json

import pytest

import textile
from tests.beam.test_solver import bar as held_straight_bar
from textile.io import render, sample_pictures

QUIET = dict(verbose=False)


def bar(compression: float):
    """tests/beam/test_solver.py's fibre held straight, pushed at its tip by
    ``compression`` E A: beyond 0.19245 E A there is no equilibrium."""
    fibre, model, EA = held_straight_bar()
    model.add_force(fibre, -1, [-compression * EA, 0, 0])
    return model


@pytest.fixture
def no_vtk(monkeypatch):
    """Pictures by the matplotlib fallback: these tests are about when
    pictures are drawn, not how (test_render.py checks VTK)."""
    def unavailable(size):
        raise render.RenderingUnavailable("not in these tests")
    monkeypatch.setattr(render, "_scene_command", unavailable)


def meta(directory):
    return json.loads((directory / "results.json").read_text())["meta"]


@pytest.mark.filterwarnings("ignore::textile.io.render.RenderingWarning")
def test_a_failed_run_gets_pictures_of_its_last_converged_state(tmp_path, no_vtk):
    model = bar(0.3)
    solver = textile.Solver(model, dict(initial_step=0.25, max_step=0.25, min_step=1e-3, **QUIET),
                            output=textile.Output(str(tmp_path)))
    with pytest.raises(textile.ConvergenceError):
        solver.solve()
    pictures = meta(tmp_path)["pictures"]
    assert set(pictures) == {"sample.png", "sample_top.png", "cut.png"}
    assert {p["step"] for p in pictures.values()} == {len(solver.history)}
    # how long the drawing took, the same for the pictures drawn together
    assert len({p["seconds"] for p in pictures.values()}) == 1
    assert 0 < pictures["cut.png"]["seconds"] < 60
    assert len(list(tmp_path.glob("fibres_*.vtu"))) == len(solver.history)


@pytest.mark.filterwarnings("ignore::textile.io.render.RenderingWarning")
def test_pictures_true_draws_every_written_step_and_false_none(tmp_path, no_vtk):
    model = bar(0.1)
    solver = textile.Solver(model, dict(initial_step=0.25, max_step=0.25, **QUIET),
                            output=textile.Output(str(tmp_path / "all"), every=2,
                                                  pictures=True))
    solver.solve()
    assert sorted(p.name for p in (tmp_path / "all").glob("sample_0*.png")) == \
        ["sample_00002.png", "sample_00004.png"]
    model = bar(0.1)
    textile.Solver(model, dict(initial_step=0.5, max_step=0.5, **QUIET),
                   output=textile.Output(str(tmp_path / "none"), pictures=False)).solve()
    assert not list((tmp_path / "none").glob("*.png"))
    assert "pictures" not in meta(tmp_path / "none")


def test_a_failing_picture_is_a_warning_not_a_lost_result(tmp_path, monkeypatch, no_vtk):
    def broken(*args, **kwargs):
        raise RuntimeError("the plotting library broke")
    monkeypatch.setattr(sample_pictures, "render_cross_section_png", broken)
    monkeypatch.setattr(sample_pictures, "render_fibres_png", broken)
    model = bar(0.1)
    solver = textile.Solver(model, dict(initial_step=0.5, max_step=0.5, **QUIET),
                            output=textile.Output(str(tmp_path)))
    with pytest.warns(render.RenderingWarning, match="the plotting library broke"):
        solver.solve()
    data = json.loads((tmp_path / "results.json").read_text())
    assert len(data["steps"]) == 2 and len(list(tmp_path.glob("fibres_*.vtu"))) == 2
    assert any("picture not drawn: cut.png" in w for w in data["meta"]["warnings"])
    assert data["meta"]["pictures"] == {}


@pytest.mark.filterwarnings("ignore::textile.io.render.RenderingWarning")
def test_a_run_of_stages_draws_its_final_state_once(tmp_path, no_vtk, monkeypatch):
    # "last" in Solver.run: the pictures of the last stage's end, not of
    # every stage's (each set costs seconds)
    model = bar(0.1)
    out = textile.Output(str(tmp_path))
    calls = []
    draw = out._draw
    monkeypatch.setattr(out, "_draw", lambda *a: (calls.append(len(solver.history)), draw(*a)))
    solver = textile.Solver(model, dict(initial_step=0.5, max_step=0.5, **QUIET), output=out)
    solver.run([textile.Stage("first"), textile.Stage("second")])
    assert calls == [len(solver.history)]
    assert {p["step"] for p in meta(tmp_path)["pictures"].values()} == {len(solver.history)}


@pytest.mark.filterwarnings("ignore::textile.io.render.RenderingWarning")
def test_pictures_are_drawn_at_the_stage_end_from_written_files(tmp_path, no_vtk, monkeypatch):
    # pictures=True: every written step's pictures, all drawn when the stage
    # ends (none while it is solved), each from its fibres file
    model = bar(0.1)
    out = textile.Output(str(tmp_path), every=2, pictures=True)
    calls = []
    draw = out._draw
    monkeypatch.setattr(out, "_draw", lambda step, vtu, *a: (
        calls.append((len(solver.history), step, vtu)), draw(step, vtu, *a)))
    solver = textile.Solver(model, dict(initial_step=0.25, max_step=0.25, **QUIET), output=out)
    solver.solve()
    assert calls == [(4, k, str(tmp_path / f"fibres_{k:05d}.vtu")) for k in (2, 4)]
    # "last" with every=3: the stage's last step (4) is written for its pictures
    model = bar(0.1)
    out = textile.Output(str(tmp_path / "last"), every=3)
    textile.Solver(model, dict(initial_step=0.25, max_step=0.25, **QUIET), output=out).solve()
    assert sorted(p.name for p in (tmp_path / "last").glob("fibres_*.vtu")) == \
        ["fibres_00003.vtu", "fibres_00004.vtu"]
    assert {p["step"] for p in meta(tmp_path / "last")["pictures"].values()} == {4}


@pytest.mark.filterwarnings("ignore::textile.io.render.RenderingWarning")
def test_pictures_of_any_written_step_after_the_run(tmp_path, no_vtk):
    import numpy as np
    model = bar(0.1)
    solver = textile.Solver(model, dict(initial_step=0.5, max_step=0.5, **QUIET),
                            output=textile.Output(str(tmp_path), pictures=False,
                                                  fibre_data={"yarn": [7]}))
    solver.solve()
    lines, radii, yarn = sample_pictures.read_fibres_vtu(str(tmp_path / "fibres_00002.vtu"))
    np.testing.assert_array_equal(lines[0], model.centreline(0))
    assert radii.tolist() == [model.mesh.fibres[0].radius] and yarn.tolist() == [7]
    drawn, errors = sample_pictures.draw_vtu_pictures(str(tmp_path / "fibres_00001.vtu"),
                                                      str(tmp_path), suffix="_first")
    assert not errors and set(drawn) == {"sample_first.png", "sample_top_first.png",
                                         "cut_first.png"}
    assert all((tmp_path / name).stat().st_size > 1000 for name in drawn)


@pytest.mark.filterwarnings("ignore::textile.io.render.RenderingWarning")
def test_pictures_of_a_saved_state(tmp_path, no_vtk):
    """A saved state's fibres read back as drawn (two fibres of unequal
    node counts: the offsets, not a fixed length, split them), and its
    pictures drawn from the file alone."""
    import numpy as np
    from mpi4py import MPI
    mat = textile.Material(1.0e9, 0.3)
    model = textile.Model([textile.straight_fibre([0, 0, 0], [1, 0, 0], 0.01, mat, 2),
                           textile.straight_fibre([0, 0.1, 0], [0, 1.1, 0], 0.02, mat, 3)],
                          comm=MPI.COMM_SELF)
    path = str(tmp_path / "state.h5")
    textile.save_state(model, path, fibre_data={"yarn": [3, 5]})
    lines, radii, data = textile.saved_fibres(path)
    assert [len(x) for x in lines] == [5, 7]
    np.testing.assert_array_equal(lines[1], model.centreline(1))
    assert radii.tolist() == [0.01, 0.02] and data["yarn"].tolist() == [3, 5]
    axes = sample_pictures.yarn_axes({3: "warp", 5: "weft"})
    drawn, errors = sample_pictures.draw_state_pictures(path, str(tmp_path / "pictures"), axes)
    assert not errors and set(drawn) == {"sample.png", "sample_top.png", "cut_warp.png",
                                         "cut_weft.png"}
    assert all((tmp_path / "pictures" / name).stat().st_size > 1000 for name in drawn)


@pytest.mark.filterwarnings("ignore::textile.io.render.RenderingWarning")
def test_pictures_of_a_state_without_yarns_given_its_yarns(tmp_path, no_vtk):
    """A state saved without yarn numbers (a weave's checkpoint) drawn with
    the fabric's yarns gets a cut across each yarn direction, not one cut
    of the whole; yarn numbers that do not match its fibres are an error."""
    from mpi4py import MPI
    mat = textile.Material(1.0e9, 0.3)
    model = textile.Model([textile.straight_fibre([0, 0, 0], [1, 0, 0], 0.01, mat, 2),
                           textile.straight_fibre([0, 0.1, 0], [0, 1.1, 0], 0.02, mat, 3)],
                          comm=MPI.COMM_SELF)
    path = str(tmp_path / "state.h5")
    textile.save_state(model, path)
    axes = sample_pictures.yarn_axes({3: "warp", 5: "weft"})
    drawn, errors = sample_pictures.draw_state_pictures(path, str(tmp_path / "pictures"), axes,
                                                        yarn=[3, 5])
    assert not errors and {"cut_warp.png", "cut_weft.png"} <= set(drawn) \
        and "cut.png" not in drawn
    with pytest.raises(ValueError, match="3 yarn numbers for the 2 fibres"):
        sample_pictures.draw_state_pictures(path, str(tmp_path / "p2"), axes, yarn=[3, 5, 5])
