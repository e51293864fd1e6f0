"""A load curve: what drives a virtual test against what it costs in force.

Abscissa: the driving quantity (a strain, a displacement, a shear angle, a
rotation); ordinate: the driving body's force or moment. The first point is
the sample after its release, before loading. Written as CSV and PNG.
"""
from __future__ import annotations

import csv
import os
from dataclasses import dataclass, field

import numpy as np


@dataclass
class LoadCurve:
    """Points (x, y) of a load curve with their labels (quantity [unit])."""

    xlabel: str
    ylabel: str
    title: str = ""
    x: list = field(default_factory=list)
    y: list = field(default_factory=list)

    def add(self, x: float, y: float) -> None:
        self.x.append(float(x))
        self.y.append(float(y))

    def __len__(self) -> int:
        return len(self.x)

    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        return np.asarray(self.x), np.asarray(self.y)

    def tangent(self) -> tuple[np.ndarray, np.ndarray]:
        """(midpoints, slopes) of the curve's successive intervals."""
        x, y = self.arrays()
        return 0.5 * (x[1:] + x[:-1]), np.diff(y) / np.diff(x)

    def initial_slope(self, fraction: float = 0.2) -> float:
        """Least-squares slope of the points whose |x| is within ``fraction``
        of the largest |x| (at least the first two points): the small-strain
        stiffness."""
        x, y = self.arrays()
        if len(x) < 2:
            raise ValueError("LoadCurve.initial_slope: the curve has fewer than two points")
        n = max(2, int(np.count_nonzero(np.abs(x) <= fraction * np.abs(x).max())))
        return float(np.polyfit(x[:n], y[:n], 1)[0])

    def stiffening_point(self, factor: float = 10.0) -> float | None:
        """Abscissa where the tangent stiffness first reaches ``factor`` times
        its value on the curve's first interval (linear interpolation between
        interval midpoints); None if it never does in the range computed."""
        xm, k = self.tangent()
        if len(k) < 2 or k[0] == 0:
            return None
        ratio = k / k[0]
        above = np.flatnonzero(ratio >= factor)
        if not len(above):
            return None
        i = int(above[0])
        if i == 0:
            return float(xm[0])
        t = (factor - ratio[i - 1]) / (ratio[i] - ratio[i - 1])
        return float(xm[i - 1] + t * (xm[i] - xm[i - 1]))

    def write_csv(self, path: str) -> None:
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow([self.xlabel, self.ylabel])
            w.writerows(zip(self.x, self.y))

    def write_png(self, path: str, others: list["LoadCurve"] = (), labels=None) -> None:
        """The curve (and ``others`` on the same axes, e.g. the mirror test)."""
        from ..io.plots import plot_curve

        if not others:
            x, y = self.arrays()
            plot_curve(path, x, y, self.xlabel, self.ylabel, title=self.title)
            return
        curves = [self] + list(others)
        plot_curve(path, [np.asarray(c.x) for c in curves], [np.asarray(c.y) for c in curves],
                   self.xlabel, self.ylabel, title=self.title, label=labels)

    def write(self, directory: str, name: str) -> list[str]:
        """``<name>.csv`` and ``<name>.png`` in ``directory``; their paths.
        An empty curve (a test stopped before its first loading step) has
        its CSV header only and no picture."""
        os.makedirs(directory, exist_ok=True)
        paths = [os.path.join(directory, f"{name}.csv"), os.path.join(directory, f"{name}.png")]
        self.write_csv(paths[0])
        if not len(self):
            return paths[:1]
        self.write_png(paths[1])
        return paths
