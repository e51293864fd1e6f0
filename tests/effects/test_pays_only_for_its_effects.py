"""A scene pays only for its effects (issue 21 section 4), proved by
instrumenting the code -- what is imported, constructed, called, allocated --
never by reading the scene's flags.

- no matrix: neither gmsh nor dolfinx's Python layer (fem, mesh, UFL, FFCx)
  is imported; only dolfinx's compiled core (index maps, sparsity patterns,
  block vectors: the global system's layout) is loaded
  (textile.system.dolfinx_core); the matrix block's, contact's and rigid bodies'
  modules are not even imported;
- no contact: no detection, no contact set, no coupling pattern, no penalty
  adaptation is made (every C++ entry point counted);
- friction off (coefficient 0, or a stage with ``friction=False``): no
  contact element gets a friction law, so none keeps a history;
- no rigid bodies: the system has 9 unknowns a node, no body unknowns or
  multiplier rows;
- stability check off: no SLEPc eigensolver, no inertia, no search for
  zero-energy motions.

tests/contact/test_effect_switches.py and tests/matrix/test_matrix_mesh.py
hold the first checks of the kind (detection, friction histories, a
matrix mesh with output).
"""
import os
import subprocess
import sys

import numpy as np
import pytest
from mpi4py import MPI

import textile
import textile.solver.stability_check as solver_module  # where the check looks them up
from textile.effects.fibre_contact import FibreContact

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MAT = textile.Material(1.0e9, 0.3)
R = 1e-3

FIBRE_ONLY = r"""
import sys
import textile
fibres = [textile.straight_fibre([0, 0.05 * k, 0], [1, 0.05 * k, 0], 0.01,
                                 textile.Material(1e9, 0.3), num_elements=6) for k in range(2)]
model = textile.Model(fibres)
for k in range(2):
    model.clamp(k, 0)
    model.add_force(k, -1, [0, 0, -2e-2])
history = textile.Solver(model, {"verbose": False}).solve()
assert model.load_factor == 1.0 and history[-1].newton_iterations >= 1
print(" ".join(sorted(m for m in sys.modules if m.split(".")[0] in
                      ("gmsh", "dolfinx", "ufl", "ffcx", "slepc4py")
                      or m.startswith(("textile.effects.", "textile.composite.matrix_mesh",
                                       "textile.composite")))))
# dolfinx's Python layer, imported after its core was loaded alone, works
# and shares the core (one set of types)
import dolfinx
import dolfinx.cpp
from dolfinx import mesh as dmesh
assert dolfinx.cpp is sys.modules["dolfinx.cpp"] and dmesh.Mesh is not None
cube = dmesh.create_unit_cube(textile.PETSc.COMM_SELF.tompi4py(), 1, 1, 1)
assert isinstance(cube.topology, dolfinx.cpp.mesh.Topology)   # the core's type
print("later import works")
"""


def test_fibre_only_scene_imports_no_matrix_machinery():
    """In a fresh interpreter, a fibre-only scene solved to convergence
    (stability check on: it found nothing unstable): gmsh, dolfinx's
    Python package, UFL, FFCx and slepc4py are not imported, nor the
    modules of the matrix block, junctions, contact or rigid bodies; the
    dolfinx package imported afterwards is the usual one, on the same core."""
    run = subprocess.run([sys.executable, "-c", FIBRE_ONLY], capture_output=True, text=True,
                         cwd=ROOT, timeout=300)
    assert run.returncode == 0, run.stderr
    lines = run.stdout.strip().splitlines()
    assert lines[-1] == "later import works"
    loaded = set(lines[-2].split())
    unused = {"gmsh", "dolfinx", "dolfinx.fem", "dolfinx.mesh", "dolfinx.io", "ufl", "ffcx",
              "slepc4py", "textile.composite.matrix_mesh", "textile.composite"} | {
        f"textile.effects.{name}" for name in ("elastic_block", "fibre_matrix_tie",
                                               "fibre_matrix_junction", "fibre_contact",
                                               "weaving_contact", "rigid_bodies")}
    assert not loaded & unused, loaded & unused
    # of dolfinx, the compiled core and the submodules it registers only
    assert "dolfinx.cpp" in loaded
    assert all(m == "dolfinx.cpp" or m.startswith("dolfinx.cpp.")
               for m in loaded if m.startswith("dolfinx")), loaded


# -- contact -----------------------------------------------------------------------
CONTACT_ENTRY_POINTS = ("detect_contacts", "ContactSet", "CouplingPattern", "PenaltyAdaptation",
                        "WeavingOrder")


def crossed_model(*effects):
    A = textile.straight_fibre([0, -0.05, 0], [0, 0.05, 0], R, MAT, num_elements=8)
    B = textile.straight_fibre([-0.05, 0, 2 * R], [0.05, 0, 2 * R], R, MAT, num_elements=8)
    model = textile.Model([A, B], comm=MPI.COMM_SELF)
    for n in range(A.num_nodes):
        model.fix(A, n, "all")
    model.fix(B, 0, ["position", "g1x"], [0, 0, -1e-4, 0])
    press = model.fix(B, -1, ["y", "z"], [0, -1e-4])
    for e in effects:
        model.add_effect(e)
    return model, press


@pytest.fixture
def contact_calls(monkeypatch):
    """Every C++ entry point of contact, counted (FibreContact calls them
    through the module ``textile._cpp``)."""
    calls = {name: 0 for name in CONTACT_ENTRY_POINTS}

    def counted(name, real):
        def wrapper(*args, **kwargs):
            calls[name] += 1
            return real(*args, **kwargs)
        return wrapper

    for name in CONTACT_ENTRY_POINTS:
        monkeypatch.setattr(textile._cpp, name, counted(name, getattr(textile._cpp, name)))
    return calls


def test_no_contact_builds_no_contact_structure(contact_calls):
    model, _ = crossed_model()
    textile.Solver(model, dict(verbose=False)).solve()
    assert all(v == 0 for v in contact_calls.values()), contact_calls
    # the instrument sees them when the scene has contact
    model, _ = crossed_model(FibreContact())
    textile.Solver(model, dict(verbose=False)).solve()
    assert all(contact_calls[k] > 0 for k in CONTACT_ENTRY_POINTS if k != "WeavingOrder"), \
        contact_calls


# -- friction ------------------------------------------------------------------------
@pytest.fixture
def friction_laws(monkeypatch):
    """Every contact set FibreContact makes, as the coefficients it hands
    the C++ (a friction law, hence a history, exists only where they are
    > 0), and the histories each committed set keeps (its counter)."""
    made, kept = [], []
    real_commit = FibreContact.commit

    def commit(self, model):
        real_commit(self, model)
        kept.append((self.friction_on, self.set.num_friction_histories, self.set.size,
                     float(np.abs(self.elements()["tangential_force"]).max(initial=0.0))))

    real_next = textile._cpp.ContactSet.next

    def next_(self, found, q, first, order, radius, k0, g_r, mu, *args, **kwargs):
        made.append(max([mu] + list(kwargs.get("group_mu", []))))
        return real_next(self, found, q, first, order, radius, k0, g_r, mu, *args, **kwargs)

    monkeypatch.setattr(FibreContact, "commit", commit)
    monkeypatch.setattr(textile._cpp.ContactSet, "next", next_)
    return made, kept


def test_friction_off_stage_allocates_no_history(friction_laws):
    """Friction 0.3 switched off in the first stage (a stage option), on in
    the second: no friction law is handed to the C++ and no history kept in
    the first; the first stage's answer is that of a scene built without
    friction (off is off), and friction is back in the second."""
    made, kept = friction_laws
    press = {}

    factorizations = []

    def count(solver):
        c = solver.counters
        factorizations.append((c["ldlt_factorizations"], c["lu_factorizations"]))

    def run(contact, first, second):
        model, press["handle"] = crossed_model(contact)
        solver = textile.Solver(model, dict(verbose=False, initial_step=0.5, max_step=0.5))
        count(solver)
        solver.run_stage(textile.Stage("press", effects={contact: first}))
        count(solver)
        after_first = model.centreline(1).copy()
        n = len(made)
        solver.run_stage(textile.Stage("slide", ramp={press["handle"]: [1e-3, -1.2e-4]},
                                       effects={contact: second}))
        count(solver)
        return after_first, n, model.centreline(1)

    first, n_first, _ = run(FibreContact(dict(friction=0.3)), dict(friction=False),
                            dict(friction=True))
    assert n_first > 0 and max(made[:n_first]) == 0.0
    off = [k for k in kept if not k[0]]
    assert off and all(h == 0 and f == 0.0 for _, h, _, f in off), off
    on = [k for k in kept if k[0]]
    assert on and all(h == size > 0 for _, h, size, _ in on), on
    assert min(made[n_first:]) == pytest.approx(0.3)
    assert max(f for *_, f in on) > 0
    # the frictionless stage factorizes its symmetric tangent with LDL^T
    # (half the work), the frictional one with LU
    (ldlt0, lu0), (ldlt1, lu1), (ldlt2, lu2) = factorizations
    assert ldlt1 > ldlt0 and lu1 == lu0
    assert lu2 > lu1 and ldlt2 == ldlt1
    # the same scene built without friction: the same first stage
    made.clear()
    kept.clear()
    frictionless, _, _ = run(FibreContact(dict(friction=0.0)), {}, {})
    assert max(made) == 0.0 and all(h == 0 for _, h, _, _ in kept)
    np.testing.assert_allclose(first, frictionless, rtol=0, atol=1e-14)


def test_friction_switch_refuses_what_is_not_a_switch():
    with pytest.raises(ValueError, match="friction must be True or False"):
        textile.Stage("s", effects={FibreContact(): dict(friction=0.2)}).apply()


# -- rigid bodies ---------------------------------------------------------------------
def test_no_rigid_bodies_no_extra_unknowns(monkeypatch):
    import textile.effects.rigid_bodies as rigid_bodies

    made = []
    init = rigid_bodies.RigidBodies.__init__
    monkeypatch.setattr(rigid_bodies.RigidBodies, "__init__",
                        lambda self, *a, **k: made.append(1) or init(self, *a, **k))
    model, _ = crossed_model()
    textile.Solver(model, dict(verbose=False)).solve()
    nodes = sum(f.num_nodes for f in model.mesh.fibres)
    assert made == []
    assert model.A.getSize() == (9 * nodes, 9 * nodes) and model.x.getSize() == 9 * nodes
    assert [f.name for f in model.layout.fields] == ["beam"]
    # the comparison sees a body: its 6 unknowns and its multiplier rows
    model, _ = crossed_model()
    body = textile.RigidBody("end", sections=[(1, -1)])
    body.fix("all")
    model.add_rigid_body(body)
    model.setup()
    assert made == [1] and model.x.getSize() > 9 * nodes + 6


# -- stability check ------------------------------------------------------------------
def test_stability_check_off_makes_no_eigen_solve(monkeypatch):
    """A column loaded past its buckling load: with the check on, branch
    switching creates SLEPc eigensolvers; off, none, and neither the
    inertia nor zero-energy motions are computed."""
    from slepc4py import SLEPc

    calls = dict(eps=0, inertia=0, zero_motions=0)

    class CountedEPS(SLEPc.EPS):
        def create(self, comm=None):
            calls["eps"] += 1
            return super().create(comm)

    def counted(name, real):
        def wrapper(*args, **kwargs):
            calls[name] += 1
            return real(*args, **kwargs)
        return wrapper

    monkeypatch.setattr(SLEPc, "EPS", CountedEPS)
    monkeypatch.setattr(solver_module, "factor_negative_pivots",
                        counted("inertia", solver_module.factor_negative_pivots))
    monkeypatch.setattr(solver_module, "zero_energy_motions",
                        counted("zero_motions", solver_module.zero_energy_motions))

    def column(check):
        E, L = MAT.young, 0.5
        load = np.pi ** 2 * E * (np.pi * R ** 4 / 4) / (4 * L ** 2)
        fib = textile.straight_fibre([0, 0, 0], [L, 0, 0], R, MAT, num_elements=8)
        model = textile.Model(fib, comm=MPI.COMM_SELF)
        model.clamp(fib, 0)
        model.add_force(fib, -1, [-1.3 * load, 0, 0])
        textile.Solver(model, dict(initial_step=0.25, max_step=0.25, verbose=False,
                                   stability_check=check)).solve()
        assert model.load_factor == 1.0

    column("off")
    assert calls == dict(eps=0, inertia=0, zero_motions=0)
    with pytest.warns(Warning):
        column("auto")
    assert all(v > 0 for v in calls.values()), calls
