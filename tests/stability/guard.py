"""What every case of the stability suite checks, besides its own physics.

- **Newton counts.** Each case's total Newton iterations (failed attempts
  included) and the largest count of any one converged step are compared
  with the counts committed in ``newton_counts.json``; the case fails when
  either grows by more than 50%, as 4C's input-file tests guard their
  Newton counts. The largest step matters on its own: a case may take
  fewer, larger steps and keep its total while each step gets slower
  (tests/stability/test_guard.py shows both checks firing). Record new
  counts with ``TEXTILE_RECORD_NEWTON=1 pytest tests/stability
  tests/virtual`` after a solver change and commit the file.
- **Clean output.** results.json parses, holds one record per converged
  step, finite numbers only; one VTU per converged step; after a failure the
  message is in results.json and the last converged state is on disk.
"""
from __future__ import annotations

import json
import math
import os
from pathlib import Path

COUNTS = Path(__file__).with_name("newton_counts.json")
GROWTH = 1.5  # allowed growth of a Newton count before the guard fails


def counts_of(run) -> dict:
    """The guarded counts of a run: a :class:`textile.Solver` (its history
    and counters) or a virtual test's result (its loading steps and
    counters)."""
    steps = run.history if hasattr(run, "history") else run.steps
    per_step = [s.newton_iterations if hasattr(s, "newton_iterations")
                else s["newton_iterations"] for s in steps]
    return {"total": int(run.counters["newton_iterations"]),
            "largest step": int(max(per_step, default=0))}


def check_counts(name: str, counts: dict, committed: dict) -> None:
    """AssertionError naming what grew beyond GROWTH times its committed value."""
    assert name in committed, (f"no committed Newton count for {name!r}: run "
                               f"TEXTILE_RECORD_NEWTON=1 pytest tests/stability tests/virtual "
                               f"and commit {COUNTS.name}")
    for key, value in counts.items():
        assert value <= GROWTH * committed[name][key], (
            f"{name}: {key} {value} Newton iterations, {committed[name][key]} committed "
            f"(> +{GROWTH - 1:.0%})")


def newton_count(name: str, run, record: bool | None = None) -> dict:
    """Check (or, with TEXTILE_RECORD_NEWTON set, record) the Newton counts
    of case ``name`` (:func:`counts_of`). ``record=False`` checks even then
    (the guard's own control cases)."""
    counts = counts_of(run)
    assert counts["total"] > 0, f"{name}: no Newton iteration, nothing to guard"
    committed = json.loads(COUNTS.read_text()) if COUNTS.exists() else {}
    if record is None:
        record = bool(os.environ.get("TEXTILE_RECORD_NEWTON"))
    if record:
        committed[name] = counts
        COUNTS.write_text(json.dumps(dict(sorted(committed.items())), indent=1) + "\n")
        return counts
    check_counts(name, counts, committed)
    return counts


def _finite(value) -> bool:
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, dict):
        return all(_finite(v) for v in value.values())
    if isinstance(value, list):
        return all(_finite(v) for v in value)
    return True


def clean_output(directory, solver, failed: str | None = None) -> dict:
    """results.json and VTUs consistent with the solver's history."""
    d = Path(directory)
    data = json.loads((d / "results.json").read_text())
    assert len(data["steps"]) == len(solver.history)
    assert all(_finite(s) for s in data["steps"])
    assert len(list(d.glob("fibres_*.vtu"))) == len(solver.history)
    if failed is not None:
        assert failed in data["meta"]["failure"]
    return data
