// Proximity zones: where two centre lines (or two distant parts of one)
// come closer than a criterion, docs/method.md §3.2.
//
// Detection runs in three stages:
//  1. broad phase (broad_phase.h): candidate segment pairs from a grid;
//  2. narrow phase: exact closest distance between the two chords of each
//     candidate; the pair is "close" when that distance is below
//         delta_factor (r_i + r_j) + sag_a + sag_b
//     (sag: chord-to-curve bound of a quadratic element, 0 for straight
//     elements, see Segment), and the "close part" of each chord, the
//     parameter interval where the distance from the chord's point to the
//     other chord is below the same criterion, is computed (the distance
//     from a moving point to a fixed segment is convex in the parameter, so
//     that set is one interval; its ends are found to round-off by a
//     bracketed secant method);
//  3. grouping: per fibre pair, close pairs whose segments are equal or
//     adjacent on BOTH fibres belong to the same zone (connected components
//     of the close cells in the (s_i, s_j) plane: a connected close region
//     crosses cells through edges or corners, so it is never split), and a
//     zone's intervals are the extent of the close parts of its pairs.
// Fibre pairs are ordered: fibre_i <= fibre_j; for a self zone
// (fibre_i == fibre_j) the i side is the part with the smaller abscissas.
#pragma once

#include "centreline.h"

#include <Eigen/Core>

#include <optional>
#include <span>
#include <vector>

namespace textile::contact
{

/// Zone Z(i, j): abscissa intervals [a_i, b_i] on fibre_i and [a_j, b_j] on
/// fibre_j (element coordinates s, see centreline.h) on which the centre
/// lines are closer than the criterion.
struct ProximityZone
{
  int fibre_i = 0, fibre_j = 0;   ///< fibre_i <= fibre_j
  double a_i = 0, b_i = 0;        ///< interval on fibre_i, a_i <= b_i
  double a_j = 0, b_j = 0;        ///< interval on fibre_j, a_j <= b_j
  double min_distance = 0;        ///< smallest centre-line distance in the zone (length)
  double s_i = 0, s_j = 0;        ///< abscissas where min_distance is reached
  /// fibre j runs against fibre i there (their tangents at s_i, s_j point
  /// apart): the zone pairs a_i with b_j and b_i with a_j
  bool reversed = false;

  /// Abscissa on fibre j paired with fraction t in [0, 1] of the zone
  /// (t = 0 at a_i on fibre i).
  double along_j(double t) const
  {
    const double u = reversed ? 1.0 - t : t;
    return (1.0 - u) * a_j + u * b_j;
  }
};

/// Closest points of segments P(t) = p0 + t (p1 - p0) and
/// Q(u) = q0 + u (q1 - q0), t, u in [0, 1].
struct SegmentDistance
{
  double distance = 0; ///< |P(t) - Q(u)| (length, >= 0)
  double t = 0, u = 0; ///< parameters of a pair of closest points
};

/// Exact closest distance between two segments. Robust for parallel and
/// degenerate (zero-length) segments: there the distance is still exact and
/// (t, u) is one of the closest pairs.
SegmentDistance segment_distance(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                                 const Eigen::Vector3d& q0, const Eigen::Vector3d& q1);

/// A pair of segments closer than the criterion.
struct ClosePair
{
  int seg_i = 0, seg_j = 0;   ///< global segment numbers, seg_i < seg_j
  double distance = 0;        ///< chord-to-chord distance (length)
  double s_i = 0, s_j = 0;    ///< abscissas of the closest points
  double lo_i = 0, hi_i = 0;  ///< close part of seg_i (abscissas)
  double lo_j = 0, hi_j = 0;  ///< close part of seg_j (abscissas)
};

/// Narrow phase for one pair of segments (seg_i < seg_j, global numbers of
/// `segments`): the close pair if their distance is below
/// delta_factor (r_i + r_j) + sag_i + sag_j, nothing otherwise. Applies no
/// self-contact exclusion (the caller's choice).
std::optional<ClosePair> close_pair(const Centrelines& c, std::span<const Segment> segments,
                                    int seg_i, int seg_j, double delta_factor);

/// All close pairs, sorted by (seg_i, seg_j): broad phase, then narrow
/// phase on the candidates. `segments` must be make_segments(c).
///
/// @param delta_factor   criterion factor (> 0): close when the centre-line
///                       distance is below delta_factor (r_i + r_j).
/// @param self_exclusion length along a fibre (>= 0, +inf: no self-contact);
///                       see find_candidate_pairs.
/// @throws std::invalid_argument for bad input (see find_proximity_zones).
std::vector<ClosePair> find_close_pairs(const Centrelines& c, std::span<const Segment> segments,
                                        double delta_factor, double self_exclusion);

/// Groups close pairs into zones (see the file comment), sorted by
/// (fibre_i, fibre_j, a_i, a_j).
std::vector<ProximityZone> group_into_zones(std::span<const Segment> segments,
                                            std::span<const ClosePair> pairs);

/// Proximity zones of the current centre lines.
///
/// @param c              centre lines (validated here).
/// @param delta_factor   criterion: the centre lines are close where their
///                       distance is below delta_factor (r_i + r_j); > 0
///                       (docs/method.md §3.2: "a few radii", so typically 1.5 to 3).
/// @param self_exclusion length (unit of the coordinates, >= 0) along a
///                       fibre below which two of its parts are neighbours,
///                       not a self contact; make it larger than
///                       delta_factor * 2 r, +inf to ignore self-contact.
/// @throws std::invalid_argument: invalid centre lines (negative radius,
///         ...), delta_factor <= 0 or not finite, self_exclusion < 0 or NaN;
///         GeometryError: a NaN or infinite coordinate (a diverged state).
std::vector<ProximityZone> find_proximity_zones(const Centrelines& c, double delta_factor,
                                                double self_exclusion);

} // namespace textile::contact
