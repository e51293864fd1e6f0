"""Results of a run on disk: ParaView series, results.json, PNG plots.

:class:`Output` is handed to :class:`~textile.Solver`; after every converged
step it writes the fibres (centre lines with section vectors, displacement,
and per-segment section-averaged strain and stress) to
``<directory>/fibres_<step>.vtu``, indexes them in ``fibres.pvd``, and
appends the step's statistics to ``results.json``. The fibres' loads
(:mod:`textile.beam.fibre_loads`) go with them: per segment the element's
``curvature`` and ``surface_stress``, per fibre (point and cell arrays, one
value per fibre) ``max_axial_strain``, ``max_curvature`` and
``max_stress``, and in each step's record of results.json
``most_loaded_fibres``: the 5 fibres of largest ``max_stress``, as
{"fibre": [5 indices], "max_axial_strain": [5 values], "max_curvature":
[...], "max_stress": [...]}. Everything is gathered
to rank 0 and written there. Files are replaced atomically, so a run that
fails keeps every converged step.

A scene with elastic matrix blocks (:class:`~textile.effects.elastic_block.
ElasticBlock`) also gets, at the same steps, each block written by
dolfinx's VTKFile (``<block>/<block>_<step>000000.pvtu`` with one ``.vtu``
piece per rank; point field ``displacement``, cell fields ``J`` and
``von_mises``; points at their current positions, like the fibres), the
block's own index ``<block>.pvd``, and ``scene.pvd``: the one index to open
in ParaView, listing per step the fibres (part 0, ``name="fibres"``) and
each block (parts 1, 2, ...) as the blocks of one multiblock data set.

Per-fibre labels (``fibre_data``, e.g. each fibre's yarn) go on every
fibres .vtu as point and cell arrays. Pictures of the final state
(``sample.png``, ``sample_top.png``, ``cut_*.png``; see
:mod:`textile.io.sample_pictures`) are drawn from the written fibres file
when a stage ends (or the run fails, or on :meth:`Output.finish`), never
while a stage is being solved; a picture that fails is a warning, never a
lost result. Rank 0 draws them; at a stage's end the other ranks wait for
it without spinning (:func:`textile.runtime.waiting_quietly`), leaving
their cores to the VTK process that renders the 3D views.
"""
from __future__ import annotations

import os
import time
import warnings
from collections.abc import Mapping

import numpy as np
from mpi4py import MPI

from ..beam.fibre_loads import (FIGURES, element_loads, fibre_maxima, gathered_element_fields,
                                top_fibres)
from . import PVDSeries, ResultsLog, SceneSeries, write_fibres_vtu
from ..effects.base import stage_ended
from ..runtime import waiting_quietly

_VOIGT = ("11", "22", "33", "23", "13", "12")
# arrays Output writes itself: a fibre_data array may not take their names
_RESERVED = {"fibre_id", "radius", "displacement", "g1", "g2", "curvature",
             "surface_stress"} | set(FIGURES) | {
    f"{kind}_{c}" for kind in ("strain", "stress") for c in _VOIGT}
#: fibres listed per step in results.json (most_loaded_fibres)
TOP_FIBRES = 5


class Output:
    """Per-step ParaView files and a results log in ``directory``.

    ``every``: write the VTU of one step in ``every`` (results.json always).
    ``extra``: optional callable ``model -> dict`` of scalars to log per step
    (e.g. a reaction force for a load curve).
    ``fibre_data``: {name: one integer or float per fibre, in the model's
    fibre order}, written as point and cell arrays of every fibres .vtu
    (e.g. ``{"yarn": fabric.fibre_yarn}``); ``"yarn"`` also colours the
    pictures.
    ``pictures``: ``"last"`` (default) draws the pictures when a stage ends
    (load factor 1; in :meth:`Solver.run` the last stage only), when the run
    fails (its last written step) and on :meth:`finish`; ``True`` of every
    written step (files suffixed ``_<step>``), drawn when its stage ends or
    the run fails; ``False`` never. Either way from the written fibres
    files (:func:`textile.io.sample_pictures.draw_vtu_pictures`), and a
    stage's last step is always written when there are pictures.
    ``yarn_directions``: per yarn id, ``"warp"``, ``"weft"`` or a 3-vector:
    one cut picture per direction (``cut_warp.png``, ...); without it one
    cut normal to the mean fibre direction. For a fabric,
    ``Output(directory, **textile.io.fabric_labels(fabric))`` sets both.
    ``picture_size``: (width, height) of the 3D pictures in pixels.
    """

    def __init__(self, directory: str, every: int = 1, extra=None, fibre_data=None,
                 pictures="last", yarn_directions=None, picture_size=(1600, 1000)):
        """Contact elements, when the scene has contact, go to
        ``contacts_<step>.vtu`` (indexed by ``contacts.pvd``): one line per
        element between its two particles, with its normal force, gap,
        normal, tangential force and slip flag."""
        if not isinstance(every, int) or every < 1:
            raise ValueError(f"every must be a positive integer, got {every!r}")
        if not (pictures is True or pictures is False or pictures == "last"):
            raise ValueError(f"pictures must be True, False or 'last', got {pictures!r}")
        self.directory = directory
        self.every = every
        self.extra = extra
        self.fibre_data = self._checked_fibre_data(fibre_data)
        self.pictures = pictures
        self.picture_size = tuple(picture_size)
        self._yarn_axes = None
        if yarn_directions is not None:
            from .sample_pictures import yarn_axes
            self._yarn_axes = yarn_axes(yarn_directions)
            missing = set(np.unique(self.fibre_data.get("yarn", [])).tolist()) \
                - set(self._yarn_axes)
            if "yarn" not in self.fibre_data or missing:
                raise ValueError("yarn_directions needs fibre_data['yarn'] and a direction for "
                                 f"each of its yarns (missing: {sorted(missing)})")
        self._pvd = None
        self._contact_pvd = None
        self._scene_pvd = None
        self._block_pvds = {}
        self._log = None
        self._last_step = (0, 0.0)     # (step, time) of the last state written or not
        self._written_steps = set()    # the steps whose fibres .vtu is written (every rank)
        self._written = []             # [(step, fibres .vtu)] in order, rank 0
        self._drawn_step = None        # the step the "last" pictures show
        self._drawn_steps = set()      # the steps drawn with pictures=True
        #: set by Solver.run while stages remain: "last" draws at the run's end
        self.hold_pictures = False

    @staticmethod
    def _checked_fibre_data(fibre_data) -> dict:
        if fibre_data is None:
            return {}
        if not isinstance(fibre_data, Mapping):
            raise ValueError(f"fibre_data must be a dict name -> array (one value per fibre), "
                             f"got {type(fibre_data).__name__}")
        out = {}
        for name, values in fibre_data.items():
            if not isinstance(name, str) or not name or name in _RESERVED:
                raise ValueError(f"fibre_data name {name!r} is empty, not a string, or one "
                                 f"Output writes itself ({sorted(_RESERVED)})")
            a = np.asarray(values)
            if a.ndim != 1 or a.dtype.kind not in "biuf":
                raise ValueError(f"fibre_data[{name!r}] must be a 1-D integer or float array "
                                 f"(one value per fibre), got shape {a.shape} dtype {a.dtype}")
            if a.dtype.kind == "f" and not np.all(np.isfinite(a)):
                raise ValueError(f"fibre_data[{name!r}] has non-finite values")
            out[name] = a.astype(np.int64) if a.dtype.kind in "bu" else a
        return out

    def _check_fibre_count(self, model) -> None:
        n = len(model.mesh.fibres)
        for name, a in self.fibre_data.items():
            if len(a) != n:
                raise ValueError(f"fibre_data[{name!r}] has {len(a)} values but the model has "
                                 f"{n} fibres (one value per fibre, in the model's fibre order)")

    def _open(self, model) -> None:
        if self._log is not None:
            return
        self._check_fibre_count(model)     # on every rank: all raise together
        if model.comm.rank == 0:
            os.makedirs(self.directory, exist_ok=True)
            self._pvd = PVDSeries(os.path.join(self.directory, "fibres.pvd"))
            self._log = ResultsLog(os.path.join(self.directory, "results.json"))
            self._log.set_meta(num_fibres=len(model.mesh.fibres), num_ranks=model.comm.size,
                               element=dict(order=model.element.order,
                                            axial_points=model.element.axial_points,
                                            section_order=model.element.section_order,
                                            poisson_cure=model.element.poisson_cure))
        else:
            self._log = False

    def centrelines(self, model) -> list[np.ndarray]:
        q = model.nodal_unknowns()
        return [q[model.mesh.fibre_nodes(f), 0:3] for f in range(len(model.mesh.fibres))]

    def write_step(self, solver, record) -> None:
        model = solver.model
        self._open(model)
        extra = self.extra(model) if self.extra else {}
        stage_end = stage_ended(record.load_factor)
        # a stage's last step is written whenever there are pictures: they
        # are drawn from it
        write_vtu = record.step % self.every == 0 or (bool(self.pictures) and stage_end)
        # every step: the fibres' loads for results.json
        q = model.nodal_unknowns()
        element_fields = gathered_element_fields(model, root=0)
        contacts = self._contact_elements(model) if write_vtu else None
        blocks = self._write_blocks(model, record) if write_vtu else []
        self._last_step = (record.step, record.time)
        if write_vtu:
            self._written_steps.add(record.step)
        if model.comm.rank != 0:
            if stage_end:
                waiting_quietly(model.comm)   # while rank 0 draws
            return
        try:
            self._write_step_root(model, record, q, element_fields, contacts, blocks,
                                  write_vtu, stage_end, extra)
        finally:
            if stage_end:
                waiting_quietly(model.comm)

    def _write_step_root(self, model, record, q, element_fields, contacts, blocks, write_vtu,
                         stage_end, extra) -> None:
        """Rank 0's part of :meth:`write_step`: the files, and the
        pictures at a stage's end."""
        if contacts is not None and len(contacts["gap"]):
            self._write_contacts(record, contacts)
        mesh = model.mesh
        per_element = element_loads(mesh, q[:, 0:3], element_fields)
        loads = fibre_maxima(mesh, per_element)
        if write_vtu:
            path = self._write_fibres(mesh, q, element_fields, per_element, loads,
                                      (record.step, record.time))
            self._index_blocks(record, path, blocks)
        self._log.append(dict(step=record.step, stage=record.stage, time=record.time,
                              load_factor=record.load_factor,
                              newton_iterations=record.newton_iterations,
                              attempts=record.attempts, wall_time=record.wall_time,
                              final_residual=record.residual_norms[-1] if record.residual_norms
                              else 0.0,
                              energy=record.energy, updates=record.updates,
                              # (Newton iterations, change); null: new contact forces
                              contact_passes=[[n, c if np.isfinite(c) else None]
                                              for n, c in record.passes],
                              most_loaded_fibres=top_fibres(loads, TOP_FIBRES),
                              **{f"residual_{k}": v for k, v in record.residuals.items()},
                              **record.stability,
                              **record.effects, **extra))
        # pictures only at a stage's end, from the written files (never
        # while a stage is being solved): "last" of the run's last stage
        if stage_end and not (self.pictures == "last" and self.hold_pictures):
            self._draw_due()

    def _write_fibres(self, mesh, q, element_fields, per_element, loads, record) -> str:
        """Rank 0: the fibres' .vtu of a step, added to fibres.pvd; its path."""
        lines = [q[mesh.fibre_nodes(f), 0:3] for f in range(len(mesh.fibres))]
        counts = np.array([f.num_nodes for f in mesh.fibres])
        per_fibre = {**{k: loads[k] for k in FIGURES}, **self.fibre_data}
        point_data = {"displacement": q[:, 0:3] - mesh.X_global[:, 0:3],
                      "g1": q[:, 3:6], "g2": q[:, 6:9],
                      "radius": np.repeat([f.radius for f in mesh.fibres], counts)}
        point_data.update({k: np.repeat(a, counts) for k, a in per_fibre.items()})
        fields = self._segment_fields(mesh, element_fields, per_element)
        fields.update({k: np.repeat(a, counts - 1) for k, a in per_fibre.items()})
        path = os.path.join(self.directory, f"fibres_{record[0]:05d}.vtu")
        write_fibres_vtu(path, lines, point_data=point_data, cell_data=fields)
        self._pvd.add(record[1], path)
        self._written.append((record[0], path))
        return path

    @staticmethod
    def _blocks(model) -> list:
        """The effects with a ParaView part of their own (Effect.vtk_name:
        the matrix blocks, written by dolfinx)."""
        return [e for e in model.effects if e.vtk_name is not None]

    def _write_blocks(self, model, record) -> list[tuple[str, str]]:
        """Write every block of the step (collective); [(name, .pvtu path)]."""
        out = []
        for block in self._blocks(model):
            name = block.vtk_name
            sub = os.path.join(self.directory, name)
            if model.comm.rank == 0:
                os.makedirs(sub, exist_ok=True)
            model.comm.barrier()
            out.append((name, block.write_vtk(sub, f"{name}_{record.step:05d}", record.time)))
        return out

    def _index_blocks(self, record, fibres_path: str, blocks: list) -> None:
        """Rank 0: each block's own series and the combined scene.pvd."""
        if not blocks:
            return
        for name, path in blocks:
            if name not in self._block_pvds:
                self._block_pvds[name] = PVDSeries(os.path.join(self.directory, f"{name}.pvd"))
            self._block_pvds[name].add(record.time, path)
        if self._scene_pvd is None:
            self._scene_pvd = SceneSeries(os.path.join(self.directory, "scene.pvd"))
        self._scene_pvd.add(record.time, [("fibres", fibres_path)] + blocks)

    def _contact_elements(self, model) -> dict | None:
        """All ranks' contact elements (Effect.contact_elements) gathered on
        rank 0 (None without contact)."""
        mine = [e.contact_elements() for e in model.effects]
        mine = [d for d in mine if d is not None]
        if not model.comm.allreduce(bool(mine), op=MPI.LOR):
            return None
        parts = model.comm.gather(mine, root=0)
        if model.comm.rank != 0:
            return None
        flat = [d for rank in parts for d in rank]
        return {k: np.concatenate([d[k] for d in flat]) for k in flat[0]}

    def _write_contacts(self, record, d: dict) -> None:
        if self._contact_pvd is None:
            self._contact_pvd = PVDSeries(os.path.join(self.directory, "contacts.pvd"))
        # one two-point line per element, as one (n, 2, 3) array
        lines = np.stack([d["position_i"], d["position_j"]], axis=1)
        name = os.path.join(self.directory, f"contacts_{record.step:05d}.vtu")
        write_fibres_vtu(name, lines, cell_data={
            "normal_force": d["normal_force"], "gap": d["gap"], "normal": d["normal"],
            "tangential_force": d["tangential_force"], "slip": d["slip"].astype(np.int32),
            "penalty": d["penalty"], "fibre_i": d["fibre_i"].astype(np.int32),
            "fibre_j": d["fibre_j"].astype(np.int32)})
        self._contact_pvd.add(record.time, name)

    @staticmethod
    def _segment_fields(mesh, element_fields: np.ndarray, per_element: dict) -> dict:
        """Gathered element fields and loads mapped to polyline segments (an
        element of order p spans p segments)."""
        def segments(v):
            return np.repeat(v, mesh.order, axis=0)
        out = {}
        for k, c in enumerate(_VOIGT):
            out[f"strain_{c}"] = segments(element_fields[:, k])
            out[f"stress_{c}"] = segments(element_fields[:, 6 + k])
        out["curvature"] = segments(per_element["curvature"])
        out["surface_stress"] = segments(per_element["surface_stress"])
        return out

    def failure(self, message: str) -> None:
        """Record why a run stopped (kept in results.json's meta), then draw
        the pictures due: "last" of the last written step (the last
        converged one unless ``every`` > 1), True of each written step not
        drawn yet."""
        if self._log:
            self._log.set_meta(failure=message)
            self._draw_due()

    def finish(self, model) -> None:
        """Draw the pictures of the model's state now (every rank must call),
        e.g. after ``solver.solve(t)`` stopped inside a stage: its last step
        (or the start, before any) is written first if it was not, and the
        pictures are drawn from that file. Results are not touched."""
        self._open(model)
        step, time = self._last_step
        if self.pictures and step not in self._written_steps:
            q = model.nodal_unknowns()
            element_fields = gathered_element_fields(model, root=0)
            self._written_steps.add(step)
            if model.comm.rank == 0:
                per_element = element_loads(model.mesh, q[:, 0:3], element_fields)
                self._write_fibres(model.mesh, q, element_fields, per_element,
                                   fibre_maxima(model.mesh, per_element), (step, time))
        try:
            if model.comm.rank == 0 and self.pictures:
                self._drawn_step = None
                self._draw_due()
        finally:
            waiting_quietly(model.comm)   # the other ranks, while rank 0 draws

    def _draw_due(self) -> None:
        """Rank 0: "last": the pictures of the last written step, unless
        drawn already; True: of every written step not drawn yet (suffix
        ``_<step>``)."""
        if self.pictures is True:
            for step, path in self._written:
                if step not in self._drawn_steps:
                    self._drawn_steps.add(step)
                    self._draw(step, path, f"_{step:05d}")
        elif self.pictures == "last" and self._written \
                and self._drawn_step != self._written[-1][0]:
            self._draw(*self._written[-1])

    def _draw(self, step: int, vtu: str, suffix: str = "") -> None:
        """Pictures of step ``step`` from its fibres file ``vtu`` (rank 0);
        failures are warnings."""
        from .render import RenderingWarning
        from .sample_pictures import draw_vtu_pictures
        start = time.perf_counter()
        try:
            drawn, errors = draw_vtu_pictures(vtu, self.directory, self._yarn_axes, suffix,
                                              self.picture_size)
        except Exception as e:    # a picture must never cost the results
            drawn, errors = {}, [f"{type(e).__name__}: {e}"]
        if not suffix:
            self._drawn_step = step
        # seconds: of the drawing that made it (the pictures of a step are
        # drawn together, the 3D views in a process beside the cuts)
        seconds = time.perf_counter() - start
        self._log.set_meta(pictures={**self._log.meta.get("pictures", {}),
                                     **{k: dict(step=step, drawn_by=v, seconds=seconds)
                                        for k, v in drawn.items()}})
        for error in errors:
            message = f"picture not drawn: {error}"
            warnings.warn(message, RenderingWarning, stacklevel=2)
            self.warning(message)

    def warning(self, message: str) -> None:
        """Record a warning of the run (results.json meta ``warnings``)."""
        if self._log:
            self._log.set_meta(warnings=list(self._log.meta.get("warnings", [])) + [message])

    def plot_shape(self, model, filename: str = "shape.png", view: str = "3d",
                   title: str = "") -> str:
        """PNG of the current centre lines over the reference ones (rank 0
        writes; every rank must call). Returns the file's path."""
        lines = self.centrelines(model)
        path = os.path.join(self.directory, filename)
        if model.comm.rank == 0:
            from . import plot_fibres
            os.makedirs(self.directory, exist_ok=True)
            ref = [f.points for f in model.mesh.fibres]
            plot_fibres(path, lines, title=title, reference=ref, view=view)
        return path
