"""Factorization reuse and block low-rank: what they save, and what they cost.

The 61-fibre compressed bundle of ``contact_costs.py`` (friction 0.2,
adaptive penalty, the solver's defaults otherwise) solved with

- the default: a fresh MUMPS factorization every Newton iteration;
- ``reuse_factorization = 2, 3``: the exact tangent is still assembled, the
  factorization is refreshed every n-th iteration and used in between as
  the preconditioner of GMRES on the exact tangent;
- ``low_rank_tolerance = 1e-8``: MUMPS block low-rank factorization, GMRES
  on the exact tangent;

counting every Newton iteration, factorization and Krylov iteration (failed
attempts included), the wall time, and the largest difference of the
converged positions from the default's (the answer must not change beyond
the solver tolerances). Writes ``output/factorization_reuse.json``.

    .venv/bin/python benchmarks/factorization_reuse.py
"""
from __future__ import annotations

import json
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from contact_costs import R, bundle_run  # noqa: E402

from textile import PETSc, runtime  # noqa: E402

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "output")

VARIANTS = [
    ("fresh LU every iteration (default)", {}),
    ("reuse 2", dict(reuse_factorization=2)),
    ("reuse 3", dict(reuse_factorization=3)),
    ("block low-rank 1e-8", dict(low_rank_tolerance=1e-8)),
    ("reuse 3 + block low-rank", dict(reuse_factorization=3, low_rank_tolerance=1e-8)),
]


def gmres_orthogonalizations() -> int:
    """One per GMRES iteration (a fresh LU is applied without GMRES)."""
    return int(PETSc.Log.Event("KSPGMRESOrthog").getPerfInfo()["count"])


def main():
    PETSc.Log.begin()
    print(runtime.describe())
    rows = []
    reference = None
    for name, options in VARIANTS:
        k0 = gmres_orthogonalizations()
        b = bundle_run(4, 8, True, options)
        q = b.pop("positions")
        krylov = gmres_orthogonalizations() - k0
        if reference is None:
            reference = q
        diff = float(np.abs(q - reference).max())
        rows.append(dict(variant=name, options=options, newton_iterations=b["newton_iterations"],
                         newton_solves=b["newton_solves"],
                         failed_newton_solves=b["failed_newton_solves"],
                         factorizations=b["factorizations"], gmres_orthogonalizations=krylov,
                         factorization_seconds=b["factorization_seconds"],
                         total_seconds=b["total_seconds"],
                         max_position_difference_over_radius=diff / R))
        r = rows[-1]
        print(f"{name:<36} {r['newton_iterations']:3d} its ({r['failed_newton_solves']} failed "
              f"solves), {r['factorizations']:3d} factorizations "
              f"({r['factorization_seconds']:.2f} s), {krylov:4d} GMRES orthogonalizations, "
              f"{r['total_seconds']:6.2f} s, positions "
              f"differ by {r['max_position_difference_over_radius']:.1e} R")
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "factorization_reuse.json"), "w") as f:
        json.dump(dict(date=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
                       blas=runtime.blas_info(), results=rows), f, indent=1)
    print(f"wrote {os.path.join(OUT, 'factorization_reuse.json')}")


if __name__ == "__main__":
    main()
