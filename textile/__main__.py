"""The command line: ``python3 -m textile run SCENE`` runs a scene file
(docs/scene_files.md); ``python3 -m textile check SCENE`` only checks it.
Also under ``mpirun -n N``: every rank reads the file, rank 0 prints.

Exit status: 0 done; 1 the run stopped (a step that did not converge, with
every converged step written); 2 a scene file that does not follow the
schema (the message names the file and the key's path) or a bad command
line."""
from __future__ import annotations

import argparse
import sys

EPILOG = """examples:
  python3 -m textile run demos/scenes/fibre_rollup.toml
  python3 -m textile run scene.toml --output out --set fabric.yarn.fibres=1
  python3 -m textile run scene.toml --resume out/state_weaving.h5 --output resumed
  mpirun -n 2 python3 -m textile run scene.toml
  python3 -m textile check scene.toml

Progress: one line per converged step (the solver's log; [solver] verbose = false
silences it). Results: the output directory (ParaView series, results.json,
pictures, the tests' curves) and summary.json there (the key figures).
The schema: docs/scene_files.md."""


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python3 -m textile", description="Run textile scenes described in TOML files.",
        epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True, metavar="{run,check}")
    run = sub.add_parser("run", help="run a scene file", epilog=EPILOG,
                         formatter_class=argparse.RawDescriptionHelpFormatter,
                         description="Build the scene of a TOML file and run it.")
    check = sub.add_parser("check", help="check a scene file against the schema, run nothing",
                           description="Check a scene file against the schema (no run).")
    for s in (run, check):
        s.add_argument("scene", metavar="SCENE", help="the scene file (.toml)")
        s.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                       dest="overrides",
                       help="replace a value of the file before it is checked, e.g. "
                            "fabric.yarn.fibres=1 or fibres[0].elements=12 (VALUE in TOML; "
                            "a bare word is a string); repeatable")
    run.add_argument("--output", metavar="DIR", default=None,
                     help="output directory (default: [output] directory of the file)")
    run.add_argument("--resume", metavar="STATE", default=None,
                     help="go on from a state saved by an earlier run of the same scene "
                          "([output] checkpoint: state_<stage>.h5 or state_<step>.h5; a "
                          "virtual test's checkpoint.h5)")
    return p


def main(argv=None, comm=None) -> int:
    """Run the command line ``argv`` (default sys.argv[1:]); the exit status."""
    args = parser().parse_args(argv)
    # textile (PETSc, MPI) only once the command line is understood: --help
    # and usage errors need neither
    from mpi4py import MPI

    from .io.state_file import SceneMismatchError, StateFileError
    from .log import get_logger
    from .scene.scene_file import SceneError, read_scene
    from .solver import ConvergenceError
    comm = MPI.COMM_WORLD if comm is None else comm

    log = get_logger("textile.cli")

    def say(message, error=False):
        # every rank meets the same (collective) error: rank 0 names it
        if comm.rank == 0:
            (log.error if error else log.info)(message)

    try:
        scene = read_scene(args.scene, args.overrides)
    except SceneError as error:
        say(f"error: {error}", error=True)
        return 2
    if args.command == "check":
        say(f"{args.scene}: a valid {scene.kind} scene")
        return 0
    title = scene.data["scene"]["title"]
    say(f"textile: {scene.kind} scene {args.scene}" + (f" ({title})" if title else "")
        + (f" on {comm.size} ranks" if comm.size > 1 else "")
        + f"; output in {scene.output_directory(args.output)}")
    try:
        scene.run(output=args.output, resume=args.resume, comm=comm)
    except (SceneError, SceneMismatchError, StateFileError) as error:
        # a state file of another scene, or unreadable (--resume, test.woven)
        say(f"error: {error}", error=True)
        return 2
    except ConvergenceError as error:
        say(f"stopped: {error}", error=True)
        return 1
    say(f"done; key figures in {scene.output_directory(args.output)}/summary.json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
