"""The small woven sample of the tests that start from a woven state, woven
and saved once, on rank 0 alone, read by every rank."""
from mpi4py import MPI

from textile.fabric import Fabric, Yarn, woven_state


def woven_once(tmp_path_factory, fabric, solver_options=None) -> str:
    """Path of the woven state of ``fabric`` (woven on rank 0 with
    COMM_SELF, saved in a fresh temporary directory), on every rank."""
    comm = MPI.COMM_WORLD
    path = str(tmp_path_factory.mktemp("woven") / "woven.h5") if comm.rank == 0 else None
    path = comm.bcast(path, root=0)
    if comm.rank == 0:
        woven_state(fabric, path, solver_options, MPI.COMM_SELF, report=False)
    comm.Barrier()
    return path


def plain_weave(material, radius, spacing=6.0, fibres=1, num_weft=2):
    """The tests' small sample: a 2 x ``num_weft`` plain weave of flat
    yarns of ``fibres`` fibres (default monofilaments), ``spacing`` yarn
    widths apart (6: it weaves in a fraction of a second)."""
    yarn = Yarn(fibres, radius, material, packing="layers 1")
    return Fabric(yarn, num_warp=2, num_weft=num_weft, spacing=spacing * yarn.width,
                  pattern="plain", elements_per_crossing=4)


def bundle_weave(material, radius, fibres):
    """A 2 x 2 plain weave of hexagonal bundles of ``fibres`` fibres, 2 yarn
    widths apart: the main demo's scene (7 fibres)."""
    yarn = Yarn(fibres, radius, material, packing="hexagonal")
    return Fabric(yarn, num_warp=2, num_weft=2, spacing=2 * yarn.width, pattern="plain",
                  elements_per_crossing=4)
