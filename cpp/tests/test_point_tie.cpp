#include "fd.h"
#include <textile/junction/point_tie.h>

#include <gtest/gtest.h>

using namespace textile;

TEST(PointTie, TangentAndBalance)
{
  const std::vector<double> phi = {0.1, 0.2, 0.3, 0.4};
  const std::vector<double> gap0 = {0.01, -0.02, 0.0};
  std::vector<double> u = {0.1, 0.2, -0.3, 0.5, 0.1, 0.0, -0.2, 0.3, 0.1,
                           0.0, 0.0, 0.2, 0.4, -0.1, 0.3};
  const double k = 12.5;
  auto res = [&](const std::vector<double>& w)
  {
    std::vector<double> r(15, 0.0);
    junction::point_tie(k, phi, std::span(w.data(), 3), std::span(w.data() + 3, 12), gap0, r, {});
    return r;
  };
  std::vector<double> r(15, 0.0), K(225, 0.0);
  junction::point_tie(k, phi, std::span(u.data(), 3), std::span(u.data() + 3, 12), gap0, r, K);
  EXPECT_LT(test::relative_error(K, test::fd_jacobian(res, u, 1e-6)), 1e-8); // linear: FD exact
  // the tie force on the node balances the forces on the cell (sum phi = 1)
  for (int c = 0; c < 3; ++c)
  {
    double s = 0;
    for (int p = 0; p < 5; ++p)
      s += r[3 * p + c];
    EXPECT_NEAR(s, 0.0, 1e-14);
  }
}
