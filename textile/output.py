"""Results of a run on disk: ParaView series, results.json, PNG plots.

:class:`Output` is handed to :class:`~textile.Solver`; after every converged
step it writes the fibres (centre lines with section vectors, displacement,
and per-segment section-averaged strain and stress) to
``<directory>/fibres_<step>.vtu``, indexes them in ``fibres.pvd``, and
appends the step's statistics to ``results.json``. Everything is gathered
to rank 0 and written there. Files are replaced atomically, so a run that
fails keeps every converged step.
"""
from __future__ import annotations

import os

import numpy as np

from .io import PVDSeries, ResultsLog, write_fibres_vtu

_VOIGT = ("11", "22", "33", "23", "13", "12")


class Output:
    """Per-step ParaView files and a results log in ``directory``.

    ``every``: write the VTU of one step in ``every`` (results.json always).
    ``extra``: optional callable ``model -> dict`` of scalars to log per step
    (e.g. a reaction force for a load curve).
    """

    def __init__(self, directory: str, every: int = 1, extra=None):
        """Contact elements, when the scene has contact, go to
        ``contacts_<step>.vtu`` (indexed by ``contacts.pvd``): one line per
        element between its two particles, with its normal force, gap,
        normal, tangential force and slip flag."""
        if not isinstance(every, int) or every < 1:
            raise ValueError(f"every must be a positive integer, got {every!r}")
        self.directory = directory
        self.every = every
        self.extra = extra
        self._pvd = None
        self._contact_pvd = None
        self._log = None

    def _open(self, model) -> None:
        if self._log is not None:
            return
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
        write_vtu = record.step % self.every == 0
        q = model.nodal_unknowns() if write_vtu else None
        fields = self._segment_fields(model) if write_vtu else None
        contacts = self._contact_elements(model) if write_vtu else None
        if model.comm.rank != 0:
            return
        if contacts is not None and len(contacts["gap"]):
            self._write_contacts(record, contacts)
        if write_vtu:
            mesh = model.mesh
            lines = [q[mesh.fibre_nodes(f), 0:3] for f in range(len(mesh.fibres))]
            point_data = {"displacement": q[:, 0:3] - mesh.X_global[:, 0:3],
                          "g1": q[:, 3:6], "g2": q[:, 6:9],
                          "radius": np.concatenate([np.full(f.num_nodes, f.radius)
                                                    for f in mesh.fibres])}
            name = f"fibres_{record.step:05d}.vtu"
            path = os.path.join(self.directory, name)
            write_fibres_vtu(path, lines, point_data=point_data, cell_data=fields)
            self._pvd.add(record.time, path)
        self._log.append(dict(step=record.step, stage=record.stage, time=record.time,
                              load_factor=record.load_factor,
                              newton_iterations=record.newton_iterations,
                              attempts=record.attempts, wall_time=record.wall_time,
                              final_residual=record.residual_norms[-1] if record.residual_norms
                              else 0.0,
                              energy=record.energy, updates=record.updates,
                              **{f"residual_{k}": v for k, v in record.residuals.items()},
                              **record.stability,
                              **record.effects, **extra))

    def _contact_elements(self, model) -> dict | None:
        """All ranks' contact elements gathered on rank 0 (None without contact)."""
        from .effects.fibre_contact import FibreContact
        effects = [e for e in model.effects if isinstance(e, FibreContact)]
        if not effects:
            return None
        parts = model.comm.gather([e.elements() for e in effects], root=0)
        if model.comm.rank != 0:
            return None
        flat = [d for rank in parts for d in rank]
        return {k: np.concatenate([d[k] for d in flat]) for k in flat[0]}

    def _write_contacts(self, record, d: dict) -> None:
        if self._contact_pvd is None:
            self._contact_pvd = PVDSeries(os.path.join(self.directory, "contacts.pvd"))
        lines = [np.vstack([a, b]) for a, b in zip(d["position_i"], d["position_j"])]
        name = os.path.join(self.directory, f"contacts_{record.step:05d}.vtu")
        write_fibres_vtu(name, lines, cell_data={
            "normal_force": d["normal_force"], "gap": d["gap"], "normal": d["normal"],
            "tangential_force": d["tangential_force"], "slip": d["slip"].astype(np.int32),
            "penalty": d["penalty"], "fibre_i": d["fibre_i"].astype(np.int32),
            "fibre_j": d["fibre_j"].astype(np.int32)})
        self._contact_pvd.add(record.time, name)

    def _segment_fields(self, model) -> dict | None:
        """Element fields mapped to polyline segments (an element of order p
        spans p segments), gathered to rank 0."""
        mesh = model.mesh
        local = model.beam.element_fields(model.state().u["beam"])
        ids = mesh.local_element_ids
        parts = model.comm.gather((ids, local), root=0)
        if model.comm.rank != 0:
            return None
        vals = np.zeros((len(mesh.elements_global), 12))
        for i, v in parts:
            vals[i] = v
        per_segment = np.repeat(vals, mesh.order, axis=0)
        out = {}
        for k, c in enumerate(_VOIGT):
            out[f"strain_{c}"] = per_segment[:, k]
            out[f"stress_{c}"] = per_segment[:, 6 + k]
        return out

    def failure(self, message: str) -> None:
        """Record why a run stopped (kept in results.json's meta)."""
        if self._log:
            self._log.set_meta(failure=message)

    def warning(self, message: str) -> None:
        """Record a warning of the run (results.json meta ``warnings``)."""
        if self._log:
            self._log.set_meta(warnings=list(self._log.meta.get("warnings", [])) + [message])

    def plot_shape(self, model, filename: str = "shape.png", view: str = "3d", title: str = "") -> str:
        """PNG of the current centre lines over the reference ones (rank 0
        writes; every rank must call). Returns the file's path."""
        lines = self.centrelines(model)
        path = os.path.join(self.directory, filename)
        if model.comm.rank == 0:
            from .io import plot_fibres
            os.makedirs(self.directory, exist_ok=True)
            ref = [f.points for f in model.mesh.fibres]
            plot_fibres(path, lines, title=title, reference=ref, view=view)
        return path
