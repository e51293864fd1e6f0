// Every tolerance and switch of the fibre contact, in one place.
//
// Contact is geometry between curved, moving centre lines, and a few
// choices have no exact answer: when two fibres count as crossing or lying
// along each other, how far a kink is spread, how far a kept
// element may drift. Each lives here, with what it decides, its unit, and
// the test that pins it: the test that failed when the value was changed
// as said (2026-12-01); "no test pins it" marks a gap to close.
#pragma once

namespace textile::contact
{

// -- what kind of contact a zone is ------------------------------------------

/// Margin of the crossing criterion's hysteresis (is_crossing,
/// intermediate_geometry.h): a zone that was a crossing stays one down to
/// (1 - bias) parallel_angle, a line contact becomes a crossing only above
/// (1 + bias). Pinned by cpp/tests/test_zone_kind.cpp and
/// tests/contact/test_penalty_units.py (both fail at 0: no hysteresis).
inline constexpr double crossing_bias = 0.25;

/// Out-of-plane separation of the centre lines, in units of r_i + r_j,
/// from which two fibres at an angle lie on each other (crossing normal)
/// rather than side by side in one plane (contact_normal.h). Pinned from
/// above by tests/contact/test_capstan.py (at 3 the frictionless wrap
/// fails); from below no test pins it (at 0.05 every contact and weaving
/// test passes).
inline constexpr double crossing_separation = 0.5;

/// Width of a wrap's contact region above the closest distance, in units of
/// r_i + r_j (wrapping_fibre, wrap_contact.h). Pinned by
/// cpp/tests/test_contact_wrap.cpp (fails at 0.5).
inline constexpr double wrap_band = 0.05;

/// |cos| of the angle between a centroid gap and a fibre's axis above which
/// the point faces the fibre's end (an end cap, excluded): within about 8
/// degrees. Pinned by tests/contact/test_stacked_fibres.py (at 0.5 the
/// stacked yarns no longer settle within each step).
inline constexpr double end_cap_cosine = 0.99;

// -- where a crossing's element sits -------------------------------------------

/// Half-width of blended_tangent's window (element coordinates): half an
/// element, so the tangent turns as slowly as it can; with a quarter the
/// normal turned so fast with the crossing's place that the passes
/// oscillated (a picture frame of monofilaments 4 widths apart stopped at
/// 23 deg; it reaches 28 deg with half an element, as without blending).
/// Pinned by tests/virtual/test_picture_frame.py (fails at 0.25).
inline constexpr double kink_blend = 0.5;

/// Widest half-width (element lengths) of the window over which a
/// two-element patch is smoothed across its shared node: the same spread
/// of a kink as kink_blend. Pinned by cpp/tests/test_gap_function.cpp
/// (ContactPatch fails at 0.1).
inline constexpr double patch_smoothing = kink_blend;

/// Smallest |sin| of the angle between the two centre lines' projections on
/// the plane normal to N for which they face each other at one point
/// (gap_function.h, facing; below it the gap is measured at the particles,
/// as held). Also the bound of vertical_crossing's placement. Pinned by
/// cpp/tests/test_gap_function.cpp (fails at 0.6).
inline constexpr double facing_min_sine = 0.1;

/// |cos| between a new normal and the previous one below which the
/// previous one says nothing about the side (the normal changed kind, e.g.
/// from the crossing normal to an in-plane one): the centroid gap orients
/// it then (contact_normal.cpp). Pinned by cpp/tests/test_contact_normal.cpp
/// (fails at 0.04 and 0.35: a previous normal at |cos| 0.05 does not
/// orient, one at 0.3 does); the contact, weaving, stability and
/// virtual-test suites also pass at 0.6.
inline constexpr double orientation_cosine = 0.1;

// -- line contacts ---------------------------------------------------------------

/// Pieces of a line contact shorter than this fraction of the spacing are
/// merged into a neighbour (contact_points). Pinned by
/// cpp/tests/test_intermediate_geometry.cpp (fails at 4e-4 and 2.5e-3: a
/// piece of 5e-4 spacing is merged, one of 2e-3 is not); the contact,
/// weaving, stability and virtual-test suites also pass at 0.2.
inline constexpr double merge_fraction = 1e-3;

/// A line contact's pieces may exceed 2 x spacing by this fraction before
/// they are cut in two: a zone stretched by a hair keeps its elements
/// (contact_points). Pinned by tests/stability/test_contact_sliding.py
/// (a fibre folded onto itself fails at 0.6).
inline constexpr double piece_tolerance = 0.1;

/// Passes that re-orient a line contact's section plane (contact_points);
/// it settles to round-off in 2-4 on curved fibres.
inline constexpr int max_section_passes = 8;

// -- from one pass to the next -----------------------------------------------------

/// Fraction of the search distance beyond which a closed element may be
/// lost by the next detection (the centre lines' distance is at most its
/// centroids', so below it a zone is found): such elements are held
/// (held_contact.h). Pinned by tests/contact/test_tunnelling.py (at 5,
/// never held, the indenter pushed through in one step is lost).
inline constexpr double hold_fraction = 0.9;

/// How far (|u - u0| + |v - v0| in abscissas, element lengths) a line
/// contact's points may have slid from its pass's particles for it to be
/// kept within a step (ElementParameters::persist, history_transfer.h): a
/// fifth of what a fibre sliding over an arc moves in a step. Pinned by
/// tests/contact/test_frictionless_drag.py (fails at 1).
inline constexpr double persist_drift = 0.01;

/// How far (|s_i - s_i'| + |s_j - s_j'|, element lengths) a new contact
/// point may be from an old element to take over its history
/// (match_history, history_transfer.h): within one element on both fibres.
/// It also bounds which ranks may evaluate an element's successor
/// (history_handover.h; on two ranks, tests/contact/test_capstan.py).
inline constexpr double history_match_distance = 0.75;

// -- friction ------------------------------------------------------------------

/// Fraction of u_rev by which a slipping element's moved stick point
/// leaves it inside the stick cone (updated_stick, contact_element.h):
/// evaluated again at the same positions (the next step's first iterate),
/// it is stick by 1e-8 of u_rev, far above round-off (about 1e-12 of it
/// when the slip is 1e4 u_rev). On the cone exactly, round-off chose stick
/// or slip, whose tangents differ by the whole friction stiffness along the
/// slip: the capstan's slip reversal then cycled on one rank and not on two
/// once the contact loop's later solves dropped the tangent floor. Pinned
/// by tests/contact/test_capstan.py::test_capstan_on_two_ranks_equals_one
/// (fails at 0). The force it changes is 1e-8 of the friction force.
inline constexpr double stick_margin = 1e-8;

} // namespace textile::contact
