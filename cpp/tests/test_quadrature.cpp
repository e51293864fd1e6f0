#include <textile/beam/quadrature.h>

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

using namespace textile::beam;

TEST(GaussLegendre, ExactForDegree2nMinus1)
{
  for (int n = 1; n <= 8; ++n)
  {
    const auto rule = gauss_legendre(n);
    for (int k = 0; k <= 2 * n - 1; ++k)
    {
      double s = 0;
      for (int i = 0; i < n; ++i)
        s += rule.weights[i] * std::pow(rule.points[i], k);
      const double exact = (k % 2) ? 0.0 : 2.0 / (k + 1);
      EXPECT_NEAR(s, exact, 1e-14) << "n=" << n << " k=" << k; // round-off only
    }
  }
}

/// Integral of xi1^a xi2^b over the disk of radius R.
double disk_monomial(int a, int b, double R)
{
  if (a % 2 or b % 2)
    return 0.0;
  return 2.0 * std::tgamma((a + 1) / 2.0) * std::tgamma((b + 1) / 2.0)
         / std::tgamma((a + b + 2) / 2.0) * std::pow(R, a + b + 2) / (a + b + 2);
}

TEST(DiskQuadrature, ExactUpToOrder)
{
  const double R = 0.37;
  for (int order = 2; order <= 8; ++order)
  {
    const auto q = disk_quadrature(R, order);
    for (int a = 0; a <= order; ++a)
      for (int b = 0; a + b <= order; ++b)
      {
        double s = 0;
        for (std::size_t i = 0; i < q.size(); ++i)
          s += q.weights[i] * std::pow(q.xi1[i], a) * std::pow(q.xi2[i], b);
        // relative to R^(a+b+2), the monomial's scale; round-off only
        EXPECT_NEAR(s, disk_monomial(a, b, R), 1e-13 * std::pow(R, a + b + 2))
            << "order=" << order << " a=" << a << " b=" << b;
      }
  }
  // area and second moment, the quantities beam stiffnesses rest on
  const auto q = disk_quadrature(1.0, 2);
  double A = 0, I = 0;
  for (std::size_t i = 0; i < q.size(); ++i)
  {
    A += q.weights[i];
    I += q.weights[i] * q.xi1[i] * q.xi1[i];
  }
  EXPECT_NEAR(A, std::numbers::pi, 1e-14);
  EXPECT_NEAR(I, std::numbers::pi / 4, 1e-14);
}

TEST(DiskQuadrature, OrdersFourAndFiveUseRadonsSevenPoints)
{
  // the default section order: half the points of the polar rule (15 at
  // order 4), exactness checked in ExactUpToOrder
  for (int order : {4, 5})
  {
    const auto q = disk_quadrature(0.3, order);
    ASSERT_EQ(q.size(), 7u);
    EXPECT_EQ(q.xi1[0], 0.0); // the centre, weight A/4
    EXPECT_NEAR(q.weights[0], std::numbers::pi * 0.09 / 4, 1e-16);
    for (std::size_t i = 1; i < 7; ++i) // the hexagon at R sqrt(2/3)
      EXPECT_NEAR(std::hypot(q.xi1[i], q.xi2[i]), 0.3 * std::sqrt(2.0 / 3.0), 1e-15);
  }
  // degree 6 is not exact (so ExactUpToOrder could fail for order 5 + 1)
  const auto q = disk_quadrature(1.0, 4);
  double s = 0;
  for (std::size_t i = 0; i < q.size(); ++i)
    s += q.weights[i] * std::pow(q.xi1[i], 6);
  EXPECT_GT(std::abs(s - disk_monomial(6, 0, 1.0)), 1e-3);
}

TEST(DiskQuadrature, RejectsBadInput)
{
  EXPECT_THROW(disk_quadrature(-1.0, 4), std::invalid_argument);
  EXPECT_THROW(disk_quadrature(0.0, 4), std::invalid_argument);
  EXPECT_THROW(disk_quadrature(std::nan(""), 4), std::invalid_argument);
  EXPECT_THROW(disk_quadrature(1.0, 1), std::invalid_argument);
}
