#include "contact_normal.h"
#include "tolerances.h"

#include <cmath>

namespace textile::contact
{
namespace
{
/// The centroid gap without its component along the intermediate tangent,
/// or, when the centroids lie on one line along the fibres, the previous
/// normal (or any direction) orthogonal to the tangent.
Eigen::Vector3d centroid_direction(const Eigen::Vector3d& t, const Eigen::Vector3d& d,
                                   const Eigen::Vector3d& previous)
{
  const Eigen::Vector3d N = d - d.dot(t) * t;
  if (N.norm() > 1e-14 * (d.norm() + 1e-300))
    return N;
  return previous.norm() > 0 ? Eigen::Vector3d(previous - previous.dot(t) * t)
                             : Eigen::Vector3d(t.unitOrthogonal());
}

/// N oriented along `previous` when that tells the side, else along d.
Eigen::Vector3d oriented(Eigen::Vector3d N, const Eigen::Vector3d& d,
                         const Eigen::Vector3d& previous)
{
  N.normalize();
  const bool previous_tells = previous.norm() > 0
                              and std::abs(N.dot(previous)) > orientation_cosine * previous.norm();
  const Eigen::Vector3d& side = previous_tells ? previous : d;
  return N.dot(side) < 0 ? Eigen::Vector3d(-N) : N;
}
} // namespace

Eigen::Vector3d centroid_normal(const Eigen::Vector3d& t, const Eigen::Vector3d& d,
                                const Eigen::Vector3d& previous)
{
  return oriented(centroid_direction(t, d, previous), d, previous);
}

bool lie_on_each_other(const Eigen::Vector3d& ti, const Eigen::Vector3d& tj,
                       const Eigen::Vector3d& d, double parallel_angle, bool crossing,
                       double contact_distance)
{
  const Eigen::Vector3d N = ti.cross(tj);
  const double sin_angle = N.norm();
  return sin_angle > std::sin(parallel_angle)
         and (crossing or std::abs(d.dot(N)) >= crossing_separation * contact_distance * sin_angle);
}

Eigen::Vector3d contact_normal(const Eigen::Vector3d& ti, const Eigen::Vector3d& tj,
                               const Eigen::Vector3d& t, const Eigen::Vector3d& d,
                               const Eigen::Vector3d& previous, double parallel_angle,
                               bool crossing, double contact_distance)
{
  return lie_on_each_other(ti, tj, d, parallel_angle, crossing, contact_distance)
             ? oriented(ti.cross(tj), d, previous)
             : centroid_normal(t, d, previous);
}
} // namespace textile::contact
