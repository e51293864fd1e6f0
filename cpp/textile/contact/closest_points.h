// Closest points of two centre lines (the single element of a crossing).
#pragma once

#include "centreline.h"

#include <Eigen/Core>

#include <utility>

namespace textile::contact
{

/// Closest points (s, t) of the centre lines of fibres f and g, searched
/// from (s, t): Gauss-Newton on |x_f(s) - x_g(t)|^2, within [0, ne] of each
/// fibre.
///
/// Centre lines are only C0 between elements: a fibre bent over another by
/// the contact force has a kink at a node, and the closest point often sits
/// right there. A step therefore never crosses a node; at a node, the
/// one-sided derivatives decide: the search goes on into the element where
/// the distance decreases, and stops at the node if it increases on both
/// sides (a kink minimum), instead of jumping across the node from one
/// iteration (or one detection pass) to the next.
/// Parallel tangents (no unique closest pair) keep the start.
std::pair<double, double> closest_points(const Centrelines& c, int f, double s, int g, double t);

/// Closest point (abscissa) of fibre f's centre line to `point`, searched
/// from s, within [0, ne]: the same search with one abscissa (nodes and
/// kinks as above).
double project_onto(const Centrelines& c, int f, const Eigen::Vector3d& point, double s);

} // namespace textile::contact
