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
