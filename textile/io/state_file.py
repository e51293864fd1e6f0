"""Saved states: a run's unknowns and history in one HDF5 file, to resume from.

A state file holds everything a later run needs to continue exactly where a
run stopped (e.g. a woven fabric that loading tests or a composite start
from), independent of how many MPI ranks wrote or read it:

``/`` attributes
    ``format`` ("textile-state"), ``version`` (1), ``load_factor``,
    ``stage``, ``stage_index``, ``time``, ``num_fibres``, ``num_nodes``.
``/fibres/reference`` (nodes, 9), ``/fibres/unknowns`` (nodes, 9)
    Reference [X0, G1, G2] and current displacements of every fibre node,
    in the global node numbering (fibre after fibre).
``/fibres/first_node``, ``/fibres/radius``
    Where each fibre starts, and its radius.
``/fibres/data/<name>``
    Optional per-fibre labels given to :func:`save_state` (e.g. ``yarn``,
    each fibre's yarn), returned by :func:`load_state` under
    ``"fibre_data"``.
``/schedules/<name>/{start,target,active}``
    Every loading quantity's stage values (:mod:`textile.loading`).
``/effects/<name>/...``
    Each effect's own state (rigid bodies: unknowns, accumulated rotations,
    multipliers by coupling; contact: elements and their history), written
    and read by the effect (``save_state`` / ``load_state``).

Written by rank 0 from gathered data; read on every rank.

:func:`load_state` resumes the *same* scene; :func:`load_fibres` starts a
*new* scene (other loads, rigid bodies, a matrix) from the saved fibres:
their unknowns and, if both scenes have fibre contact, the contact history.
"""
from __future__ import annotations

import numpy as np

FORMAT, VERSION = "textile-state", 1


def save_state(model, path: str, solver=None, fibre_data=None) -> None:
    """Write the model's current state (collective: call on every rank).
    ``fibre_data``: optional name -> array with one value per fibre."""
    import h5py

    model.setup()
    labels = {}
    for name, values in (fibre_data or {}).items():
        a = np.asarray(values)
        if a.shape[:1] != (len(model.mesh.fibres),):
            raise ValueError(f"save_state: fibre_data[{name!r}] has {a.shape[:1]} values, the "
                             f"model has {len(model.mesh.fibres)} fibres")
        labels[name] = a
    u = model._gather_beam(model.state().u["beam"])
    effects = {}
    for e in model.effects:
        if hasattr(e, "save_state"):
            effects[e.state_name] = e.save_state(model)  # collective
    if model.comm.rank != 0:
        return
    with h5py.File(path, "w") as f:
        f.attrs.update(format=FORMAT, version=VERSION, load_factor=model.load_factor,
                       num_fibres=len(model.mesh.fibres), num_nodes=model.mesh.num_nodes_global)
        if solver is not None:
            f.attrs.update(stage=solver._stage.name, stage_index=solver._stage_index,
                           time=solver._stage_index + model.load_factor)
        g = f.create_group("fibres")
        g["reference"] = model.mesh.X_global
        g["unknowns"] = u
        g["first_node"] = model.mesh.first_node
        g["radius"] = np.array([fib.radius for fib in model.mesh.fibres])
        d = g.create_group("data")
        for name, a in labels.items():
            d[name] = a
        s = f.create_group("schedules")
        for k, sched in enumerate(model.schedules()):
            h = s.create_group(f"{k:03d} {sched.name}")
            h["start"], h["target"], h["active"] = sched.start, sched.target, sched.active
        eg = f.create_group("effects")
        for name, data in effects.items():
            h = eg.create_group(name)
            for key, value in data.items():
                h[key] = value


def _check_fibres(model, f, path: str) -> None:
    """The saved fibres are the model's: same count, nodes and reference."""
    attrs = f.attrs
    if attrs.get("format") != FORMAT:
        raise ValueError(f"{path}: not a textile state file")
    if attrs["num_nodes"] != model.mesh.num_nodes_global or \
            attrs["num_fibres"] != len(model.mesh.fibres):
        raise ValueError(f"{path}: saved for {attrs['num_fibres']} fibres and "
                         f"{attrs['num_nodes']} nodes; this model has "
                         f"{len(model.mesh.fibres)} and {model.mesh.num_nodes_global}")
    if not np.allclose(f["fibres/reference"][...], model.mesh.X_global, rtol=0,
                       atol=1e-12 * max(1.0, np.abs(model.mesh.X_global).max())):
        raise ValueError(f"{path}: the fibres' reference geometry differs from this model's")


def _set_beam_unknowns(model, u: np.ndarray) -> None:
    """Put the saved global fibre unknowns (nodes, 9) into the model's x."""
    arrays = [a.copy() for a in model.layout.get_local(model.x)]
    arrays[model.layout.index("beam")][:] = u[model.mesh.local_to_global].ravel()
    model.layout.scatter(model.x, arrays)


def saved_configuration(path: str) -> np.ndarray:
    """(nodes, 9) current [x0, g1, g2] of every fibre node of a saved state
    (reference plus unknowns, global node numbering), read without a
    model: what a new scene builds around (a matrix box, junctions) before
    its model exists. Read on the calling rank only."""
    import h5py

    with h5py.File(path, "r") as f:
        if f.attrs.get("format") != FORMAT:
            raise ValueError(f"{path}: not a textile state file")
        return f["fibres/reference"][...] + f["fibres/unknowns"][...]


def load_fibres(model, path: str) -> dict:
    """Start a new scene from the fibres of a saved state (collective).

    The model must hold the same fibres (count, nodes, reference geometry:
    build them as the saving run did, e.g. from the same
    :class:`~textile.fabric.Fabric`); its loads, rigid bodies and other
    effects may differ. Sets the fibre unknowns (the fibres keep the saved
    deformation and stresses) and, if the model has fibre contact, the saved
    contact history. Rigid bodies created for the new scene grab what they
    hold in this loaded configuration (see
    :mod:`textile.effects.rigid_bodies`). Returns the file's attributes,
    with the per-fibre labels under ``"fibre_data"``.
    """
    import h5py

    model.setup()
    with h5py.File(path, "r") as f:
        _check_fibres(model, f, path)
        attrs = dict(f.attrs)
        u = f["fibres/unknowns"][...]
        effects = {name: {k: v[...] for k, v in grp.items()}
                   for name, grp in f["effects"].items()}
        if "data" in f["fibres"]:
            attrs["fibre_data"] = {k: v[...] for k, v in f["fibres/data"].items()}
    _set_beam_unknowns(model, u)
    model.x.ghostUpdate()
    for e in model.effects:
        name = getattr(e, "state_name", None)
        if hasattr(e, "load_fibres"):
            e.load_fibres(model, effects.get(name, {}) if name else {})
    model.x.ghostUpdate()
    return attrs


def load_state(model, path: str, solver=None) -> dict:
    """Set the model (built as when the state was saved) to the saved state:
    unknowns, stage values, effects' history. Collective. Returns the file's
    attributes, and the saved per-fibre labels under ``"fibre_data"``."""
    import h5py

    model.setup()
    with h5py.File(path, "r") as f:
        _check_fibres(model, f, path)
        attrs = dict(f.attrs)
        u = f["fibres/unknowns"][...]
        schedules = model.schedules()
        saved = sorted(f["schedules"].keys())
        if len(saved) != len(schedules):
            raise ValueError(f"{path}: {len(saved)} schedules saved, the model has "
                             f"{len(schedules)}: build the scene as it was saved")
        for key, sched in zip(saved, schedules):
            h = f["schedules"][key]
            if len(h["start"]) != len(sched):
                raise ValueError(f"{path}: schedule {key!r} does not match {sched.name!r}")
            sched.start, sched.target = h["start"][...], h["target"][...]
            sched.active = h["active"][...].astype(bool)
            sched._callables = []
        effects = {name: {k: v[...] for k, v in grp.items()}
                   for name, grp in f["effects"].items()}
        if "data" in f["fibres"]:
            attrs["fibre_data"] = {k: v[...] for k, v in f["fibres/data"].items()}
    model.load_factor = float(attrs["load_factor"])
    model._constraint_cache = None
    model._setup_constraints()
    model._setup_residual_groups()
    _set_beam_unknowns(model, u)
    for e in model.effects:
        if hasattr(e, "load_state"):
            e.load_state(model, effects.get(e.state_name, {}))
    model.x.ghostUpdate()
    if solver is not None and "stage" in attrs:
        from ..loading import Stage

        solver._stage = Stage(str(attrs["stage"]))
        solver._stage_index = int(attrs["stage_index"])
        solver._stage_started = True
        solver._previous = None
    return attrs
