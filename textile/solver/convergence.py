"""Newton convergence measured per group of unknowns, each on its own scale.

The residual mixes quantities of different units: forces on the fibres'
positions (N), generalized forces on their section vectors (N times a
length), forces on a matrix field, and, on constrained rows, the gap to the
prescribed value (a length). One norm over all of them lets the largest
unit decide, and a fixed absolute tolerance cannot fit every mesh: the
round-off floor of assembled internal forces grows with the stiffness of the
discretization. So each *group* is tested on its own:

    |r_g| <= max(rtol F_g,  floor_g,  atol_g)

(the floor counts only once Newton has stopped moving: the last update
below ``floor_update`` times the size of the unknowns as the kernels see
them, |q|)

- ``F_g``: the group's force scale, the norm of the external generalized
  forces applied on it and of its support reactions (for the constrained
  rows, whose residual is a length: the size of the unknowns |q|). Not the
  step's first residual: a poor predictor (a large rotation extrapolated)
  makes that huge, and a very slender fibre would then be accepted far
  from equilibrium in bending;
- ``floor_g = floor_factor * eps * | (|K| |q|)_g |``: the round-off floor,
  eps times the size of the terms that make up the internal forces, with K
  the last assembled tangent and q the unknowns as the kernels see them
  (positions X + u for fibres): a residual at that level cannot be reduced
  further and the iterate is converged to machine precision (a backward
  error test);
- ``atol_g``: an absolute safety net, a tiny fraction of the group's force
  scale, used before any tangent exists.

Groups: ``positions`` and ``sections`` (the fibres' x0 and g1, g2 rows),
one per other field (e.g. ``matrix``), and ``constraints`` (prescribed
rows, residual u - u_prescribed, a length).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from mpi4py import MPI

#: Machine epsilon of the residual's floating point type.
EPS = float(np.finfo(float).eps)


@dataclass
class ResidualGroups:
    """Named groups of the owned rows of the global system.

    ``rows[name]`` are positions in this rank's owned part of a global
    vector; ``scale[name]`` is the group's force scale (for atol).
    """

    comm: MPI.Comm
    names: list[str]
    rows: dict[str, np.ndarray]
    scale: dict[str, float]
    #: positions, in this rank's list of constrained rows, of each group's
    #: reactions
    reactions: dict[str, np.ndarray]

    def __post_init__(self):
        # every group's rows one after another: one gather per norms() into
        # a kept buffer, then a dot product of each group's contiguous slice
        # (the same values in the same order as dot(owned[rows], owned[rows]))
        self._order = np.concatenate([np.asarray(self.rows[n], dtype=np.int64)
                                      for n in self.names]) if self.names \
            else np.zeros(0, np.int64)
        self._bounds = np.cumsum([0] + [len(self.rows[n]) for n in self.names]).tolist()
        self._gathered = np.empty(len(self._order))

    def _sum(self, local: np.ndarray) -> np.ndarray:
        """Sum over the ranks (none to add on one rank)."""
        return local if self.comm.size == 1 else self.comm.allreduce(local, op=MPI.SUM)

    def norms(self, owned: np.ndarray) -> np.ndarray:
        """2-norm of each group of the owned array (collective)."""
        g = np.take(owned, self._order, out=self._gathered, mode="clip")  # valid rows: unbuffered
        b = self._bounds
        local = np.array([float(np.dot(g[b[i]:b[i + 1]], g[b[i]:b[i + 1]]))
                          for i in range(len(self.names))])
        return np.sqrt(self._sum(local))

    def reaction_norms(self, reactions: np.ndarray) -> np.ndarray:
        """2-norm of each group's support reactions (collective)."""
        local = np.array([float(np.sum(reactions[self.reactions[n]] ** 2)) for n in self.names])
        return np.sqrt(self._sum(local))

    def as_dict(self, values: np.ndarray) -> dict[str, float]:
        return {n: float(v) for n, v in zip(self.names, values)}


@dataclass
class GroupTolerances:
    """The per-group test's tolerances (see the module docstring)."""

    rtol: float = 1e-10
    atol: float = 1e-13
    floor_factor: float = 10.0
    floor_update: float = 1e-8
    #: the current solve's SolverOptions.path_rtol and its step's groups'
    #: first residuals (begin_solve)
    path_rtol: float = 0.0
    start: np.ndarray | None = None

    def begin_solve(self, path_rtol: float, same_step: bool = False) -> None:
        """A Newton solve begins: its path tolerance (SolverOptions.path_rtol,
        0: none). The residuals the path tolerance is relative to are the
        first converged() sees in the step: ``same_step``, a solve after a
        contact update within the step, keeps them (relative to each solve's
        own start, the passes of a step would each have to fall by
        path_rtol again, a target that recedes pass after pass)."""
        self.path_rtol = path_rtol
        if not same_step:
            self.start = None

    def converged(self, norms: np.ndarray, reference: np.ndarray, floors, scales: np.ndarray,
                  settled: bool = True, on_path: bool = False) -> np.ndarray:
        """Per group: is the residual below its threshold? ``floors``: a
        callable giving the groups' |(|K||q|)_g| (or None), called only when
        the other tests leave a group unconverged. ``settled``: the last
        Newton update was negligible; only then does the round-off floor
        count (a residual can dip to the floor of the stiff axial forces in
        the middle of an oscillating Newton sequence while a compliant mode,
        e.g. the bending of a very slender fibre, is still far off).
        ``on_path`` (a step before its stage's end): a group whose residual
        fell below path_rtol times its first in the step has converged
        too (SolverOptions.path_rtol)."""
        if self.start is None:
            self.start = np.array(norms, dtype=float)
        limit = np.maximum(self.rtol * reference, self.atol * scales)
        if on_path and self.path_rtol > 0:
            limit = np.maximum(limit, self.path_rtol * self.start)
        ok = norms <= limit
        if not np.all(ok) and settled and floors is not None:
            f = floors()
            if f is not None:
                ok = norms <= np.maximum(limit, self.floor_factor * EPS * f)
        return ok


#: A Newton solve whose residual norm repeats itself with a period of 1 to
#: CYCLE_PERIOD iterations (each of the last max(CYCLE_ITERATIONS, 2 period)
#: values within CYCLE_TOLERANCE of the one a period before) is cycling
#: (stick-slip or contact switches flipping in turn) or stuck: it would not
#: converge within max_it, so the attempt fails at once and the step is cut.
#: A residual falling by 5% a period needs 45 periods per decade: none of
#: that converges anyway.
CYCLE_ITERATIONS, CYCLE_PERIOD, CYCLE_TOLERANCE = 6, 4, 0.05


def cycling(norms: list[float]) -> bool:
    """Does this Newton residual history (norm per iteration) cycle? An
    infinite value repeats only as an infinite value (inf - x would pass
    any relative tolerance): the contact loop's changes, where inf is a new
    contact or a retuned penalty, cycle through inf, 5, inf, 5 with period
    2, not 1."""
    for period in range(1, CYCLE_PERIOD + 1):
        n = max(CYCLE_ITERATIONS, 2 * period)
        if len(norms) < n + period + 2:  # the first two iterations never count
            continue
        h = norms[-n - period:]
        if all(a == b or (math.isfinite(a) and math.isfinite(b)
                          and abs(a - b) <= CYCLE_TOLERANCE * max(a, b))
               for a, b in zip(h[period:], h[:-period])):
            return True
    return False


#: A Newton solve whose last STALL_ITERATIONS iterates have not gone below
#: the lowest of the STALL_ITERATIONS before them has stalled: an iterate
#: wandering among contact sets, or a cycle longer than CYCLE_PERIOD, and
#: its attempt fails at once, not at max_it (the 6 x 6 sample of 28-fibre
#: bundles: a solve wandered between 0.28 and 470, its first residual 1.7,
#: for 50 iterations and 15 matrix rebuilds, where half the step converges
#: in 5; past a bar's limit load, 20 iterations). The solve's first
#: residual (the predictor's, a perturbation's) is not an iterate and does
#: not count; a residual that jumps and then falls steadily, however
#: slowly, never stalls (the first
#: iterate of a rotation 100 times too large is 1e8 times the start, a
#: column pushed off its unstable branch jumps 1e7-fold before it settles
#: on the buckled one). Twice the longest period the cycle test looks for:
#: the cycle test, which needs 8-10 iterations, names a cycle first
#: (benchmarks/README.md, "Newton solves that stall").
STALL_ITERATIONS = 2 * CYCLE_PERIOD
STALL_MESSAGE = (f"its last {STALL_ITERATIONS} residuals have not gone below the "
                 f"{STALL_ITERATIONS} before them")


def stalled(norms: list[float]) -> bool:
    """Has this Newton solve stalled? ``norms``: its residual norm at each
    iteration, the first (before any Newton update) excluded."""
    n = STALL_ITERATIONS
    return len(norms) >= 2 * n and min(norms[-n:]) >= min(norms[-2 * n:-n])


def capped_passes_stalled(changes: list[float]) -> bool:
    """Do capped Newton solves (SolverOptions.newton_per_pass) no longer
    bring the effects closer to settling? ``changes``: the effects' change
    after each capped solve of the attempt so far, in units of their
    tolerance. Yes once the last, finite, is not CYCLE_TOLERANCE below the
    one before (the cycle test's period 1 over two passes): the solves run
    to convergence from there, whose changes effects_unsettled judges (the
    6 x 6 shear of 7-fibre bundles: capped passes that stood, 2.34, 2.31,
    then full solves at 2.33, 2.4, 2.45 failed the attempt after 16 Newton
    iterations, where 10 capped passes and 9 full solves took 60-75;
    capped passes that fall 10-45% a pass go on; benchmarks/README.md, "A
    contact loop judged by its trend")."""
    last = changes[-2:]
    return len(last) == 2 and bool(np.all(np.isfinite(last))) \
        and last[1] >= (1 - CYCLE_TOLERANCE) * last[0]


#: changes of the effects after successive Newton solves run to convergence
#: that the contact loop judges by their trend (effects_unsettled): two
#: ratios, the fewest that show a rate; a trend that cannot reach 1 in the
#: solves left fails the attempt there instead of after the cycle test's
#: 9 solves (the 6 x 6 shear of 7-fibre bundles: 22 attempts failed after
#: 10 capped + 9 full solves, 60-75 Newton iterations each, whose changes
#: stood or fell 1-4% a solve from 1.1-6: benchmarks/README.md, "A
#: contact loop judged by its trend")
TREND_SOLVES = 3


def effects_unsettled(changes: list[float], solves_left: int) -> str:
    """Why the effects' changes after successive Newton solves run to
    convergence within one load step (ContactLoop: contact elements,
    normals, penalties, in units of their tolerance: settled at 1) will not
    settle, or "" while they may: the step fails at once instead of after
    max_updates solves.

    - The trend of the last TREND_SOLVES changes, all finite (a new contact
      or a retuned penalty, inf, has none): at their mean rate a solve,
      (last / first) ** (1 / (TREND_SOLVES - 1)), the last does not reach
      1 within the ``solves_left`` solves the attempt has left: "not
      falling" at a rate within the cycle test's CYCLE_TOLERANCE above 1
      (a period-1 cycle, told after TREND_SOLVES solves instead of the
      cycle test's 9); a steady fall, however slow, goes on while its rate
      brings it to 1 in time (the 6 x 6 shear of 7-fibre bundles once went
      1.13, 1.1, 1.07, 1.04, 1.01 and settled one solve later;
      benchmarks/README.md, "The bundle shear's contact loop"). Changes
      that rise faster are a transient, not judged by their trend: a rod
      pushed through a cantilever in one step, its contact held and its
      zone stiffened, went 51, 111, 180, 315, then 8.2, 5.4 and settled
      (tests/contact/test_tunnelling.py).
    - Changes that repeat with a period of 1 to CYCLE_PERIOD solves (the
      Newton cycle test on them: states that repeat give changes that
      repeat; a swing between two contact sets whose trend over the last
      few solves looks like a fall), unless their last CYCLE_ITERATIONS + 1
      fall steadily at a rate that brings them to 1 in time.
    """
    tail = changes[-TREND_SOLVES:]
    if len(tail) == TREND_SOLVES and all(np.isfinite(tail)) and tail[-1] > 1.0:
        rate = (tail[-1] / tail[0]) ** (1.0 / (TREND_SOLVES - 1)) if tail[0] > 0 else np.inf
        if 1.0 <= rate <= 1.0 + CYCLE_TOLERANCE:
            return "not falling"
        if rate < 1.0 and tail[-1] * rate ** solves_left > 1.0:
            return _too_slow(rate, solves_left)
    if not cycling(changes):
        return ""
    tail = changes[-(CYCLE_ITERATIONS + 1):]
    if all(b < a for a, b in zip(tail, tail[1:])):
        rate = (tail[-1] / tail[0]) ** (1.0 / (len(tail) - 1))
        if tail[-1] * rate ** solves_left <= 1.0:
            return ""
        return _too_slow(rate, solves_left)
    return "cycling"


def _too_slow(rate: float, solves_left: int) -> str:
    return (f"falling by {100 * (1 - rate):.2g}% a Newton solve, too slowly to settle in "
            f"the {solves_left} solves left,")
