"""Scene files (textile/scene/scene_file.py, docs/scene_files.md) and the command
line ``python3 -m textile run``.

- every demo's scene file in demos/scenes/ is valid, and every demo has one;
- the demos' quick variants (the ones tests/demos runs: ``--set`` puts the
  demos' own options) run to completion through ``python3 -m textile run``
  in a subprocess, and their key figure is the same API call's (or the
  demo's reference);
- unknown keys, wrong types, missing fields, bad handles and unknown presets
  are refused with the file's name and the key's full path; a preset fills
  the knobs the file leaves out;
- ``--resume`` from a state saved within a stage ends where the
  uninterrupted run does;
- under mpirun -n 2 the command gives the one-rank answer.
"""
import copy
import glob
import json
import math
import os
import shutil
import subprocess
import sys
import tomllib

import numpy as np
import pytest
from mpi4py import MPI

from tests.installed import missing

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENES = os.path.join(ROOT, "demos", "scenes")
PYTHON = sys.executable
#: the demos and their scene files (render_weave_start.py solves nothing)
DEMO_SCENES = {"demo_plain_weave.py": "plain_weave.toml",
               "demo_fabric_shear.py": "fabric_shear.toml",
               "demo_fabric_tension.py": "fabric_tension.toml",
               "demo_picture_frame.py": "picture_frame.toml",
               "demo_composite_bending.py": "composite_bending.toml",
               "demo_composite_twisting.py": "composite_twisting.toml",
               "demo_fibre_rollup.py": "fibre_rollup.toml",
               "demo_buckled_column.py": "buckled_column.toml",
               "demo_twisted_pair.py": "twisted_pair.toml"}
#: the demos' quick monofilament variant (--fibres 1 --spacing 6)
MONO = ["--set", "fabric.yarn.fibres=1", "--set", "fabric.spacing_widths=6"]


def run_cli(*args, check=True, ranks=1):
    """``python3 -m textile ...`` in a subprocess; (status, stdout, stderr)."""
    env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
    cmd = [PYTHON, "-m", "textile", *args]
    if ranks > 1:
        cmd = ["mpirun", "-n", str(ranks)] + cmd
    p = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
    if check:
        assert p.returncode == 0, p.stdout[-3000:] + p.stderr[-3000:]
    return p.returncode, p.stdout, p.stderr


def summary(directory):
    with open(os.path.join(directory, "summary.json")) as f:
        return json.load(f)


def scene_of(name, **changes):
    """A demo's scene file as a dict, for variants written to tmp files."""
    with open(os.path.join(SCENES, name), "rb") as f:
        data = tomllib.load(f)
    data = copy.deepcopy(data)
    data.update(changes)
    return data


def write_toml(path, data):
    """A minimal TOML writer for the tests' variants (tables, arrays of
    tables, inline values)."""
    def value(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, str):
            return json.dumps(v)
        if isinstance(v, list):
            return "[" + ", ".join(value(x) for x in v) + "]"
        if isinstance(v, dict):
            return "{" + ", ".join(f"{json.dumps(k)} = {value(x)}" for k, x in v.items()) + "}"
        return repr(v)

    lines = []

    def emit(prefix, d):
        scalars = {k: v for k, v in d.items() if not isinstance(v, dict)
                   and not (isinstance(v, list) and v and all(isinstance(x, dict) for x in v))}
        for k, v in scalars.items():
            lines.append(f"{json.dumps(k)} = {value(v)}")
        for k, v in d.items():
            name = f"{prefix}.{json.dumps(k)}" if prefix else json.dumps(k)
            if isinstance(v, dict):
                lines.append(f"[{name}]")
                emit(name, v)
            elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
                for item in v:
                    lines.append(f"[[{name}]]")
                    emit(name, item)
    emit("", data)
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    return str(path)


# -- every file ----------------------------------------------------------------
def test_every_demo_has_a_scene_file():
    demos = {os.path.basename(p) for p in glob.glob(os.path.join(ROOT, "demos", "demo_*.py"))}
    assert demos == set(DEMO_SCENES)
    assert {os.path.basename(p) for p in glob.glob(os.path.join(SCENES, "*.toml"))} \
        == set(DEMO_SCENES.values())


@pytest.mark.parametrize("name", sorted(DEMO_SCENES.values()))
def test_scene_file_is_valid(name):
    from textile.scene.scene_file import read_scene
    scene = read_scene(os.path.join(SCENES, name))
    assert scene.kind in ("weave", "virtual_test", "fibres")
    # the demos' outputs go to demos/output/ (ignored by git)
    assert scene.output_directory().startswith(os.path.join(ROOT, "demos", "output"))


# -- the quick variants run and give the API's answer ------------------------------
def test_rollup_scene_is_on_the_exact_ring(tmp_path):
    """The roll-up's tip comes back onto the clamp: the demo's check (1e-4 L),
    with the demo's quick --elements 16 (tests/demos)."""
    run_cli("run", "demos/scenes/fibre_rollup.toml", "--output", str(tmp_path),
            "--set", "fibres[0].elements=16")
    s = summary(tmp_path)
    assert s["steps"] == 40 and s["load_factor"] == 1.0
    tip = [s["figures"][f"tip_{c}"] for c in "xyz"]
    assert np.linalg.norm(tip) < 1e-4
    assert os.path.getsize(tmp_path / "fibres.pvd") > 0


@pytest.fixture(scope="module")
def woven_mono(tmp_path_factory):
    """The plain weave's quick variant through the command line, checkpoints
    at every step (its output directory)."""
    out = tmp_path_factory.mktemp("weave")
    run_cli("run", "demos/scenes/plain_weave.toml", "--output", str(out), *MONO,
            "--set", 'output.checkpoint="step"')
    return out


def mono_fabric():
    import textile
    from textile.fabric import Fabric
    from textile.fabric import Yarn
    yarn = Yarn(1, 0.1e-3, textile.Material(5.0e9, 0.35), packing="layers 1")
    # the default free length, half a spacing: the picture frame's 0.5 spacings
    return Fabric(yarn, num_warp=2, num_weft=2, spacing=6 * yarn.width, pattern="plain",
                  elements_per_crossing=4)


def test_plain_weave_scene_is_the_api_weave(woven_mono):
    """The woven figures are Weaving(...).run()'s on the same fabric."""
    from textile.fabric import Weaving
    s = summary(woven_mono)
    assert s["steps"] == 6
    weaving = Weaving(mono_fabric(), steps=5, tension=1e-4)
    weaving.run(solver_options=dict(verbose=False))
    ref = weaving.summary()
    assert s["figures"]["crossings in pattern order"] == ref["crossings"] == 4
    for key in ("warp crimp", "weft crimp", "warp shrinkage", "max penetration / radius"):
        assert s["figures"][key] == pytest.approx(ref[key], rel=1e-8), key
    assert os.path.getsize(woven_mono / "woven.h5") > 0


def test_resume_between_stages_ends_as_the_uninterrupted_run(woven_mono, tmp_path):
    """--resume from the state saved at the end of the weaving stage (step
    5) relaxes to the same woven state, to round-off. (Within the weaving
    stage: tests/io/test_state_file.py, through the API.)"""
    state = woven_mono / "state_00005.h5"
    _, out, _ = run_cli("run", "demos/scenes/plain_weave.toml", "--output", str(tmp_path),
                        *MONO, "--resume", str(state))
    assert "step    6  relaxation" in out and "weaving s=" not in out
    full, resumed = summary(woven_mono), summary(tmp_path)
    assert resumed["steps"] == full["steps"] == 6
    for key, value in full["figures"].items():
        assert resumed["figures"][key] == pytest.approx(value, rel=1e-9, abs=1e-15), key


def test_resume_within_a_stage_ends_as_the_uninterrupted_run(tmp_path):
    """The twisted pair (8 elements a fibre) saved at every step; --resume
    from step 5, within the twist stage, goes on to the same final state as
    the uninterrupted run: the same steps, the same forces to round-off."""
    sets = ["--set", "fibres[0].elements=8", "--set", "fibres[1].elements=8"]
    full, part = tmp_path / "full", tmp_path / "resumed"
    run_cli("run", "demos/scenes/twisted_pair.toml", "--output", str(full), *sets,
            "--set", 'output.checkpoint="step"')
    _, out, _ = run_cli("run", "demos/scenes/twisted_pair.toml", "--output", str(part), *sets,
                        "--resume", str(full / "state_00005.h5"))
    assert "twist resumed at s=" in out and "step    6  twist" in out
    a, b = summary(full), summary(part)
    assert a["steps"] == b["steps"] and a["time"] == b["time"] == 2.0
    for key, value in a["figures"].items():
        assert b["figures"][key] == pytest.approx(value, rel=1e-10, abs=1e-12), key


def test_picture_frame_scene_is_the_api_test(woven_mono, tmp_path):
    """The picture frame's quick variant (tests/demos': 15 deg in 3 steps),
    from the woven state of the weave scene (test.woven), gives
    PictureFrame(...).run()'s curve."""
    from textile.virtual_tests import PictureFrame
    woven = str(woven_mono / "woven.h5")
    run_cli("run", "demos/scenes/picture_frame.toml", "--output", str(tmp_path), *MONO,
            "--set", "test.angle_deg=15", "--set", "test.steps=3",
            "--set", f"test.woven={json.dumps(woven)}")
    s = summary(tmp_path)["tests"]["picture_frame"]
    assert s["steps"] == 3
    ref = PictureFrame(mono_fabric(), woven, angle=math.radians(15), steps=3,
                       solver_options=dict(verbose=False)).run()
    assert s["curve"]["x"] == pytest.approx(ref.curve.x, rel=1e-10)
    assert s["curve"]["y"] == pytest.approx(ref.curve.y, rel=1e-7, abs=1e-12)
    assert os.path.getsize(tmp_path / "picture_frame.csv") > 0


def test_a_virtual_test_scene_resumes_from_its_checkpoint(woven_mono, tmp_path):
    """[output] checkpoint = "step" keeps a virtual test's state and rows
    after every step; --resume from it goes on with that test (here from
    its last step: the same curve and steps, nothing solved again). A
    scene of several tests cannot be resumed, and "stage" is no virtual
    test's checkpoint. (Resumed within the loading: tests/virtual/
    test_fabric_tests.py, through the API.)"""
    woven = str(woven_mono / "woven.h5")
    sets = [*MONO, "--set", "test.angle_deg=15", "--set", "test.steps=3",
            "--set", f"test.woven={json.dumps(woven)}"]
    full, again = tmp_path / "full", tmp_path / "again"
    run_cli("run", "demos/scenes/picture_frame.toml", "--output", str(full), *sets,
            "--set", 'output.checkpoint="step"')
    assert (full / "checkpoint.h5").exists() and (full / "checkpoint.json").exists()
    _, out, _ = run_cli("run", "demos/scenes/picture_frame.toml", "--output", str(again),
                        *sets, "--resume", str(full / "checkpoint.h5"))
    assert "step " not in out   # the checkpoint was the test's end
    a, b = (summary(d)["tests"]["picture_frame"] for d in (full, again))
    assert a["steps"] == b["steps"] == 3
    assert b["curve"] == a["curve"] and b["figures"] == pytest.approx(a["figures"], rel=1e-12)
    status, _, err = run_cli("run", "demos/scenes/fabric_shear.toml", *MONO,
                             "--resume", str(full / "checkpoint.h5"), check=False)
    assert status == 2 and "--resume goes on with one virtual test; this scene runs 2" in err
    data = scene_of("picture_frame.toml")
    data["output"] = {"checkpoint": "stage"}
    refused(tmp_path, data, "scene.toml: output.checkpoint: a virtual test keeps \"step\"")


def test_test_table_reaches_the_sample_options(woven_mono, tmp_path):
    """test.turning_ends and test.settle_drag reach the VirtualTest (held
    end bodies on monofilaments, a drag through the settling): the shear's
    quick variant gives Shear(...).run()'s curve with them; a wrong type is
    named by its key."""
    from textile.virtual_tests import Shear
    woven = str(woven_mono / "woven.h5")
    run_cli("run", "demos/scenes/fabric_shear.toml", "--output", str(tmp_path), *MONO,
            "--set", "test.steps=2", "--set", f"test.woven={json.dumps(woven)}",
            "--set", "test.turning_ends=false", "--set", "test.settle_drag=0.05")
    s = summary(tmp_path)["tests"]["positive"]      # its first case: +0.2 spacing
    ref = Shear(mono_fabric(), woven, 0.2 * mono_fabric().spacing[0], steps=2,
                turning_ends=False, settle_drag=0.05, solver_options=dict(verbose=False)).run()
    assert s["curve"]["y"] == pytest.approx(ref.curve.y, rel=1e-7, abs=1e-12)
    data = scene_of("fabric_shear.toml")
    data["test"]["turning_ends"] = "no"
    refused(tmp_path, data, "scene.toml: test.turning_ends: must be true or false, got \"no\"")
    data["test"]["turning_ends"] = True
    data["test"]["settle_drag"] = -1
    refused(tmp_path, data, "scene.toml: test.settle_drag: must be a number >= 0, got -1")


def test_composite_bending_scene_is_the_api_test(woven_mono, tmp_path):
    """The composite bending's quick variant (2 steps) gives Bending's
    moments; matrix.junction_spacing reaches the Composite (3 R: one
    junction station an element instead of two)."""
    import textile
    from textile.virtual_tests import Bending
    woven = str(woven_mono / "woven.h5")
    run_cli("run", "demos/scenes/composite_bending.toml", "--output", str(tmp_path), *MONO,
            "--set", "test.steps=2", "--set", f"test.woven={json.dumps(woven)}",
            "--set", "matrix.junction_spacing=3e-4")
    s = summary(tmp_path)["tests"]["bending"]
    ref = Bending(mono_fabric(), woven, math.radians(10), steps=2,
                  matrix=textile.Material(3.0e9, 0.35),
                  composite=dict(size=8 * 0.1e-3, degree=2, junction_spacing=3e-4),
                  release_steps=2,
                  solver_options=dict(verbose=False)).run()
    assert s["curve"]["y"] == pytest.approx(ref.curve.y, rel=1e-7)
    key = "bending stiffness per width (moment per width per unit curvature)"
    assert s["figures"][key] == pytest.approx(ref.figures[key], rel=1e-7)


@pytest.mark.parametrize("name,args", [
    ("composite_twisting.toml", ["--set", "test.steps=1"]),
    ("fabric_shear.toml", ["--set", "test.steps=2"]),
    ("fabric_tension.toml", ["--set", "test.steps=1"]),
])
def test_virtual_test_scenes_run(name, args, woven_mono, tmp_path):
    """The other virtual tests' quick variants run through: every case, its
    figures and curve; the shear's two directions mirror each other."""
    woven = str(woven_mono / "woven.h5")
    run_cli("run", f"demos/scenes/{name}", "--output", str(tmp_path), *MONO, *args,
            "--set", f"test.woven={json.dumps(woven)}")
    tests = summary(tmp_path)["tests"]
    with open(os.path.join(SCENES, name), "rb") as f:
        cases = tomllib.load(f)["test"].get("cases")
    assert sorted(tests) == sorted(c["name"] for c in cases) if cases else len(tests) == 1
    for t in tests.values():
        assert t["steps"] >= 1 and len(t["curve"]["y"]) == t["steps"] + 1
    if name == "fabric_shear.toml":
        plus, minus = (np.array(tests[k]["curve"]["y"]) for k in ("positive", "negative"))
        assert np.abs((plus - plus[0]) + (minus - minus[0])).max() \
            < 0.05 * np.abs(plus - plus[0]).max()


def test_buckled_column_scene_is_on_the_elastica(tmp_path):
    """The column at 1.2 P_cr lies on the inextensible elastica (the demo's
    check, 1e-3), with the demo's --elements 8 --step 0.05."""
    import scipy.special
    run_cli("run", "demos/scenes/buckled_column.toml", "--output", str(tmp_path),
            "--set", "fibres[0].elements=8", "--set", "solver.initial_step=0.05",
            "--set", "solver.max_step=0.05")
    f = summary(tmp_path)["figures"]
    alpha = math.atan2(-f["tip_section_g2x"], f["tip_section_g2z"])
    elastica = (2 * scipy.special.ellipk(math.sin(alpha / 2) ** 2) / math.pi) ** 2
    assert math.degrees(alpha) == pytest.approx(67.86, abs=0.3)
    assert 1.2 / elastica == pytest.approx(1.0, abs=1e-3)


def test_twisted_pair_scene_is_the_demos_pair(tmp_path):
    """The twisted pair through a rigid body and two stages: the demo's
    axial force after one turn and 1% stretch (118.81 N with 12 elements:
    demo_twisted_pair.py --elements 12, measured), to the difference of
    their load paths (0.04%), far from two straight fibres' 47.1 N."""
    run_cli("run", "demos/scenes/twisted_pair.toml", "--output", str(tmp_path),
            "--set", "fibres[0].elements=12", "--set", "fibres[1].elements=12")
    f = summary(tmp_path)["figures"]
    assert f["top_fz"] == pytest.approx(118.81, rel=2e-3)


# -- errors name the file and the key's path --------------------------------------
def refused(tmp_path, data, *messages):
    from textile.scene.scene_file import SceneError, read_scene
    path = write_toml(tmp_path / "scene.toml", data)
    with pytest.raises(SceneError) as error:
        read_scene(path)
    text = str(error.value)
    assert text.startswith("scene.toml: "), text
    for m in messages:
        assert m in text, text
    return text


def test_unknown_key(tmp_path):
    data = scene_of("plain_weave.toml")
    data["fabric"]["yarn"]["colour"] = "red"
    refused(tmp_path, data, "scene.toml: fabric.yarn.colour: unknown key \"colour\"; known:",
            "radius")


def test_wrong_type(tmp_path):
    data = scene_of("plain_weave.toml")
    data["fabric"]["yarn"]["radius"] = -1
    refused(tmp_path, data, "scene.toml: fabric.yarn.radius: must be a positive number, got -1")
    data["fabric"]["yarn"]["radius"] = "thin"
    refused(tmp_path, data, "fabric.yarn.radius: must be a positive number, got \"thin\"")
    data = scene_of("twisted_pair.toml")
    data["stages"][1]["solver"]["max_step"] = True
    refused(tmp_path, data, "scene.toml: stages[1].solver.max_step: must be a number, got true")
    data = scene_of("plain_weave.toml")
    data.setdefault("weaving", {})["drag"] = -1
    refused(tmp_path, data, "scene.toml: weaving.drag: must be a number >= 0, got -1")
    # a valid drag reaches Weaving (docs/method.md §6.4)
    data["weaving"]["drag"] = 0.1
    data["weaving"]["lifting_drag"] = 0.2
    write_toml(tmp_path / "drag.toml", data)
    from textile.scene.scene_file import read_scene
    options = read_scene(str(tmp_path / "drag.toml")).weaving_options()
    assert options["drag"] == 0.1 and options["lifting_drag"] == 0.2
    assert "viscous_fading" not in options   # the default: Weaving's own
    data["weaving"]["viscous_fading"] = True
    data["weaving"]["viscous_settling"] = True
    write_toml(tmp_path / "viscous.toml", data)
    options = read_scene(str(tmp_path / "viscous.toml")).weaving_options()
    assert options["viscous_fading"] is True and options["viscous_settling"] is True
    data["weaving"]["viscous_fading"] = 1
    refused(tmp_path, data, "scene.toml: weaving.viscous_fading: must be true or false, got 1")
    data["weaving"]["viscous_fading"] = True
    assert "drag_within_yarns" not in read_scene(str(tmp_path / "viscous.toml")) \
        .weaving_options()                       # the default: Weaving's own
    data["weaving"]["drag_within_yarns"] = True
    write_toml(tmp_path / "within.toml", data)
    assert read_scene(str(tmp_path / "within.toml")).weaving_options()[
        "drag_within_yarns"] is True
    data["weaving"]["drag_within_yarns"] = "no"
    refused(tmp_path, data, "scene.toml: weaving.drag_within_yarns: must be true or false, "
                            "got \"no\"")


def test_missing_field(tmp_path):
    data = scene_of("plain_weave.toml")
    del data["fabric"]["yarn"]["radius"]
    refused(tmp_path, data, "scene.toml: fabric.yarn.radius: missing (required)")
    data = scene_of("fibre_rollup.toml")
    del data["fibres"][0]["end"]
    refused(tmp_path, data, "scene.toml: fibres[0].end: missing (required)")


def test_unknown_names(tmp_path):
    data = scene_of("twisted_pair.toml")
    data["stages"][0]["ramp"] = {"turn": 6.28}
    refused(tmp_path, data, "scene.toml: stages[0].ramp.turn: unknown handle \"turn\"; known: ",
            "\"top.rz\"", "\"bottom 0\"")
    data = scene_of("twisted_pair.toml")
    data["stages"][1]["release"] = ["top.force"]
    refused(tmp_path, data, "stages[1].release[0]: unknown handle \"top.force\"")
    data = scene_of("twisted_pair.toml")
    data["bodies"][0]["sections"][1] = ["fibre 2", -1]
    refused(tmp_path, data, "bodies[0].sections[1]: unknown fibre \"fibre 2\"")
    data = scene_of("plain_weave.toml")
    data["fabric"]["yarn"]["material"] = "nylon"
    refused(tmp_path, data, "fabric.yarn.material: unknown material \"nylon\"; known: "
                            "\"polyester\"")
    data = scene_of("fabric_tension.toml")
    data["test"]["cases"][4]["angle_deg"] = 3.0
    refused(tmp_path, data, "test.cases[4].angle_deg: not an argument of a \"shear\" test")


def test_kind_tables_and_presets(tmp_path):
    data = scene_of("fibre_rollup.toml")
    data["scene"]["preset"] = "accurate"
    refused(tmp_path, data, "scene.toml: scene.preset: must be one of \"draft\", "
                            "\"standard\", \"fine\"; got \"accurate\"")
    data = scene_of("fibre_rollup.toml", test={"type": "shear"})
    refused(tmp_path, data, "scene.toml: test: not a table of a \"fibres\" scene")
    data = scene_of("plain_weave.toml")
    data["scene"]["kind"] = "knit"
    refused(tmp_path, data, "scene.kind: must be one of \"weave\", \"virtual_test\", \"fibres\"")
    data = scene_of("plain_weave.toml")
    data["fabric"]["spacing"] = 1e-3
    refused(tmp_path, data, "fabric.spacing_widths: give one of spacing, spacing_widths")


def test_preset_sets_the_knobs_the_file_does_not(tmp_path):
    """scene.preset (textile.presets) fills every knob the file leaves out;
    the file's own keys win; no preset is "standard", today's defaults."""
    from textile import presets
    from textile.scene.scene_file import read_scene
    data = scene_of("plain_weave.toml")
    del data["fabric"]["elements_per_crossing"], data["weaving"]["steps"]
    data["weaving"]["contact"] = {"friction": 0.2}
    plain = read_scene(write_toml(tmp_path / "plain.toml", data))
    data["scene"]["preset"] = "fine"
    data["solver"] = {"rtol": 1e-9}
    fine = read_scene(write_toml(tmp_path / "fine.toml", data))
    p, s = presets.preset("fine"), presets.preset("standard")
    w = fine.weaving_options()
    assert w["steps"] == p["weaving"]["steps"]
    assert w["contact"] == dict(p["contact"], friction=0.2)
    assert fine.fabric().elements_per_crossing == p["fabric"]["elements_per_crossing"]
    assert fine.solver_options(MPI.COMM_SELF) == dict(p["solver"], rtol=1e-9, verbose=True)
    assert plain.fabric().elements_per_crossing == s["fabric"]["elements_per_crossing"] == 4
    assert plain.weaving_options()["contact"] == dict(s["contact"], friction=0.2)
    assert plain.weaving_options()["steps"] == 5
    data["fabric"]["elements_per_crossing"] = 3
    data["weaving"]["contact"]["regularization"] = 0.01
    mine = read_scene(write_toml(tmp_path / "mine.toml", data))
    assert mine.fabric().elements_per_crossing == 3
    assert mine.weaving_options()["contact"]["regularization"] == 0.01


def test_draft_preset_weaves_in_its_steps(tmp_path):
    """A weave scene with preset "draft" runs its 3 weaving steps (the
    file gives none) and 1 relaxation step, on 2 elements a crossing."""
    from textile.scene.scene_file import read_scene
    data = scene_of("plain_weave.toml")
    del data["fabric"]["elements_per_crossing"], data["weaving"]["steps"]
    data["fabric"]["yarn"]["fibres"], data["fabric"]["spacing_widths"] = 1, 6.0
    data["scene"]["preset"] = "draft"
    data["output"] = {"checkpoint": "none", "pictures": False}
    data["solver"] = {"verbose": False}
    scene = read_scene(write_toml(tmp_path / "scene.toml", data))
    out = scene.run(output=str(tmp_path / "out"), comm=MPI.COMM_SELF)
    assert out["steps"] == 4
    assert out["figures"]["crossings in pattern order"] == out["figures"]["crossings"] == 4


def test_api_errors_are_named_by_their_table(tmp_path):
    """An error the objects raise when built is named by the table's path."""
    from textile.scene.scene_file import SceneError, read_scene
    data = scene_of("plain_weave.toml")
    data["fabric"]["pattern"] = "satin 1"
    scene = read_scene(write_toml(tmp_path / "scene.toml", data))
    with pytest.raises(SceneError, match=r"^scene.toml: fabric: "):
        scene.fabric()


def test_command_line_errors(tmp_path):
    """The command line: exit status 2 and the message on stderr; --set
    values are checked like the file's; --help."""
    status, out, err = run_cli("run", "demos/scenes/plain_weave.toml", "--set",
                               "fabric.yarn.radius=-1", check=False)
    assert status == 2
    assert "error: plain_weave.toml: fabric.yarn.radius: must be a positive number, got -1" \
        in err
    status, out, err = run_cli("run", "no_such.toml", check=False)
    assert status == 2 and "no_such.toml: no such file" in err
    status, out, _ = run_cli("--help")
    assert "run" in out and "check" in out
    status, out, _ = run_cli("run", "--help")
    assert "--resume STATE" in out and "--output DIR" in out


# -- MPI ---------------------------------------------------------------------------
@pytest.mark.mpi
def test_two_ranks_give_the_one_rank_answer(tmp_path_factory):
    """``mpirun -n 2 python3 -m textile run`` of the twisted pair (contact,
    a rigid body, two stages; 8 elements a fibre) gives the answer of one
    rank. On one rank the command runs under mpirun in a subprocess; under
    mpirun (the mpi tests) the command line runs here on both ranks."""
    from textile.__main__ import main
    from textile.scene.scene_file import read_scene
    comm = MPI.COMM_WORLD
    sets = ["--set", "fibres[0].elements=8", "--set", "fibres[1].elements=8"]
    base = comm.bcast(str(tmp_path_factory.mktemp("mpi")) if comm.rank == 0 else None)
    parallel = os.path.join(base, "parallel")
    if comm.size == 1:
        if shutil.which("mpirun") is None:
            missing("mpirun")   # skipped here, a failure under .ci/test
        run_cli("run", "demos/scenes/twisted_pair.toml", "--output", parallel, *sets, ranks=2)
    else:
        assert main(["run", os.path.join(SCENES, "twisted_pair.toml"), "--output", parallel,
                     *sets]) == 0
    comm.Barrier()
    serial = os.path.join(base, f"serial_{comm.rank}")
    scene = read_scene(os.path.join(SCENES, "twisted_pair.toml"),
                       [s for s in sets if s != "--set"])
    one = scene.run(output=serial, comm=MPI.COMM_SELF)
    two = summary(parallel)
    assert two["ranks"] == 2 and one["ranks"] == 1
    assert two["steps"] == one["steps"]
    for key, value in one["figures"].items():
        assert two["figures"][key] == pytest.approx(value, rel=1e-8, abs=1e-10), key
