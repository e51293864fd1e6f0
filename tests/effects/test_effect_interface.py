"""One explicit effect interface (issue 23, item 1).

Every hook the model, the solver, saved states and the output call is
declared in :class:`textile.effects.base.Effect` with a neutral default, so
an effect that overrides nothing takes part in every part of a run (solve,
saved states, output) and changes nothing; the output finds contact
elements through a hook, not by the contact's class; the Newton iteration
reaches effects through the State (``tangent_index``). The source scans
keep it so: no ``hasattr`` on effects, no isinstance on effect classes, no
writes to (nor reads of) another object's private attributes in the model,
the solver, the output and saved states, and no effect assigning to the
model's attributes.
"""
import inspect
import json
import os
import re

import numpy as np
import pytest
from mpi4py import MPI

import textile
from textile.effects.base import Effect, State

E, NU, R, L = 1.0e9, 0.3, 1e-3, 0.1
EI = E * np.pi * R ** 4 / 4
F = 0.5 * EI / L ** 2
QUIET = dict(verbose=False, initial_step=0.5, max_step=0.5)
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


class Bare(Effect):
    """An effect that implements nothing: only the base class's defaults."""


def cantilever(*extra):
    fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, textile.Material(E, NU),
                                 num_elements=8, section_vector=[0, 1, 0])
    model = textile.Model(fib, comm=MPI.COMM_SELF)
    model.clamp(fib, 0)
    model.add_force(fib, -1, [0, 0, F])
    for e in extra:
        model.add_effect(e)
    return fib, model


def test_base_hooks_are_neutral():
    e = Bare()
    assert e.fields == () and not e.dynamic_sparsity and not e.constant_tangent
    assert e.schedules() == [] and e.saddle_point_rows() == 0
    assert e.constraints(0.5) == {} and e.reference_values() == {}
    assert e.update(None) is False and e.statistics() == {}
    assert e.state_name is None and e.save_state(None) == {}
    assert e.vtk_name is None and e.contact_elements() is None
    assert e.residual_global(State(0.0), None) is False
    with pytest.raises(NotImplementedError):
        e.write_vtk("somewhere", "stem", 0.0)   # only called with a vtk_name
    with pytest.raises(ValueError, match="takes no stage options"):
        e.configure(mode="x")


def test_a_bare_effect_solves_saves_loads_and_writes(tmp_path):
    """The scene with the bare effect: the same answer as without it (and
    the same Newton iterations; not the same round-off: a bare effect does
    not say its tangent is symmetric, so the solver factorizes with LU, not
    LDL^T), a saved state loads back (into the scene with or without it, and as the
    fibres of a new scene), the output writes the fibres and results but no
    contacts or parts of its own."""
    _, plain = cantilever()
    reference = textile.Solver(plain, QUIET).solve()

    bare = Bare()
    fib, model = cantilever(bare)
    out = str(tmp_path / "out")
    history = textile.Solver(model, QUIET, output=textile.Output(out, pictures=False)).solve()
    assert [r.newton_iterations for r in history] == [r.newton_iterations for r in reference]
    assert np.allclose(model.nodal_unknowns(), plain.nodal_unknowns(), rtol=0, atol=1e-12 * L)
    assert model.saddle_point_rows == 0
    assert [s.name for s in model.schedules()] == [s.name for s in plain.schedules()]
    files = sorted(os.listdir(out))
    assert "fibres.pvd" in files and "results.json" in files
    assert not any(f.startswith(("contacts", "scene")) for f in files)
    with open(os.path.join(out, "results.json")) as f:
        assert len(json.load(f)["steps"]) == len(history)

    path = str(tmp_path / "state.h5")
    textile.save_state(model, path)
    q = model.nodal_unknowns()
    for again in (cantilever(Bare())[1], cantilever()[1]):   # the bare effect saves nothing
        textile.load_state(again, path)
        assert np.array_equal(again.nodal_unknowns(), q)
    fresh = cantilever(Bare())[1]
    textile.load_fibres(fresh, path)
    assert np.array_equal(fresh.nodal_unknowns(), q)
    # the loaded scene goes on: the next stage solves from the loaded state
    solver = textile.Solver(fresh, QUIET)
    solver.run_stage(textile.Stage("hold"))
    assert np.allclose(fresh.nodal_unknowns(), q, atol=1e-9 * L)


class Touching(Effect):
    """Shows one contact element between the fibre's two ends (nothing
    else): the output writes any effect's contact elements."""

    def setup(self, model):
        self.model = model

    def contact_elements(self):
        q = self.model.nodal_unknowns()
        one = lambda v: np.array([v])  # noqa: E731
        return dict(position_i=q[:1, 0:3], position_j=q[-1:, 0:3], normal_force=one(1.0),
                    gap=one(-1e-6), normal=np.array([[0.0, 0.0, 1.0]]),
                    tangential_force=np.zeros((1, 3)), slip=one(False), penalty=one(2.0),
                    fibre_i=one(0), fibre_j=one(0))


def test_contact_elements_of_any_effect_are_written(tmp_path):
    _, model = cantilever(Touching())
    out = str(tmp_path / "out")
    textile.Solver(model, QUIET, output=textile.Output(out, pictures=False)).solve()
    assert os.path.exists(os.path.join(out, "contacts.pvd"))
    assert os.path.exists(os.path.join(out, "contacts_00002.vtu"))


class Recorder(Effect):
    """Records the load-step protocol and the tangent index of each tangent."""

    def __init__(self):
        self.events = []

    def prepare(self, model):
        self.events.append("prepare")

    def update(self, model):
        self.events.append("update")
        return False

    def jacobian(self, state, A):
        self.events.append(state.tangent_index)


def test_tangent_index_counts_the_newton_iterations():
    """The first tangent after the effects prepare or update has index 0,
    each next one the previous plus 1; one Newton iteration, one tangent."""
    rec = Recorder()
    _, model = cantilever(rec)
    solver = textile.Solver(model, QUIET)
    solver.solve()
    ev = rec.events
    tangents = [k for k, v in enumerate(ev) if not isinstance(v, str)]
    assert tangents and ev[0] == "prepare"
    for k in tangents:
        before = ev[k - 1]
        assert ev[k] == (0 if isinstance(before, str) else before + 1)
    assert len(tangents) == solver.counters["jacobian_evaluations"]


# -- source scans -------------------------------------------------------------------
def _sources(*patterns):
    import glob
    files = sorted({f for p in patterns for f in glob.glob(os.path.join(ROOT, "textile", p))})
    assert files
    return {os.path.relpath(f, ROOT): open(f).read() for f in files}


CALLERS = ("model.py", "solver/*.py", "output*.py", "io/*.py")


def _code_lines(text):
    """(line number, line) of the code, without comments and docstrings'
    prose lines (a line inside triple quotes)."""
    inside = False
    for n, line in enumerate(text.splitlines(), 1):
        quotes = line.count('"""') + line.count("'''")
        if not inside and not line.lstrip().startswith("#"):
            yield n, line.split(" #")[0]
        if quotes % 2:
            inside = not inside


def _own_classes(text):
    return set(re.findall(r"^class (\w+)", text, re.M))


def _effect_classes():
    """Names of the package's Effect subclasses (every module of
    textile.effects imported)."""
    import importlib
    import pkgutil

    import textile.effects as package
    names = set()
    for info in pkgutil.iter_modules(package.__path__):
        module = importlib.import_module(f"textile.effects.{info.name}")
        names |= {name for name, c in inspect.getmembers(module, inspect.isclass)
                  if issubclass(c, Effect) and c is not Effect}
    return names


def test_no_hasattr_nor_isinstance_on_effects():
    effect_classes = _effect_classes()
    assert {"FibreContact", "RigidBodies", "ElasticBlock"} <= effect_classes
    isinstance_effect = re.compile(r"isinstance\([^)]*\b(%s)\b" % "|".join(effect_classes))
    found = []
    for path, text in _sources(*CALLERS).items():
        for n, line in _code_lines(text):
            if re.search(r"\bhasattr\((?!self\b)", line) or isinstance_effect.search(line):
                found.append(f"{path}:{n}: {line.strip()}")
    assert not found, "\n".join(found)


def test_no_access_to_another_objects_private_attributes():
    """Writes (the issue's regex, augmented assignments included) and reads
    of ``other._private`` in the model, solver, output, saved states and
    effects; a class's own private class attributes (``Solver._count``)
    are its own."""
    write = re.compile(r"\b(?!self\b|cls\b)([A-Za-z]\w*)\._\w+\s*(?:[-+*/|&]?=)(?!=)")
    read = re.compile(r"\b(?!self\b|cls\b)([A-Za-z]\w*)\._[A-Za-z]\w*")
    found = []
    for path, text in _sources(*CALLERS, "effects/*.py").items():
        own = _own_classes(text)
        for n, line in _code_lines(text):
            if line.lstrip().startswith(("from ", "import ")):
                continue
            if any(m.group(1) not in own for p in (write, read) for m in p.finditer(line)):
                found.append(f"{path}:{n}: {line.strip()}")
    assert not found, "\n".join(found)


def test_effects_do_not_assign_to_the_model():
    """Effects change the model only through its methods
    (request_matrix_rebuild, set_field_values)."""
    assign = re.compile(r"\bmodel\.\w+(?:\.\w+)*\s*(?:[-+*/|&]?=)(?!=)")
    found = [f"{path}:{n}: {line.strip()}" for path, text in _sources("effects/*.py").items()
             for n, line in _code_lines(text) if assign.search(line)]
    assert not found, "\n".join(found)
