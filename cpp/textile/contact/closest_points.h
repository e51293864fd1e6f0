// Closest points of two centre lines (the single element of a crossing).
#pragma once

#include "centreline.h"

#include <Eigen/Core>

#include <utility>

namespace textile::contact
{

/// Closest points (s, t) of the centre lines of fibres f and g, searched
/// from (s, t): Gauss-Newton on |x_f(s) - x_g(t)|^2, within [0, ne] of each
/// fibre, on the lines smoothed to C1 across their nodes
/// (Centrelines::smooth_position).
///
/// The fibre elements are only C0: a fibre bent over another by the
/// contact force has a kink at a node, and on the kinked line the closest
/// point locks at the node in one configuration and sits inside an element
/// in the next, while Newton moves the crossing's point on the smoothed
/// line of its patch (gap_function.h, particle.h): the detection and
/// Newton then disagree from pass to pass and the contact loop cycles. On
/// the smoothed line the search finds the point Newton settles at.
/// A step moves an abscissa by at most half an element (the search stays
/// near its start). Parallel tangents (no unique closest pair) keep the
/// start.
std::pair<double, double> closest_points(const Centrelines& c, int f, double s, int g, double t);

/// Closest point (abscissa) of fibre f's centre line to `point`, searched
/// from s, within [0, ne]: the same search with one abscissa (on the same
/// smoothed line).
double project_onto(const Centrelines& c, int f, const Eigen::Vector3d& point, double s);

} // namespace textile::contact
