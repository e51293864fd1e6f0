"""An independent reference for a woven monofilament: the crimped yarn as a
plane Timoshenko beam between its clamps, resting on the crossing yarns.

Not textile's beam: a textbook small-rotation Timoshenko beam in the x-z
plane, discretized here with many linear elements (reduced integration of
the shear term, so no shear locking), numpy only.

The model (one yarn of a woven sample, x along it, z vertical):

- the yarn runs from its clamp at x_0 to its clamp at x_1: there z = 0 and
  the rotation is 0 (the weaving run's clamp and pull bodies hold the yarn
  ends level; the virtual tests' side bodies hold the woven ends);
- at each crossing x_c the crossing yarn holds it at the height z_c the
  contact leaves it (above or below; taken from the woven state);
- between crossings nothing loads it: bending E I, shear k G A (Cowper's
  k = 6 (1 + nu) / (7 + 6 nu) for a round section), axial tension T_0 (the
  weaving tension) giving the geometric stiffness T_0 z'' of a taut string.

**Woven shape** (reference (d) of issue 22): the beam with z prescribed at
the crossings and clamped ends; its deflection z(x) and the forces that
hold it at the crossings (the contact forces). In energy form: minimize

    1/2 int (E I psi'^2 + k G A (z' - psi)^2 + T_0 z'^2) dx

over z(x), psi(x) (the section's rotation) with those constraints. The
contact forces are the reactions of the crossing constraints.

**Tension** (reference (a)): the woven yarn pulled by a tension increment
dT, its crossings left free. In uniaxial tension the crossing yarns' ends
are free (the weaving run's end forces are kept as dead loads): when two
parallel yarns straighten they push a crossing yarn down at one crossing
and up at the other, which turns it about its axis at no cost, so the
crossing forces stay what they were (dead). The increment dT then acts on
the crimp z_0 through the geometric term: its virtual work on a deflection
dz is -dT int z_0' dz' dx, a load f on the beam (clamped ends, free
crossings); the yarn straightens by dz = K^-1 f, which lengthens its
projection by dT f . K^-1 f, while the fibre stretches by dT s / (E A)
(s: its length). Per yarn, end force over end displacement:

    k = 1 / (s / (E A) + f . K^-1 f),

a crimp interchange model with the crossing yarn offering no resistance:
crimp straightened against the yarn's own bending and shear.

What the model leaves out, the error to expect: rotations are small (the
woven monofilament's centre line turns by up to 0.25 rad, an error of the
order of its square, a few %); the contact is a point at the crossing
yarn's centre line (the penalty law's penetration is left in z_c); the
crossing yarn's own resistance in tension (its turn costs T_f L_f: about
1% of the yarn's bending stiffness at the crossing).
"""
from __future__ import annotations

import math

import numpy as np


def cowper(nu: float) -> float:
    """Shear coefficient of a round section (Cowper 1966)."""
    return 6 * (1 + nu) / (7 + 6 * nu)


class CrimpedYarn:
    """The beam of the module docstring.

    Parameters
    ----------
    ends:
        (x_0, x_1), the clamps' positions along the yarn.
    crossings:
        Positions x_c of the crossings (strictly between the ends).
    heights:
        z_c, the centre line's height at each crossing, relative to the ends.
    young, poisson, radius:
        The fibre's material and radius.
    tension:
        The yarn's axial force T_0 in the woven state.
    elements:
        Linear elements of the discretization (the crossings are nodes).
    """

    def __init__(self, ends, crossings, heights, young, poisson, radius, tension=0.0,
                 elements=400):
        x = np.linspace(ends[0], ends[1], elements + 1)
        self.x = np.unique(np.concatenate([x, crossings]))
        self.crossing_nodes = [int(np.argmin(np.abs(self.x - c))) for c in crossings]
        self.heights = np.asarray(heights, dtype=float)
        area = math.pi * radius ** 2
        self.EA = young * area
        EI = young * math.pi * radius ** 4 / 4
        kGA = cowper(poisson) * young / (2 * (1 + poisson)) * area
        self.K = self._stiffness(EI, kGA, tension)
        n = len(self.x)
        self.clamped = [0, 1, 2 * (n - 1), 2 * (n - 1) + 1]   # z and psi at both ends

    def _stiffness(self, EI, kGA, T):
        """Assembled stiffness of the unknowns (z_0, psi_0, z_1, psi_1, ...)."""
        n = len(self.x)
        K = np.zeros((2 * n, 2 * n))
        for e in range(n - 1):
            h = self.x[e + 1] - self.x[e]
            dofs = np.arange(2 * e, 2 * e + 4)
            bending = EI / h * np.array([[0, 0, 0, 0], [0, 1, 0, -1],
                                         [0, 0, 0, 0], [0, -1, 0, 1]])
            # shear strain z' - psi at the element's middle (one point)
            B = np.array([-1 / h, -0.5, 1 / h, -0.5])
            string = T / h * np.array([[1, 0, -1, 0], [0, 0, 0, 0],
                                       [-1, 0, 1, 0], [0, 0, 0, 0]])
            K[np.ix_(dofs, dofs)] += bending + kGA * h * np.outer(B, B) + string
        return K

    def woven_shape(self) -> tuple[np.ndarray, np.ndarray]:
        """(z at the nodes self.x, the crossing forces on the yarn): the
        beam held at the crossing heights."""
        fixed = self.clamped + [2 * i for i in self.crossing_nodes]
        u = np.zeros(self.K.shape[0])
        u[[2 * i for i in self.crossing_nodes]] = self.heights
        free = np.setdiff1d(np.arange(len(u)), fixed)
        u[free] = np.linalg.solve(self.K[np.ix_(free, free)],
                                  -self.K[np.ix_(free, fixed)] @ u[fixed])
        forces = (self.K @ u)[[2 * i for i in self.crossing_nodes]]
        return u[0::2], forces

    def tension_stiffness(self, length: float) -> float:
        """End force per end displacement of the yarn pulled with its
        crossings free (module docstring); ``length``: the fibre's length."""
        z0, _ = self.woven_shape()
        f = np.zeros(self.K.shape[0])
        slope = np.diff(z0) / np.diff(self.x)
        f[0:-2:2] -= slope      # -int z_0' dz' dx, z linear in each element
        f[2::2] += slope
        free = np.setdiff1d(np.arange(len(f)), self.clamped)
        straightening = f[free] @ np.linalg.solve(self.K[np.ix_(free, free)], f[free])
        return 1.0 / (length / self.EA + straightening)
