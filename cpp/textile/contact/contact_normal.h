// The normal of a contact element (METHOD.md section 3).
#pragma once

#include <Eigen/Dense>

namespace textile::contact
{

/// Unit normal N of the plane that shields particle i from particle j,
/// pointing from fibre j towards fibre i (so gap = N . (x_i - x_j)).
///
/// Crossing fibres (angle between the tangents above `parallel_angle`,
/// radians): N = +-(t_i x t_j)/|t_i x t_j|, the direction in which the two
/// centre lines cannot pass each other. Near-parallel fibres: the
/// centroid-to-centroid direction orthogonal to the intermediate tangent.
/// Orientation: along `previous` when given (non-zero), so that a normal
/// once set keeps the side each fibre is on even under deep penetration;
/// otherwise along the centroid gap x0_i - x0_j.
///
/// @param tangent_i, tangent_j  unit tangents of the centre lines
/// @param tangent               unit intermediate tangent
/// @param centroid_gap          x0_i - x0_j at the element's sections
/// @param previous              the element's last normal, or zero
Eigen::Vector3d contact_normal(const Eigen::Vector3d& tangent_i, const Eigen::Vector3d& tangent_j,
                               const Eigen::Vector3d& tangent,
                               const Eigen::Vector3d& centroid_gap,
                               const Eigen::Vector3d& previous, double parallel_angle);

} // namespace textile::contact
