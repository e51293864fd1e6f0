"""Colours of fibres by a per-fibre key (yarn, fibre id, ...).

One rule for every picture (VTK tubes, matplotlib sketch, cross-sections),
so a yarn has the same colour in all of them: the i-th smallest key gets
the i-th colour of a qualitative palette, cycling after 10.
"""
from __future__ import annotations

import numpy as np

__all__ = ["PALETTE", "key_colours"]

#: matplotlib's "tab10" (Tableau 10): distinct hues of similar lightness,
#: readable on white and in print. RGB in 0..1.
PALETTE = (
    (0.122, 0.467, 0.706), (1.000, 0.498, 0.055), (0.173, 0.627, 0.173),
    (0.839, 0.153, 0.157), (0.580, 0.404, 0.741), (0.549, 0.337, 0.294),
    (0.890, 0.467, 0.761), (0.498, 0.498, 0.498), (0.737, 0.741, 0.133),
    (0.090, 0.745, 0.812),
)


def key_colours(keys) -> dict:
    """{key: (r, g, b)} for the distinct values of ``keys`` (ints or floats)."""
    values = np.unique(np.asarray(keys).ravel())
    return {v.item(): PALETTE[i % len(PALETTE)] for i, v in enumerate(values)}
