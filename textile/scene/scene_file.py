"""Scene files: a whole run described in a TOML file (docs/scene_files.md).

``python3 -m textile run scene.toml`` (:mod:`textile.__main__`) reads the
file with the standard library's :mod:`tomllib`, checks it against the
schema below and builds the scene from textile's public objects
(:class:`~textile.fabric.Fabric`, :class:`~textile.fabric.weaving.Weaving`,
:mod:`textile.virtual_tests`, :class:`~textile.Model`,
:class:`~textile.RigidBody`, :class:`~textile.Stage`, ...). Three kinds:

- ``weave``: a fabric woven from its straight start (the weaving and
  relaxation stages), the woven state saved to ``woven.h5``;
- ``virtual_test``: tension, shear, bending, twisting or the picture frame
  of a woven fabric (with a matrix: the composite), one test or several
  cases from the same woven state;
- ``fibres``: fibres, supports and loads, rigid bodies, contact, and stages
  that ramp or release the loads by the names the file gives them.

Every check names the file and the full path of the key in it
(``scene.toml: stages[2].ramp.turn: unknown handle 'turn'; known: ...``):
unknown keys, wrong types, missing fields, unknown names (materials,
fibres, handles), and errors the objects raise when built, under the path
of the table they were built from. Array indices count from 0.
"""
from __future__ import annotations

import dataclasses
import json
import math
import os
import tomllib

from .. import presets
from ..log import get_logger

_log = get_logger(__name__)
KINDS = ("weave", "virtual_test", "fibres")
TEST_TYPES = ("tension", "shear", "bending", "twisting", "picture_frame")
REQUIRED = object()
#: the names of a rigid body's components (textile.scene.rigid_body)
BODY_DOFS = ("x", "y", "z", "rx", "ry", "rz")
BODY_GROUPS = ("all", "translation", "rotation")


class SceneError(ValueError):
    """A scene file that cannot be read, or that does not follow the schema:
    the message starts with the file and the path of the key."""


def _show(value) -> str:
    """A value as the TOML file spells it."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return "[" + ", ".join(_show(v) for v in value) + "]"
    return repr(value)


def _key(path: str, key) -> str:
    if isinstance(key, int):
        return f"{path}[{key}]"
    return f"{path}.{key}" if path else str(key)


class _Reader:
    """Checks values at paths of one file; errors name the file and path."""

    def __init__(self, file: str):
        self.file = file

    def fail(self, path: str, message: str):
        raise SceneError(f"{self.file}: {path}: {message}" if path else f"{self.file}: {message}")


# -- value checks: (reader, value, path) -> the value to use ----------------------
def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def number(positive=False, minimum=None, maximum=None, nonzero=False, below=None):
    def check(r, v, path):
        what = "a positive number" if positive else "a number"
        if not _is_number(v) or not math.isfinite(v):
            r.fail(path, f"must be {what}, got {_show(v)}")
        if positive and v <= 0:
            r.fail(path, f"must be a positive number, got {_show(v)}")
        if minimum is not None and v < minimum:
            r.fail(path, f"must be a number >= {minimum}, got {_show(v)}")
        if maximum is not None and v > maximum:
            r.fail(path, f"must be a number <= {maximum}, got {_show(v)}")
        if below is not None and v >= below:
            r.fail(path, f"must be a number below {below}, got {_show(v)}")
        if nonzero and v == 0:
            r.fail(path, "must be a non-zero number, got 0")
        return float(v)
    return check


def integer(minimum=None):
    def check(r, v, path):
        if isinstance(v, bool) or not isinstance(v, int):
            r.fail(path, f"must be an integer, got {_show(v)}")
        if minimum is not None and v < minimum:
            r.fail(path, f"must be an integer >= {minimum}, got {_show(v)}")
        return int(v)
    return check


def string(choices=None):
    def check(r, v, path):
        if not isinstance(v, str) or not v:
            r.fail(path, f"must be a non-empty string, got {_show(v)}")
        if choices is not None and v not in choices:
            r.fail(path, f"must be one of {', '.join(map(_show, choices))}; got {_show(v)}")
        return v
    return check


def boolean(r, v, path):
    if not isinstance(v, bool):
        r.fail(path, f"must be true or false, got {_show(v)}")
    return v


def vector(size=3):
    def check(r, v, path):
        if not isinstance(v, list) or len(v) != size or not all(
                _is_number(x) and math.isfinite(x) for x in v):
            r.fail(path, f"must be an array of {size} numbers, got {_show(v)}")
        return [float(x) for x in v]
    return check


def numbers_or_number(r, v, path):
    if _is_number(v) and math.isfinite(v):
        return float(v)
    if isinstance(v, list) and v and all(_is_number(x) and math.isfinite(x) for x in v):
        return [float(x) for x in v]
    r.fail(path, f"must be a number or an array of numbers, got {_show(v)}")


def strings(r, v, path):
    """A string or an array of strings -> a list."""
    if isinstance(v, str) and v:
        return [v]
    if isinstance(v, list) and v and all(isinstance(x, str) and x for x in v):
        return list(v)
    r.fail(path, f"must be a string or an array of strings, got {_show(v)}")


def array(item):
    def check(r, v, path):
        if not isinstance(v, list):
            r.fail(path, f"must be an array, got {_show(v)}")
        return [item(r, x, _key(path, i)) for i, x in enumerate(v)]
    return check


def tables(item):
    """An array of tables ([[name]]), each checked by ``item``."""
    def check(r, v, path):
        if not isinstance(v, list) or not all(isinstance(x, dict) for x in v):
            r.fail(path, f"must be an array of tables ([[{path.split('.')[-1]}]]), got "
                         f"{_show(v)}")
        return [item(r, x, _key(path, i)) for i, x in enumerate(v)]
    return check


def table(spec, extra=None):
    """A table of the keys in ``spec`` ({key: (check, default)}, default
    REQUIRED for a required key, None for an optional one left out);
    ``extra``: a check of any other key (a table of user-named entries)."""
    def check(r, v, path):
        if not isinstance(v, dict):
            r.fail(path, f"must be a table, got {_show(v)}")
        out = {}
        for key, value in v.items():
            if key in spec:
                out[key] = spec[key][0](r, value, _key(path, key))
            elif extra is not None:
                out[key] = extra(r, value, _key(path, key))
            else:
                r.fail(_key(path, key), f"unknown key {_show(key)}; known: "
                                        f"{', '.join(sorted(spec)) or 'none'}")
        for key, (_, default) in spec.items():
            if key not in out:
                if default is REQUIRED:
                    r.fail(_key(path, key), "missing (required)")
                out[key] = default
        return out
    return check


def anything_scalar(r, v, path):
    if isinstance(v, (dict, list)):
        r.fail(path, f"must be a number, string or boolean, got {_show(v)}")
    return v


def _options_spec(cls, keys=None):
    """A spec from an Options dataclass's fields: their defaults' types."""
    spec = {}
    for f in dataclasses.fields(cls):
        if f.name.startswith("_") or (keys is not None and f.name not in keys):
            continue
        default = f.default if f.default is not dataclasses.MISSING else f.default_factory()
        kind = f.type if isinstance(f.type, str) else getattr(f.type, "__name__", "")
        if isinstance(default, bool) or kind == "bool":
            check = boolean
        elif isinstance(default, int) and not isinstance(default, bool) or kind == "int":
            check = integer()
        elif isinstance(default, float) or kind.startswith("float"):
            check = number()
        elif isinstance(default, str) or kind == "str":
            check = string()
        elif isinstance(default, dict):
            check = table({}, extra=anything_scalar)
        elif isinstance(default, tuple):
            check = array(number())
        else:
            check = anything_scalar
        spec[f.name] = (check, None)
    return spec


def _given(d: dict) -> dict:
    """The keys a table gave (not the optional ones left out)."""
    return {k: v for k, v in d.items() if v is not None}


# -- the schema ------------------------------------------------------------------
def _schema():
    from ..effects.fibre_contact import ContactOptions
    from ..solver import Solver, SolverOptions
    contact = table(_options_spec(ContactOptions))
    solver = table(_options_spec(SolverOptions))
    stage_solver = table(_options_spec(SolverOptions, Solver.STAGE_OPTIONS))
    material = table({"young": (number(positive=True), REQUIRED),
                      "poisson": (number(minimum=-1.0, below=0.5), 0.3)})
    yarn = table({"fibres": (integer(1), REQUIRED), "radius": (number(positive=True), REQUIRED),
                  "material": (string(), REQUIRED), "packing": (packing, "hexagonal"),
                  "clearance": (number(minimum=0.0), 0.0), "twist": (number(), 0.0),
                  "friction": (number(minimum=0.0), None)})
    fabric = table({"yarn": (yarn, REQUIRED), "weft_yarn": (yarn, None),
                    "num_warp": (integer(1), 2), "num_weft": (integer(1), 2),
                    "pattern": (pattern, "plain"),
                    "spacing": (number(positive=True), None),
                    "spacing_widths": (number(positive=True), None),
                    "free_length": (number(minimum=0.0), None),
                    "free_length_spacings": (number(minimum=0.0), None),
                    "elements_per_crossing": (integer(1), None), "order": (integer(1), 2)})
    weaving = table({"steps": (integer(1), None), "relaxation_steps": (integer(1), None),
                     "tension": (number(positive=True), 1e-4), "drag": (number(minimum=0), 0.0),
                     "lifting_drag": (number(minimum=0), 0.0),
                     "viscous_fading": (boolean, False), "viscous_settling": (boolean, False),
                     "drag_within_yarns": (boolean, False), "contact": (contact, None)})
    test_keys = {"type": (string(TEST_TYPES), None), "name": (string(), None),
                 "steps": (integer(1), None), "release_steps": (integer(0), None),
                 "strain": (number(nonzero=True), None), "ratio": (number(), None),
                 "displacement": (number(nonzero=True), None),
                 "displacement_spacings": (number(nonzero=True), None),
                 "angle_deg": (number(nonzero=True), None),
                 "pin": (string(("fibre", "yarn")), None),
                 "settle_drag": (number(minimum=0), None), "turning_ends": (boolean, None)}
    test = table(dict(test_keys, woven=(string(), None), contact=(contact, None),
                      cases=(tables(table(test_keys)), None)))
    matrix = table({"material": (string(), REQUIRED), "size": (number(positive=True), None),
                    "size_radii": (number(positive=True), None), "degree": (integer(1), None),
                    "law": (string(("neo-hookean", "svk")), None),
                    "overlap": (number(minimum=0.0), None),
                    "junction_stiffness": (number(positive=True), None),
                    "junction_spacing": (number(positive=True), None)})
    fibre = table({"name": (string(), REQUIRED), "start": (vector(), REQUIRED),
                   "end": (vector(), REQUIRED), "radius": (number(positive=True), REQUIRED),
                   "material": (string(), REQUIRED), "elements": (integer(1), 10),
                   "order": (integer(1), 2), "section_vector": (vector(), None)})
    load = table({"name": (string(), REQUIRED),
                  "type": (string(("clamp", "fix", "force", "moment")), REQUIRED),
                  "fibre": (string(), REQUIRED), "node": (integer(), REQUIRED),
                  "dofs": (strings, None), "value": (numbers_or_number, None)})
    body = table({"name": (string(), REQUIRED),
                  "sections": (array(section), REQUIRED),
                  "fix": (strings, None),
                  "prescribe": (table({d: (number(), None) for d in BODY_DOFS}), None),
                  "force": (vector(), None), "moment": (vector(), None)})
    stage = table({"name": (string(), REQUIRED),
                   "ramp": (table({}, extra=numbers_or_number), None),
                   "release": (strings, None),
                   "effects": (table({"contact": (table(_options_spec(ContactOptions, (
                       "friction",)) | {"mode": (string(("ordinary",)), None)}), None),
                                      "drag": (table({"coefficient": (number(minimum=0.0),
                                                                      None)}), None)}), None),
                   "solver": (stage_solver, None)})
    probe = table({"name": (string(), REQUIRED),
                   "type": (string(("position", "section", "reaction", "body_reaction")),
                            REQUIRED),
                   "fibre": (string(), None), "node": (integer(), None),
                   "dofs": (strings, None), "body": (string(), None)})
    output = table({"directory": (string(), None), "every": (integer(1), None),
                    "pictures": (pictures, None),
                    "checkpoint": (string(("none", "stage", "step")), None),
                    "probes": (tables(probe), None)})
    scene = table({"kind": (string(KINDS), REQUIRED), "title": (string(), None),
                   "preset": (string(presets.names()), None)})
    return table({"scene": (scene, REQUIRED),
                  "materials": (table({}, extra=material), None),
                  "fabric": (fabric, None), "weaving": (weaving, None),
                  "test": (test, None), "matrix": (matrix, None),
                  "fibres": (tables(fibre), None), "loads": (tables(load), None),
                  "bodies": (tables(body), None), "contact": (contact, None),
                  "drag": (table({"coefficient": (number(minimum=0.0), 1.0)}), None),
                  "stages": (tables(stage), None), "solver": (solver, None),
                  "output": (output, None)})


def packing(r, v, path):
    if isinstance(v, str) and v:
        return v
    if isinstance(v, list) and v and all(isinstance(p, list) and len(p) == 2 and all(
            _is_number(x) for x in p) for p in v):
        return v
    r.fail(path, f"must be a packing name (\"hexagonal\", \"round\", \"layers n\") or an "
                 f"array of [d, h] offsets, got {_show(v)}")


def pattern(r, v, path):
    if isinstance(v, str) and v:
        return v
    if isinstance(v, list) and v and all(isinstance(row, list) and row and all(
            x in (0, 1) and not isinstance(x, bool) for x in row) for row in v):
        return v
    r.fail(path, f"must be a pattern name (\"plain\", \"twill 2/2\", ...) or an array of rows "
                 f"of 0 and 1, got {_show(v)}")


def section(r, v, path):
    if isinstance(v, list) and len(v) == 2 and isinstance(v[0], str) \
            and isinstance(v[1], int) and not isinstance(v[1], bool):
        return (v[0], int(v[1]))
    r.fail(path, f"must be [fibre name, node index], got {_show(v)}")


def pictures(r, v, path):
    if isinstance(v, bool) or v == "last":
        return v
    r.fail(path, f"must be true, false or \"last\", got {_show(v)}")


#: the tables each kind takes (besides scene, materials, solver, output)
KIND_TABLES = {"weave": {"fabric", "weaving"},
               "virtual_test": {"fabric", "weaving", "test", "matrix"},
               "fibres": {"fibres", "loads", "bodies", "contact", "drag", "stages"}}
COMMON_TABLES = {"scene", "materials", "solver", "output"}
#: the keys of each test type (besides those of every type, TEST_COMMON)
TEST_ARGUMENTS = {"tension": {"strain": True, "ratio": False},
                  "shear": {"displacement": None, "displacement_spacings": None},
                  "bending": {"angle_deg": True}, "twisting": {"angle_deg": True},
                  "picture_frame": {"angle_deg": None, "displacement": None, "pin": False}}
TEST_COMMON = {"type", "name", "steps", "release_steps", "settle_drag", "turning_ends"}


# -- reading ---------------------------------------------------------------------
def _set_value(reader: _Reader, data: dict, assignment: str) -> None:
    """``KEY=VALUE`` (a command line's --set): the value parsed as TOML (a
    bare word is a string), put at the dotted path (``fibres[0].elements``)."""
    if "=" not in assignment:
        reader.fail("", f"--set {assignment!r}: expected KEY=VALUE")
    key, text = assignment.split("=", 1)
    try:
        value = tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        value = text
    parts = []
    for part in key.strip().split("."):
        name, _, rest = part.partition("[")
        parts.append(name)
        while rest:
            index, _, rest = rest.partition("]")
            if not index.isdigit():
                reader.fail(key, f"--set: bad index {index!r}")
            parts.append(int(index))
            rest = rest.lstrip("[")
    node, path = data, ""
    for part in parts[:-1]:
        path = _key(path, part)
        try:
            node = node[part]
        except (KeyError, IndexError, TypeError):
            reader.fail(path, "--set: no such table in the file")
    if isinstance(parts[-1], int) and not (isinstance(node, list) and parts[-1] < len(node)):
        reader.fail(key, "--set: no such array element")
    if not isinstance(node, (dict, list)):
        reader.fail(path, "--set: not a table")
    node[parts[-1]] = value


def read_scene(path: str, overrides=()) -> "Scene":
    """Read and check a scene file (``overrides``: ``KEY=VALUE`` strings put
    in before the check); a :class:`Scene`. Raises :class:`SceneError`."""
    name = os.path.basename(path)
    reader = _Reader(name)
    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
    except FileNotFoundError:
        reader.fail("", "no such file")
    except tomllib.TOMLDecodeError as error:
        reader.fail("", f"not valid TOML: {error}")
    for assignment in overrides:
        _set_value(reader, data, assignment)
    return Scene(parse(data, reader), os.path.dirname(os.path.abspath(path)), name,
                 os.path.splitext(name)[0])


def parse(data: dict, reader: _Reader) -> dict:
    """The checked scene: every table of the schema with its defaults."""
    scene = _schema()(reader, data, "")
    kind = scene["scene"]["kind"]
    allowed = KIND_TABLES[kind] | COMMON_TABLES
    for key in data:
        if key not in allowed:
            reader.fail(key, f"not a table of a {_show(kind)} scene; its tables: "
                             f"{', '.join(sorted(allowed))}")
    materials = scene["materials"] or {}
    if kind in ("weave", "virtual_test"):
        _check_fabric(reader, scene, materials)
    if kind == "virtual_test":
        _check_test(reader, scene, materials)
    if kind == "fibres":
        _check_fibres(reader, scene, materials)
    _check_output(reader, scene, kind)
    return scene


def _material(reader, materials, name, path):
    if name not in materials:
        known = ", ".join(map(_show, sorted(materials))) or "none ([materials.<name>] tables)"
        reader.fail(path, f"unknown material {_show(name)}; known: {known}")


def _one_of(reader, d, path, keys, required=True):
    given = [k for k in keys if d.get(k) is not None]
    if len(given) > 1:
        reader.fail(_key(path, given[1]), f"give one of {', '.join(keys)}, not both")
    if required and not given:
        reader.fail(_key(path, keys[0]), f"missing (required: one of {', '.join(keys)})")


def _check_fabric(reader, scene, materials):
    fabric = scene["fabric"]
    if fabric is None:
        reader.fail("fabric", f"missing (required by a {_show(scene['scene']['kind'])} scene)")
    for yarn in ("yarn", "weft_yarn"):
        if fabric[yarn] is not None:
            _material(reader, materials, fabric[yarn]["material"], f"fabric.{yarn}.material")
    _one_of(reader, fabric, "fabric", ("spacing", "spacing_widths"))
    _one_of(reader, fabric, "fabric", ("free_length", "free_length_spacings"), required=False)


def _check_test(reader, scene, materials):
    test = scene["test"]
    if test is None:
        reader.fail("test", "missing (required by a \"virtual_test\" scene)")
    if scene["matrix"] is not None:
        _material(reader, materials, scene["matrix"]["material"], "matrix.material")
        _one_of(reader, scene["matrix"], "matrix", ("size", "size_radii"), required=False)
    cases = test["cases"]
    base = {k: v for k, v in test.items() if k not in ("cases", "woven", "contact")}
    if not cases:
        cases_paths = [(base, "test")]
    else:
        names = [c["name"] for c in cases]
        for i, c in enumerate(cases):
            if c["name"] is None:
                reader.fail(f"test.cases[{i}].name", "missing (required: each case's output "
                                                     "goes to a directory of that name)")
            if names.index(c["name"]) != i:
                reader.fail(f"test.cases[{i}].name", f"{_show(c['name'])} is used twice")
        cases_paths = [(base | _given(c), f"test.cases[{i}]") for i, c in enumerate(cases)]
    test["runs"] = []
    for k, (case, path) in enumerate(cases_paths):
        own = set(_given(cases[k])) if cases else set(case)
        if case["type"] is None:
            reader.fail(_key(path, "type"), "missing (required: one of "
                                            f"{', '.join(TEST_TYPES)})")
        arguments = TEST_ARGUMENTS[case["type"]]
        for key, value in list(case.items()):
            if value is not None and key not in TEST_COMMON and key not in arguments:
                if key not in own:
                    # a shared argument of [test] another case's type takes
                    case[key] = None
                    continue
                where = path if key in own else "test"
                reader.fail(_key(where, key), f"not an argument of a {_show(case['type'])} "
                                              f"test; its arguments: "
                                              f"{', '.join(sorted(arguments))}")
        for key, required in arguments.items():
            if required and case.get(key) is None:
                reader.fail(_key(path, key), f"missing (required by a {_show(case['type'])} "
                                             f"test)")
        optional = [k for k, req in arguments.items() if req is None]
        if optional:
            _one_of(reader, case, path, optional)
        if case["type"] == "picture_frame" and case.get("angle_deg") is not None \
                and abs(case["angle_deg"]) >= 90:
            reader.fail(_key(path, "angle_deg"), f"must be below 90 in size (the frame folds "
                                                 f"flat), got {_show(case['angle_deg'])}")
        test["runs"].append((case, path))
    for key, value in base.items():
        if value is not None and key not in TEST_COMMON and not any(
                key in TEST_ARGUMENTS[case["type"]] for case, _ in test["runs"]):
            types = sorted({c["type"] for c, _ in test["runs"]})
            reader.fail(_key("test", key), f"not an argument of any of the tests (their "
                                           f"types: {', '.join(types)})")


def _check_fibres(reader, scene, materials):
    fibres = scene["fibres"]
    if not fibres:
        reader.fail("fibres", "missing (required by a \"fibres\" scene: [[fibres]] tables)")
    names = {}
    for i, f in enumerate(fibres):
        if f["name"] in names:
            reader.fail(f"fibres[{i}].name", f"{_show(f['name'])} is already fibres"
                                             f"[{names[f['name']]}]")
        names[f["name"]] = i
        _material(reader, materials, f["material"], f"fibres[{i}].material")
        if f["order"] not in (1, 2):
            reader.fail(f"fibres[{i}].order", f"must be 1 or 2, got {f['order']}")

    def fibre_node(path, fibre, node):
        if fibre not in names:
            reader.fail(path, f"unknown fibre {_show(fibre)}; known: "
                              f"{', '.join(map(_show, names))}")
        f = fibres[names[fibre]]
        count = f["elements"] * f["order"] + 1
        if not -count <= node < count:
            reader.fail(path, f"node {node} is not one of fibre {_show(fibre)}'s {count} "
                              f"nodes (0 to {count - 1}, or -1 for the last)")

    # handles: name -> (kind, components)
    handles = {}

    def add_handle(path, name, kind, size):
        if name in handles:
            reader.fail(path, f"handle {_show(name)} is defined twice")
        handles[name] = (kind, size)

    from ..beam.fibre_mesh import dof_indices
    for i, load in enumerate(scene["loads"] or []):
        path = f"loads[{i}]"
        fibre_node(_key(path, "fibre"), load["fibre"], load["node"])
        kind = load["type"]
        if kind in ("clamp", "force", "moment") and load["dofs"] is not None:
            reader.fail(_key(path, "dofs"), f"not a key of a {_show(kind)} load")
        if kind == "clamp":
            if load["value"] is not None:
                reader.fail(_key(path, "value"), "not a key of a \"clamp\" (it holds the node "
                                                 "where it is: use \"fix\" to move it)")
            size = 9
        elif kind == "fix":
            dofs = load["dofs"] or ["all"]
            try:
                size = len(dof_indices(dofs))
            except ValueError as error:
                reader.fail(_key(path, "dofs"), str(error))
            value = load["value"] if load["value"] is not None else 0.0
            if isinstance(value, list) and len(value) != size:
                reader.fail(_key(path, "value"), f"must be one number or {size} (one per dof), "
                                                 f"got {len(value)}")
            load["dofs"], load["value"] = dofs, value
        else:
            if load["value"] is None:
                reader.fail(_key(path, "value"), f"missing (required: the {kind} vector)")
            vector()(reader, load["value"], _key(path, "value"))
            size = 3
        add_handle(_key(path, "name"), load["name"], "prescription" if kind in (
            "clamp", "fix") else kind, size)
    bodies = {}
    for i, b in enumerate(scene["bodies"] or []):
        path = f"bodies[{i}]"
        if b["name"] in bodies:
            reader.fail(_key(path, "name"), f"body {_show(b['name'])} is defined twice")
        bodies[b["name"]] = b
        if not b["sections"]:
            reader.fail(_key(path, "sections"), "must hold at least one [fibre, node]")
        for j, (fibre, node) in enumerate(b["sections"]):
            fibre_node(f"{path}.sections[{j}]", fibre, node)
        if b["fix"] is not None:
            for d in b["fix"]:
                if d not in BODY_DOFS + BODY_GROUPS:
                    reader.fail(_key(path, "fix"), f"unknown component {_show(d)}; known: "
                                                   f"{', '.join(BODY_DOFS + BODY_GROUPS)}")
            add_handle(_key(path, "fix"), f"{b['name']}.fix", "prescription", None)
        for d, v in _given(b["prescribe"] or {}).items():
            add_handle(f"{path}.prescribe.{d}", f"{b['name']}.{d}", "prescription", 1)
        for load in ("force", "moment"):
            if b[load] is not None:
                add_handle(_key(path, load), f"{b['name']}.{load}", load, 3)
    scene["handles"] = handles
    known = ", ".join(map(_show, handles)) or "none"
    stage_names = set()
    for i, stage in enumerate(scene["stages"] or []):
        path = f"stages[{i}]"
        if stage["name"] in stage_names:
            reader.fail(_key(path, "name"), f"stage {_show(stage['name'])} is defined twice")
        stage_names.add(stage["name"])
        for name, target in (stage["ramp"] or {}).items():
            p = f"{path}.ramp.{name}"
            if name not in handles:
                reader.fail(p, f"unknown handle {_show(name)}; known: {known}")
            size = handles[name][1]
            if isinstance(target, list) and size is not None and len(target) != size:
                reader.fail(p, f"must be one number or {size} (one per component), got "
                               f"{len(target)}")
        for j, name in enumerate(stage["release"] or []):
            p = f"{path}.release[{j}]"
            if name not in handles:
                reader.fail(p, f"unknown handle {_show(name)}; known: {known}")
            if handles[name][0] != "prescription":
                reader.fail(p, f"{_show(name)} is a {handles[name][0]}: only prescriptions "
                               f"(clamp, fix, a body's fix or prescribe) can be released")
            if name in (stage["ramp"] or {}):
                reader.fail(p, f"{_show(name)} is both ramped and released in this stage")
        for effect in _given(stage["effects"] or {}):
            if scene[effect] is None:
                reader.fail(f"{path}.effects.{effect}", f"the scene has no [{effect}] table: "
                                                        f"no such effect to configure")
    if scene["contact"] is not None:
        _options(reader, "contact", scene["contact"])
    probe_names = set()
    for i, probe in enumerate((scene["output"] or {}).get("probes") or []):
        path = f"output.probes[{i}]"
        if probe["name"] in probe_names:
            reader.fail(_key(path, "name"), f"probe {_show(probe['name'])} is defined twice")
        probe_names.add(probe["name"])
        if probe["type"] == "body_reaction":
            if probe["body"] not in bodies:
                reader.fail(_key(path, "body"), f"unknown body {_show(probe['body'])}; known: "
                                                f"{', '.join(map(_show, bodies)) or 'none'}")
        else:
            if probe["fibre"] is None:
                reader.fail(_key(path, "fibre"), "missing (required by this probe type)")
            fibre_node(_key(path, "fibre"), probe["fibre"],
                       probe["node"] if probe["node"] is not None else -1)


def _options(reader, path, options):
    """An Options table built once, so a bad value is named here."""
    from ..effects.fibre_contact import ContactOptions
    try:
        ContactOptions.from_dict(_given(options))
    except (TypeError, ValueError) as error:
        reader.fail(path, str(error))


def _check_output(reader, scene, kind):
    out = scene["output"] = scene["output"] or {"directory": None, "every": None,
                                                "pictures": None, "checkpoint": None,
                                                "probes": None}
    for key, kinds in (("pictures", ("weave", "fibres")), ("every", ("weave", "fibres")),
                       ("checkpoint", ("weave", "fibres", "virtual_test")),
                       ("probes", ("fibres",))):
        if out[key] is not None and kind not in kinds:
            reader.fail(f"output.{key}", f"not available in a {_show(kind)} scene (only "
                                         f"{', '.join(map(_show, kinds))})")
    if kind == "virtual_test" and out["checkpoint"] == "stage":
        reader.fail("output.checkpoint", 'a virtual test keeps "step" (its state and '
                                         'result after every step) or "none" (the default)')
    if scene["solver"] is not None:
        from ..solver import SolverOptions
        try:
            SolverOptions.from_dict(_given(scene["solver"]))
        except (TypeError, ValueError) as error:
            reader.fail("solver", str(error))
    for name in ("weaving", "test"):
        if scene.get(name) and scene[name].get("contact") is not None:
            _options(reader, f"{name}.contact", scene[name]["contact"])


# -- building and running ------------------------------------------------------------
class Scene:
    """A checked scene file: ``data`` (every table with its defaults),
    ``directory`` (relative paths in the file are relative to it), ``file``
    (its name, for messages) and ``stem`` (the default output name)."""

    def __init__(self, data: dict, directory: str, file: str, stem: str):
        self.data, self.directory, self.file, self.stem = data, directory, file, stem
        self.reader = _Reader(file)

    @property
    def kind(self) -> str:
        return self.data["scene"]["kind"]

    def path(self, p: str) -> str:
        return p if os.path.isabs(p) else os.path.normpath(os.path.join(self.directory, p))

    def output_directory(self, override: str | None = None) -> str:
        if override:
            return os.path.abspath(override)
        given = self.data["output"]["directory"]
        return self.path(given) if given else os.path.abspath(os.path.join("output", self.stem))

    def _building(self, path: str):
        """Errors the API raises while building from table ``path``, named."""
        scene = self

        class Context:
            def __enter__(self):
                return self

            def __exit__(self, kind, error, tb):
                if kind is not None and issubclass(kind, (TypeError, ValueError)) \
                        and not issubclass(kind, SceneError):
                    raise SceneError(f"{scene.file}: {path}: {error}") from error
                return False
        return Context()

    def preset(self) -> dict:
        """The option blocks of the scene's accuracy preset (``scene.preset``,
        default "standard": textile's defaults), textile.presets.options."""
        return presets.options(self.data["scene"]["preset"])

    def solver_options(self, comm) -> dict:
        options = dict(self.preset()["solver"], **_given(self.data["solver"] or {}))
        options["verbose"] = bool(options.get("verbose", True)) and comm.rank == 0
        return options

    def contact_options(self, given) -> dict:
        """The preset's contact options with the table ``given`` (or None) winning."""
        return dict(self.preset()["contact"], **_given(given or {}))

    def element(self):
        """The fibres' BeamElement: the preset's."""
        return presets.element(self.data["scene"]["preset"])

    # -- the parts ---------------------------------------------------------------
    def materials(self) -> dict:
        from ..beam.material import Material
        out = {}
        for name, m in (self.data["materials"] or {}).items():
            with self._building(f"materials.{name}"):
                out[name] = Material(m["young"], m["poisson"])
        return out

    def fabric(self):
        from ..fabric.fabric import Fabric
        from ..fabric.yarn import Yarn
        d, materials = self.data["fabric"], self.materials()
        yarns = {}
        for key in ("yarn", "weft_yarn"):
            y = d[key]
            if y is None:
                continue
            with self._building(f"fabric.{key}"):
                yarns[key] = Yarn(y["fibres"], y["radius"], materials[y["material"]],
                                  packing=y["packing"], clearance=y["clearance"],
                                  twist=y["twist"], friction=y["friction"])
        warp = yarns["yarn"]
        spacing = d["spacing"] if d["spacing"] is not None else d["spacing_widths"] * warp.width
        free = d["free_length"]
        if d["free_length_spacings"] is not None:
            free = d["free_length_spacings"] * spacing
        with self._building("fabric"):
            return Fabric(warp, yarns.get("weft_yarn"), num_warp=d["num_warp"],
                          num_weft=d["num_weft"], spacing=spacing, pattern=d["pattern"],
                          free_length=free, elements_per_crossing=d["elements_per_crossing"]
                          or self.preset()["fabric"]["elements_per_crossing"],
                          order=d["order"])

    def weaving_options(self) -> dict:
        w = self.data["weaving"] or {"steps": None, "relaxation_steps": None, "tension": 1e-4,
                                     "drag": 0.0, "lifting_drag": 0.0, "viscous_fading": False,
                                     "viscous_settling": False,
                                     "drag_within_yarns": False, "contact": None}
        return dict(steps=w["steps"] or self.preset()["weaving"]["steps"],
                    relaxation_steps=w["relaxation_steps"], tension=w["tension"],
                    contact=self.contact_options(w["contact"]), element=self.element(),
                    **{k: w[k] for k in ("drag", "lifting_drag") if w[k] > 0},
                    **({"viscous_fading": True} if w["viscous_fading"] else {}),
                    **({"viscous_settling": True} if w["viscous_settling"] else {}),
                    **({"drag_within_yarns": True} if w["drag_within_yarns"] else {}))

    # -- running -----------------------------------------------------------------
    def run(self, output: str | None = None, resume: str | None = None, comm=None) -> dict:
        """Build and run the scene (collective); the key figures, also
        written to ``summary.json`` in the output directory."""
        from mpi4py import MPI
        comm = MPI.COMM_WORLD if comm is None else comm
        directory = self.output_directory(output)
        if comm.rank == 0:
            os.makedirs(directory, exist_ok=True)
        comm.Barrier()
        if resume is not None:
            resume = os.path.abspath(resume)
            if self.kind == "virtual_test" and (len(self.data["test"]["runs"]) > 1
                                                or self.data["test"]["cases"]):
                raise SceneError(f"{self.file}: --resume goes on with one virtual test; this "
                                 f"scene runs {len(self.data['test']['runs'])} (a scene of "
                                 f"one test, with [output] checkpoint = \"step\", resumes)")
            if not os.path.exists(resume):
                raise SceneError(f"{resume}: no such state file (--resume)")
        runner = {"weave": self._run_weave, "virtual_test": self._run_test,
                  "fibres": self._run_fibres}[self.kind]
        summary = dict(scene=self.file, kind=self.kind, title=self.data["scene"]["title"],
                       ranks=comm.size, output=directory)
        summary.update(runner(directory, resume, comm))
        if comm.rank == 0:
            with open(os.path.join(directory, "summary.json"), "w") as f:
                json.dump(summary, f, indent=1, default=_jsonable)
        return summary

    def _checkpoint(self, directory):
        """An on_step that saves the state as [output] checkpoint says."""
        from ..io.state_file import save_state
        mode = self.data["output"]["checkpoint"] or "stage"
        if mode == "none":
            return None

        def on_step(solver, rec):
            if mode == "step":
                save_state(solver.model, os.path.join(directory, f"state_{rec.step:05d}.h5"),
                           solver)
            elif rec.load_factor >= 1.0 - 1e-14:
                save_state(solver.model, os.path.join(directory, f"state_{rec.stage}.h5"),
                           solver)
        return on_step

    def _output(self, directory, **options):
        o = self.data["output"]
        for key in ("every", "pictures"):
            if o[key] is not None:
                options[key] = o[key]
        return options

    @staticmethod
    def _run_stages(solver, stages, resumed):
        """Run ``stages`` (after a resume: those left) as Solver.run does."""
        from ..io.state_file import load_state
        from ..solver.stages import stopped_within_stage
        attrs = load_state(solver.model, resumed, solver) if resumed is not None else None
        if not stages:
            if attrs is None or stopped_within_stage(attrs):
                solver.solve()
            return
        solver.run(stages, resumed=attrs)

    def _run_weave(self, directory, resume, comm):
        from ..io.state_file import save_state
        from ..solver import Solver
        from ..fabric.weaving import Weaving
        fabric = self.fabric()
        with self._building("weaving"):
            weaving = Weaving(fabric, comm=comm, **self.weaving_options())
        output = weaving.output(directory, **self._output(directory))
        with self._building("solver"):
            solver = Solver(weaving.model, self.solver_options(comm), output=output,
                            on_step=self._checkpoint(directory))
        self._run_stages(solver, weaving.stages(), resume)
        summary = weaving.summary()
        woven = os.path.join(directory, "woven.h5")
        save_state(weaving.model, woven, fibre_data={"yarn": fabric.fibre_yarn})
        return dict(steps=solver.position()["steps"], figures=summary, woven=woven)

    def _run_test(self, directory, resume, comm):
        from .. import virtual_tests
        from ..fabric.weaving import woven_state
        test = self.data["test"]
        fabric = self.fabric()
        woven = self.path(test["woven"]) if test["woven"] else None
        if woven is None:
            with self._building("weaving"):
                woven = woven_state(fabric, os.path.join(directory, "woven.h5"),
                                    solver_options=self.solver_options(comm), comm=comm,
                                    **self.weaving_options())
        elif not os.path.exists(woven):
            raise SceneError(f"{self.file}: test.woven: no such file {woven!r}")
        matrix = self.data["matrix"]
        # without [test.contact] a virtual test's own default friction
        # (textile.virtual_tests.virtual_test: 0.2 on a fabric alone, 0
        # with a matrix) under the preset's contact knobs
        given = test["contact"] if test["contact"] is not None else {
            "friction": 0.0 if matrix is not None else 0.2}
        options = dict(solver_options=self.solver_options(comm), comm=comm,
                       contact=self.contact_options(given))
        if matrix is not None:
            radius = max(y.radius for y in (fabric.warp, fabric.weft))
            composite = {k: matrix[k] for k in ("degree", "law", "overlap",
                                                "junction_stiffness", "junction_spacing")
                         if matrix[k] is not None}
            composite.setdefault("degree", self.preset()["matrix"]["degree"])
            composite["size"] = matrix["size"] if matrix["size"] is not None else (
                matrix["size_radii"] or self.preset()["matrix"]["size_radii"]) * radius
            options.update(matrix=self.materials()[matrix["material"]], composite=composite)
        classes = dict(tension=virtual_tests.Tension, shear=virtual_tests.Shear,
                       bending=virtual_tests.Bending, twisting=virtual_tests.Twisting,
                       picture_frame=virtual_tests.PictureFrame)
        results = {}
        several = len(test["runs"]) > 1 or bool(test["cases"])
        for case, path in test["runs"]:
            label = case["name"] or case["type"]
            args = dict(options, output=os.path.join(directory, label) if several
                        else directory)
            for key in ("steps", "release_steps", "settle_drag", "turning_ends"):
                if case[key] is not None:
                    args[key] = case[key]
            kind = case["type"]
            if kind == "tension":
                args.update(strain=case["strain"], ratio=case["ratio"])
            elif kind == "shear":
                args["displacement"] = case["displacement"] if case["displacement"] \
                    is not None else case["displacement_spacings"] * fabric.spacing[0]
            elif kind in ("bending", "twisting"):
                args["angle"] = math.radians(case["angle_deg"])
            else:
                if case["angle_deg"] is not None:
                    args["angle"] = math.radians(case["angle_deg"])
                else:
                    args["displacement"] = case["displacement"]
                if case["pin"] is not None:
                    args["pin"] = case["pin"]
            # a checkpoint after every step ([output] checkpoint = "step"),
            # or the one --resume goes on from (and on with)
            if resume is not None:
                args["checkpoint"] = resume.removesuffix(".h5")
            elif self.data["output"]["checkpoint"] == "step":
                args["checkpoint"] = os.path.join(args["output"], "checkpoint")
            _log.info(f"== {label}: {kind} test")
            with self._building(path):
                runner = classes[kind](fabric, woven, **args)
            result = runner.run(resume=resume is not None)
            results[label] = dict(type=kind, figures=result.figures,
                                  curve=dict(x=result.curve.x, y=result.curve.y,
                                             xlabel=result.curve.xlabel,
                                             ylabel=result.curve.ylabel),
                                  force_balance=result.force_balance,
                                  steps=len(result.steps))
            for name, value in result.figures.items():
                _log.info(f"  {name}: {value}")
        return dict(woven=woven, tests=results)

    def _run_fibres(self, directory, resume, comm):
        import numpy as np

        from ..effects.fibre_contact import FibreContact
        from ..effects.viscous_drag import ViscousDrag
        from ..beam.fibre import straight_fibre
        from .loading import Stage
        from .model import Model
        from ..io.output import Output
        from .rigid_body import RigidBody
        from ..solver import Solver
        d, materials = self.data, self.materials()
        fibres, index = [], {}
        for i, f in enumerate(d["fibres"]):
            with self._building(f"fibres[{i}]"):
                fibres.append(straight_fibre(f["start"], f["end"], f["radius"],
                                             materials[f["material"]],
                                             num_elements=f["elements"], order=f["order"],
                                             section_vector=f["section_vector"],
                                             name=f["name"]))
            index[f["name"]] = i
        model = Model(fibres, element=self.element(), comm=comm)
        handles, effects, bodies = {}, {}, {}
        for i, load in enumerate(d["loads"] or []):
            f = index[load["fibre"]]
            with self._building(f"loads[{i}]"):
                if load["type"] == "clamp":
                    h = model.clamp(f, load["node"])
                elif load["type"] == "fix":
                    h = model.fix(f, load["node"], load["dofs"], load["value"])
                elif load["type"] == "force":
                    h = model.add_force(f, load["node"], load["value"])
                else:
                    h = model.add_end_moment(f, load["node"], load["value"])
            handles[load["name"]] = h
        for i, b in enumerate(d["bodies"] or []):
            with self._building(f"bodies[{i}]"):
                body = RigidBody(b["name"], sections=[(index[f], n) for f, n in b["sections"]])
                if b["fix"] is not None:
                    handles[f"{b['name']}.fix"] = body.prescribe(b["fix"], 0.0)
                for dof, v in _given(b["prescribe"] or {}).items():
                    handles[f"{b['name']}.{dof}"] = body.prescribe(dof, v)
                if b["force"] is not None:
                    handles[f"{b['name']}.force"] = body.add_force(b["force"])
                if b["moment"] is not None:
                    handles[f"{b['name']}.moment"] = body.add_moment(b["moment"])
                model.add_rigid_body(body)
            bodies[b["name"]] = body
        if d["contact"] is not None:
            with self._building("contact"):
                effects["contact"] = FibreContact(self.contact_options(d["contact"]))
            model.add_effect(effects["contact"])
        if d["drag"] is not None:
            with self._building("drag"):
                effects["drag"] = ViscousDrag(d["drag"]["coefficient"])
            model.add_effect(effects["drag"])
        stages = []
        for i, s in enumerate(d["stages"] or []):
            with self._building(f"stages[{i}]"):
                stages.append(Stage(
                    s["name"], ramp={handles[k]: v for k, v in (s["ramp"] or {}).items()},
                    release=[handles[k] for k in s["release"] or []],
                    effects={effects[k]: _given(v) for k, v in _given(s["effects"] or {}).items()},
                    solver=_given(s["solver"] or {})))
        probes = d["output"]["probes"] or []

        def measure(m):
            out = {}
            for p in probes:
                node = p["node"] if p["node"] is not None else -1
                if p["type"] == "position":
                    v = m.centreline(index[p["fibre"]])[node]
                    out.update({f"{p['name']}_{c}": float(x) for c, x in zip("xyz", v)})
                elif p["type"] == "section":
                    g1, g2 = m.section_vectors(index[p["fibre"]])
                    out.update({f"{p['name']}_g1{c}": float(x) for c, x in zip("xyz", g1[node])})
                    out.update({f"{p['name']}_g2{c}": float(x) for c, x in zip("xyz", g2[node])})
                elif p["type"] == "reaction":
                    dofs = p["dofs"] or ["position"]
                    v = np.atleast_1d(m.reaction(index[p["fibre"]], node, dofs))
                    out.update({f"{p['name']}_{k}": float(x) for k, x in enumerate(v)})
                else:
                    r = m.rigid_bodies.reactions()[list(bodies).index(p["body"])]
                    out.update({f"{p['name']}_{c}": float(x) for c, x in
                                zip(("fx", "fy", "fz", "mx", "my", "mz"), r)})
            return out
        with self._building("output"):
            output = Output(directory, extra=measure if probes else None,
                            **self._output(directory))
        with self._building("solver"):
            solver = Solver(model, self.solver_options(comm), output=output,
                            on_step=self._checkpoint(directory))
        self._run_stages(solver, stages, resume)
        figures = measure(model)
        for name, value in figures.items():
            _log.info(f"  {name}: {value:.10g}")
        return dict(steps=solver.position()["steps"], load_factor=model.load_factor,
                    time=solver.history[-1].time if solver.history else None,
                    energy=solver.history[-1].energy if solver.history else None,
                    figures=figures)


def _jsonable(value):
    try:
        return float(value)
    except (TypeError, ValueError):
        return str(value)
