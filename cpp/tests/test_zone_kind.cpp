// The crossing criterion and its hysteresis (is_crossing, detection.h): a
// zone near either threshold (angle, distance at the zone's ends) keeps the
// kind it had in the last pass, so that it does not flip between a point
// crossing and a line contact from pass to pass.
#include <textile/contact/intermediate_geometry.h>
#include <textile/contact/proximity_zone.h>

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

using namespace textile::contact;

namespace
{
constexpr double radius = 1.0, delta_factor = 2.0, parallel = 10.0 * std::numbers::pi / 180;
constexpr double delta = delta_factor * 2 * radius; // search distance
constexpr double h = 1.8;                           // centre lines' distance at the crossing
constexpr double half = 40.0;                       // fibres from -half to +half
constexpr int elements = 40;

/// Two straight fibres (linear elements) crossing at `angle` in parallel
/// planes h apart, and the zone from -t to t on both (where their distance
/// is `end_distance`).
struct Crossing
{
  Centrelines c;
  ProximityZone zone;
  Crossing(double angle, double end_distance)
  {
    c.order = 1;
    c.radius = {radius, radius};
    c.fibre_offsets = {0};
    for (int f = 0; f < 2; ++f)
    {
      const double a = f * angle;
      for (int k = 0; k <= elements; ++k)
      {
        const double t = -half + 2 * half * k / elements;
        c.x.insert(c.x.end(), {t * std::cos(a), t * std::sin(a), f * h});
      }
      c.fibre_offsets.push_back(c.x.size() / 3);
    }
    // 2 t^2 (1 - cos angle) + h^2 = end_distance^2
    const double t = std::sqrt((end_distance * end_distance - h * h) / (2 * (1 - std::cos(angle))));
    const double s = [](double x) { return (x + half) * elements / (2 * half); }(t);
    const double s0 = elements / 2.0;
    zone = {.fibre_i = 0, .fibre_j = 1, .a_i = 2 * s0 - s, .b_i = s, .a_j = 2 * s0 - s,
            .b_j = s, .min_distance = h, .s_i = s0, .s_j = s0};
  }
  bool crossing(double bias) const { return is_crossing(c, zone, parallel, delta_factor, bias); }
};

/// The distance at a fraction of the way from the crossing's to the search distance.
double between(double fraction) { return h + fraction * (delta - h); }
} // namespace

TEST(ZoneKind, EndDistanceThresholdHasHysteresis)
{
  const double angle = 30 * std::numbers::pi / 180;
  // ends 0.4 of the way: a line contact for a new zone, a crossing stays one
  const Crossing near(angle, between(0.4));
  EXPECT_FALSE(near.crossing(0.0));
  EXPECT_TRUE(near.crossing(crossing_bias));
  EXPECT_FALSE(near.crossing(-crossing_bias));
  // ends 0.6 of the way: a crossing for a new zone, a line contact stays one
  const Crossing far(angle, between(0.6));
  EXPECT_TRUE(far.crossing(0.0));
  EXPECT_TRUE(far.crossing(crossing_bias));
  EXPECT_FALSE(far.crossing(-crossing_bias));
  // beyond the margins the kind follows the geometry whatever it was
  EXPECT_FALSE(Crossing(angle, between(0.2)).crossing(crossing_bias));
  EXPECT_TRUE(Crossing(angle, between(0.8)).crossing(-crossing_bias));
}

TEST(ZoneKind, AngleThresholdHasHysteresis)
{
  const double deg = std::numbers::pi / 180;
  // 9 degrees: below parallel_angle (10), above (1 - bias) of it (7.5)
  const Crossing shallow(9 * deg, between(0.9));
  EXPECT_FALSE(shallow.crossing(0.0));
  EXPECT_TRUE(shallow.crossing(crossing_bias));
  // 11 degrees: above parallel_angle, below (1 + bias) of it (12.5)
  const Crossing steeper(11 * deg, between(0.9));
  EXPECT_TRUE(steeper.crossing(0.0));
  EXPECT_FALSE(steeper.crossing(-crossing_bias));
  EXPECT_FALSE(Crossing(7 * deg, between(0.9)).crossing(crossing_bias));
  EXPECT_TRUE(Crossing(13 * deg, between(0.9)).crossing(-crossing_bias));
}

TEST(ZoneKind, BlendedTangentIsContinuousAcrossAKink)
{
  // linear elements (0,0,0) -> (1,0,0) -> (2,1,0): a 45 degree kink at node 1
  Centrelines c;
  c.order = 1;
  c.x = {0, 0, 0, 1, 0, 0, 2, 1, 0};
  c.fibre_offsets = {0, 3};
  c.radius = {0.1};
  const Eigen::Vector3d left(1, 0, 0), right = Eigen::Vector3d(1, 1, 0).normalized();
  const Eigen::Vector3d bisector = (left + right).normalized();
  // outside the window: the element's own tangent
  EXPECT_LT((blended_tangent(c, 0, 1.0 - kink_blend) - left).norm(), 1e-14);
  EXPECT_LT((blended_tangent(c, 0, 1.0 + kink_blend) - right).norm(), 1e-14);
  EXPECT_LT((blended_tangent(c, 0, 0.1) - left).norm(), 1e-14); // no blending at fibre ends
  // both sides meet at the bisector: no jump as a point moves across the node
  EXPECT_LT((blended_tangent(c, 0, 1.0 - 1e-9) - bisector).norm(), 1e-8);
  EXPECT_LT((blended_tangent(c, 0, 1.0 + 1e-9) - bisector).norm(), 1e-8);
  EXPECT_LT((blended_tangent(c, 0, 1.0) - bisector).norm(), 1e-14);
  // and it turns monotonically in between
  double previous = -1;
  for (double s = 1.0 - kink_blend; s <= 1.0 + kink_blend + 1e-12; s += kink_blend / 8)
  {
    const double turned = std::atan2(blended_tangent(c, 0, s).y(), blended_tangent(c, 0, s).x());
    EXPECT_GE(turned, previous - 1e-14) << s;
    previous = turned;
  }
}
