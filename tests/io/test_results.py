"""Tests for textile.io.results: JSON step log and CSV export."""

import csv
import json

import numpy as np
import pytest

from textile.io.results import ResultsLog


def test_json_roundtrip(tmp_path):
    path = tmp_path / "results.json"
    log = ResultsLog(path)
    log.set_meta(case="cantilever", n_fibres=np.int64(4), E=np.float32(2.5))
    log.append({"step": 0, "load": np.float64(0.5), "u_tip": np.array([0.0, -1e-3, 2.0])})
    log.append({"step": np.int32(1), "load": 1.0, "converged": np.bool_(True), "extra": {"it": 3}})

    with open(path) as f:
        data = json.load(f)
    # metadata is stored with numpy scalars converted to plain numbers
    assert data["meta"] == {"case": "cantilever", "n_fibres": 4, "E": 2.5}
    # steps are stored in order, arrays as lists, nested dicts preserved
    assert data["steps"] == [
        {"step": 0, "load": 0.5, "u_tip": [0.0, -1e-3, 2.0]},
        {"step": 1, "load": 1.0, "converged": True, "extra": {"it": 3}},
    ]
    # the records property matches the file contents
    assert log.records == data["steps"]
    # converted values are plain Python types, not numpy ones
    assert type(log.records[1]["step"]) is int and type(log.records[0]["load"]) is float


def test_file_valid_after_each_append(tmp_path):
    path = tmp_path / "results.json"
    log = ResultsLog(path)
    # the file exists and is valid from construction on
    assert json.loads(path.read_text()) == {"meta": {}, "steps": []}
    for k in range(3):
        log.append({"step": k})
        # a crash after step k leaves a file with exactly k+1 steps
        assert len(json.loads(path.read_text())["steps"]) == k + 1


@pytest.mark.parametrize(
    "record, key",
    [
        ({"step": 1, "residual": float("nan")}, "residual"),
        ({"step": 1, "energy": np.float64(np.inf)}, "energy"),
        ({"step": 1, "reaction": np.array([1.0, np.nan, 2.0])}, "reaction"),
        ({"step": 1, "history": [1.0, [2.0, -np.inf]]}, r"history\[1\]\[1\]"),
        ({"step": 1, "solver": {"res": np.nan}}, r"solver\.res"),
    ],
)
def test_nonfinite_rejected(tmp_path, record, key):
    path = tmp_path / "results.json"
    log = ResultsLog(path)
    log.append({"step": 0, "residual": 1e-9})
    before = path.read_text()
    # NaN/inf must never be written silently; the message names the key
    with pytest.raises(ValueError, match=key):
        log.append(record)
    # the rejected record is neither kept in memory nor written
    assert len(log.records) == 1 and path.read_text() == before


def test_meta_nonfinite_rejected(tmp_path):
    log = ResultsLog(tmp_path / "r.json")
    # metadata is validated like step records
    with pytest.raises(ValueError, match="tolerance"):
        log.set_meta(tolerance=float("nan"))
    # rejected metadata leaves the existing metadata unchanged
    assert log.meta == {}


def test_unsupported_types(tmp_path):
    log = ResultsLog(tmp_path / "r.json")
    # objects without a JSON representation are refused, naming the key
    with pytest.raises(TypeError, match="obj"):
        log.append({"obj": object()})
    # a record must be a mapping
    with pytest.raises(TypeError, match="record must be a dict"):
        log.append([("a", 1)])
    # JSON object keys must be strings
    with pytest.raises(TypeError, match="keys must be strings"):
        log.append({1: 2.0})


def test_records_and_column(tmp_path):
    log = ResultsLog(tmp_path / "r.json")
    log.append({"step": 0, "load": 0.0})
    log.append({"step": 1, "load": 0.5, "u": 1.0})
    # column collects a key over all steps, None where it is missing
    assert log.column("u") == [None, 1.0]
    # a key that no step has is most likely a typo
    with pytest.raises(KeyError, match="lod"):
        log.column("lod")
    log.records[0]["load"] = 99.0
    # records returns a copy, so callers cannot corrupt the log
    assert log.column("load") == [0.0, 0.5]


def test_write_csv(tmp_path):
    log = ResultsLog(tmp_path / "r.json")
    log.append({"step": 0, "load": 0.1, "u_tip": [0.0, 1.0, 2.0], "status": "ok"})
    log.append({"step": 1, "load": 1 / 3, "u_tip": [1.0, 1.0, 2.0], "energy": 2.5})
    csv_path = tmp_path / "r.csv"
    log.write_csv(csv_path)

    with open(csv_path, newline="") as f:
        rows = list(csv.DictReader(f))
    # only scalar columns are written, in order of first appearance
    assert list(rows[0].keys()) == ["step", "load", "status", "energy"]
    # one row per step
    assert len(rows) == 2
    # floats are written with full round-trip precision
    assert [float(r["load"]) for r in rows] == [0.1, 1 / 3]
    # missing values become empty cells
    assert rows[0]["energy"] == "" and rows[1]["status"] == ""
