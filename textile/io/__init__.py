"""Output of textile simulations: ParaView files, result logs and plots.

- :mod:`textile.io.vtu`: fibre centre lines as VTK XML UnstructuredGrid
  (``.vtu``) polylines, written by meshio.
- :mod:`textile.io.pvd`: ParaView ``.pvd`` collections (one writer for
  every series: fibres, contacts, blocks, the scene).
- :mod:`textile.io.results`: per-step result records in JSON (+ CSV export).
- :mod:`textile.io.plots`: headless PNG plots of fibres and load curves.
- :mod:`textile.io.render`: pictures of a sample: fibres as tubes of their
  true radius (VTK, off-screen; matplotlib fallback) and cross-sections;
  :mod:`textile.io.sample_pictures`: the ones :class:`textile.Output` draws.

All writers replace their files atomically and are serial: call them on MPI
rank 0 with already-gathered data.

The plotting and rendering functions are imported lazily so that
``import textile.io`` does not pay for importing matplotlib unless a
picture is actually made.
"""

from textile.io.pvd import PVDSeries, SceneSeries, write_pvd
from textile.io.results import ResultsLog
from textile.io.vtu import write_fibres_vtu

# name -> module that defines it, imported on first access (PEP 562)
_LAZY = {"plot_curve": "plots", "plot_fibres": "plots",
         "RenderingUnavailable": "render", "RenderingWarning": "render",
         "render_cross_section_png": "render", "render_fibres_png": "render",
         "sketch_fibres_png": "render", "fabric_labels": "sample_pictures",
         "draw_state_pictures": "sample_pictures", "yarn_axes": "sample_pictures"}

__all__ = ["PVDSeries", "ResultsLog", "SceneSeries", "write_fibres_vtu", "write_pvd", *_LAZY]


def __getattr__(name: str):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(f"textile.io.{_LAZY[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
