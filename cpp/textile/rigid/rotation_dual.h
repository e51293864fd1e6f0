// A rotation vector theta as dual numbers, for the exact first and second
// derivatives in theta that the couplings to a rigid body need (their
// tangents must be exact for Newton's quadratic convergence).
#pragma once

#include <Eigen/Dense>
#include <unsupported/Eigen/AutoDiff>

namespace textile::rigid
{
/// A value and its gradient in the 3 components of theta.
using AD1 = Eigen::AutoDiffScalar<Eigen::Vector3d>;
/// A value, its gradient and its Hessian in the 3 components of theta.
using AD2 = Eigen::AutoDiffScalar<Eigen::Matrix<AD1, 3, 1>>;

/// theta as second-order dual numbers: value, gradient and Hessian of any
/// function of it come out of one evaluation.
inline Eigen::Matrix<AD2, 3, 1> dual(const Eigen::Vector3d& theta)
{
  Eigen::Matrix<AD2, 3, 1> x;
  for (int i = 0; i < 3; ++i)
  {
    x[i].value() = AD1(theta[i], 3, i);
    x[i].derivatives() = Eigen::Matrix<AD1, 3, 1>::Constant(AD1(0.0, Eigen::Vector3d::Zero()));
    x[i].derivatives()[i] = AD1(1.0, Eigen::Vector3d::Zero());
  }
  return x;
}
} // namespace textile::rigid
