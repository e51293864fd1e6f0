#include "rigid_coupling.h"
#include "rotation.h"
#include "rotation_dual.h"

#include <stdexcept>

namespace textile::rigid
{
using Vec3 = Eigen::Vector3d;

void rigid_coupling(const CouplingBase& base, std::span<const double> q,
                    std::span<const double> centre, std::span<const double> theta,
                    std::span<const double> lambda, std::span<const double> scale,
                    std::span<double> r, std::span<double> K)
{
  const int m = base.rows();
  const int n = 2 * m + 6; // [q, u, theta, lambda]
  if (static_cast<int>(q.size()) != m or centre.size() != 3 or theta.size() != 3
      or static_cast<int>(lambda.size()) != m or static_cast<int>(scale.size()) != m
      or static_cast<int>(r.size()) != n or (!K.empty() and static_cast<int>(K.size()) != n * n))
    throw std::invalid_argument("rigid_coupling: wrong array size");
  const Vec3 th(theta.data());
  const Vec3 c(centre.data());
  // targets phi and their derivatives in theta: per coupled vector v (offset,
  // g1, g2), f_v = exp([theta]) v; grad/Hessian of mu . f_v by dual numbers
  const Vec3 vs[3] = {base.offset, base.g1, base.g2};
  const int nv = base.section ? 3 : 1;
  Eigen::Matrix<double, 9, 1> phi;
  Eigen::Matrix<double, 9, 3> dphi; // d phi / d theta
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero(); // sum_k (s lambda)_k d2 phi_k / dtheta2
  const Eigen::Matrix<AD2, 3, 1> x = dual(th);
  for (int v = 0; v < nv; ++v)
  {
    const Eigen::Matrix<AD2, 3, 1> f = rotate<AD2>(x, vs[v]);
    for (int k = 0; k < 3; ++k)
    {
      phi(3 * v + k) = f[k].value().value() + (v == 0 ? c(k) : 0.0);
      for (int i = 0; i < 3; ++i)
        dphi(3 * v + k, i) = f[k].value().derivatives()[i];
      const double mu = scale[3 * v + k] * lambda[3 * v + k];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          H(i, j) += mu * f[k].derivatives()[i].derivatives()[j];
    }
  }
  // residual: [s lambda, -(dphi/du, dphi/dtheta)^T s lambda, s (q - phi)]
  for (int k = 0; k < m; ++k)
  {
    const double sl = scale[k] * lambda[k];
    r[k] += sl;
    if (k < 3)
      r[m + k] -= sl; // d phi / du = identity on x0
    for (int i = 0; i < 3; ++i)
      r[m + 3 + i] -= dphi(k, i) * sl;
    r[m + 6 + k] += scale[k] * (q[k] - phi(k));
  }
  if (K.empty())
    return;
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> Kt(
      K.data(), n, n);
  for (int k = 0; k < m; ++k)
  {
    const int l = m + 6 + k;
    Kt(k, l) += scale[k]; // r_q / lambda
    Kt(l, k) += scale[k]; // r_lambda / q
    if (k < 3)
    {
      Kt(m + k, l) -= scale[k]; // r_u / lambda
      Kt(l, m + k) -= scale[k]; // r_lambda / u
    }
    for (int i = 0; i < 3; ++i)
    {
      Kt(m + 3 + i, l) -= dphi(k, i) * scale[k]; // r_theta / lambda
      Kt(l, m + 3 + i) -= scale[k] * dphi(k, i); // r_lambda / theta
    }
  }
  Kt.block<3, 3>(m + 3, m + 3) -= H; // r_theta / theta
}

void body_moment(std::span<const double> theta, std::span<const double> moment,
                 std::span<double> r, std::span<double> K)
{
  if (theta.size() != 3 or moment.size() != 3 or r.size() != 3
      or (!K.empty() and K.size() != 9))
    throw std::invalid_argument("body_moment: wrong array size");
  // f = -J_l(theta)^T M; J_l^T M = J_l(-theta) M (J_l(theta)^T = J_l(-theta))
  Eigen::Matrix<AD1, 3, 1> x;
  for (int i = 0; i < 3; ++i)
    x[i] = AD1(-theta[i], 3, i);
  const Eigen::Matrix<AD1, 3, 1> M = Vec3(moment.data()).cast<AD1>();
  const Eigen::Matrix<AD1, 3, 1> f = left_jacobian_times<AD1>(x, M);
  for (int k = 0; k < 3; ++k)
  {
    r[k] -= f[k].value();
    if (!K.empty())
      for (int i = 0; i < 3; ++i)
        K[3 * k + i] += f[k].derivatives()[i]; // d(-f)/dtheta = +df/d(-theta)
  }
}
} // namespace textile::rigid
