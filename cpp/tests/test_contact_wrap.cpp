// Wraps: a fibre bent around another over a finite angle gets contact
// elements along the wrap, each facing the other fibre radially (stability
// issue item 6); point crossings, straight or kinked, keep one element.
#include <textile/contact/intermediate_geometry.h>
#include <textile/contact/proximity_zone.h>
#include <textile/contact/wrap_contact.h>

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

using namespace textile::contact;
using Vec3 = Eigen::Vector3d;

namespace
{
constexpr double R = 1e-3, r = 1e-5, pi = std::numbers::pi;

/// Fibre 0: thick, straight along y. Fibre 1: thin, in the plane y = 0,
/// from `points` (quadratic elements: an odd number of nodes).
struct Scene
{
  Centrelines c;
  std::vector<double> g;
  explicit Scene(const std::vector<Vec3>& points)
  {
    c.order = 2;
    c.radius = {R, r};
    c.fibre_offsets = {0};
    for (int k = 0; k <= 8; ++k)
      c.x.insert(c.x.end(), {0.0, -2 * R + 4 * R * k / 8, 0.0});
    c.fibre_offsets.push_back(9);
    for (const auto& p : points)
      c.x.insert(c.x.end(), {p.x(), p.y(), p.z()});
    c.fibre_offsets.push_back(c.x.size() / 3);
    for (std::size_t n = 0; n < c.x.size() / 3; ++n) // g1 = x on A, y on B
      g.insert(g.end(), {double(n >= 9), double(n < 9), 0.0, 0.0, 0.0, 1.0});
  }
  std::vector<ContactPoint> points(double spacing)
  {
    const auto zones = find_proximity_zones(c, 2.0, 1.0);
    EXPECT_EQ(zones.size(), 1u);
    return contact_points(c, SectionVectors{g}, zones.at(0), spacing, 0.17, 2.0,
                          Vec3::Zero(), 0.17);
  }
};

/// A quarter turn of radius R + r over the top of fibre 0, with straight
/// legs of length 2R leaving tangentially (2 n + 1 nodes per part).
std::vector<Vec3> quarter_wrap(int n)
{
  const double rho = R + r;
  std::vector<Vec3> p;
  for (int k = 0; k < 2 * n; ++k)
    p.emplace_back(-2 * R + 2 * R * k / (2 * n), 0, rho);
  for (int k = 0; k < 2 * n; ++k)
  {
    const double a = pi / 2 - (pi / 2) * k / (2 * n);
    p.emplace_back(rho * std::cos(a), 0, rho * std::sin(a));
  }
  for (int k = 0; k <= 2 * n; ++k)
    p.emplace_back(rho, 0, -2 * R * k / (2 * n));
  return p;
}
} // namespace

TEST(Wrap, QuarterTurnIsSpreadWithRadialNormals)
{
  Scene s(quarter_wrap(8));
  const auto points = s.points(0.5 * (pi / 2 * (R + r)) / 8);
  int on_arc = 0;
  for (const auto& p : points)
  {
    EXPECT_TRUE(p.wrap);
    EXPECT_FALSE(p.crossing);
    // facing the closest point of the thick fibre: centroid gap radial
    // from its axis, orthogonal to it
    EXPECT_NEAR(p.centroid_gap.y(), 0.0, 1e-15);
    const Vec3 x = -p.centroid_gap; // from A's axis to B's centre line
    const double angle = std::atan2(x.z(), x.x());
    on_arc += angle >= 0 and angle <= pi / 2;
    if (angle >= 0 and angle <= pi / 2)
      EXPECT_NEAR(x.norm(), R + r, 1e-5 * R); // in touch all along (quadratic elements on a circle: 3e-6)
  }
  EXPECT_GE(on_arc, 16); // two per element of the arc at least
  // the arc's elements stand for its length
  double arc = 0;
  for (const auto& p : points)
  {
    const Vec3 x = -p.centroid_gap;
    const double angle = std::atan2(x.z(), x.x());
    if (angle >= 0 and angle <= pi / 2)
      arc += p.length;
  }
  EXPECT_NEAR(arc, pi / 2 * (R + r), 0.1 * pi / 2 * (R + r) / 8); // within the ends' pieces
}

TEST(Wrap, StraightCrossingKeepsOnePoint)
{
  std::vector<Vec3> p;
  for (int k = 0; k <= 16; ++k)
    p.emplace_back(-2 * R + 4 * R * k / 16, 0, R + r);
  Scene s(p);
  const auto points = s.points(R / 8);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_TRUE(points[0].crossing);
}

TEST(Wrap, KinkedCrossingKeepsOnePoint)
{
  // a fibre kinked by 20 degrees at the crossing, its legs leaving the
  // other fibre (pressed onto it at that one point): its tangent turns, but
  // it touches only at the kink
  const double half = 10 * pi / 180;
  std::vector<Vec3> p;
  for (int k = -8; k <= 8; ++k)
  {
    const double s = 2 * R * k / 8;
    p.emplace_back(s * std::cos(half), 0, R + r + std::abs(s) * std::sin(half));
  }
  Scene s(p);
  const auto points = s.points(R / 8);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_TRUE(points[0].crossing);
}
