// Where two crossing fibres face each other.
//
// A crossing's single element must sit where the two centre lines pass
// over each other along the contact normal: where their projections on the
// plane normal to it intersect. The 3D closest point of the centre lines
// is ill-defined between fibres bent around each other (when the centre
// lines' curvature radii approach the distance of their centre lines, the
// crossing point turns from a minimum of the distance into a saddle): it
// jumps from one side of the crossing to the other at every re-detection
// and the contact loop never settles. The projected intersection stays
// put: the projections cross at a large angle.
//
// During the weaving stage the normal is the vertical (weaving_order.h);
// otherwise the crossing's normal of the previous pass (the 3D closest
// point is the point where the projection along t_i x t_j of that same
// point vanishes: re-evaluating the direction there would fall back onto
// it). A new crossing keeps its closest point.
#pragma once

#include "centreline.h"
#include "intermediate_geometry.h"

#include <Eigen/Core>

namespace textile::contact
{

/// Move the crossing point p (abscissas s_i, s_j, tangents, centroid gap)
/// to the intersection of the two centre lines' projections on the plane
/// normal to `direction` (a unit vector), found by Newton from p's
/// abscissas. Returns false, leaving p unchanged, when the projections are
/// near parallel (|sin| < 0.1) or the intersection lies off either fibre.
bool facing_crossing(const Centrelines& c, ContactPoint& p, const Eigen::Vector3d& direction);

/// facing_crossing along the vertical (the weaving stage).
bool vertical_crossing(const Centrelines& c, ContactPoint& p);

} // namespace textile::contact
