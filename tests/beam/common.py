"""Helpers shared by the beam tests: a round fibre's section constants."""
import numpy as np


def section(E, nu, R):
    """A, I, J, G of a round section of radius R."""
    A = np.pi * R ** 2
    I = np.pi * R ** 4 / 4
    return A, I, 2 * I, E / (2 * (1 + nu))


QUIET = {"verbose": False}
