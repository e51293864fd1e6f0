#include "sliding_coupling.h"
#include "rotation.h"
#include "rotation_dual.h"

#include <stdexcept>

namespace textile::rigid
{
using Vec3 = Eigen::Vector3d;

void sliding_coupling(const CouplingBase& base, std::span<const SlidingRow> rows,
                      std::span<const double> q, std::span<const double> centre,
                      std::span<const double> theta, std::span<const double> lambda,
                      std::span<const double> scale, std::span<double> r, std::span<double> K)
{
  const int nq = base.rows();
  const int m = static_cast<int>(rows.size());
  const int n = nq + 6 + m; // [q, u, theta, lambda]
  if (static_cast<int>(q.size()) != nq or centre.size() != 3 or theta.size() != 3
      or static_cast<int>(lambda.size()) != m or static_cast<int>(scale.size()) != m
      or static_cast<int>(r.size()) != n or (!K.empty() and static_cast<int>(K.size()) != n * n))
    throw std::invalid_argument("sliding_coupling: wrong array size");
  const Vec3 c(centre.data());
  const Vec3 vs[3] = {base.offset, base.g1, base.g2};
  const Eigen::Matrix<AD2, 3, 1> x = dual(Vec3(theta.data()));
  const int iu = nq, it = nq + 3, il = nq + 6;
  for (int k = 0; k < m; ++k)
  {
    const int v = rows[k].vector;
    if (v < 0 or 3 * v >= nq)
      throw std::invalid_argument("sliding_coupling: row holds a vector the coupling lacks");
    // c_k(theta) = d(theta) . (q_v - [C + u] - R(theta) V): q and the
    // centre enter linearly, so only theta needs dual numbers
    const Eigen::Matrix<AD2, 3, 1> d = rotate<AD2>(x, rows[k].direction);
    const Eigen::Matrix<AD2, 3, 1> p = rotate<AD2>(x, vs[v]);
    AD2 ck = AD2(0.0);
    for (int i = 0; i < 3; ++i)
      ck += d[i] * (q[3 * v + i] - (v == 0 ? c(i) : 0.0) - p[i]);
    Vec3 dval, dc; // d, and dc/dtheta
    Eigen::Matrix3d Jd, H; // Jd(i, j) = d d_i / d theta_j; H = d2 c / dtheta2
    for (int i = 0; i < 3; ++i)
    {
      dval(i) = d[i].value().value();
      dc(i) = ck.value().derivatives()[i];
      for (int j = 0; j < 3; ++j)
      {
        Jd(i, j) = d[i].value().derivatives()[j];
        H(i, j) = ck.derivatives()[i].derivatives()[j];
      }
    }
    const double s = scale[k], sl = scale[k] * lambda[k];
    for (int i = 0; i < 3; ++i)
    {
      r[3 * v + i] += sl * dval(i);
      if (v == 0)
        r[iu + i] -= sl * dval(i);
      r[it + i] += sl * dc(i);
    }
    r[il + k] += s * ck.value().value();
    if (K.empty())
      continue;
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> Kt(
        K.data(), n, n);
    for (int i = 0; i < 3; ++i)
    {
      Kt(3 * v + i, il + k) += s * dval(i);
      Kt(il + k, 3 * v + i) += s * dval(i);
      if (v == 0)
      {
        Kt(iu + i, il + k) -= s * dval(i);
        Kt(il + k, iu + i) -= s * dval(i);
      }
      Kt(it + i, il + k) += s * dc(i);
      Kt(il + k, it + i) += s * dc(i);
      for (int j = 0; j < 3; ++j)
      {
        Kt(3 * v + i, it + j) += sl * Jd(i, j);
        Kt(it + j, 3 * v + i) += sl * Jd(i, j);
        if (v == 0)
        {
          Kt(iu + i, it + j) -= sl * Jd(i, j);
          Kt(it + j, iu + i) -= sl * Jd(i, j);
        }
      }
    }
    Kt.block<3, 3>(it, it) += sl * H;
  }
}
} // namespace textile::rigid
