"""Picture-frame shear of a woven sample (docs/method.md §10; docs/references.md
§11-12; the conventions of Cao et al., Composites Part A 39 (2008)).

The frame: the four side bodies (xmin, xmax, ymin, ymax) pin the yarn ends
of their side (positions follow the arm, the ends turn freely; or one
hinged body per yarn end: Pins below). The arms
meet at hinged corners, so the frame is a one-degree-of-freedom mechanism:
corner A = (xmin, ymin) is fixed, the opposite corner C = (xmax, ymax) is
moved by ``displacement`` d along the diagonal AC. The frame's side L is the
distance between the yarn ends of opposite sides in the woven state (the
sample must be square: as many warp as weft yarns, the same spacing).

Kinematics (exact, any angle): the frame angle theta (half the angle at
corner A, 45 deg at the start) and the shear angle gamma follow from

    cos theta = (sqrt(2) L + d) / (2 L),    gamma = 90 deg - 2 theta;

the arms parallel to x (ymin, ymax: they hold the weft ends) turn by
+gamma/2 about z, those parallel to y (xmin, xmax: the warp ends) by
-gamma/2. Each body is prescribed exactly: its rotation phi about z, and
the displacement u of its centre c from where its hinge corner H goes,
H' = c + u + R(phi) (H - c) (a point X of the body goes to
c + u + R(phi)(X - c)); z, rx and ry are held. The corners are
A' = A, B' = A + L (cos gamma/2, sin gamma/2), D' = A + L (sin gamma/2,
cos gamma/2), C' = B' + D' - A.

Measured (every step): the pulling force F on the diagonal, the generalized
force conjugate to d (virtual work of the bodies' reactions: F = sum over
the bodies of f_b . du_b/dd + m_b . dphi_b/dd, with f_b, m_b what body b
exerts on the yarn ends it holds, m_b about its current centre: what the
machine driving the frame must apply to the massless body; a yarn body's
free rotation carries no moment, so only its f_b . du_b/dd counts); the shear
force F_s = F / (2 cos theta); the normalized shear force
F_s L_frame / L_fabric^2 (= F_s / L here: the sample fills the frame).
Also the shear angle seen by the fibres: 90 deg minus the angle between
the mean in-plane directions of the warp and of the weft fibres' centre
lines over the central part of the sample (segments whose midpoints lie in
the middle half of the frame, in the frame's own coordinates, widened across
the fibre by a quarter spacing so that the yarns of a 2 x 2 sample, on the
frame's quarter lines, count).

Curve: normalized shear force against the frame's shear angle (degrees).
Figures: the small-angle shear stiffness (normalized force per radian),
the locking angle (where the tangent stiffness has risen tenfold,
:meth:`~textile.virtual_tests.load_curve.LoadCurve.stiffening_point`) beside
the pin-joint bound arccos(w / p) (w the yarn width, p the spacing), the
shear angle from which parallel yarns press each other (the first step
with lateral contact force, :meth:`PictureFrame.lateral_contact_force`,
recorded every step: it tells locking by jamming from other stiffening),
and the largest difference between the fibres' shear angle and the
frame's.

Pins (``pin``): with "fibre" (the default) the four side bodies pin every
fibre end of their side: the ends turn freely about z but do not spin
about their own axis (:class:`~textile.fabric.sample.Sample`: a round fibre pinned
at both ends would otherwise have a zero-stiffness spin). Each fibre of a
yarn of several fibres then gets its own pin on the arm: as the arm turns
against the yarn, those pins (a fibre diameter apart along the arm) come
closer than a diameter across the yarn, so such yarns resist from the
first degree on, a boundary effect of the pins, not locking (figures in
benchmarks/README.md, "Picture frame"). With "yarn" each yarn end is
clamped by a body of its own (the Sample's split sides): its fibres keep
their layout and turn together; the body's centre (the mean of its fibre
ends, the pin point on the arm) follows the arm, its rotation about z is
free (the hinge: the yarn turns about its pin) and z, rx, ry are held. The
side bodies turn with their arms (rz prescribed); the yarn bodies do not,
so the frame's corners are checked from the side bodies
(:meth:`PictureFrame.corner_positions`) and the pins from either
(:meth:`PictureFrame.pin_positions`).

Stiffening, not locking: in the tests' small flat-yarn weaves the tangent
stiffness rises progressively below the pin-joint bound before any parallel
yarns touch (tests/virtual/test_picture_frame.py; the measured figures and
what the sample needs, crossings several elements from the yarn clamps, in
benchmarks/README.md, "Picture frame"). Use yarn pins for multi-fibre yarns.

Units: those of the fabric; ``angle`` and rotations in radians, reported
angles in degrees.
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

from .shear import locking_bound
from .virtual_test import VirtualTest

#: the frame's arms: the hinge corner each body's kinematics is built from
#: and the sign of its turn (a fraction of gamma)
ARMS = {"xmin": ("A", -0.5), "xmax": ("B", -0.5), "ymin": ("A", 0.5), "ymax": ("D", 0.5)}
#: the corners and the two bodies meeting at each
CORNERS = {"A": ("xmin", "ymin"), "B": ("ymin", "xmax"), "C": ("xmax", "ymax"),
           "D": ("ymax", "xmin")}
SQRT2 = math.sqrt(2.0)
#: how the arms hold the yarn ends (module docstring, Pins)
PIN_OPTIONS = ("fibre", "yarn")


@dataclass(frozen=True)
class ArmBody:
    """A rigid body the frame drives: on the arm of ``side``, holding the
    ends of ``yarn`` (None: every yarn end of the side); ``index`` in the
    model's rigid bodies; ``centre`` its reference centre (the pin point on
    the arm: the mean of the held fibre ends in the woven state)."""

    side: str
    yarn: int | None
    index: int
    centre: np.ndarray


def _rz(phi: float) -> np.ndarray:
    c, s = math.cos(phi), math.sin(phi)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


class PictureFrame(VirtualTest):
    """Picture-frame shear (module docstring).

    Parameters
    ----------
    fabric, woven:
        As :class:`~textile.virtual_tests.VirtualTest`; the fabric must be
        square (as many warp as weft yarns, equal spacings).
    displacement:
        d, the pull of corner C along the diagonal at the end of loading
        (> 0 opens the frame along AC: positive shear angles), in
        (-sqrt(2) L, (2 - sqrt(2)) L), non-zero.
    angle:
        Instead of ``displacement``: the frame's shear angle at the end of
        loading (radians, non-zero, |angle| < pi/2).
    pin:
        How the arms hold the yarn ends (module docstring, Pins): "fibre"
        (default), each fibre end pinned on its side's body, or "yarn",
        each yarn end clamped by a body of its own hinged on the arm.
    **options:
        Those of :class:`~textile.virtual_tests.VirtualTest` (steps,
        contact (default friction 0.2), output, comm, ...).
    """

    name = "picture_frame"
    xlabel = "shear angle [deg]"
    ylabel = "normalized shear force F_s L_frame / L_fabric^2"
    sides = ("xmin", "xmax", "ymin", "ymax")
    pins = ("xmin", "xmax", "ymin", "ymax")

    def __init__(self, fabric, woven, displacement: float | None = None, *,
                 angle: float | None = None, pin: str = "fibre", **options):
        if pin not in PIN_OPTIONS:
            raise ValueError(f"PictureFrame: pin must be one of {PIN_OPTIONS}, got {pin!r}")
        #: "fibre" or "yarn": how the arms hold the yarn ends
        self.pin = pin
        if pin == "yarn":
            # one clamping body per yarn end (Sample's split sides)
            self.pins, self.split = (), self.sides
        if (displacement is None) == (angle is None):
            raise ValueError("PictureFrame: give either displacement or angle (not both)")
        for label, v in (("displacement", displacement), ("angle", angle)):
            if v is not None and (isinstance(v, bool) or not isinstance(v, numbers.Real)
                                  or not np.isfinite(v) or v == 0):
                raise ValueError(f"PictureFrame: {label} must be a non-zero finite number, "
                                 f"got {v!r}")
        if angle is not None and abs(angle) >= math.pi / 2:
            raise ValueError(f"PictureFrame: |angle| must be below pi/2 (the frame folds "
                             f"flat at 90 deg), got {angle!r}")
        if fabric.num_warp != fabric.num_weft or not math.isclose(
                fabric.spacing[0], fabric.spacing[1], rel_tol=1e-12):
            raise ValueError(f"PictureFrame: the sample must be square (a square frame holds "
                             f"it): as many warp as weft yarns and the same spacing, got "
                             f"{fabric.num_warp} x {fabric.num_weft} yarns, spacing "
                             f"{fabric.spacing}")
        super().__init__(fabric, woven, **options)
        sample = self.sample
        lx, ly = sample.side_distance("x"), sample.side_distance("y")
        if abs(lx - ly) > 0.02 * max(lx, ly):
            raise ValueError(f"PictureFrame: the woven sample is not square: its yarn ends are "
                             f"{lx:.6g} apart across x and {ly:.6g} across y")
        #: the frame's side: the distance between the yarn ends of opposite sides
        self.side = 0.5 * (lx + ly)
        ends = {s: sample.end_positions(s) for s in self.sides}
        middle = np.array([0.5 * (ends["xmin"][:, 0].mean() + ends["xmax"][:, 0].mean()),
                           0.5 * (ends["ymin"][:, 1].mean() + ends["ymax"][:, 1].mean()),
                           np.concatenate(list(ends.values()))[:, 2].mean()])
        #: corner A (xmin, ymin) in the starting configuration (fixed)
        self.origin = middle - np.array([0.5 * self.side, 0.5 * self.side, 0.0])
        L = self.side
        self.max_displacement = (2.0 - SQRT2) * L   # the frame folded flat
        if angle is not None:
            displacement = SQRT2 * L * (math.cos(angle / 2) + math.sin(angle / 2)) - SQRT2 * L
        if not -SQRT2 * L < displacement < self.max_displacement:
            raise ValueError(f"PictureFrame: displacement must lie in ({-SQRT2 * L:.6g}, "
                             f"{self.max_displacement:.6g}) for a frame of side {L:.6g} (it "
                             f"folds flat at the ends), got {displacement!r}")
        self.displacement = float(displacement)
        rigid = sample.model.rigid_bodies
        index = {id(b): i for i, b in enumerate(rigid.bodies)}
        held = ([(side, None, sample.sides[side]) for side in self.sides] if pin == "fibre"
                else [(side, k, body) for side in self.sides
                      for k, body in sorted(sample.yarn_bodies[side].items())])
        #: the bodies the frame drives, arm by arm
        self.arm_bodies: list[ArmBody] = []
        for side, k, body in held:
            i = index[id(body)]
            self.arm_bodies.append(ArmBody(side, k, i, np.array(rigid.centres[i])))
        #: the yarn width w (the wider of warp and weft)
        self.yarn_width = float(max(fabric.warp.width, fabric.weft.width))
        #: the pin-joint locking bound arccos(w / p) (radians)
        self.lock_bound = math.radians(locking_bound(fabric))

    # -- the frame's kinematics ---------------------------------------------------
    def shear_angle(self, d: float) -> float:
        """gamma (radians) of the frame pulled by d along its diagonal."""
        return math.pi / 2 - 2.0 * math.acos((SQRT2 * self.side + d) / (2.0 * self.side))

    def frame_angle(self, d: float) -> float:
        """theta (radians): cos theta = (sqrt(2) L + d) / (2 L)."""
        return math.acos((SQRT2 * self.side + d) / (2.0 * self.side))

    def corners(self, gamma: float) -> dict[str, np.ndarray]:
        """The hinge corners A, B, C, D at shear angle ``gamma``."""
        L, c, s = self.side, math.cos(gamma / 2), math.sin(gamma / 2)
        a = self.origin
        b = a + L * np.array([c, s, 0.0])
        d = a + L * np.array([s, c, 0.0])
        return {"A": a.copy(), "B": b, "C": b + d - a, "D": d}

    def arm_motion(self, side: str, point: np.ndarray, gamma: float) -> tuple[np.ndarray, float]:
        """(u, phi): displacement of the arm's point ``point`` (reference
        position) and the arm's rotation about z at shear angle ``gamma``,
        from its hinge corner H: point -> H' + R(phi)(point - H)."""
        corner, turn = ARMS[side]
        phi = turn * gamma
        h0, h = self.corners(0.0)[corner], self.corners(gamma)[corner]
        u = h - point - _rz(phi) @ (h0 - point)
        u[2] = 0.0
        return u, phi

    def arm_rates(self, side: str, point: np.ndarray, d: float) -> tuple[np.ndarray, float]:
        """(du/dd, dphi/dd) of :meth:`arm_motion` at displacement d."""
        gamma = self.shear_angle(d)
        dgamma = 1.0 / (self.side * math.sin(self.frame_angle(d)))
        corner, turn = ARMS[side]
        phi = turn * gamma
        L, c, s = self.side, math.cos(gamma / 2), math.sin(gamma / 2)
        dh = {"A": np.zeros(3), "B": 0.5 * L * np.array([-s, c, 0.0]),
              "D": 0.5 * L * np.array([c, -s, 0.0])}[corner]
        arm = _rz(phi) @ (self.corners(0.0)[corner] - point)
        du = dh - turn * np.cross([0.0, 0.0, 1.0], arm)
        du[2] = 0.0
        return du * dgamma, turn * dgamma

    def corner_positions(self) -> dict[str, list[np.ndarray]]:
        """Each hinge corner where the two side bodies meeting there carry it
        now (from their current centres and accumulated rotations): the
        frame holds together when the two agree (``pin="fibre"`` only: yarn
        bodies turn freely, see :meth:`pin_positions`; collective)."""
        if self.pin != "fibre":
            raise ValueError("PictureFrame.corner_positions: the yarn bodies turn freely about "
                             "their pins (pin='yarn'); use pin_positions")
        rb = self.sample.model.rigid_bodies
        positions = rb.positions()
        ref = self.corners(0.0)
        body = {b.side: b for b in self.arm_bodies}
        out = {}
        for corner, pair in CORNERS.items():
            out[corner] = [positions[body[side].index]
                           + rb.rotation[body[side].index] @ (ref[corner] - body[side].centre)
                           for side in pair]
        return out

    def pin_positions(self, gamma: float) -> np.ndarray:
        """(bodies, 2, 3): per arm body (:attr:`arm_bodies`), its current
        centre and where the arm at shear angle ``gamma`` carries its pin
        point (collective)."""
        positions = self.sample.model.rigid_bodies.positions()
        return np.array([[positions[b.index],
                          b.centre + self.arm_motion(b.side, b.centre, gamma)[0]]
                         for b in self.arm_bodies])

    # -- the test -------------------------------------------------------------------
    def drive(self) -> dict:
        # a side body turns with its arm; a yarn body turns freely (hinge)
        driven = ("x", "y", "rz") if self.pin == "fibre" else ("x", "y")
        bodies = self.sample.model.rigid_bodies.bodies
        targets = {}
        for b in self.arm_bodies:
            body = bodies[b.index]
            body.fix(("z", "rx", "ry"))
            handle = body.prescribe(driven, 0.0)
            targets[handle] = lambda s, b=b: self._prescribed(b, s)
        return targets

    def _prescribed(self, body: ArmBody, s: float) -> np.ndarray:
        u, phi = self.arm_motion(body.side, body.centre, self.shear_angle(s * self.displacement))
        return np.array([u[0], u[1], phi] if self.pin == "fibre" else [u[0], u[1]])

    def pulling_force(self, d: float) -> float:
        """F, the generalized force conjugate to d (module docstring), at the
        current state: the virtual work of the arm bodies' reactions (a
        yarn body's free rz carries no moment; collective)."""
        r = self.sample.model.rigid_bodies.reactions()
        F = 0.0
        for b in self.arm_bodies:
            du, dphi = self.arm_rates(b.side, b.centre, d)
            f = r[b.index]
            F += float(f[0:3] @ du) + (float(f[5] * dphi) if self.pin == "fibre" else 0.0)
        return F

    def fibre_shear_angle(self, gamma: float) -> float:
        """The shear angle (degrees) of the fibres' centre lines in the
        central part of the sample (module docstring), in the current state;
        ``gamma``: the frame's shear angle (radians), which places the
        central part (collective)."""
        model, fabric = self.sample.model, self.sample.fabric
        x = model.nodal_unknowns()[:, 0:3]
        first = model.mesh.first_node
        corners = self.corners(gamma)
        L = self.side
        # frame coordinates (xi along AB, eta along AD) of a point: solve
        # P - A = xi L a1 + eta L a2
        a1 = (corners["B"] - corners["A"])[0:2] / L
        a2 = (corners["D"] - corners["A"])[0:2] / L
        inverse = np.linalg.inv(np.column_stack([a1, a2]) * L)
        margin = 0.25 * fabric.spacing[0] / L
        sums = {"warp": np.zeros(2), "weft": np.zeros(2)}
        for f in range(len(first) - 1):
            p = x[first[f]:first[f + 1], 0:2]
            seg = np.diff(p, axis=0)
            mid = 0.5 * (p[1:] + p[:-1])
            xi, eta = inverse @ (mid - corners["A"][0:2]).T
            direction = fabric.yarn_direction(int(fabric.fibre_yarn[f]))
            along, across = (xi, eta) if direction == "warp" else (eta, xi)
            inside = (np.abs(along - 0.5) <= 0.25) & (np.abs(across - 0.5) <= 0.25 + margin)
            sums[direction] += seg[inside].sum(axis=0)
        t1, t2 = (v / np.linalg.norm(v) for v in (sums["warp"], sums["weft"]))
        between = math.degrees(math.atan2(abs(t1[0] * t2[1] - t1[1] * t2[0]),
                                          float(t1 @ t2)))
        return 90.0 - between

    def lateral_contact_force(self) -> float:
        """Sum of the contact normal forces (N) between fibres of different
        yarns of the same direction: parallel yarns pressed against each
        other, the jamming behind shear locking (0 without contact;
        collective)."""
        contact = self.sample.contact
        if contact is None:
            return 0.0
        d = contact.elements()
        fabric = self.sample.fabric
        yarn_i, yarn_j = fabric.fibre_yarn[d["fibre_i"]], fabric.fibre_yarn[d["fibre_j"]]
        parallel = (yarn_i != yarn_j) & ((yarn_i < fabric.num_warp) == (yarn_j < fabric.num_warp))
        return float(self.sample.model.comm.allreduce(float(d["normal_force"][parallel].sum())))

    def measure(self, s: float):
        d = s * self.displacement
        theta = self.frame_angle(d)
        gamma = self.shear_angle(d)
        F = self.pulling_force(d)
        Fs = F / (2.0 * math.cos(theta))
        normalized = Fs * self.side / self.side ** 2
        fibres = self.fibre_shear_angle(gamma)
        return math.degrees(gamma), normalized, {
            "displacement": d, "frame_angle": math.degrees(theta), "pulling_force": F,
            "shear_force": Fs, "fibre_shear_angle": fibres,
            "fibre_angle_error": fibres - math.degrees(gamma),
            "lateral_contact_force": self.lateral_contact_force()}

    def summarize(self, result) -> dict:
        lock = result.curve.stiffening_point(10.0)
        errors = [abs(s["fibre_angle_error"]) for s in result.steps]
        # the first step where parallel yarns press each other
        jammed = [s["x"] for s in result.steps if s["lateral_contact_force"] > 0]
        return {"shear stiffness (normalized force per radian)":
                result.curve.initial_slope() * 180.0 / math.pi,
                "locking angle [deg]": lock,
                "pin-joint locking bound arccos(w/p) [deg]": math.degrees(self.lock_bound),
                "lateral yarn contact from [deg]": jammed[0] if jammed else None,
                "largest fibre angle error [deg]": max(errors, default=0.0),
                "frame side": self.side, "yarn width": self.yarn_width,
                "spacing": float(self.sample.fabric.spacing[0])}
