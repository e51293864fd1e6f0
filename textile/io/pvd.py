"""ParaView collections (``.pvd``): the one writer of every series' index.

:func:`write_pvd` writes a collection from its data sets; :class:`PVDSeries`
(one file per time step: the fibres, the contacts, a block) and
:class:`SceneSeries` (several named parts per step, shown by ParaView as one
multiblock data set) keep their entries and rewrite the file through it
after every ``add``, so a crashed run still leaves a valid index of the
steps written so far. Files are named relative to the ``.pvd``'s directory,
so an output folder can be moved as a whole.
"""
from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path

from textile.io.vtu import atomic_write_bytes

__all__ = ["PVDSeries", "SceneSeries", "write_pvd"]


def write_pvd(path: str | os.PathLike,
              steps: Sequence[tuple[float, Sequence[tuple[str | None, str]]]]) -> None:
    """Atomically write the collection ``path``: per step ``(time, parts)``,
    ``parts`` = [(name or None, file relative to the .pvd's directory)],
    numbered ``part`` 0, 1, ... in order (a ``name`` attribute when given)."""
    root = ET.Element("VTKFile", {"type": "Collection", "version": "0.1",
                                  "byte_order": "LittleEndian"})
    collection = ET.SubElement(root, "Collection")
    for time, parts in steps:
        for k, (name, file) in enumerate(parts):
            # repr keeps the full float precision of the time value
            attrib = {"timestep": repr(float(time)), "group": "", "part": str(k)}
            if name is not None:
                attrib["name"] = name
            attrib["file"] = file
            ET.SubElement(collection, "DataSet", attrib)
    ET.indent(root)
    atomic_write_bytes(path, ET.tostring(root, encoding="utf-8", xml_declaration=True))


class _Series:
    """Steps of a collection, rewritten by :func:`write_pvd` after each."""

    def __init__(self, path: str | os.PathLike):
        self._path = Path(path)
        self._steps: list[tuple[float, list[tuple[str | None, str]]]] = []
        write_pvd(self._path, self._steps)

    @property
    def path(self) -> Path:
        """Path of the ``.pvd`` file."""
        return self._path

    def _add(self, time: float, parts: list[tuple[str | None, str | os.PathLike]]) -> None:
        t = float(time)
        if not math.isfinite(t):
            raise ValueError(f"time must be finite; got {time!r}")
        if self._steps and t < self._steps[-1][0]:
            raise ValueError(
                f"time must be non-decreasing; got {t!r} after {self._steps[-1][0]!r}")
        base = os.path.dirname(os.path.abspath(self._path))
        rel = [(name, Path(os.path.relpath(os.path.abspath(p), start=base)).as_posix())
               for name, p in parts]
        self._steps.append((t, rel))
        write_pvd(self._path, self._steps)


class PVDSeries(_Series):
    """ParaView collection indexing a time series of ``.vtu`` files, one per
    step; (re)written atomically on construction (empty) and every :meth:`add`.

    Example::

        series = PVDSeries("out/fibres.pvd")
        for step, t in enumerate(times):
            vtu = f"out/fibres_{step:06d}.vtu"
            write_fibres_vtu(vtu, centrelines)
            series.add(t, vtu)
    """

    @property
    def entries(self) -> list[tuple[float, str]]:
        """Recorded ``(time, file)`` pairs in insertion order, ``file``
        relative to the ``.pvd``'s directory with ``/`` separators."""
        return [(t, parts[0][1]) for t, parts in self._steps]

    def add(self, time: float, vtu_path: str | os.PathLike) -> None:
        """Record the data set ``vtu_path`` (absolute or relative to the
        current directory) at ``time`` and rewrite the ``.pvd`` file.

        Raises:
            ValueError: If ``time`` is non-finite or decreases.
        """
        self._add(time, [(None, vtu_path)])


class SceneSeries(_Series):
    """ParaView collection of several named parts per time step (``part``
    numbers and ``name`` attributes): one multiblock data set per step."""

    def add(self, time: float, parts: list[tuple[str, str | os.PathLike]]) -> None:
        """One step at ``time``: ``parts`` = [(name, file path)], in part order."""
        self._add(time, list(parts))
