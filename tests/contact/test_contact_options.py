"""Contact option values (project issue 22, item 4): negative, NaN and
wrongly typed values are named errors (ContactOptions and the option's
name in the message), raised when the effect is made."""
import pytest

from textile.effects.fibre_contact import ContactOptions, FibreContact

NAN = float("nan")


@pytest.mark.parametrize("name", ["search_factor", "regularization", "target_penetration",
                                  "reversible_slip", "update_tolerance",
                                  "max_penalty_change"])
@pytest.mark.parametrize("value", [-1.0, 0.0, NAN, float("inf"), "2", None, True])
def test_positive_options(name, value):
    with pytest.raises(ValueError, match=f"ContactOptions.{name} must be a positive number"):
        FibreContact({name: value})


@pytest.mark.parametrize("name", ["spacing", "penalty"])
@pytest.mark.parametrize("value", [-1.0, 0.0, NAN, "1e9"])
def test_positive_or_default_options(name, value):
    with pytest.raises(ValueError, match=f"ContactOptions.{name} must be positive"):
        FibreContact({name: value})


@pytest.mark.parametrize("value", [-0.1, NAN, 10.0, "0.2", None])
def test_friction(value):
    with pytest.raises(ValueError, match=r"ContactOptions.friction must be in \[0, 10\)"):
        FibreContact({"friction": value})


@pytest.mark.parametrize("value", [-0.5, 1.5, NAN, "1"])
def test_tangent_floor(value):
    with pytest.raises(ValueError, match=r"ContactOptions.tangent_floor must be in \[0, 1\]"):
        FibreContact({"tangent_floor": value})


@pytest.mark.parametrize("name,value,message", [
    ("parallel_angle", 0.0, r"parallel_angle must be in \(0, 90\)"),
    ("parallel_angle", NAN, r"parallel_angle must be in \(0, 90\)"),
    ("parallel_angle", 90.0, r"parallel_angle must be in \(0, 90\)"),
    ("penalty_range", (2.0, 10.0), "penalty_range must be"),
    ("penalty_range", (NAN, 10.0), "penalty_range must be"),
    ("penalty_range", (-1.0, 10.0), "penalty_range must be"),
    ("penalty_band", (0.5, 1.0), "penalty_band must be"),
    ("penalty_band", (NAN, 2.0), "penalty_band must be"),
    ("max_penalty_change", 0.5, "max_penalty_change must be >= 1"),
])
def test_ranges(name, value, message):
    with pytest.raises(ValueError, match=f"ContactOptions.{message}"):
        FibreContact({name: value})


def test_unknown_name_and_the_defaults():
    with pytest.raises(ValueError, match=r"unknown contact option\(s\) \['frction'\]"):
        FibreContact({"frction": 0.2})
    # the defaults pass their own checks
    assert FibreContact().options == ContactOptions()
