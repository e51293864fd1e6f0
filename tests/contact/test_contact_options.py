"""Contact option values (project issue 22, item 4): negative, NaN,
infinite, out-of-range and wrongly typed values (a string, a bool for a
number, a number for a bool, a scalar for a pair) are named errors
(ContactOptions and the option's name in the message, with what is
expected), raised when the effect is made."""
import numpy as np
import pytest

from textile.effects.fibre_contact import ContactOptions, FibreContact

NAN = float("nan")


@pytest.mark.parametrize("name", ["search_factor", "regularization", "target_penetration",
                                  "reversible_slip", "update_tolerance",
                                  "max_penalty_change"])
@pytest.mark.parametrize("value", [-1.0, 0.0, NAN, float("inf"), "2", None, True])
def test_positive_options(name, value):
    if name == "update_tolerance" and value == float("inf"):
        # a contact loop that lags (FibreContact.configure)
        assert FibreContact({name: value}).options.update_tolerance == value
        return
    with pytest.raises(ValueError, match=f"ContactOptions.{name} must be a positive number"):
        FibreContact({name: value})


@pytest.mark.parametrize("name", ["spacing", "penalty"])
@pytest.mark.parametrize("value", [-1.0, 0.0, NAN, float("inf"), "1e9", True])
def test_positive_or_default_options(name, value):
    with pytest.raises(ValueError, match=f"ContactOptions.{name} must be positive"):
        FibreContact({name: value})


@pytest.mark.parametrize("value", [-0.1, NAN, 10.0, float("inf"), "0.2", None, True])
def test_friction(value):
    with pytest.raises(ValueError, match=r"ContactOptions.friction must be in \[0, 10\)"):
        FibreContact({"friction": value})


@pytest.mark.parametrize("value", [-0.5, 1.5, NAN, "1", True, None])
def test_tangent_floor(value):
    with pytest.raises(ValueError, match=r"ContactOptions.tangent_floor must be in \[0, 1\]"):
        FibreContact({"tangent_floor": value})


@pytest.mark.parametrize("name,value,message", [
    ("parallel_angle", 0.0, r"parallel_angle must be in \(0, 90\)"),
    ("parallel_angle", NAN, r"parallel_angle must be in \(0, 90\)"),
    ("parallel_angle", 90.0, r"parallel_angle must be in \(0, 90\)"),
    ("parallel_angle", "10", r"parallel_angle must be in \(0, 90\) degrees, got '10'"),
    ("parallel_angle", True, r"parallel_angle must be in \(0, 90\)"),
    ("parallel_angle", None, r"parallel_angle must be in \(0, 90\)"),
    ("penalty_range", (2.0, 10.0), "penalty_range must be"),
    ("penalty_range", (NAN, 10.0), "penalty_range must be"),
    ("penalty_range", (-1.0, 10.0), "penalty_range must be"),
    ("penalty_range", (1e-3, float("inf")), "penalty_range must be a pair of finite numbers"),
    ("penalty_range", 10.0, r"penalty_range must be a pair of finite numbers \(low, high\)"),
    ("penalty_range", (1e-3,), "penalty_range must be a pair"),
    ("penalty_range", (1e-3, 10.0, 100.0), "penalty_range must be a pair"),
    ("penalty_range", ("1e-3", 10.0), "penalty_range must be a pair of finite numbers"),
    ("penalty_range", (True, 10.0), "penalty_range must be a pair of finite numbers"),
    ("penalty_band", (0.5, 1.0), "penalty_band must be"),
    ("penalty_band", (NAN, 2.0), "penalty_band must be"),
    ("penalty_band", 2.0, r"penalty_band must be a pair of finite numbers \(low, high\)"),
    ("penalty_band", "0.5, 2", "penalty_band must be a pair"),
    ("max_penalty_change", 0.5, "max_penalty_change must be >= 1"),
])
def test_ranges(name, value, message):
    with pytest.raises(ValueError, match=f"ContactOptions.{message}"):
        FibreContact({name: value})


@pytest.mark.parametrize("name", ["adapt_penalty", "self_contact"])
@pytest.mark.parametrize("value", ["no", "False", 0, 1, 2, 1.0, None])
def test_switches_are_bools(name, value):
    """A string is truthy ("no" would switch it on) and a number only looks
    like a switch: both refused."""
    with pytest.raises(ValueError, match=f"ContactOptions.{name} must be True or False, got"):
        FibreContact({name: value})


def test_accepted_kinds():
    """What a number or a pair may be: ints, numpy scalars, lists (a pair
    read from JSON); switches both ways."""
    opts = FibreContact(dict(penalty=np.float64(1e6), spacing=2, friction=np.float32(0.2),
                             parallel_angle=np.int64(12), penalty_range=[1e-2, 1e2],
                             penalty_band=(0.5, 2), tangent_floor=0, adapt_penalty=False,
                             self_contact=False)).options
    assert opts.penalty_range == [1e-2, 1e2] and opts.adapt_penalty is False


def test_options_of_the_wrong_kind():
    with pytest.raises(TypeError, match="FibreContact: options must be a ContactOptions, a "
                                        "dict of contact options or None"):
        FibreContact([("friction", 0.2)])


def test_unknown_name_and_the_defaults():
    with pytest.raises(ValueError, match=r"unknown contact option\(s\) \['frction'\]"):
        FibreContact({"frction": 0.2})
    # the defaults pass their own checks
    assert FibreContact().options == ContactOptions()
