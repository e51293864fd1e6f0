"""What every case of the stability suite checks, besides its own physics.

- **Newton counts.** Each case's total Newton iterations (failed attempts
  included) is compared with the count committed in ``newton_counts.json``;
  the case fails when it grows by more than 50%, as 4C's input-file tests
  guard their Newton counts. Record new counts with
  ``TEXTILE_RECORD_NEWTON=1 pytest tests/stability`` and commit the file.
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


def newton_count(name: str, solver) -> int:
    """Check (or record) the total Newton iterations of case ``name``."""
    count = int(solver.counters["newton_iterations"])
    counts = json.loads(COUNTS.read_text()) if COUNTS.exists() else {}
    if os.environ.get("TEXTILE_RECORD_NEWTON"):
        counts[name] = count
        COUNTS.write_text(json.dumps(dict(sorted(counts.items())), indent=1) + "\n")
        return count
    assert name in counts, (f"no committed Newton count for {name!r}: run "
                            f"TEXTILE_RECORD_NEWTON=1 pytest tests/stability and commit "
                            f"{COUNTS.name}")
    assert count <= GROWTH * counts[name], (f"{name}: {count} Newton iterations, "
                                            f"{counts[name]} committed (> +50%)")
    return count


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
