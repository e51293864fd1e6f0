#include "fd.h"
#include <textile/loads/end_moment.h>

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

using namespace textile;

TEST(EndMoment, TangentMatchesFiniteDifferences)
{
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int trial = 0; trial < 5; ++trial)
  {
    std::vector<double> M = {U(gen), U(gen), U(gen)};
    // a deformed, non-orthonormal section
    std::vector<double> g = {1 + 0.2 * U(gen), 0.3 * U(gen), 0.3 * U(gen),
                             0.3 * U(gen),     1 + 0.2 * U(gen), 0.3 * U(gen)};
    std::vector<double> f(6), J(36);
    loads::end_moment(M, g, f, J);
    auto fun = [&](const std::vector<double>& gg)
    {
      std::vector<double> ff(6);
      loads::end_moment(M, gg, ff, {});
      return ff;
    };
    const auto Jfd = test::fd_jacobian(fun, g, 1e-6);
    EXPECT_LT(test::relative_error(J, Jfd), 1e-6); // central FD truncation ~1e-9
  }
}

TEST(EndMoment, ResultantIsTheMomentForOrthonormalSections)
{
  // rotate an orthonormal section arbitrarily
  const Eigen::Matrix3d R
      = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d g1 = R.col(0), g2 = R.col(1);
  std::vector<double> g = {g1(0), g1(1), g1(2), g2(0), g2(1), g2(2)};
  std::vector<double> M = {0.3, -1.2, 0.8}, f(6);
  loads::end_moment(M, g, f, {});
  const Eigen::Vector3d res = g1.cross(Eigen::Vector3d(f[0], f[1], f[2]))
                              + g2.cross(Eigen::Vector3d(f[3], f[4], f[5]));
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(res(i), M[i], 1e-14); // identity, round-off only
}
