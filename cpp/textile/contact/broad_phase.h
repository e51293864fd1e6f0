// Broad phase of contact detection: a uniform grid (spatial hashing) over
// the segments' axis-aligned boxes.
//
// Each segment's box is inflated by its `reach`, half of the search
// distance it takes part in (for two fibres of radii r_i, r_j searched up
// to delta (r_i + r_j), the reach of a segment of fibre i is delta r_i plus
// its chord sag). Two segments are candidates when their inflated boxes
// overlap, which every pair closer than reach_i + reach_j satisfies. Boxes
// are binned into cubic cells whose size is the median largest extent of
// the inflated boxes, so a typical box touches O(1) cells and a cell holds
// O(1) boxes at bounded density. Cells are found through a hash table and
// filled by a counting sort, and the output is ordered by bucketing, so the
// expected cost is O(segments + candidate pairs), never O(n^2).
#pragma once

#include "centreline.h"

#include <span>
#include <utility>
#include <vector>

namespace textile::contact
{

/// Candidate segment pairs (i, j), i < j in the global segment numbering
/// of make_segments, each once, sorted lexicographically.
///
/// @param segments  All segments (make_segments order).
/// @param reach     Inflation of each segment's box (length, >= 0), one per
///                  segment.
/// @param self_exclusion  Length along a fibre (>= 0, may be +inf): two
///                  segments of the same fibre are skipped when the chord
///                  length separating them (from the end of the first to the
///                  start of the second) is below it, so a fibre's
///                  neighbouring parts are never candidates but a distant
///                  part of the same fibre folding back is. Choose it larger
///                  than the search distance, or a fibre's own corners are
///                  found. +inf disables self-contact.
/// @throws std::invalid_argument on a size mismatch, a negative or
///         non-finite reach, a negative or NaN self_exclusion.
std::vector<std::pair<int, int>> find_candidate_pairs(std::span<const Segment> segments,
                                                      std::span<const double> reach,
                                                      double self_exclusion);

/// True when the pair (a, b) of segments of one fibre is excluded from
/// self-contact (same fibre and separated by less than self_exclusion
/// along it); false for segments of different fibres.
bool self_excluded(const Segment& a, const Segment& b, double self_exclusion);

} // namespace textile::contact
