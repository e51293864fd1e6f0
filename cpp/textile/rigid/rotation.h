// Rotations by rotation vectors (exponential map of SO(3)).
//
// A rotation vector theta turns by the angle |theta| about theta/|theta|
// (right hand). Rigid bodies keep their rotation as a matrix R_n, updated
// when a load step is accepted, and carry an *incremental* rotation vector
// theta as unknowns, R = exp([theta]) R_n: exact for any total rotation (a
// body turned by 2 pi is back to R_n = I up to round-off) and smooth in the
// unknowns, whatever the rotation accumulated so far. The functions are
// templates so that automatic differentiation (Eigen's AutoDiffScalar)
// gives exact first and second derivatives.
#pragma once

#include <Eigen/Dense>

#include <cmath>

namespace textile::rigid
{

/// sin(p)/p, (1 - cos p)/p^2 and (p - sin p)/p^3 as functions of p^2
/// (series below 1e-6: smooth at zero, and derivable).
template <typename T>
void rotation_coefficients(const T& p2, T& a, T& b, T& c)
{
  using std::cos;
  using std::sin;
  using std::sqrt;
  if (p2 < 1e-6)
  {
    a = T(1.0) - p2 / 6.0 + p2 * p2 / 120.0;
    b = T(0.5) - p2 / 24.0 + p2 * p2 / 720.0;
    c = T(1.0 / 6.0) - p2 / 120.0 + p2 * p2 / 5040.0;
  }
  else
  {
    const T p = sqrt(p2);
    a = sin(p) / p;
    b = (T(1.0) - cos(p)) / p2;
    c = (p - sin(p)) / (p2 * p);
  }
}

/// exp([theta]) w (Rodrigues' formula).
template <typename T>
Eigen::Matrix<T, 3, 1> rotate(const Eigen::Matrix<T, 3, 1>& theta, const Eigen::Vector3d& w)
{
  T a, b, c;
  rotation_coefficients<T>(theta.dot(theta), a, b, c);
  const Eigen::Matrix<T, 3, 1> wt = w.cast<T>();
  const Eigen::Matrix<T, 3, 1> tw = theta.cross(wt);
  return wt + a * tw + b * theta.cross(tw);
}

/// Left Jacobian of SO(3): exp([theta + d]) = exp([J_l(theta) d]) exp([theta]) + O(d^2);
/// the spin (virtual rotation) of the body is J_l(theta) dtheta.
/// J_l w = w + b theta x w + c theta x (theta x w).
template <typename T>
Eigen::Matrix<T, 3, 1> left_jacobian_times(const Eigen::Matrix<T, 3, 1>& theta,
                                           const Eigen::Matrix<T, 3, 1>& w)
{
  T a, b, c;
  rotation_coefficients<T>(theta.dot(theta), a, b, c);
  const Eigen::Matrix<T, 3, 1> tw = theta.cross(w);
  return w + b * tw + c * theta.cross(tw);
}

/// The rotation matrix exp([theta]).
Eigen::Matrix3d rotation_matrix(const Eigen::Vector3d& theta);

/// The rotation vector of a rotation matrix (|theta| <= pi).
Eigen::Vector3d rotation_vector(const Eigen::Matrix3d& R);

} // namespace textile::rigid
