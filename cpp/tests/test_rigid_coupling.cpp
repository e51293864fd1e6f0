// Rigid bodies: rotations by rotation vectors, the multiplier coupling of a
// fibre end section (or a point) to a body, and body moments.
#include "../textile/rigid/rigid_coupling.h"
#include "../textile/rigid/rotation.h"
#include "coupling_case.h"
#include "fd.h"
#include "symmetric_tangent_check.h"

#include <gtest/gtest.h>

#include <numbers>
#include <vector>

using namespace textile::rigid;
using Vec3 = Eigen::Vector3d;

TEST(Rotation, FullTurnIsExact)
{
  // a body turned by 2 pi about any axis is back: R = I to round-off
  const Vec3 axis = Vec3(0.3, -0.5, 0.8).normalized();
  const Eigen::Matrix3d R = rotation_matrix(2 * std::numbers::pi * axis);
  EXPECT_LT((R - Eigen::Matrix3d::Identity()).norm(), 1e-15);
  // and a quarter turn about z maps x to y
  EXPECT_LT((rotate<double>(Vec3(0, 0, std::numbers::pi / 2), Vec3::UnitX()) - Vec3::UnitY()).norm(),
            1e-15);
}

TEST(Rotation, VectorMatrixRoundTripAndSmallAngles)
{
  for (double angle : {1e-12, 1e-7, 1e-3, 0.5, 3.0})
  {
    const Vec3 theta = angle * Vec3(0.2, 0.9, -0.4).normalized();
    const Eigen::Matrix3d R = rotation_matrix(theta);
    EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-15);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-15);
    EXPECT_LT((rotation_vector(R) - theta).norm(), 1e-14 * std::max(1.0, angle)) << angle;
  }
}

TEST(Rotation, LeftJacobianIsTheSpin)
{
  // exp([theta + d]) v - exp([theta]) v = (J_l(theta) d) x exp([theta]) v + O(d^2)
  const Vec3 theta(0.4, -0.7, 0.2), v(0.3, 1.0, -2.0), d(1e-7, -2e-7, 1.5e-7);
  const Vec3 diff = rotate<double>(theta + d, v) - rotate<double>(theta, v);
  const Vec3 spin = left_jacobian_times<double>(theta, d);
  EXPECT_LT((diff - spin.cross(rotate<double>(theta, v))).norm(), 1e-12);
}

namespace
{
using textile::test::CouplingCase;

/// A fully held section (or point): one multiplier per coupled value.
CouplingCase section_case(bool section, double angle)
{
  CouplingCase c = textile::test::coupling_case(section, angle);
  textile::test::set_multipliers(c, c.base.rows());
  return c;
}

std::vector<double> residual(const CouplingCase& c, const std::vector<double>& x)
{
  const int m = c.base.rows();
  std::vector<double> r(2 * m + 6, 0.0);
  rigid_coupling(c.base, std::span(x).subspan(0, m), std::span(x).subspan(m, 3),
                 std::span(x).subspan(m + 3, 3), std::span(x).subspan(m + 6, m), c.scale, r, {});
  return r;
}
} // namespace

class RigidCouplingTangent : public ::testing::TestWithParam<std::tuple<bool, double>>
{
};

TEST_P(RigidCouplingTangent, MatchesFiniteDifferencesAndIsSymmetric)
{
  const auto [section, angle] = GetParam();
  const CouplingCase c = section_case(section, angle);
  const int m = c.base.rows(), n = 2 * m + 6;
  const std::vector<double> x = textile::test::pack(c);
  std::vector<double> r(n, 0.0), K(n * n, 0.0);
  rigid_coupling(c.base, std::span(x).subspan(0, m), std::span(x).subspan(m, 3),
                 std::span(x).subspan(m + 3, 3), std::span(x).subspan(m + 6, m), c.scale, r, K);
  const auto Kfd = textile::test::fd_jacobian([&](const std::vector<double>& y)
                                              { return residual(c, y); }, x, 1e-6);
  textile::test::expect_symmetric_tangent(K, Kfd, n, 1e-8, 1e-14);
}

INSTANTIATE_TEST_SUITE_P(SectionsAndPoints, RigidCouplingTangent,
                         ::testing::Combine(::testing::Bool(),
                                            ::testing::Values(0.0, 1e-4, 0.3, 2.5)));

TEST(RigidCoupling, SatisfiedConstraintHasZeroRows)
{
  // q on the body: the constraint rows vanish, and the force on the body is
  // the reaction of the multipliers (equal and opposite on x0)
  CouplingCase c = section_case(true, 0.7);
  const Vec3 th(c.theta.data()), ctr(c.centre.data());
  const Vec3 x0 = ctr + rotate<double>(th, c.base.offset);
  const Vec3 g1 = rotate<double>(th, c.base.g1), g2 = rotate<double>(th, c.base.g2);
  for (int k = 0; k < 3; ++k)
  {
    c.q[k] = x0(k);
    c.q[3 + k] = g1(k);
    c.q[6 + k] = g2(k);
  }
  const std::vector<double> r = residual(c, textile::test::pack(c));
  for (int k = 0; k < 9; ++k)
    EXPECT_NEAR(r[15 + k], 0.0, 1e-15);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(r[9 + k], -r[k], 1e-15); // force on the centre = -force on x0
}

TEST(BodyMoment, TangentAndWork)
{
  const std::vector<double> theta = {0.3, -0.4, 0.9}, M = {1.0, -2.0, 0.5};
  std::vector<double> r(3, 0.0), K(9, 0.0);
  body_moment(theta, M, r, K);
  const auto Kfd = textile::test::fd_jacobian(
      [&](const std::vector<double>& t)
      {
        std::vector<double> rr(3, 0.0);
        body_moment(t, M, rr, {});
        return rr;
      },
      theta, 1e-7);
  for (int k = 0; k < 9; ++k)
    EXPECT_NEAR(K[k], Kfd[k], 1e-7);
  // at theta = 0 the generalized force is the moment itself
  std::vector<double> r0(3, 0.0);
  body_moment(std::vector<double>{0, 0, 0}, M, r0, {});
  for (int k = 0; k < 3; ++k)
    EXPECT_DOUBLE_EQ(r0[k], -M[k]);
}
