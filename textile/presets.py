"""Accuracy presets: ``"draft"``, ``"standard"`` (today's defaults) and
``"fine"`` (issue 21 §3).

Each preset sets the same knobs, chosen from the Pareto fronts of
``benchmarks/accuracy_cost.py`` (report: ``benchmarks/accuracy_cost.md``;
what each preset measured, and how to measure it again:
``benchmarks/README.md``, "What accuracy costs"):

- ``solver``: the Newton tolerances (:class:`~textile.solver.SolverOptions`
  ``rtol``, ``stol``, ``atol``) and ``reuse_factorization``;
- ``contact``: the penalty law's regularization depth and target
  penetration, the adaptation and its band, the update tolerance and the
  proximity criterion (:class:`~textile.effects.fibre_contact.ContactOptions`);
- ``beam``: the section quadrature order (:class:`~textile.BeamElement`);
- ``fabric``: elements per crossing (:class:`~textile.fabric.Fabric`);
- ``weaving``: load steps of the weaving stage
  (:class:`~textile.fabric.weaving.Weaving`);
- ``matrix``: the matrix tetrahedra's size in fibre radii and their degree
  (:class:`~textile.composite.Composite`).

What each sets (:data:`PRESETS`):

- ``draft``: Newton tolerances 1e-6 (atol 1e-9), contact update tolerance
  1e-2, 2 elements a crossing, 3 weaving steps, matrix tetrahedra of 12
  fibre radii; the rest as standard.
- ``standard``: exactly the defaults of those classes
  (tests/solver/test_presets.py checks it field by field): a scene that
  names no preset, or ``"standard"``, runs as before presets existed.
  Newton tolerances 1e-10 (atol 1e-13), g_r = 0.02 R at a target
  penetration of 2 g_r, update tolerance 1e-3, 4 elements a crossing, 5
  weaving steps, matrix tetrahedra of 8 fibre radii, P2.
- ``fine``: standard with g_r = 0.005 R at a target of 1 g_r, 8 elements a
  crossing and matrix tetrahedra of 4 fibre radii.

Every preset keeps quadratic elements with section order 4, the penalty
adaptation and its band (0.5, 2), the proximity criterion 2 and one
factorization a Newton iteration. The elements of fibres a scene builds
itself (``straight_fibre(num_elements=...)``) are the scene's: no preset
sets them.

Documented error bounds (:data:`BOUNDS`; tests/solver/test_presets.py
holds the weave and the composite to them), per case of
``benchmarks/accuracy_cost.py``:

========== ================ ===================== ================ ==========
preset     weave crimp      composite stiffness   crossed force    capstan
========== ================ ===================== ================ ==========
draft      0.2              0.1                   0.25             1e-3
standard   0.1              0.04                  0.25             1e-3
fine       0.02             0.013                 0.035            1e-3
========== ================ ===================== ================ ==========

(weave: the crimp of the 2 x 2 monofilament weave against its
extrapolated reference; composite: its bending stiffness over the plate
formula against the run on a matrix of 2 fibre radii; crossed: a pressed
crossing's contact force against hard contact; capstan: the tension ratio
against exp(mu theta R / (R + r)); all relative.)

Scene classes take a preset in one argument, ``preset=`` (:func:`checked`,
:func:`knob`, :func:`contact`, :func:`solver`: the preset's knob unless the
user gave one); scene files in ``scene.preset``.
"""
from __future__ import annotations

import copy

#: the knobs each preset sets, by the options they belong to
PRESETS = {
    "draft": {
        "solver": dict(rtol=1e-6, stol=1e-6, atol=1e-9, reuse_factorization=1),
        "contact": dict(regularization=0.02, target_penetration=2.0, adapt_penalty=True,
                        penalty_band=(0.5, 2.0), update_tolerance=1e-2, search_factor=2.0),
        "beam": dict(section_order=4),
        "fabric": dict(elements_per_crossing=2),
        "weaving": dict(steps=3),
        "matrix": dict(size_radii=12.0, degree=2),
    },
    "standard": {
        "solver": dict(rtol=1e-10, stol=1e-10, atol=1e-13, reuse_factorization=1),
        "contact": dict(regularization=0.02, target_penetration=2.0, adapt_penalty=True,
                        penalty_band=(0.5, 2.0), update_tolerance=1e-3, search_factor=2.0),
        "beam": dict(section_order=4),
        "fabric": dict(elements_per_crossing=4),
        "weaving": dict(steps=5),
        "matrix": dict(size_radii=8.0, degree=2),
    },
    "fine": {
        "solver": dict(rtol=1e-10, stol=1e-10, atol=1e-13, reuse_factorization=1),
        "contact": dict(regularization=0.005, target_penetration=1.0, adapt_penalty=True,
                        penalty_band=(0.5, 2.0), update_tolerance=1e-3, search_factor=2.0),
        "beam": dict(section_order=4),
        "fabric": dict(elements_per_crossing=8),
        "weaving": dict(steps=5),
        "matrix": dict(size_radii=4.0, degree=2),
    },
}

#: the default preset (today's defaults)
DEFAULT = "standard"

#: documented error bounds per preset and case of benchmarks/accuracy_cost.py
#: (module docstring): about 1.5 times the errors measured (benchmarks/
#: README.md, "What accuracy costs")
BOUNDS = {
    "draft": dict(weave=0.2, composite=0.1, crossed=0.25, capstan=1e-3),
    "standard": dict(weave=0.1, composite=0.04, crossed=0.25, capstan=1e-3),
    "fine": dict(weave=0.02, composite=0.013, crossed=0.035, capstan=1e-3),
}

BLOCKS = tuple(PRESETS[DEFAULT])


def names() -> tuple:
    """The presets, coarsest first."""
    return tuple(PRESETS)


def preset(name: str) -> dict:
    """A copy of preset ``name``'s knobs, by block; ValueError naming the
    presets for an unknown name."""
    if not isinstance(name, str) or name not in PRESETS:
        raise ValueError(f"unknown accuracy preset {name!r}; known: {', '.join(PRESETS)}")
    return copy.deepcopy(PRESETS[name])


def options(name: str | None = None, **overrides) -> dict:
    """The option dicts of preset ``name`` (default ``"standard"``), with
    the user's ``overrides`` winning key by key, e.g.
    ``options("fine", contact=dict(friction=0.3), solver=dict(verbose=False))``
    -> ``{"solver": {...}, "contact": {...}, "beam": {...}, "fabric": {...},
    "weaving": {...}, "matrix": {...}}``. ``solver`` and ``contact`` are
    checked against :class:`~textile.solver.SolverOptions` and
    :class:`~textile.effects.fibre_contact.ContactOptions` (unknown names
    raise ValueError); give them to ``Solver(model, out["solver"])`` and
    ``FibreContact(out["contact"])``; ``beam`` to ``BeamElement(**out["beam"])``
    (or :func:`element`)."""
    out = preset(DEFAULT if name is None else name)
    unknown = sorted(set(overrides) - set(BLOCKS))
    if unknown:
        raise ValueError(f"presets.options: unknown block(s) {unknown}; known: {list(BLOCKS)}")
    for block, given in overrides.items():
        if given is None:
            continue
        if not isinstance(given, dict):
            raise TypeError(f"presets.options: {block} must be a dict, got "
                            f"{type(given).__name__}")
        out[block].update(given)
    from .effects.fibre_contact import ContactOptions
    from .solver.options import SolverOptions
    SolverOptions.from_dict(out["solver"])
    ContactOptions.from_dict(out["contact"])
    return out


# -- what the scene classes call (``preset=`` of Fabric, Weaving, Sample,
# Composite and the virtual tests): the preset's knob unless the user gave one
def checked(name: str | None, who: str) -> str:
    """The preset ``name`` (None: :data:`DEFAULT`); ValueError naming the
    scene class ``who`` and the presets for an unknown name."""
    if name is None:
        return DEFAULT
    if not isinstance(name, str) or name not in PRESETS:
        raise ValueError(f"{who}: unknown accuracy preset {name!r}; known: "
                         f"{', '.join(PRESETS)}")
    return name


def knob(name: str | None, block: str, key: str, given=None):
    """``given`` if the user gave it (not None), else preset ``name``'s
    ``block[key]`` (e.g. ``knob("fine", "fabric", "elements_per_crossing",
    None)`` -> 8)."""
    return given if given is not None else PRESETS[DEFAULT if name is None else name][block][key]


def _options(name: str | None, given, block: str, options_class):
    """``given`` over preset ``name``'s ``block``: an ``options_class``
    instance as given (every field of it is the user's), a dict over the
    block key by key, None the block itself; anything else is returned as
    is, to be refused by name where the options are built."""
    if isinstance(given, options_class) or not (given is None or isinstance(given, dict)):
        return given
    defaults = preset(DEFAULT if name is None else name)[block]
    return defaults if given is None else dict(defaults, **given)


def contact(name: str | None, given=None):
    """A scene's contact options under preset ``name``: a ``ContactOptions``
    as given (every field of it is the user's), a dict over the preset's
    contact block key by key, None the preset's block (checked where the
    contact is built: :class:`~textile.effects.fibre_contact.FibreContact`)."""
    from .effects.fibre_contact import ContactOptions
    return _options(name, given, "contact", ContactOptions)


def solver(name: str | None, given=None):
    """A scene's solver options under preset ``name``: as :func:`contact`,
    for :class:`~textile.solver.SolverOptions`."""
    from .solver.options import SolverOptions
    return _options(name, given, "solver", SolverOptions)


def element(name: str | None = None, **overrides):
    """The :class:`~textile.BeamElement` of preset ``name`` (``overrides``:
    its fields, e.g. ``order=1``)."""
    from .beam.element import BeamElement
    return BeamElement(**dict(preset(DEFAULT if name is None else name)["beam"], **overrides))
