// Wraps: a fibre bent around another over a finite angle (stability issue
// item 6), e.g. a thin fibre over a thick one (a capstan) or a crimped yarn
// over a crossing yarn.
//
// Such a zone is a crossing by its ends (the centre lines move apart on both
// sides) but not a point contact: along the wrap the wrapping fibre stays at
// the same distance from the other one's centre line, so its closest point
// is not unique, and a single element there jumps between the two ends of
// the wrap (where a fibre with bending stiffness presses hardest) from one
// detection pass to the next. The contact is distributed instead: elements
// at a composite 2-point Gauss rule along the wrapping fibre's interval of
// the zone (cut at its element boundaries), each standing for its share of
// that fibre's arc length, each facing the closest point of the other
// fibre's centre line. Their centroid gap is then orthogonal to the other
// fibre, radial for a round one: the normal follows the wrapping fibre
// around the other.
#pragma once

#include "centreline.h"
#include "tolerances.h"
#include "intermediate_geometry.h"
#include "proximity_zone.h"

#include <vector>

namespace textile::contact
{

/// The fibre of crossing zone z that wraps around the other: the one whose
/// unit tangent turns the most between the ends of its interval of the
/// zone, if that turn exceeds `wrap_angle` (radians) AND it stays within
/// wrap_band (r_i + r_j) of its closest distance to the other centre line
/// over at least `min_length` of its length (the contact region: a wrap's
/// arc, where a point crossing of kinked or straight fibres has a short V
/// or bowl). -1 when there is no such fibre, and when the centre lines come
/// closer than crossing_separation (r_i + r_j) (contact_normal.h): deeply
/// interpenetrating fibres keep the crossing, whose normal t_i x t_j holds
/// them apart.
int wrapping_fibre(const Centrelines& c, const ProximityZone& z, double wrap_angle,
                   double min_length);

/// The contact elements of a wrap (see the file comment): `wrapping` is
/// z.fibre_i or z.fibre_j; elements closer than `spacing` to each other
/// (length) at most twice as far apart as spacing. Points whose centroid gap
/// runs along a fibre's axis (a fibre end) are left out, as in
/// contact_points. Each point has wrap = true, crossing = false, its arc
/// length as `length`, and the other fibre's tangent as intermediate
/// tangent: its normal is the centroid direction orthogonal to it
/// (contact_normal.h, centroid_normal), radial around a round fibre.
std::vector<ContactPoint> wrap_points(const Centrelines& c, const SectionVectors& g,
                                      const ProximityZone& z, int wrapping, double spacing);

} // namespace textile::contact
