"""A scene pays only for the effects it has; end caps are excluded."""
import numpy as np
import pytest
from mpi4py import MPI

import textile
import textile.effects.fibre_contact as fibre_contact
from textile.effects.fibre_contact import FibreContact
from tests.effects.test_pays_only_for_its_effects import crossed_model as crossed_scene

MAT = textile.Material(1.0e9, 0.3)
R = 1e-3


def crossed_model(contact=None):
    """Fibre B pressed on fibre A, crossing it (the scene of
    tests/effects/test_pays_only_for_its_effects.py)."""
    model, _ = crossed_scene(*([] if contact is None else [contact]))
    return model


def test_no_contact_builds_no_detection(monkeypatch):
    calls = []
    real = fibre_contact._cpp.detect_contacts
    monkeypatch.setattr(fibre_contact._cpp, "detect_contacts",
                        lambda *a, **k: calls.append(1) or real(*a, **k))
    model = crossed_model()
    textile.Solver(model, dict(verbose=False)).solve()
    assert calls == []  # without the effect, nothing is detected
    assert all(not isinstance(e, FibreContact) for e in model.effects)
    # and B passes through A, as it should with no contact in the scene
    assert model.centreline(1)[8, 2] < 2 * R - 5e-5
    model = crossed_model(FibreContact())
    textile.Solver(model, dict(verbose=False)).solve()
    assert len(calls) > 0  # with it, every step detects


@pytest.mark.parametrize("mu", [0.0, 0.3])
def test_friction_history_only_with_friction(mu):
    contact = FibreContact(dict(friction=mu))
    model = crossed_model(contact)
    textile.Solver(model, dict(verbose=False)).solve()
    assert contact.set.size > 0
    if mu == 0:
        assert contact.set.num_friction_histories == 0
        assert np.all(contact.elements()["tangential_force"] == 0)
    else:
        assert contact.set.num_friction_histories == contact.set.size


def test_end_caps_are_excluded():
    """A fibre pushed head-on into the side of another: no contact element is
    made at the end cap (documented exclusion), the run stays clean, and the
    fibre's end goes into the other one without resistance."""
    A = textile.straight_fibre([-0.05, 0, 0], [0.05, 0, 0], R, MAT, num_elements=8)
    B = textile.straight_fibre([0, 0, 1.2 * R], [0, 0, 0.05], R, MAT, num_elements=8)
    model = textile.Model([A, B], comm=MPI.COMM_SELF)
    for n in range(A.num_nodes):
        model.fix(A, n, "all")
    model.fix(B, -1, "all", [0, 0, -0.5 * R, 0, 0, 0, 0, 0, 0])
    contact = FibreContact()
    model.add_effect(contact)
    history = textile.Solver(model, dict(verbose=False)).solve()
    assert history[-1].load_factor == pytest.approx(1.0)
    assert history[-1].effects["active_contacts"] == 0
    assert model.centreline(B)[0, 2] == pytest.approx(0.7 * R, rel=1e-6)
