"""Every demo runs in the test suite (a quick variant), on one rank and
under mpirun -n 2, as dolfinx runs its own demos: a demo cannot break
unnoticed. Each demo that prints an answer checks it against its reference
and exits with status 1 otherwise; here we check that it ran through and
wrote its outputs, and (controls) that the checks fail on a wrong answer."""
import json
import os
import runpy
import sys

import pytest
from mpi4py import MPI

DEMOS = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(__file__))), "demos")

CASES = [
    ("demo_plain_weave.py", ["--fibres", "1", "--spacing", "6"],
     ["fibres.pvd", "contacts.pvd", "results.json", "sample.png", "cut_warp.png", "cut_weft.png",
      "woven.h5"]),
    ("demo_fibre_rollup.py", ["--elements", "16"], ["fibres.pvd", "results.json", "shape.png"]),
    # fibre slenderness and coarse steps: the straight column past P_cr is
    # seen as unstable and left for the buckled one (issue 22)
    ("demo_buckled_column.py", ["--elements", "8", "--slenderness", "10000", "--step", "0.05"],
     ["fibres.pvd", "results.json", "load_rotation.png"]),
    ("demo_twisted_pair.py", ["--elements", "12"], ["fibres.pvd", "contacts.pvd",
                                                    "results.json"]),
    ("demo_composite_bending.py", ["--fibres", "1", "--spacing", "6", "--steps", "2"],
     ["scene.pvd", "bending.png", "bending.csv", "bending.json", "results.json", "woven.h5"]),
    ("demo_composite_twisting.py", ["--fibres", "1", "--spacing", "6", "--steps", "2"],
     ["scene.pvd", "twisting.png", "twisting.csv", "twisting.json", "results.json",
      "woven.h5"]),
    ("demo_fabric_shear.py", ["--fibres", "1", "--spacing", "6", "--steps", "2"],
     ["shear.png", "positive/shear.csv", "negative/shear.json", "positive/results.json",
      "woven.h5"]),
    ("demo_fabric_tension.py", ["--fibres", "1", "--spacing", "6", "--steps", "2"],
     ["tension.png", "uniaxial/tension.csv", "uniaxial/results.json", "woven.h5"]),
    ("demo_picture_frame.py", ["--fibres", "1", "--spacing", "6", "--angle", "15", "--steps", "3"],
     ["picture_frame.csv", "picture_frame.png", "picture_frame.json", "fibres.pvd",
      "results.json", "woven.h5"]),
    ("render_weave_start.py", [], ["sample.png", "sample_top.png", "cut_warp.png",
                                   "cut_weft.png"]),
]


@pytest.mark.mpi
@pytest.mark.parametrize("name,args,outputs", CASES)
def test_demo_runs(name, args, outputs, tmp_path_factory):
    comm = MPI.COMM_WORLD
    out = comm.bcast(str(tmp_path_factory.mktemp(name[:-3])) if comm.rank == 0 else None)
    argv = sys.argv
    sys.argv = [name, "--output", out] + args
    try:
        runpy.run_path(os.path.join(DEMOS, name), run_name="__main__")
    finally:
        sys.argv = argv
    comm.Barrier()
    if comm.rank == 0:
        for f in outputs:
            assert os.path.getsize(os.path.join(out, f)) > 0, f
        for f in [f for f in outputs if f.endswith("results.json")]:  # it solved something
            results = json.load(open(os.path.join(out, f)))
            assert results["steps"] and "failure" not in results["meta"]


def run_demo(name, args, out):
    argv = sys.argv
    sys.argv = [name, "--output", str(out)] + args
    try:
        runpy.run_path(os.path.join(DEMOS, name), run_name="__main__")
    finally:
        sys.argv = argv


@pytest.mark.parametrize("name,args", [
    # 4 elements: the tip 2e-2 L off the exact arc (tolerance 1e-4 L)
    ("demo_fibre_rollup.py", ["--elements", "4"]),
    # linear tetrahedra lock (4.12 times the quadratic ones' stiffness in
    # tests/virtual/test_composite_tests.py): above the bonded bound
    ("demo_composite_bending.py", ["--fibres", "1", "--spacing", "6", "--steps", "1",
                                   "--degree", "1"]),
    ("demo_composite_twisting.py", ["--fibres", "1", "--spacing", "6", "--steps", "1",
                                    "--degree", "1"]),
])
def test_demo_check_fails_on_a_wrong_answer(name, args, tmp_path):
    """Controls: a demo run made wrong on purpose fails its own check."""
    with pytest.raises(SystemExit) as failed:
        run_demo(name, args, tmp_path)
    assert failed.value.code == 1
