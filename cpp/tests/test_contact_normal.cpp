// The normal of a contact element: crossing normal only where centre lines
// really cross, the centroid direction side by side (stability issue item 7).
#include <textile/contact/contact_normal.h>
#include <textile/contact/weaving_order.h>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

using namespace textile::contact;
using Vec3 = Eigen::Vector3d;

namespace
{
constexpr double radius = 1e-3, contact_distance = 2 * radius;
const double parallel_angle = 10 * std::numbers::pi / 180;

Vec3 in_plane(double degrees)
{
  const double a = degrees * std::numbers::pi / 180;
  return {std::cos(a), std::sin(a), 0.0};
}

Vec3 mean(const Vec3& a, const Vec3& b) { return (a + b).normalized(); }
} // namespace

TEST(ContactNormal, CoplanarFibresAtAnAngleGetTheInPlaneNormal)
{
  // side by side in z = 0, 30 degrees apart, centroids 1.9 R apart in the
  // plane: a line contact, whose normal must stay in the plane (t_i x t_j
  // = z would read a gap of -2R)
  for (double angle : {15.0, 30.0, 60.0})
  {
    const Vec3 ti = in_plane(0), tj = in_plane(angle), t = mean(ti, tj);
    const Vec3 d = 1.9 * radius * Vec3(-t.y(), t.x(), 0.0);
    const Vec3 N = contact_normal(ti, tj, t, d, Vec3::Zero(), parallel_angle, false,
                                  contact_distance);
    EXPECT_NEAR(N.z(), 0.0, 1e-15) << angle;
    EXPECT_NEAR(N.dot(d.normalized()), 1.0, 1e-12) << angle;
  }
}

TEST(ContactNormal, FibresLyingOnEachOtherGetTheCrossingNormal)
{
  const Vec3 ti = in_plane(0), tj = in_plane(40), t = mean(ti, tj);
  // centroids separated out of plane by the radii (plus an in-plane part)
  const Vec3 d(0.0, 0.3 * radius, -1.8 * radius);
  const Vec3 N = contact_normal(ti, tj, t, d, Vec3::Zero(), parallel_angle, false,
                                contact_distance);
  EXPECT_NEAR(N.z(), -1.0, 1e-15); // t_i x t_j, towards fibre i (below)
}

TEST(ContactNormal, CrossingZoneKeepsTheCrossingNormalAtZeroSeparation)
{
  // interpenetrating crossing (the weaving start): centroids coincide
  const Vec3 ti = in_plane(0), tj = in_plane(90), t = mean(ti, tj);
  const Vec3 N = contact_normal(ti, tj, t, Vec3::Zero(), Vec3::Zero(), parallel_angle, true,
                                contact_distance);
  EXPECT_NEAR(std::abs(N.z()), 1.0, 1e-15);
  // once set, the previous normal keeps the side under deep penetration
  const Vec3 below(0.0, 0.0, 0.3 * radius);
  const Vec3 kept = contact_normal(ti, tj, t, below, Vec3(0, 0, -1), parallel_angle, true,
                                   contact_distance);
  EXPECT_NEAR(kept.z(), -1.0, 1e-15);
}

TEST(ContactNormal, PreviousOrthogonalNormalDoesNotOrient)
{
  // a normal that changes kind (vertical -> in-plane) is oriented by the
  // centroid gap, not by the sign of a round-off dot product
  const Vec3 ti = in_plane(0), tj = in_plane(20), t = mean(ti, tj);
  const Vec3 d = -1.5 * radius * Vec3(-t.y(), t.x(), 0.0);
  const Vec3 N = contact_normal(ti, tj, t, d, Vec3(0, 0, 1), parallel_angle, false,
                                contact_distance);
  EXPECT_NEAR(N.dot(d.normalized()), 1.0, 1e-12);
}

TEST(ContactNormal, PreviousNormalOrientsOnlyWhenItTellsTheSide)
{
  // fibres side by side along x, the centroid gap along -y: the normal is
  // +-y. A previous normal nearly orthogonal to it (|cos| 0.05, half
  // orientation_cosine: a normal that changed kind, with some tilt) says
  // nothing about the side: the centroid gap orients it. One at |cos| 0.3
  // (three times orientation_cosine) keeps the side it had, against the
  // centroid gap (fibres pressed past each other's centre lines).
  const Vec3 t(1, 0, 0), d(0, -1.5 * radius, 0);
  const Vec3 tilted(0, 0.05, std::sqrt(1 - 0.05 * 0.05));
  EXPECT_NEAR(centroid_normal(t, d, tilted).y(), -1.0, 1e-15);
  const Vec3 telling(0, 0.3, std::sqrt(1 - 0.3 * 0.3));
  EXPECT_NEAR(centroid_normal(t, d, telling).y(), 1.0, 1e-15);
}

TEST(WeavingOrder, VerticalNormalFromTheOrder)
{
  // fibres 0, 1 in yarn 0 (warp), fibre 2 in yarn 1 (weft), weft on top
  const WeavingOrder order({0, 0, 1}, {0, -1, 1, 0}, 2);
  EXPECT_EQ(order.sign(2, 0), 1);  // fibre 2 above fibre 0: N = +z from 0 to 2
  EXPECT_EQ(order.sign(0, 2), -1);
  EXPECT_EQ(order.sign(0, 1), 0);  // one yarn: no order
  EXPECT_EQ(order.normal(0, 2), Vec3(0, 0, -1));
  EXPECT_EQ(order.normal(1, 0), Vec3::Zero());
}

TEST(WeavingOrder, RejectsInconsistentOrders)
{
  EXPECT_THROW(WeavingOrder({0, 1}, {0, 1, 1, 0}, 2), std::invalid_argument);  // not antisymmetric
  EXPECT_THROW(WeavingOrder({0, 1}, {0, 2, -2, 0}, 2), std::invalid_argument); // not -1, 0, 1
  EXPECT_THROW(WeavingOrder({0, 2}, {0, 1, -1, 0}, 2), std::invalid_argument); // yarn 2 of 2
  EXPECT_THROW(WeavingOrder({0, 1}, {0, 1, -1}, 2), std::invalid_argument);    // size
  EXPECT_THROW(WeavingOrder({0, 1}, {0, 1, -1, 0}, 2).sign(0, 2), std::invalid_argument);
}
