"""Saved states: a run's unknowns and history in one HDF5 file, to resume from.

A state file holds everything a later run needs to continue exactly where a
run stopped, between stages or within one (e.g. a woven fabric that loading
tests or a composite start from, or a long run saved every step), whatever
the number of MPI ranks that wrote or read it (version 2):

``/`` attributes
    ``format`` ("textile-state"), ``version`` (2), ``load_factor``,
    ``num_fibres``, ``num_nodes``, ``checksum`` (SHA-256 of everything else:
    a corrupt file is refused); with a solver: ``stage``, ``stage_index``,
    ``stage_started``, ``time``, ``steps``, ``next_step``, ``steps_since_cut``,
    ``previous_load_factor``, ``older_load_factor``, ``negative_eigenvalues``
    (:meth:`Solver.position`).
``/fibres/reference`` (nodes, 9), ``/fibres/unknowns`` (nodes, 9)
    Reference [X0, G1, G2] and current displacements of every fibre node,
    in the global node numbering (fibre after fibre); ``/fibres/previous``
    and ``/fibres/older`` the predictor's earlier states within a stage.
``/fibres/first_node``, ``/fibres/radius``
    Where each fibre starts, and its radius.
``/fibres/data/<name>``
    Optional per-fibre labels given to :func:`save_state` (e.g. ``yarn``,
    each fibre's yarn), returned by :func:`load_state` under
    ``"fibre_data"``.
``/fields/<name>/{keys,reference,unknowns[,previous[,older]]}``
    Every other field of the system (a matrix block's node displacements,
    rigid bodies' unknowns, their couplings' multipliers), one row per
    block sorted by its key (:meth:`Model.block_keys`: a matrix node by its
    mesh input vertices, a multiplier by body, coupling and row), with the
    kernels' reference values (node coordinates, body centres) that
    identify the scene.
``/schedules/<k> <name>/{start,target,active,following,current}``
    Every loading quantity's stage values (:mod:`textile.scene.loading`); which
    components followed a callable of the load factor, and their values at
    the saved load factor.
``/effects/<name>/...``
    Each effect's own state (:meth:`Effect.save_state`: rigid bodies' names
    and rotations; contact elements and their history; a matrix block's
    law; where the junctions were made).

Written by rank 0 from gathered data, into a temporary file renamed over
``path`` once complete (a failed save leaves an earlier file there as it
was); read by rank 0 and broadcast.

:func:`load_state` resumes the *same* scene: a file of another scene
(other fibres, matrix mesh, bodies, junctions, effects) is refused with a
:class:`SceneMismatchError` naming what differs, an unreadable one
(missing, truncated, corrupt) with a :class:`StateFileError`, both before
anything of the model is changed. :func:`load_fibres` starts a *new* scene
(other loads, rigid bodies, a matrix) from the saved fibres: their unknowns
and, if both scenes have fibre contact, the contact history.
"""
from __future__ import annotations

import hashlib
import os

import numpy as np
from petsc4py import PETSc

from ..effects.base import SAME_SCENE_RTOL

FORMAT, VERSION = "textile-state", 2
#: versions whose fibres load_fibres and saved_configuration read (the
#: fibres' layout is the same); load_state needs VERSION
FIBRE_VERSIONS = (1, 2)


class StateFileError(ValueError):
    """A state file that cannot be read or written: missing, truncated,
    corrupt (checksum), or not a textile state file."""


class SceneMismatchError(ValueError):
    """A state file saved for another scene than the model's."""


# -- reading and writing ---------------------------------------------------------
def _canonical_hash(tree: dict, attrs: dict) -> str:
    """SHA-256 of a file's content as read back (datasets by path, attributes
    but the checksum), independent of the order HDF5 lists them in."""
    h = hashlib.sha256()

    def add(name: str, value) -> None:
        a = np.asarray(value)
        h.update(name.encode())
        h.update(str((a.dtype.str, a.shape)).encode())
        h.update(a.tobytes() if a.dtype.kind not in "OU" else str(value).encode())

    for key in sorted(k for k in attrs if k != "checksum"):
        add("@" + key, attrs[key])

    def walk(prefix: str, node: dict) -> None:
        for key in sorted(node):
            if isinstance(node[key], dict):
                walk(f"{prefix}/{key}", node[key])
            else:
                add(f"{prefix}/{key}", node[key])

    walk("", tree)
    return h.hexdigest()


def _read_tree(f) -> dict:
    import h5py

    return {k: _read_tree(v) if isinstance(v, h5py.Group) else v[()] for k, v in f.items()}


def _read_local(path: str) -> dict:
    """The whole file as nested dicts (``"attrs"`` at the top), checked:
    format, version, checksum. Raises StateFileError."""
    import h5py

    try:
        with h5py.File(path, "r") as f:
            attrs = dict(f.attrs)
            tree = _read_tree(f)
    except (OSError, KeyError, ValueError, TypeError, RuntimeError) as exc:
        raise StateFileError(f"{path}: cannot read the state file (missing, truncated or "
                             f"corrupt): {exc}") from None
    if attrs.get("format") != FORMAT:
        raise StateFileError(f"{path}: not a textile state file (format "
                             f"{attrs.get('format')!r})")
    version = int(attrs.get("version", 0))
    if version not in FIBRE_VERSIONS:
        raise StateFileError(f"{path}: state file version {version}; this textile reads "
                             f"{FIBRE_VERSIONS}")
    if version >= 2 and attrs.get("checksum") != _canonical_hash(tree, attrs):
        raise StateFileError(f"{path}: the state file is corrupt (its checksum does not match "
                             f"its content)")
    tree["attrs"] = attrs
    for name in ("reference", "unknowns"):
        a = tree.get("fibres", {}).get(name)
        if a is None or np.ndim(a) != 2 or np.shape(a)[1] != 9 \
                or len(a) != int(attrs.get("num_nodes", -1)):
            raise StateFileError(f"{path}: /fibres/{name} is missing or not (num_nodes, 9)")
    return tree


def _read(path: str, comm) -> dict:
    """_read_local on rank 0, broadcast; its error raised on every rank."""
    data, error = None, None
    if comm.rank == 0:
        try:
            data = _read_local(path)
        except StateFileError as exc:
            error = str(exc)
    data, error = comm.bcast((data, error), root=0)
    if error is not None:
        raise StateFileError(error)
    return data


def _write(path: str, attrs: dict, tree: dict) -> None:
    """Write into a temporary file next to ``path``, add the checksum of
    what was written, rename it to ``path`` (rank 0 alone)."""
    import h5py

    tmp = os.path.join(os.path.dirname(os.path.abspath(path)),
                       f".{os.path.basename(path)}.{os.getpid()}.partial")

    def put(group, node: dict) -> None:
        for key, value in node.items():
            if isinstance(value, dict):
                put(group.create_group(key), value)
            else:
                group[key] = value

    try:
        with h5py.File(tmp, "w") as f:
            f.attrs.update(attrs)
            put(f, tree)
        with h5py.File(tmp, "a") as f:
            f.attrs["checksum"] = _canonical_hash(_read_tree(f), dict(f.attrs))
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


# -- fields by key -------------------------------------------------------------------
def _gather_field(model, name: str, vectors: list, reference: np.ndarray) -> dict | None:
    """Field ``name`` of each vector in ``vectors`` by block key, sorted:
    keys, reference and one (blocks, bs) array per vector; on rank 0 (None
    elsewhere). Collective."""
    f = model.layout.field(name)
    n, bs = f.index_map.size_local, f.bs
    index = model.layout.index(name)
    keys = model.block_keys(name)[:n]
    reference = reference[: n * bs].reshape(n, bs)
    values = []
    for v in vectors:
        v.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        values.append(model.layout.get_local(v)[index][: n * bs].reshape(n, bs).copy())
    parts = model.comm.gather((keys, reference, values), root=0)
    if parts is None:
        return None
    keys = np.concatenate([p[0] for p in parts]).reshape(-1, keys.shape[1])
    order = np.lexsort(keys.T[::-1])
    keys = keys[order]
    out = dict(keys=keys, reference=np.concatenate([p[1] for p in parts])[order])
    for k, label in enumerate(["unknowns", "previous", "older"][:len(vectors)]):
        out[label] = np.concatenate([p[2][k] for p in parts])[order]
    return out


def _positions(saved: np.ndarray, local: np.ndarray) -> np.ndarray:
    """Row of each ``local`` key among the ``saved`` keys, -1 if absent."""
    if saved.shape[1:] != local.shape[1:]:
        return np.full(len(local), -1)
    both = np.concatenate([saved, local])
    _, inverse = np.unique(both, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    where = np.full(inverse.max() + 1 if len(inverse) else 0, -1)
    where[inverse[:len(saved)]] = np.arange(len(saved))
    return where[inverse[len(saved):]]


def _collective(comm, message: str | None) -> None:
    """Raise SceneMismatchError on every rank if any rank found a mismatch."""
    messages = [m for m in comm.allgather(message) if m]
    if messages:
        raise SceneMismatchError(messages[0])


def _field_values(model, data: dict, path: str) -> dict:
    """Field name -> local (owned + ghost) arrays of the saved unknowns (and
    "previous" and "older" ones when saved), matched by key; a field, key or reference
    that is not this model's raises SceneMismatchError (collective)."""
    saved_fields = dict(data.get("fields", {}))
    fib = data["fibres"]
    saved_fields["beam"] = dict(keys=np.arange(len(fib["unknowns"]), dtype=np.int64)[:, None],
                                unknowns=fib["unknowns"],
                                **{k: fib[k] for k in ("previous", "older") if k in fib})
    names = [f.name for f in model.layout.fields]
    extra = sorted(set(saved_fields) - set(names))
    missing = sorted(set(names) - set(saved_fields))
    if extra or missing:
        raise SceneMismatchError(f"{path}: the state file's fields are {sorted(saved_fields)}, "
                                 f"this model's {sorted(names)} (saved with "
                                 f"{extra or 'nothing else'}, without {missing or 'nothing'})")
    references = model.reference_values()
    out, message = {}, None
    for f in model.layout.fields:
        owner = model.field_owner(f.name)
        label = f"field {f.name!r} ({type(owner).__name__ if owner else 'the fibres'})"
        saved = saved_fields[f.name]
        keys = np.asarray(saved["keys"], dtype=np.int64)
        n_global = f.index_map.size_global
        arrays = {k: np.asarray(saved[k], dtype=float) for k in ("unknowns", "previous", "older")
                  if k in saved}
        for k, a in arrays.items():
            if a.shape != (len(keys), f.bs) or not np.all(np.isfinite(a)):
                raise StateFileError(f"{path}: {label}: {k} are not {len(keys)} finite rows of "
                                     f"{f.bs}")
        if len(keys) != n_global:
            raise SceneMismatchError(f"{path}: {label}: the state file has {len(keys)} blocks, "
                                     f"this model {n_global}")
        local = model.block_keys(f.name)
        pos = _positions(keys, local)
        if message is None and np.any(pos < 0):
            first = local[np.flatnonzero(pos < 0)[0]].tolist()
            message = (f"{path}: {label}: {int(np.count_nonzero(pos < 0))} of this model's "
                       f"blocks are not in the state file (key {first}): another scene")
            continue
        if f.name != "beam" and message is None:
            saved_ref = np.asarray(saved["reference"], dtype=float)
            mine = references[f.name].reshape(-1, f.bs)
            scale = max(np.abs(saved_ref).max(initial=0.0), np.finfo(float).tiny)
            worst = np.abs(saved_ref[pos] - mine).max(initial=0.0)
            if worst > SAME_SCENE_RTOL * scale:
                message = (f"{path}: {label}: the reference values (node coordinates, body "
                           f"centres) differ from this model's by {worst:.3g} (of {scale:.3g}): "
                           f"another mesh or scene")
                continue
        out[f.name] = {k: a[pos].ravel() for k, a in arrays.items()}
    _collective(model.comm, message)
    return out


# -- checks --------------------------------------------------------------------------
def _check_fibres(model, data: dict, path: str) -> None:
    """The saved fibres are the model's: count, nodes, radii, reference."""
    attrs, fib = data["attrs"], data["fibres"]
    mesh = model.mesh
    if int(attrs["num_nodes"]) != mesh.num_nodes_global or \
            int(attrs["num_fibres"]) != len(mesh.fibres):
        raise SceneMismatchError(f"{path}: saved for {attrs['num_fibres']} fibres and "
                                 f"{attrs['num_nodes']} nodes; this model has "
                                 f"{len(mesh.fibres)} and {mesh.num_nodes_global}")
    first = np.asarray(fib["first_node"])
    if first.shape != mesh.first_node.shape or np.any(first != mesh.first_node):
        k = int(np.flatnonzero(first != mesh.first_node)[0]) if first.shape == \
            mesh.first_node.shape else 0
        raise SceneMismatchError(f"{path}: fibre {k} starts at node {first[k]} in the state "
                                 f"file, at node {mesh.first_node[k]} in this model (other "
                                 f"node counts)")
    radius = np.array([f.radius for f in mesh.fibres])
    differ = np.abs(np.asarray(fib["radius"]) - radius) > SAME_SCENE_RTOL * radius.max()
    if differ.any():
        k = int(np.flatnonzero(differ)[0])
        raise SceneMismatchError(f"{path}: fibre {k} has radius {fib['radius'][k]:.6g} in the "
                                 f"state file, {radius[k]:.6g} in this model")
    X = mesh.X_global
    gap = np.abs(np.asarray(fib["reference"]) - X).max(axis=1)
    bad = np.flatnonzero(gap > SAME_SCENE_RTOL * np.abs(X).max())
    if len(bad):
        k = int(np.searchsorted(mesh.first_node, bad[0], side="right") - 1)
        raise SceneMismatchError(f"{path}: the reference geometry of fibre {k} differs from "
                                 f"this model's (by {gap[bad].max():.3g}; {len(bad)} nodes)")


def _stateful(model) -> dict:
    """Group name -> effect, for the effects with a saved state (a second
    effect of the same name gets " #2", ...)."""
    out = {}
    for e in model.effects:
        if e.state_name is None:
            continue
        name, k = e.state_name, 1
        while name in out:
            k += 1
            name = f"{e.state_name} #{k}"
        out[name] = e
    return out


def _check_effects(model, data: dict, path: str) -> dict:
    """Every effect with a state finds its group, every saved group its
    effect, and each effect accepts its data (check_state); collective."""
    saved = data.get("effects", {})
    effects = _stateful(model)
    if set(saved) != set(effects):
        raise SceneMismatchError(f"{path}: the state file holds the states of "
                                 f"{sorted(saved)}, this model has {sorted(effects)}")
    message = None
    for name, e in effects.items():
        try:   # every rank calls every check: some are collective
            e.check_state(model.system, saved[name])
        except ValueError as exc:
            message = message or f"{path}: {exc}"
    _collective(model.comm, message)
    return saved


def _check_schedules(model, data: dict, path: str) -> list:
    schedules = model.schedules()
    saved = data.get("schedules", {})
    keys = sorted(saved)
    names = [k.split(" ", 1)[1] if " " in k else k for k in keys]
    mine = [s.name for s in schedules]
    if names != mine:
        raise SceneMismatchError(f"{path}: the state file's loading schedules are {names}, "
                                 f"this model's {mine}: build the scene as it was saved")
    for key, sched in zip(keys, schedules):
        if len(saved[key]["start"]) != len(sched):
            raise SceneMismatchError(f"{path}: schedule {sched.name!r} has "
                                     f"{len(saved[key]['start'])} components in the state "
                                     f"file, {len(sched)} in this model")
    return [saved[k] for k in keys]


# -- the entry points -----------------------------------------------------------------
def save_state(model, path: str, solver=None, fibre_data=None) -> None:
    """Write the model's current state, and with ``solver`` where the run
    stands (stage, step size, predictor), to ``path`` (collective: call on
    every rank). ``fibre_data``: optional name -> array with one value per
    fibre. A failure to write raises StateFileError on every rank, and
    leaves an earlier file at ``path`` as it was."""
    model.setup()
    labels = {}
    for name, values in (fibre_data or {}).items():
        a = np.asarray(values)
        if a.shape[:1] != (len(model.mesh.fibres),):
            raise ValueError(f"save_state: fibre_data[{name!r}] has {a.shape[:1]} values, the "
                             f"model has {len(model.mesh.fibres)} fibres")
        labels[name] = a
    position = solver.position() if solver is not None else None
    previous = solver.previous_state() if solver is not None else None
    older = solver.older_state() if previous is not None else None
    vectors = [model.x] + [v for v in (previous, older) if v is not None]
    references = model.reference_values()
    fields = {f.name: _gather_field(model, f.name, vectors, references[f.name])
              for f in model.layout.fields}
    system = model.system
    effects = {name: e.save_state(system) for name, e in _stateful(model).items()}  # collective
    error = None
    if model.comm.rank == 0:
        mesh = model.mesh
        beam = fields.pop("beam")
        attrs = dict(format=FORMAT, version=VERSION, load_factor=model.load_factor,
                     num_fibres=len(mesh.fibres), num_nodes=mesh.num_nodes_global)
        attrs.update(position or {})
        fibres = dict(reference=mesh.X_global, unknowns=beam["unknowns"],
                      first_node=mesh.first_node,
                      radius=np.array([fib.radius for fib in mesh.fibres]), data=labels)
        for label in ("previous", "older"):
            if label in beam:
                fibres[label] = beam[label]
        twice = [name for name, fld in fields.items() if len(fld["keys"]) > 1 and np.any(
            np.all(fld["keys"][1:] == fld["keys"][:-1], axis=1))]
        try:   # an error on rank 0 alone is raised on every rank (below)
            if twice:   # the keys name each block once by construction
                raise RuntimeError(f"fields {twice} have two blocks with the same key")
            schedules = {}
            for k, sched in enumerate(model.schedules()):
                schedules[f"{k:03d} {sched.name}"] = dict(
                    start=sched.start, target=sched.target, active=sched.active,
                    following=sched.following(), current=sched.values(model.load_factor))
            _write(path, attrs, dict(fibres=fibres, fields=fields, schedules=schedules,
                                     effects=effects))
        except (OSError, ValueError, TypeError, RuntimeError) as exc:
            error = f"{path}: could not write the state ({exc})"
    error = model.comm.bcast(error, root=0)
    if error is not None:
        raise StateFileError(error)


def saved_configuration(path: str, comm=None) -> np.ndarray:
    """(nodes, 9) current [x0, g1, g2] of every fibre node of a saved state
    (reference plus unknowns, global node numbering), read without a
    model: what a new scene builds around (a matrix box, junctions) before
    its model exists. Read on the calling rank, or with ``comm`` on its rank
    0 and broadcast (collective; an unreadable file raises everywhere)."""
    data = _read_local(path) if comm is None else _read(path, comm)
    return data["fibres"]["reference"] + data["fibres"]["unknowns"]


def saved_fibres(path: str, comm=None) -> tuple[list[np.ndarray], np.ndarray, dict]:
    """(centre lines, radius per fibre, {name: per-fibre data}) of a saved
    state, read without a model: each centre line the (n, 3) current
    positions of one fibre's nodes; the data are the ``fibre_data`` given to
    :func:`save_state` (e.g. ``yarn``). Read as :func:`saved_configuration`."""
    data = _read_local(path) if comm is None else _read(path, comm)
    fibres = data["fibres"]
    x0 = (fibres["reference"] + fibres["unknowns"])[:, :3]
    first = np.asarray(fibres["first_node"], dtype=np.int64)    # num_fibres + 1 offsets
    lines = [x0[a:b] for a, b in zip(first[:-1], first[1:])]
    labels = {k: np.asarray(v) for k, v in fibres.get("data", {}).items()}
    return lines, np.asarray(fibres["radius"], dtype=float), labels


def _set_fields(model, values: dict, which: str = "unknowns", x=None) -> PETSc.Vec:
    """Put the matched saved arrays (``_field_values``) into x (default the
    model's), ghosts included."""
    x = model.x if x is None else x
    arrays = [a.copy() for a in model.layout.get_local(x)]
    for f, a in zip(model.layout.fields, arrays):
        if f.name in values and which in values[f.name]:
            a[:] = values[f.name][which]
    model.layout.scatter(x, arrays)
    x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
    return x


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
    model.setup()
    data = _read(path, model.comm)
    _check_fibres(model, data, path)
    attrs = dict(data["attrs"])
    if "data" in data["fibres"]:
        attrs["fibre_data"] = dict(data["fibres"]["data"])
    u = np.asarray(data["fibres"]["unknowns"], dtype=float)
    if not np.all(np.isfinite(u)):
        raise StateFileError(f"{path}: /fibres/unknowns holds non-finite values")
    effects = data.get("effects", {})
    _set_fields(model, {"beam": {"unknowns": u[model.mesh.local_to_global].ravel()}})
    for e in model.effects:
        e.load_fibres(model.system, effects.get(e.state_name, {}) if e.state_name else {})
    model.x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
    return attrs


def load_state(model, path: str, solver=None) -> dict:
    """Set the model, built as when the state was saved, to the saved state:
    every field's unknowns, stage values, effects' history; with ``solver``,
    where the run stood (:meth:`Solver.resume`: a state saved within a stage
    goes on in it, ``solver.run_stage`` with that stage, as the saving run
    did). Collective. Everything is checked before the model is changed:
    a file of another scene raises SceneMismatchError naming what differs,
    an unreadable one StateFileError. Returns the file's attributes, and the
    saved per-fibre labels under ``"fibre_data"``."""
    model.setup()
    data = _read(path, model.comm)
    attrs = dict(data["attrs"])
    if int(attrs["version"]) != VERSION:
        raise StateFileError(f"{path}: state file version {attrs['version']} holds the fibres "
                             f"but not every field (matrix, multipliers): load_state needs "
                             f"version {VERSION}; load_fibres starts a new scene from it")
    # the scene's parts first (their messages name what differs), then its
    # loading and every field's blocks
    _check_fibres(model, data, path)
    effects = _check_effects(model, data, path)
    schedules = _check_schedules(model, data, path)
    values = _field_values(model, data, path)
    if "data" in data["fibres"]:
        attrs["fibre_data"] = dict(data["fibres"]["data"])
    # -- everything matches: set the model ----------------------------------------
    load_factor = float(attrs["load_factor"])
    complete = load_factor >= 1.0 - 1e-14
    stage_index = int(attrs.get("stage_index", 0))
    following = []
    for saved, sched in zip(schedules, model.schedules()):
        follows = np.array(saved["following"], dtype=bool)
        following.append(follows)
        # the stage done: its callables' end values stand for them
        sched.load_saved(saved["start"], saved["target"], saved["active"],
                         (follows, saved["current"]) if complete else None)
        if complete:
            sched.forget_callables()
        elif stage_index > 0:
            # within a later stage: the scene's callables belong to its first
            # stage; the resumed Stage gives its own (Solver.run_stage)
            sched.forget_callables()
    model.load_factor = load_factor
    matrix_changed = model.update_constraints()
    _set_fields(model, values)
    for name, e in _stateful(model).items():
        e.load_state(model.system, effects[name])
    model.x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
    if solver is not None and "stage" in attrs:
        previous = older = None
        if all("previous" in v for v in values.values()):
            previous = _set_fields(model, values, "previous", model.x.duplicate())
        if all("older" in v for v in values.values()):
            older = _set_fields(model, values, "older", model.x.duplicate())
        position = {k: attrs[k] for k in ("stage", "stage_index", "stage_started", "steps",
                                          "next_step", "steps_since_cut",
                                          "previous_load_factor",
                                          "older_load_factor", "negative_eigenvalues")
                    if k in attrs}
        solver.resume(position, previous, following, matrix_changed, older)
    elif solver is not None and matrix_changed:
        # saved without a solver: where the run stood is not known (a new
        # stage starts from here), but the system matrix is new
        solver.resume_matrix()
    return attrs
