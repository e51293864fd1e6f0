"""Per-step result logging to JSON (and CSV export).

A :class:`ResultsLog` holds run metadata and one record (a dict) per load or
time step, and mirrors them to a JSON file of the form::

    {"meta": {...}, "steps": [{...}, {...}, ...]}

The file is rewritten atomically after every change, so it is always valid
JSON containing every step completed so far, even if the run crashes.

Values are converted to plain Python (numpy scalars and arrays included).
Non-finite floats (NaN, inf) are rejected with a :class:`ValueError` naming
the key: a NaN in a result means something went wrong, and must never end up
in the log silently.

This class is serial: use it on one MPI rank with gathered data.
"""

from __future__ import annotations

import copy
import csv
import io
import json
import math
import numbers
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from textile.io.vtu import atomic_write_bytes

__all__ = ["ResultsLog"]

# Plain JSON value types written to the CSV export as single cells.
_SCALAR_TYPES = (bool, int, float, str, type(None))


def _plain_array(value: np.ndarray, key: str) -> Any:
    """Convert a numpy array to nested lists, rejecting non-finite entries."""
    kind = value.dtype.kind
    if kind == "f":
        if not np.all(np.isfinite(value)):
            bad = tuple(int(i) for i in np.argwhere(~np.isfinite(value))[0])
            raise ValueError(f"results key {key!r} contains a non-finite value at index {bad}")
        return value.tolist()
    if kind in "biuU":
        return value.tolist()
    if kind == "O":
        return [_to_plain(v, f"{key}[{i}]") for i, v in enumerate(value)]
    raise TypeError(f"results key {key!r} has unsupported array dtype {value.dtype}")


def _to_plain(value: Any, key: str) -> Any:
    """Recursively convert ``value`` to JSON-compatible plain Python.

    Args:
        value: Scalar, string, None, numpy scalar/array, list, tuple or dict.
        key: Dotted/indexed key path of ``value``, used in error messages.

    Raises:
        ValueError: If a float is NaN or infinite.
        TypeError: If a value (or dict key) has an unsupported type.
    """
    if value is None or isinstance(value, str):
        return value
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        x = float(value)
        if not math.isfinite(x):
            raise ValueError(f"results key {key!r} is non-finite ({x}); refusing to log it")
        return x
    if isinstance(value, np.ndarray):
        if value.ndim == 0:
            return _to_plain(value.item(), key)
        return _plain_array(value, key)
    if isinstance(value, (list, tuple)):
        return [_to_plain(v, f"{key}[{i}]") for i, v in enumerate(value)]
    if isinstance(value, Mapping):
        return _plain_dict(value, key)
    raise TypeError(f"results key {key!r} has unsupported type {type(value).__name__}")


def _plain_dict(record: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Convert a mapping with string keys to plain Python, key by key."""
    out = {}
    for k, v in record.items():
        if not isinstance(k, str):
            raise TypeError(f"results keys must be strings; got {k!r} in {prefix or 'record'}")
        out[k] = _to_plain(v, f"{prefix}.{k}" if prefix else k)
    return out


class ResultsLog:
    """Run metadata plus one record per step, mirrored to a JSON file.

    Example::

        log = ResultsLog("out/results.json")
        log.set_meta(case="cantilever", n_fibres=4)
        for step in ...:
            log.append({"step": step, "load": lam, "tip_displacement": u_tip})
        log.write_csv("out/results.csv")
    """

    def __init__(self, path: str | os.PathLike):
        """Create (or overwrite) the log file at ``path`` with no steps.

        Args:
            path: Output JSON file; its directory must exist.
        """
        self._path = Path(path)
        self._meta: dict[str, Any] = {}
        self._steps: list[dict[str, Any]] = []
        self._write()

    @property
    def path(self) -> Path:
        """Path of the JSON file."""
        return self._path

    @property
    def meta(self) -> dict[str, Any]:
        """Copy of the run metadata."""
        return copy.deepcopy(self._meta)

    @property
    def records(self) -> list[dict[str, Any]]:
        """Copy of the step records (plain Python), in append order."""
        return copy.deepcopy(self._steps)

    def set_meta(self, **kw: Any) -> None:
        """Add or update metadata entries and rewrite the file.

        Raises:
            ValueError: If a value is non-finite (the key is named).
            TypeError: If a value has an unsupported type.
        """
        # Convert everything before touching state so bad input changes nothing.
        self._meta.update(_plain_dict(kw, "meta"))
        self._write()

    def append(self, record: Mapping[str, Any]) -> None:
        """Append one step record and rewrite the file.

        Args:
            record: Key -> value; values may be numbers, strings, None,
                numpy scalars/arrays, and (nested) lists, tuples and dicts.

        Raises:
            ValueError: If any float in ``record`` is NaN or infinite; the
                message names the key (e.g. ``'reaction[2]'``). Nothing is
                appended in that case.
            TypeError: If ``record`` is not a mapping or holds an
                unsupported type.
        """
        if not isinstance(record, Mapping):
            raise TypeError(f"record must be a dict; got {type(record).__name__}")
        self._steps.append(_plain_dict(record))
        self._write()

    def column(self, name: str) -> list[Any]:
        """Values of key ``name`` over all steps (None where a step lacks it).

        Raises:
            KeyError: If no step has the key (most likely a typo).
        """
        if not any(name in s for s in self._steps):
            raise KeyError(f"no step record has key {name!r}")
        return [copy.deepcopy(s.get(name)) for s in self._steps]

    def scalar_columns(self) -> list[str]:
        """Keys whose values are scalars in every step that has them.

        Ordered by first appearance; keys holding lists or dicts are omitted.
        """
        names: dict[str, bool] = {}
        for s in self._steps:
            for k, v in s.items():
                names[k] = names.get(k, True) and isinstance(v, _SCALAR_TYPES)
        return [k for k, is_scalar in names.items() if is_scalar]

    def write_csv(self, path: str | os.PathLike) -> None:
        """Write the scalar columns of the steps to a CSV file (atomically).

        One header row with the names from :meth:`scalar_columns`, then one
        row per step; missing values are left empty. Floats are written with
        full (round-trip) precision.

        Args:
            path: Output CSV file; its directory must exist.
        """
        columns = self.scalar_columns()
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        writer.writerow(columns)
        for s in self._steps:
            writer.writerow(["" if s.get(c) is None else s[c] for c in columns])
        atomic_write_bytes(path, buf.getvalue().encode("utf-8"))

    def _write(self) -> None:
        """Atomically rewrite the JSON file from the in-memory state."""
        # allow_nan=False: last line of defence against writing NaN.
        text = json.dumps({"meta": self._meta, "steps": self._steps}, indent=2, allow_nan=False)
        atomic_write_bytes(self._path, (text + "\n").encode("utf-8"))
