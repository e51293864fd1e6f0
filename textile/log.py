"""The ``textile`` logger: one set-up for every message of a run.

Modules log through ``textile.log.get_logger(__name__)`` (children of the
``textile`` logger). :func:`configure` runs once when ``textile`` is
imported and may be called again to change it:

- on more than one MPI rank each line starts with its rank,
  ``[rank 1] ...`` (a run on one rank prints the bare message);
- rank 0 shows INFO and above (progress: one line per step), ranks > 0
  only WARNING and above, so an ``mpirun`` prints each progress line once;
- INFO goes to standard output, WARNING and above to standard error
  (the streams are looked up at each message, so pytest's capture and
  ``contextlib.redirect_stdout`` see them).

The ``textile`` logger does not propagate to the root logger: an
application's own logging set-up does not print textile's lines twice; to
route them elsewhere, add a handler to ``logging.getLogger("textile")``.
"""
from __future__ import annotations

import logging
import sys

__all__ = ["configure", "get_logger"]

LOGGER = "textile"


def _world_rank_size() -> tuple[int, int]:
    try:
        from mpi4py import MPI
        return MPI.COMM_WORLD.rank, MPI.COMM_WORLD.size
    except ImportError:       # pragma: no cover - mpi4py is a dependency
        return 0, 1


class _Handler(logging.Handler):
    """INFO and below to sys.stdout, WARNING and above to sys.stderr, each
    looked up when a record is written."""

    def emit(self, record: logging.LogRecord) -> None:
        try:
            stream = sys.stderr if record.levelno >= logging.WARNING else sys.stdout
            stream.write(self.format(record) + "\n")
            stream.flush()
        except Exception:     # pragma: no cover - as logging.StreamHandler
            self.handleError(record)


def configure(level: int | str | None = None, all_ranks: bool = False) -> logging.Logger:
    """(Re)configure the ``textile`` logger and return it.

    Args:
        level: Level of rank 0 (default INFO); ranks > 0 show WARNING and
            above, or ``level`` too when ``all_ranks``.
        all_ranks: Every rank shows ``level`` (debugging a parallel run).
    """
    rank, size = _world_rank_size()
    logger = logging.getLogger(LOGGER)
    for handler in [h for h in logger.handlers if isinstance(h, _Handler)]:
        logger.removeHandler(handler)
    handler = _Handler()
    prefix = f"[rank {rank}] " if size > 1 else ""
    handler.setFormatter(logging.Formatter(prefix.replace("%", "%%") + "%(message)s"))
    logger.addHandler(handler)
    logger.propagate = False
    level = logging.INFO if level is None else level
    if isinstance(level, str):
        level = logging.getLevelName(level.upper())
    logger.setLevel(level if rank == 0 or all_ranks else max(level, logging.WARNING))
    return logger


def get_logger(name: str = LOGGER) -> logging.Logger:
    """The logger of a textile module (``__name__``), a child of ``textile``."""
    return logging.getLogger(name if name.startswith(LOGGER) else f"{LOGGER}.{name}")
