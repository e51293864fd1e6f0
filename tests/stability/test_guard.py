"""Controls for the Newton-count guard (guard.newton_count): it fires on a
deliberately slowed case, both on the total and on the largest step.

The case is test_extremes.py's slender cantilever (L/R = 1e4, steps of a
quarter of the load), whose committed counts are in newton_counts.json.
Slowed twice:

- standard Newton without predictor instead of MIP Newton with one, same
  steps: more iterations in every step, so the total grows;
- the whole load in one step with standard Newton: that one step takes 20
  iterations against 4 committed for the largest step. Its total (20
  against 13 committed) exceeds the guard too, so the largest step is
  checked on its own, beside the committed total: a guard of the total
  alone would pass a run with the committed total and such a step.
"""
import pytest

from . import guard
from .test_extremes import cantilever

CASE = "slenderness_1e4"


def slender(options, out):
    return cantilever(1.0, 1e4, 0.3, 64, options, out)[2]


def test_the_committed_case_passes(out):
    """The case itself, as test_extremes runs it, passes the guard (the
    controls below fail for what they changed, not for the set-up)."""
    solver = slender(dict(initial_step=0.25, max_step=0.25), out)
    guard.newton_count(CASE, solver, record=False)


def test_guard_fires_on_a_slower_newton(out):
    solver = slender(dict(initial_step=0.25, max_step=0.25, newton="standard",
                          predictor="none"), out)
    counts = guard.counts_of(solver)
    committed = guard.json.loads(guard.COUNTS.read_text())[CASE]
    assert counts["total"] > guard.GROWTH * committed["total"]
    with pytest.raises(AssertionError, match=f"{CASE}: total"):
        guard.newton_count(CASE, solver, record=False)


def test_guard_fires_on_a_slower_step(out):
    solver = slender(dict(initial_step=1.0, max_step=1.0, newton="standard"), out)
    counts = guard.counts_of(solver)
    committed = guard.json.loads(guard.COUNTS.read_text())
    assert counts["largest step"] > guard.GROWTH * committed[CASE]["largest step"]
    # with the committed total, the guard fires on the largest step alone
    with pytest.raises(AssertionError, match=f"{CASE}: largest step"):
        guard.check_counts(CASE, dict(counts, total=committed[CASE]["total"]), committed)


def test_nothing_to_guard_is_refused():
    """A run without a Newton iteration cannot be guarded (a count of 0
    cannot grow by 50%)."""
    class Idle:
        counters = {"newton_iterations": 0}
        history = []
    with pytest.raises(AssertionError, match="nothing to guard"):
        guard.newton_count("idle", Idle(), record=False)
