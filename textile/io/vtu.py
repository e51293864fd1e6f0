"""VTK XML output of fibre centre lines for ParaView.

Each fibre is written as a polyline made of VTK_LINE cells (one cell per
segment between consecutive centre-line points) in a VTK XML
UnstructuredGrid (``.vtu``) file. Time series are indexed by a ParaView
collection (``.pvd``) file, see :class:`PVDSeries`.

Data arrays are stored inline as base64-encoded binary (``format="binary"``)
with a ``UInt64`` block-size header, which keeps files small while staying
a single self-contained XML document readable by ParaView and meshio.

All writers replace their target atomically (temporary file in the same
directory, then :func:`os.replace`), so an interrupted run never leaves a
half-written file behind.

These functions are serial: call them on one MPI rank with gathered data.
"""

from __future__ import annotations

import base64
import math
import os
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import numpy.typing as npt

__all__ = [
    "VTK_LINE",
    "PVDSeries",
    "atomic_write_bytes",
    "check_centrelines",
    "write_fibres_vtu",
]

#: VTK cell type id of a 2-node line segment.
VTK_LINE = 3

# Block-size header written in front of every binary array. UInt64 so that
# arrays larger than 4 GiB remain representable.
_HEADER_TYPE = "UInt64"
_HEADER_DTYPE = np.dtype("<u8")

# Name of the array added to both point and cell data.
_FIBRE_ID = "fibre_id"


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically.

    The bytes go to a temporary file in the destination directory (same file
    system, so :func:`os.replace` is atomic), which is flushed to disk and then
    renamed over ``path``. Readers therefore see either the old or the new
    complete file, never a partial one.

    Args:
        path: Destination file. Its directory must exist.
        data: File contents.
    """
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        # Never leave the temporary file behind, whatever interrupted us.
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise


def check_centrelines(
    centrelines: Sequence[npt.ArrayLike], name: str = "centrelines"
) -> list[np.ndarray]:
    """Validate fibre centre lines and return them as float64 arrays.

    Args:
        centrelines: One array of shape ``(n_i, 3)`` per fibre, ``n_i >= 2``,
            holding point coordinates (model length units).
        name: Argument name used in error messages.

    Returns:
        List of C-contiguous ``float64`` arrays of shape ``(n_i, 3)``.

    Raises:
        ValueError: If there are no fibres, a fibre has a wrong shape, fewer
            than two points, or non-finite coordinates.
    """
    if isinstance(centrelines, np.ndarray) and centrelines.ndim == 2:
        raise ValueError(
            f"{name} must be a list of (n_i, 3) arrays, one per fibre; "
            f"got a single array of shape {centrelines.shape} (wrap it in a list)"
        )
    lines = list(centrelines)
    if not lines:
        raise ValueError(f"{name} must contain at least one fibre")
    checked = []
    for i, line in enumerate(lines):
        try:
            x = np.ascontiguousarray(line, dtype=np.float64)
        except (TypeError, ValueError) as e:
            raise ValueError(f"{name}[{i}] is not a numeric array: {e}") from None
        if x.ndim != 2 or x.shape[1] != 3:
            raise ValueError(f"{name}[{i}] must have shape (n, 3); got {x.shape}")
        if x.shape[0] < 2:
            raise ValueError(f"{name}[{i}] must have at least 2 points; got {x.shape[0]}")
        if not np.all(np.isfinite(x)):
            bad = int(np.argwhere(~np.isfinite(x))[0, 0])
            raise ValueError(f"{name}[{i}] has non-finite (NaN/inf) coordinates at point {bad}")
        checked.append(x)
    return checked


def _vtk_array(array: npt.ArrayLike, label: str) -> tuple[np.ndarray, str]:
    """Convert an array to a little-endian VTK-supported dtype.

    Floats become Float64; booleans and uint8 UInt8; other integers up to
    32 bits (uint32 excluded) Int32; remaining integers Int64.

    Returns:
        The converted array and its VTK type name.
    """
    a = np.asarray(array)
    kind = a.dtype.kind
    if kind == "f":
        if not np.all(np.isfinite(a)):
            raise ValueError(f"{label} contains non-finite (NaN/inf) values")
        return a.astype("<f8"), "Float64"
    if kind == "b" or a.dtype == np.uint8:
        return a.astype("u1"), "UInt8"
    if kind in "iu":
        if a.dtype.itemsize <= 4 and not (kind == "u" and a.dtype.itemsize == 4):
            return a.astype("<i4"), "Int32"
        if kind == "u" and a.size and int(a.max()) > np.iinfo(np.int64).max:
            raise ValueError(f"{label} has unsigned values too large for Int64")
        return a.astype("<i8"), "Int64"
    raise ValueError(f"{label} has unsupported dtype {a.dtype}; expected float, int or bool")


def _encode(a: np.ndarray) -> str:
    """Base64-encode an array as VTK inline binary (size header + raw bytes)."""
    raw = np.ascontiguousarray(a).tobytes()
    header = np.array([len(raw)], dtype=_HEADER_DTYPE).tobytes()
    # Header and data encoded as one base64 stream, as VTK itself does for
    # uncompressed data.
    return base64.b64encode(header + raw).decode("ascii")


def _data_array(parent: ET.Element, name: str, array: npt.ArrayLike, label: str) -> ET.Element:
    """Append a binary ``DataArray`` for an array of shape (m,) or (m, k)."""
    a, vtk_type = _vtk_array(array, label)
    attrib = {"type": vtk_type, "Name": name, "format": "binary"}
    if a.ndim == 2:
        attrib["NumberOfComponents"] = str(a.shape[1])
    elif a.ndim != 1:
        raise ValueError(f"{label} must have shape (m,) or (m, k); got {a.shape}")
    el = ET.SubElement(parent, "DataArray", attrib)
    el.text = _encode(a)
    return el


def _check_fields(
    fields: Mapping[str, npt.ArrayLike] | None, n_rows: int, arg: str, what: str
) -> dict[str, np.ndarray]:
    """Check that every array in ``fields`` has ``n_rows`` rows and 1 or 2 dims."""
    if fields is None:
        return {}
    if not isinstance(fields, Mapping):
        raise ValueError(f"{arg} must be a dict name -> array; got {type(fields).__name__}")
    checked = {}
    for name, values in fields.items():
        label = f"{arg}[{name!r}]"
        if not isinstance(name, str) or not name:
            raise ValueError(f"{arg} keys must be non-empty strings; got {name!r}")
        if name == _FIBRE_ID:
            raise ValueError(f"{label}: the name {_FIBRE_ID!r} is reserved (added automatically)")
        a = np.asarray(values)
        if a.ndim not in (1, 2) or a.shape[0] != n_rows:
            raise ValueError(
                f"{label} must have shape ({n_rows},) or ({n_rows}, k) "
                f"(one row per {what}); got {a.shape}"
            )
        checked[name] = a
    return checked


def _check_field_data(field_data: Mapping[str, npt.ArrayLike] | None) -> dict[str, np.ndarray]:
    """Check global (per-file) field data; scalars become length-1 arrays."""
    if field_data is None:
        return {}
    if not isinstance(field_data, Mapping):
        raise ValueError(
            f"field_data must be a dict name -> array; got {type(field_data).__name__}"
        )
    checked = {}
    for name, values in field_data.items():
        if not isinstance(name, str) or not name:
            raise ValueError(f"field_data keys must be non-empty strings; got {name!r}")
        a = np.atleast_1d(np.asarray(values))
        if a.ndim > 2:
            raise ValueError(f"field_data[{name!r}] must have at most 2 dimensions; got {a.shape}")
        checked[name] = a
    return checked


def _connectivity(counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Segment connectivity for polylines with ``counts[i]`` points each.

    Returns:
        ``(lines, fibre_of_segment)``: ``(n_segments, 2)`` global point
        indices and the fibre index of each segment.
    """
    first = np.concatenate(([0], np.cumsum(counts)[:-1]))
    starts = np.concatenate([f + np.arange(n - 1) for f, n in zip(first, counts)])
    lines = np.column_stack((starts, starts + 1))
    fibre = np.repeat(np.arange(len(counts)), counts - 1)
    return lines, fibre


def write_fibres_vtu(
    path: str | os.PathLike,
    centrelines: Sequence[npt.ArrayLike],
    point_data: Mapping[str, npt.ArrayLike] | None = None,
    cell_data: Mapping[str, npt.ArrayLike] | None = None,
    field_data: Mapping[str, npt.ArrayLike] | None = None,
) -> None:
    """Write fibre centre lines to a VTK XML UnstructuredGrid (``.vtu``) file.

    Points of all fibres are concatenated in order, giving ``N = sum(n_i)``
    points; fibre ``i`` contributes ``n_i - 1`` VTK_LINE cells joining its
    consecutive points, giving ``M = sum(n_i - 1)`` cells. An integer array
    ``"fibre_id"`` (the fibre's index in ``centrelines``) is always added to
    both point and cell data.

    Args:
        path: Output file, conventionally with suffix ``.vtu``. Its directory
            must exist. Replaced atomically.
        centrelines: One array of shape ``(n_i, 3)`` per fibre, ``n_i >= 2``,
            holding point coordinates (model length units). Must be finite.
        point_data: Name -> array of shape ``(N,)`` (scalar), ``(N, 3)``
            (vector) or ``(N, k)``; float, int or bool.
        cell_data: Name -> array of shape ``(M,)``, ``(M, 3)`` or ``(M, k)``,
            one row per segment in point order.
        field_data: Name -> scalar or array of shape ``(m,)`` or ``(m, k)``
            attached to the whole grid (e.g. time, load factor).

    Raises:
        ValueError: On bad shapes, non-finite values, unsupported dtypes,
            or a user array named ``"fibre_id"``; the message names the
            offending argument and key.
    """
    lines = check_centrelines(centrelines, "centrelines")
    counts = np.array([x.shape[0] for x in lines])
    points = np.concatenate(lines)
    n_points = points.shape[0]
    connectivity, fibre_of_segment = _connectivity(counts)
    n_cells = connectivity.shape[0]

    pdata = _check_fields(point_data, n_points, "point_data", "point")
    cdata = _check_fields(cell_data, n_cells, "cell_data", "segment")
    fdata = _check_field_data(field_data)
    pdata[_FIBRE_ID] = np.repeat(np.arange(len(lines), dtype=np.int32), counts)
    cdata[_FIBRE_ID] = fibre_of_segment.astype(np.int32)

    root = ET.Element(
        "VTKFile",
        {
            "type": "UnstructuredGrid",
            "version": "1.0",
            "byte_order": "LittleEndian",
            "header_type": _HEADER_TYPE,
        },
    )
    grid = ET.SubElement(root, "UnstructuredGrid")
    if fdata:
        fd = ET.SubElement(grid, "FieldData")
        for name, a in fdata.items():
            el = _data_array(fd, name, a, f"field_data[{name!r}]")
            el.set("NumberOfTuples", str(a.shape[0]))
    piece = ET.SubElement(
        grid, "Piece", {"NumberOfPoints": str(n_points), "NumberOfCells": str(n_cells)}
    )
    _data_array(ET.SubElement(piece, "Points"), "Points", points, "centrelines")

    cells = ET.SubElement(piece, "Cells")
    _data_array(cells, "connectivity", connectivity.ravel().astype(np.int64), "connectivity")
    _data_array(cells, "offsets", 2 * np.arange(1, n_cells + 1, dtype=np.int64), "offsets")
    _data_array(cells, "types", np.full(n_cells, VTK_LINE, dtype=np.uint8), "types")

    pd = ET.SubElement(piece, "PointData")
    for name, a in pdata.items():
        _data_array(pd, name, a, f"point_data[{name!r}]")
    cd = ET.SubElement(piece, "CellData")
    for name, a in cdata.items():
        _data_array(cd, name, a, f"cell_data[{name!r}]")

    ET.indent(root)
    atomic_write_bytes(path, ET.tostring(root, encoding="utf-8", xml_declaration=True))


class PVDSeries:
    """ParaView collection (``.pvd``) indexing a time series of ``.vtu`` files.

    The ``.pvd`` file is (re)written atomically on construction (empty
    collection) and after every :meth:`add`, so a crashed run still leaves a
    valid index of all steps written so far.

    Example::

        series = PVDSeries("out/fibres.pvd")
        for step, t in enumerate(times):
            vtu = f"out/fibres_{step:06d}.vtu"
            write_fibres_vtu(vtu, centrelines)
            series.add(t, vtu)
    """

    def __init__(self, path: str | os.PathLike):
        """Create (or overwrite) the collection file at ``path``.

        Args:
            path: Output ``.pvd`` file; its directory must exist.
        """
        self._path = Path(path)
        self._entries: list[tuple[float, str]] = []
        self._write()

    @property
    def path(self) -> Path:
        """Path of the ``.pvd`` file."""
        return self._path

    @property
    def entries(self) -> list[tuple[float, str]]:
        """Recorded ``(time, file)`` pairs in insertion order.

        ``file`` is relative to the ``.pvd``'s directory, with ``/`` separators.
        """
        return list(self._entries)

    def add(self, time: float, vtu_path: str | os.PathLike) -> None:
        """Record a data set at ``time`` and rewrite the ``.pvd`` file.

        Args:
            time: Simulation time (or load parameter) of the step; finite and
                not smaller than the previous entry's time.
            vtu_path: The step's ``.vtu`` file, absolute or relative to the
                current working directory. Stored relative to the ``.pvd``'s
                directory so the output folder can be moved as a whole.

        Raises:
            ValueError: If ``time`` is non-finite or decreases.
        """
        t = float(time)
        if not math.isfinite(t):
            raise ValueError(f"time must be finite; got {time!r}")
        if self._entries and t < self._entries[-1][0]:
            raise ValueError(
                f"time must be non-decreasing; got {t!r} after {self._entries[-1][0]!r}"
            )
        base = os.path.dirname(os.path.abspath(self._path))
        rel = Path(os.path.relpath(os.path.abspath(vtu_path), start=base)).as_posix()
        self._entries.append((t, rel))
        self._write()

    def _write(self) -> None:
        """Atomically rewrite the ``.pvd`` file from the recorded entries."""
        root = ET.Element(
            "VTKFile", {"type": "Collection", "version": "0.1", "byte_order": "LittleEndian"}
        )
        collection = ET.SubElement(root, "Collection")
        for t, rel in self._entries:
            # repr keeps the full float precision of the time value.
            ET.SubElement(
                collection, "DataSet", {"timestep": repr(t), "group": "", "part": "0", "file": rel}
            )
        ET.indent(root)
        atomic_write_bytes(self._path, ET.tostring(root, encoding="utf-8", xml_declaration=True))
