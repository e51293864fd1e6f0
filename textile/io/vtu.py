"""VTK XML output of fibre centre lines for ParaView, written by meshio.

Each fibre is written as a polyline made of VTK_LINE cells (one cell per
segment between consecutive centre-line points) in a VTK XML
UnstructuredGrid (``.vtu``) file, by ``meshio.write`` (inline base64
binary, uncompressed, ``UInt64`` block-size headers). This module checks
the data (shapes, finite values, VTK types) and builds the cells; time
series are indexed by :mod:`textile.io.pvd`.

All writers replace their target atomically (temporary file in the same
directory, then :func:`os.replace`), so an interrupted run never leaves a
half-written file behind.

These functions are serial: call them on one MPI rank with gathered data.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import numpy.typing as npt

__all__ = [
    "VTK_LINE",
    "atomic_replace",
    "atomic_write_bytes",
    "check_centrelines",
    "write_fibres_vtu",
]

#: VTK cell type id of a 2-node line segment.
VTK_LINE = 3

# Block-size header written in front of every binary array. UInt64 so that
# arrays larger than 4 GiB remain representable.
_HEADER_TYPE = "UInt64"

# Name of the array added to both point and cell data.
_FIBRE_ID = "fibre_id"


def atomic_replace(path: str | os.PathLike, write) -> None:
    """Create ``path`` atomically: ``write(tmp)`` writes the contents to a
    temporary file in the destination directory (same file system, so
    :func:`os.replace` is atomic), which is flushed to disk and renamed over
    ``path``. Readers see either the old or the new complete file, never a
    partial one; a failure leaves no temporary file behind.

    Args:
        path: Destination file. Its directory must exist.
        write: Callable taking the temporary file's path.
    """
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        os.close(fd)
        write(tmp)
        with open(tmp, "rb+") as f:
            os.fsync(f.fileno())
        os.chmod(tmp, 0o644)        # mkstemp's 0600 would hide results from others
        os.replace(tmp, path)
    except BaseException:
        # Never leave the temporary file behind, whatever interrupted us.
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (see :func:`atomic_replace`)."""
    def write(tmp):
        with open(tmp, "wb") as f:
            f.write(data)
    atomic_replace(path, write)


def check_centrelines(
    centrelines: Sequence[npt.ArrayLike], name: str = "centrelines"
) -> list[np.ndarray]:
    """Validate fibre centre lines and return them as float64 arrays.

    Args:
        centrelines: One array of shape ``(n_i, 3)`` per fibre, ``n_i >= 2``,
            holding point coordinates (model length units); or one array of
            shape ``(n_fibres, n, 3)`` when every fibre has n points (checked
            at once: contact segments, thousands a step).
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
    if isinstance(centrelines, np.ndarray) and centrelines.ndim == 3:
        x = np.ascontiguousarray(centrelines, dtype=np.float64)
        if x.shape[2] != 3 or x.shape[1] < 2:
            raise ValueError(f"{name} as one array must have shape (n_fibres, n >= 2, 3); "
                             f"got {x.shape}")
        finite = np.isfinite(x).all(axis=2)
        if not finite.all():
            i, bad = (int(v) for v in np.argwhere(~finite)[0])
            raise ValueError(f"{name}[{i}] has non-finite (NaN/inf) coordinates at point {bad}")
        centrelines = list(x)
        if not centrelines:
            raise ValueError(f"{name} must contain at least one fibre")
        return centrelines
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


def _vtk_array(array: npt.ArrayLike, label: str) -> np.ndarray:
    """Convert an array to a little-endian VTK-supported dtype.

    Floats become Float64; booleans and uint8 UInt8; other integers up to
    32 bits (uint32 excluded) Int32; remaining integers Int64.
    """
    a = np.asarray(array)
    kind = a.dtype.kind
    if kind == "f":
        if not np.all(np.isfinite(a)):
            raise ValueError(f"{label} contains non-finite (NaN/inf) values")
        return a.astype("<f8")
    if kind == "b" or a.dtype == np.uint8:
        return a.astype("u1")
    if kind in "iu":
        if a.dtype.itemsize <= 4 and not (kind == "u" and a.dtype.itemsize == 4):
            return a.astype("<i4")
        if kind == "u" and a.size and int(a.max()) > np.iinfo(np.int64).max:
            raise ValueError(f"{label} has unsigned values too large for Int64")
        return a.astype("<i8")
    raise ValueError(f"{label} has unsupported dtype {a.dtype}; expected float, int or bool")


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


def _connectivity(counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Segment connectivity for polylines with ``counts[i]`` points each.

    Returns:
        ``(lines, fibre_of_segment)``: ``(n_segments, 2)`` global point
        indices and the fibre index of each segment.
    """
    # every point starts a segment but each polyline's last
    fibre = np.repeat(np.arange(len(counts)), counts - 1)
    starts = np.arange(int(np.sum(counts)))
    last = np.cumsum(counts) - 1
    starts = np.delete(starts, last)
    lines = np.column_stack((starts, starts + 1))
    return lines, fibre


def write_fibres_vtu(
    path: str | os.PathLike,
    centrelines: Sequence[npt.ArrayLike],
    point_data: Mapping[str, npt.ArrayLike] | None = None,
    cell_data: Mapping[str, npt.ArrayLike] | None = None,
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

    Raises:
        ValueError: On bad shapes, non-finite values, unsupported dtypes,
            or a user array named ``"fibre_id"``; the message names the
            offending argument and key.
    """
    import meshio

    lines = check_centrelines(centrelines, "centrelines")
    if isinstance(centrelines, np.ndarray):  # (n_fibres, n, 3), checked: no copy per line
        counts = np.full(len(lines), centrelines.shape[1])
        points = np.ascontiguousarray(centrelines, dtype=np.float64).reshape(-1, 3)
    else:
        counts = np.array([x.shape[0] for x in lines])
        points = np.concatenate(lines)
    connectivity, fibre_of_segment = _connectivity(counts)

    def typed(fields, arg):
        return {name: _vtk_array(a, f"{arg}[{name!r}]") for name, a in fields.items()}

    pdata = typed(_check_fields(point_data, points.shape[0], "point_data", "point"),
                  "point_data")
    cdata = typed(_check_fields(cell_data, connectivity.shape[0], "cell_data", "segment"),
                  "cell_data")
    pdata[_FIBRE_ID] = np.repeat(np.arange(len(lines), dtype=np.int32), counts)
    cdata[_FIBRE_ID] = fibre_of_segment.astype(np.int32)

    mesh = meshio.Mesh(points, [("line", connectivity.astype(np.int64))], point_data=pdata,
                       cell_data={name: [a] for name, a in cdata.items()})
    atomic_replace(path, lambda tmp: meshio.write(tmp, mesh, file_format="vtu", binary=True,
                                                  compression=None, header_type=_HEADER_TYPE))
