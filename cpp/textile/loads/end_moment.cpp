#include "end_moment.h"

#include <Eigen/Dense>
#include <stdexcept>

namespace textile::loads
{
namespace
{
Eigen::Matrix3d skew(const Eigen::Vector3d& a)
{
  Eigen::Matrix3d S;
  S << 0, -a(2), a(1), a(2), 0, -a(0), -a(1), a(0), 0;
  return S;
}
} // namespace

void end_moment(std::span<const double> M_, std::span<const double> g, std::span<double> f,
                std::span<double> dfdg)
{
  if (M_.size() != 3 or g.size() != 6 or f.size() != 6 or (!dfdg.empty() and dfdg.size() != 36))
    throw std::invalid_argument("end_moment: wrong array size");
  const Eigen::Map<const Eigen::Vector3d> M(M_.data()), g1(g.data()), g2(g.data() + 3);
  const Eigen::Vector3d c = g1.cross(g2);
  const double nc = c.norm();
  if (!(nc > 0))
    throw std::runtime_error("end_moment: degenerate section (g1 parallel to g2)");
  const Eigen::Vector3d n = c / nc;
  const double m = M.dot(n);
  const Eigen::Vector3d Ms = M - 0.5 * m * n;
  const Eigen::Vector3d* ga[2] = {nullptr, nullptr};
  const Eigen::Vector3d g1v = g1, g2v = g2;
  ga[0] = &g1v;
  ga[1] = &g2v;
  for (int a = 0; a < 2; ++a)
    Eigen::Map<Eigen::Vector3d>(f.data() + 3 * a) = Ms.cross(*ga[a]);
  if (dfdg.empty())
    return;
  // dn = Dn[0] dg1 + Dn[1] dg2
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - n * n.transpose();
  const Eigen::Matrix3d Dn[2] = {-P * skew(g2v) / nc, P * skew(g1v) / nc};
  Eigen::Map<Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> J(dfdg.data());
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
    {
      Eigen::Matrix3d blk = -0.5 * (n.cross(*ga[a])) * (M.transpose() * Dn[b])
                            + 0.5 * m * skew(*ga[a]) * Dn[b];
      if (a == b)
        blk += skew(M) - 0.5 * m * skew(n);
      J.block<3, 3>(3 * a, 3 * b) = blk;
    }
}

} // namespace textile::loads
