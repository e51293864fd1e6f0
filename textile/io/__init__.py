"""Output of textile simulations: ParaView files, result logs and plots.

- :mod:`textile.io.vtu`: fibre centre lines as VTK XML UnstructuredGrid
  (``.vtu``) polylines, and ParaView ``.pvd`` time-series collections.
- :mod:`textile.io.results`: per-step result records in JSON (+ CSV export).
- :mod:`textile.io.plots`: headless PNG plots of fibres and load curves.

All writers replace their files atomically and are serial: call them on MPI
rank 0 with already-gathered data.

The plotting functions are imported lazily so that ``import textile.io`` does
not pay for importing matplotlib unless a plot is actually made.
"""

from textile.io.results import ResultsLog
from textile.io.vtu import PVDSeries, write_fibres_vtu

__all__ = ["PVDSeries", "ResultsLog", "plot_curve", "plot_fibres", "write_fibres_vtu"]

_LAZY = {"plot_curve", "plot_fibres"}


def __getattr__(name: str):
    """Import the plotting functions on first access (PEP 562)."""
    if name in _LAZY:
        from textile.io import plots

        return getattr(plots, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
