// The normal of a contact element (docs/method.md §4.1).
#pragma once

#include <Eigen/Dense>
#include "tolerances.h"

namespace textile::contact
{

/// The centroid-to-centroid direction orthogonal to the unit tangent t
/// (from the centroid gap d = x0_i - x0_j), as a unit normal oriented like
/// contact_normal's; when the centroids lie on one line along t, the
/// previous normal (or any direction) orthogonal to t.
Eigen::Vector3d centroid_normal(const Eigen::Vector3d& tangent,
                                const Eigen::Vector3d& centroid_gap,
                                const Eigen::Vector3d& previous);

/// Whether contact_normal takes the crossing normal t_i x t_j (the fibres
/// lie on each other) rather than the centroid direction (see there).
bool lie_on_each_other(const Eigen::Vector3d& tangent_i, const Eigen::Vector3d& tangent_j,
                       const Eigen::Vector3d& centroid_gap, double parallel_angle, bool crossing,
                       double contact_distance);

/// Unit normal N of the plane that shields particle i from particle j,
/// pointing from fibre j towards fibre i (so gap = N . (x_i - x_j)).
///
/// Crossing normal N = +-(t_i x t_j)/|t_i x t_j|, the direction in which two
/// crossing centre lines cannot pass each other, only where the centre
/// lines really cross: the tangents make an angle above `parallel_angle`
/// (radians) AND either the element is a crossing zone's (`crossing`) or
/// the centroid gap along t_i x t_j is at least crossing_separation x
/// `contact_distance` (the fibres lie on each other). Elsewhere (near-
/// parallel fibres, and fibres diverging side by side in one plane, whose
/// centroid gap has no component along t_i x t_j: that normal would read a
/// penetration of r_i + r_j that is not there) N is the centroid-to-centroid
/// direction orthogonal to the intermediate tangent.
/// Orientation: along `previous` when given and not orthogonal to N, so
/// that a normal once set keeps the side each fibre is on even under deep
/// penetration; otherwise along the centroid gap x0_i - x0_j.
///
/// @param tangent_i, tangent_j  unit tangents of the centre lines
/// @param tangent               unit intermediate tangent
/// @param centroid_gap          x0_i - x0_j at the element's sections
/// @param previous              the element's last normal, or zero
/// @param crossing              the element is a crossing zone's single element
/// @param contact_distance      r_i + r_j (length)
Eigen::Vector3d contact_normal(const Eigen::Vector3d& tangent_i, const Eigen::Vector3d& tangent_j,
                               const Eigen::Vector3d& tangent,
                               const Eigen::Vector3d& centroid_gap,
                               const Eigen::Vector3d& previous, double parallel_angle,
                               bool crossing, double contact_distance);

} // namespace textile::contact
