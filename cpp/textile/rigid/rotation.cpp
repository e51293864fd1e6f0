#include "rotation.h"

namespace textile::rigid
{
Eigen::Matrix3d rotation_matrix(const Eigen::Vector3d& theta)
{
  Eigen::Matrix3d R;
  for (int k = 0; k < 3; ++k)
    R.col(k) = rotate<double>(theta, Eigen::Vector3d::Unit(k));
  return R;
}

Eigen::Vector3d rotation_vector(const Eigen::Matrix3d& R)
{
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}
} // namespace textile::rigid
