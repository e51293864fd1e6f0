#include "contact_normal.h"

#include <cmath>

namespace textile::contact
{
Eigen::Vector3d contact_normal(const Eigen::Vector3d& ti, const Eigen::Vector3d& tj,
                               const Eigen::Vector3d& t, const Eigen::Vector3d& d,
                               const Eigen::Vector3d& previous, double parallel_angle)
{
  Eigen::Vector3d N = ti.cross(tj);
  const double sin_angle = N.norm();
  if (sin_angle <= std::sin(parallel_angle))
  {
    // near-parallel: centroid gap without its component along the fibres
    N = d - d.dot(t) * t;
    if (N.norm() <= 1e-14 * (d.norm() + 1e-300))
    {
      // centroids on one line along the fibres: keep the previous normal
      // if there is one, else any direction orthogonal to the tangent
      N = previous.norm() > 0 ? Eigen::Vector3d(previous - previous.dot(t) * t)
                              : Eigen::Vector3d(t.unitOrthogonal());
    }
  }
  N.normalize();
  const Eigen::Vector3d& side = previous.norm() > 0 ? previous : d;
  if (N.dot(side) < 0)
    N = -N;
  return N;
}
} // namespace textile::contact
