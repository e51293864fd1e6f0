// Contact detection, first step: centre lines, broad phase, proximity zones.
#include <textile/contact/broad_phase.h>
#include <textile/contact/centreline.h>
#include <textile/contact/proximity_zone.h>
#include <textile/geometry_error.h>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

using namespace textile::contact;
using Vec3 = Eigen::Vector3d;

namespace
{
/// Centre lines from each fibre's element end points (ne+1 points per
/// fibre); order 2 puts the middle node halfway, so elements stay straight
/// and the abscissa of end point k is exactly k.
Centrelines make_centrelines(int order, const std::vector<std::vector<Vec3>>& fibres,
                             const std::vector<double>& radius)
{
  Centrelines c;
  c.order = order;
  c.radius = radius;
  c.fibre_offsets.push_back(0);
  for (const auto& pts : fibres)
  {
    for (std::size_t k = 0; k < pts.size(); ++k)
    {
      if (order == 2 && k > 0)
      {
        const Vec3 m = 0.5 * (pts[k - 1] + pts[k]);
        c.x.insert(c.x.end(), {m[0], m[1], m[2]});
      }
      c.x.insert(c.x.end(), {pts[k][0], pts[k][1], pts[k][2]});
    }
    c.fibre_offsets.push_back(static_cast<std::int64_t>(c.x.size() / 3));
  }
  return c;
}

/// ne+1 equally spaced points from a to b.
std::vector<Vec3> straight(const Vec3& a, const Vec3& b, int ne)
{
  std::vector<Vec3> p;
  for (int k = 0; k <= ne; ++k)
    p.push_back(a + (b - a) * (static_cast<double>(k) / ne));
  return p;
}

/// Polyline through corners, legs[l] elements on leg l.
std::vector<Vec3> polyline(const std::vector<Vec3>& corners, const std::vector<int>& legs)
{
  std::vector<Vec3> p = {corners[0]};
  for (std::size_t l = 0; l + 1 < corners.size(); ++l)
  {
    auto leg = straight(corners[l], corners[l + 1], legs[l]);
    p.insert(p.end(), leg.begin() + 1, leg.end());
  }
  return p;
}

constexpr double inf = std::numeric_limits<double>::infinity();

class ProximityZones : public ::testing::TestWithParam<int>
{
};
} // namespace

// ---------------------------------------------------------------------------
TEST(ContactCentreline, QuadraticInterpolationAndTangent)
{
  // x(xi) = (xi, xi^2, 0) on element 0, a straight element 1 after it
  Centrelines c;
  c.order = 2;
  c.x = {-1, 1, 0, 0, 0, 0, 1, 1, 0, 2, 1, 0, 3, 1, 0};
  c.fibre_offsets = {0, 5};
  c.radius = {0.1};
  ASSERT_EQ(c.num_fibres(), 1);
  ASSERT_EQ(c.num_elements(0), 2);
  for (double s : {0.0, 0.25, 0.5, 0.8, 1.0})
  {
    const double xi = 2 * s - 1;
    EXPECT_LT((c.position(0, s) - Vec3(xi, xi * xi, 0)).norm(), 1e-15) << s;
    if (s < 1.0) // at s = 1 the right element (straight) is used
      EXPECT_LT((c.tangent(0, s) - 2 * Vec3(1, 2 * xi, 0)).norm(), 1e-14) << s;
  }
  EXPECT_LT((c.tangent(0, 1.0) - Vec3(2, 0, 0)).norm(), 1e-14);
  EXPECT_LT((c.position(0, 2.0) - Vec3(3, 1, 0)).norm(), 1e-15);
  EXPECT_LT((c.position(0, 1.5) - Vec3(2, 1, 0)).norm(), 1e-15);
  EXPECT_THROW(c.position(0, 2.0 + 1e-9), std::invalid_argument);
  EXPECT_THROW(c.position(0, -1e-9), std::invalid_argument);
  EXPECT_THROW(c.position(1, 0.0), std::invalid_argument);

  // chords node to node; the sag bounds (and here equals) the curve's
  // distance from the chord at the chord's middle
  const auto segs = make_segments(c);
  ASSERT_EQ(segs.size(), 4u);
  EXPECT_DOUBLE_EQ(segs[0].sag, 0.25);
  EXPECT_DOUBLE_EQ(segs[1].sag, 0.25);
  EXPECT_DOUBLE_EQ(segs[2].sag, 0.0);
  EXPECT_DOUBLE_EQ(segs[1].s0, 0.5);
  EXPECT_DOUBLE_EQ(segs[1].s1, 1.0);
  EXPECT_EQ(segs[3].index, 3);
  const Vec3 mid_chord = 0.5 * (segs[0].p0 + segs[0].p1);
  EXPECT_NEAR((c.position(0, 0.25) - mid_chord).norm(), segs[0].sag, 1e-15);
  EXPECT_NEAR(segs[3].arc1, 2 * std::sqrt(2.0) + 2.0, 1e-14);
}

TEST(ContactCentreline, LinearElements)
{
  const auto c = make_centrelines(1, {straight({0, 0, 0}, {4, 0, 0}, 4)}, {0.1});
  EXPECT_EQ(c.num_elements(0), 4);
  EXPECT_LT((c.position(0, 2.75) - Vec3(2.75, 0, 0)).norm(), 1e-15);
  EXPECT_LT((c.tangent(0, 2.75) - Vec3(1, 0, 0)).norm(), 1e-15);
  const auto segs = make_segments(c);
  ASSERT_EQ(segs.size(), 4u);
  EXPECT_EQ(segs[2].sag, 0.0);
  EXPECT_DOUBLE_EQ(segs[2].arc0, 2.0);
}

TEST(ContactCentreline, RejectsBadInput)
{
  auto good = make_centrelines(1, {straight({0, 0, 0}, {1, 0, 0}, 2)}, {0.1});
  EXPECT_NO_THROW(good.validate());
  auto c = good;
  c.radius = {-0.1};
  EXPECT_THROW(find_proximity_zones(c, 2.0, 1.0), std::invalid_argument);
  c = good;
  c.radius = {0.0};
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = good;
  c.x[4] = std::nan(""); // a diverged state: a domain error, not a bug
  EXPECT_THROW(find_proximity_zones(c, 2.0, 1.0), textile::GeometryError);
  c = good;
  c.order = 3;
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = good;
  c.order = 2; // 3 nodes: one quadratic element, fine
  EXPECT_NO_THROW(c.validate());
  c.fibre_offsets = {0, 2, 3}; // a 1-node fibre
  c.radius = {0.1, 0.1};
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = good;
  c.fibre_offsets = {0, 2};
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = good;
  c.radius = {};
  EXPECT_THROW(c.validate(), std::invalid_argument);
  EXPECT_THROW(find_proximity_zones(good, 0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(find_proximity_zones(good, -1.0, 1.0), std::invalid_argument);
  EXPECT_THROW(find_proximity_zones(good, std::nan(""), 1.0), std::invalid_argument);
  EXPECT_THROW(find_proximity_zones(good, 2.0, -1.0), std::invalid_argument);
  EXPECT_THROW(find_proximity_zones(good, 2.0, std::nan("")), std::invalid_argument);
  EXPECT_NO_THROW(find_proximity_zones(good, 2.0, inf));
  try
  {
    find_proximity_zones(good, 0.0, 1.0);
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string(e.what()).find("delta_factor"), std::string::npos) << e.what();
  }
  const auto segs = make_segments(good);
  const std::vector<double> short_reach = {0.1};
  EXPECT_THROW(find_candidate_pairs(segs, short_reach, 0.0), std::invalid_argument);
}

// ---------------------------------------------------------------------------
TEST(ContactSegmentDistance, SkewParallelAndDegenerate)
{
  // skew, closest points inside both
  auto d = segment_distance({-1, 0, 0}, {1, 0, 0}, {0.3, -1, 2}, {0.3, 1, 2});
  EXPECT_NEAR(d.distance, 2.0, 1e-15);
  EXPECT_NEAR(d.t, 0.65, 1e-15);
  EXPECT_NEAR(d.u, 0.5, 1e-15);
  // skew, closest point at an end of one
  d = segment_distance({0, 0, 0}, {1, 0, 0}, {2, -1, 1}, {2, 1, 1});
  EXPECT_NEAR(d.distance, std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(d.t, 1.0, 1e-15);
  // parallel, overlapping: distance exact, closest pair inside the overlap
  d = segment_distance({0, 0, 0}, {2, 0, 0}, {1, 0.3, 0}, {3, 0.3, 0});
  EXPECT_NEAR(d.distance, 0.3, 1e-15);
  EXPECT_GE(d.t, 0.5 - 1e-15);
  // antiparallel, disjoint along their line
  d = segment_distance({0, 0, 0}, {1, 0, 0}, {4, 0.0, 4}, {2, 0.0, 4});
  EXPECT_NEAR(d.distance, std::sqrt(1.0 + 16.0), 1e-14);
  EXPECT_NEAR(d.t, 1.0, 1e-15);
  EXPECT_NEAR(d.u, 1.0, 1e-15);
  // nearly parallel (1e-9 rad)
  d = segment_distance({0, 0, 0}, {1, 0, 0}, {0, 0.5, 0}, {1, 0.5 + 1e-9, 0});
  EXPECT_NEAR(d.distance, 0.5, 1e-12);
  // collinear, touching
  d = segment_distance({0, 0, 0}, {1, 0, 0}, {1, 0, 0}, {2, 0, 0});
  EXPECT_NEAR(d.distance, 0.0, 1e-15);
  // degenerate segments (points)
  d = segment_distance({0, 0, 0}, {0, 0, 0}, {3, 4, 0}, {3, 4, 0});
  EXPECT_NEAR(d.distance, 5.0, 1e-15);
  d = segment_distance({0, 0, 0}, {0, 0, 0}, {-1, 1, 0}, {1, 1, 0});
  EXPECT_NEAR(d.distance, 1.0, 1e-15);
  EXPECT_NEAR(d.u, 0.5, 1e-15);
}

// ---------------------------------------------------------------------------
TEST_P(ProximityZones, Crossing90Degrees)
{
  const int order = GetParam();
  const double r = 0.1, delta = 2.0, h = 0.15, c = delta * 2 * r;
  const auto cl = make_centrelines(
      order, {straight({-5, 0, 0}, {5, 0, 0}, 20), straight({1.3, -5, h}, {1.3, 5, h}, 20)},
      {r, r});
  const auto zones = find_proximity_zones(cl, delta, 1.0);
  ASSERT_EQ(zones.size(), 1u);
  const auto& z = zones[0];
  EXPECT_EQ(z.fibre_i, 0);
  EXPECT_EQ(z.fibre_j, 1);
  EXPECT_NEAR(z.min_distance, h, 1e-12);
  EXPECT_NEAR(z.s_i, 12.6, 1e-10);
  EXPECT_NEAR(z.s_j, 10.0, 1e-10);
  // the close parts: |x - x*| < sqrt(c^2 - h^2), 0.5 length per unit s
  const double w = std::sqrt(c * c - h * h) / 0.5;
  EXPECT_NEAR(z.a_i, 12.6 - w, 1e-10);
  EXPECT_NEAR(z.b_i, 12.6 + w, 1e-10);
  EXPECT_NEAR(z.a_j, 10.0 - w, 1e-10);
  EXPECT_NEAR(z.b_j, 10.0 + w, 1e-10);
}

TEST_P(ProximityZones, Crossing5Degrees)
{
  const int order = GetParam();
  const double r = 0.1, delta = 2.0, h = 0.1, c = delta * 2 * r;
  const double a = 5.0 * std::numbers::pi / 180.0;
  const Vec3 x0(0.7, 0, h), d(std::cos(a), std::sin(a), 0);
  const auto cl = make_centrelines(
      order, {straight({-10, 0, 0}, {10, 0, 0}, 40), straight(x0 - 10 * d, x0 + 10 * d, 40)},
      {r, r});
  const auto zones = find_proximity_zones(cl, delta, 1.0);
  ASSERT_EQ(zones.size(), 1u);
  const auto& z = zones[0];
  EXPECT_EQ(z.fibre_i, 0);
  EXPECT_EQ(z.fibre_j, 1);
  EXPECT_NEAR(z.min_distance, h, 1e-12);
  EXPECT_NEAR(z.s_i, 21.4, 1e-9);
  EXPECT_NEAR(z.s_j, 20.0, 1e-9);
  // a long thin zone: |u| sin(5 deg) < sqrt(c^2 - h^2) on both fibres
  const double w = std::sqrt(c * c - h * h) / std::sin(a) / 0.5;
  EXPECT_GT(w, 8.0);
  EXPECT_NEAR(z.a_i, 21.4 - w, 1e-9);
  EXPECT_NEAR(z.b_i, 21.4 + w, 1e-9);
  EXPECT_NEAR(z.a_j, 20.0 - w, 1e-9);
  EXPECT_NEAR(z.b_j, 20.0 + w, 1e-9);
}

TEST_P(ProximityZones, ParallelFibresGiveOneLongZone)
{
  const int order = GetParam();
  const double r = 0.1, delta = 2.0, h = 0.3, c = delta * 2 * r;
  // aligned: the whole fibres
  auto cl = make_centrelines(
      order, {straight({0, 0, 0}, {10, 0, 0}, 20), straight({0, h, 0}, {10, h, 0}, 20)}, {r, r});
  auto zones = find_proximity_zones(cl, delta, 1.0);
  ASSERT_EQ(zones.size(), 1u);
  EXPECT_NEAR(zones[0].min_distance, h, 1e-12);
  EXPECT_NEAR(zones[0].a_i, 0.0, 1e-12);
  EXPECT_NEAR(zones[0].b_i, 20.0, 1e-12);
  EXPECT_NEAR(zones[0].a_j, 0.0, 1e-12);
  EXPECT_NEAR(zones[0].b_j, 20.0, 1e-12);

  // shifted by 2.5 along: the overlap, extended past each end by
  // sqrt(c^2 - h^2) on the fibre that goes on
  cl = make_centrelines(
      order, {straight({0, 0, 0}, {10, 0, 0}, 20), straight({2.5, 0, h}, {12.5, 0, h}, 20)},
      {r, r});
  zones = find_proximity_zones(cl, delta, 1.0);
  ASSERT_EQ(zones.size(), 1u);
  const double w = std::sqrt(c * c - h * h);
  EXPECT_NEAR(zones[0].min_distance, h, 1e-12);
  EXPECT_NEAR(zones[0].a_i, (2.5 - w) / 0.5, 1e-10);
  EXPECT_NEAR(zones[0].b_i, 20.0, 1e-12);
  EXPECT_NEAR(zones[0].a_j, 0.0, 1e-12);
  EXPECT_NEAR(zones[0].b_j, (7.5 + w) / 0.5, 1e-10);

  // beyond the criterion: nothing
  cl = make_centrelines(
      order, {straight({0, 0, 0}, {10, 0, 0}, 20), straight({0, 0, 0.41}, {10, 0, 0.41}, 20)},
      {r, r});
  EXPECT_TRUE(find_proximity_zones(cl, delta, 1.0).empty());
}

TEST_P(ProximityZones, FibreLoopingBackOnItself)
{
  const int order = GetParam();
  const double r = 0.1, delta = 2.0, h = 0.1, c = delta * 2 * r;
  // leg 1 along x at z = 0 (s 0..20), then up, back, and down across leg 1
  // at x = 5 on leg 4 (s 60..90) at height h
  const auto pts = polyline({{0, 0, 0}, {10, 0, 0}, {10, 10, h}, {5, 10, h}, {5, -5, h}},
                            {20, 20, 20, 30});
  const auto cl = make_centrelines(order, {pts}, {r});
  const auto zones = find_proximity_zones(cl, delta, 1.0);
  ASSERT_EQ(zones.size(), 1u);
  const auto& z = zones[0];
  EXPECT_EQ(z.fibre_i, 0);
  EXPECT_EQ(z.fibre_j, 0);
  EXPECT_NEAR(z.min_distance, h, 1e-12);
  EXPECT_NEAR(z.s_i, 10.0, 1e-10);
  EXPECT_NEAR(z.s_j, 80.0, 1e-10);
  const double w = std::sqrt(c * c - h * h) / 0.5;
  EXPECT_NEAR(z.a_i, 10.0 - w, 1e-10);
  EXPECT_NEAR(z.b_i, 10.0 + w, 1e-10);
  EXPECT_NEAR(z.a_j, 80.0 - w, 1e-10);
  EXPECT_NEAR(z.b_j, 80.0 + w, 1e-10);
  EXPECT_LT(z.b_i, z.a_j); // disjoint

  // no self contact wanted
  EXPECT_TRUE(find_proximity_zones(cl, delta, inf).empty());
  // an exclusion shorter than the search distance finds the fibre's corners
  EXPECT_GT(find_proximity_zones(cl, delta, 0.01).size(), 1u);
}

TEST_P(ProximityZones, ThreeFibresMeetingAtOnePoint)
{
  const int order = GetParam();
  const double r = 0.1, delta = 2.0, c = delta * 2 * r;
  const double z[3] = {0.0, 0.05, 0.1};
  std::vector<std::vector<Vec3>> fibres;
  for (int f = 0; f < 3; ++f)
  {
    const double a = f * std::numbers::pi / 3;
    const Vec3 d(std::cos(a), std::sin(a), 0), o(0, 0, z[f]);
    fibres.push_back(straight(o - 5 * d, o + 5 * d, 20));
  }
  const auto zones = find_proximity_zones(make_centrelines(order, fibres, {r, r, r}), delta, 1.0);
  ASSERT_EQ(zones.size(), 3u);
  const int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
  for (int k = 0; k < 3; ++k)
  {
    const auto& zk = zones[k];
    EXPECT_EQ(zk.fibre_i, pairs[k][0]);
    EXPECT_EQ(zk.fibre_j, pairs[k][1]);
    const double h = z[pairs[k][1]] - z[pairs[k][0]];
    EXPECT_NEAR(zk.min_distance, h, 1e-12);
    EXPECT_NEAR(zk.s_i, 10.0, 1e-10);
    EXPECT_NEAR(zk.s_j, 10.0, 1e-10);
    // 60 or 120 degrees between each pair
    const double w = std::sqrt(c * c - h * h) / std::sin(std::numbers::pi / 3) / 0.5;
    EXPECT_NEAR(zk.a_i, 10.0 - w, 1e-10);
    EXPECT_NEAR(zk.b_i, 10.0 + w, 1e-10);
    EXPECT_NEAR(zk.a_j, 10.0 - w, 1e-10);
    EXPECT_NEAR(zk.b_j, 10.0 + w, 1e-10);
  }
}

TEST_P(ProximityZones, DifferentRadiiUseTheirSum)
{
  const int order = GetParam();
  const double delta = 1.5;
  auto crossing = [&](double h, double ri, double rj)
  {
    return make_centrelines(
        order, {straight({-2, 0, 0}, {2, 0, 0}, 8), straight({0, -2, h}, {0, 2, h}, 8)},
        {ri, rj});
  };
  // criterion 1.5 (0.1 + 0.3) = 0.6
  auto zones = find_proximity_zones(crossing(0.5, 0.1, 0.3), delta, 1.0);
  ASSERT_EQ(zones.size(), 1u);
  const double w = std::sqrt(0.36 - 0.25) / 0.5;
  EXPECT_NEAR(zones[0].min_distance, 0.5, 1e-12);
  EXPECT_NEAR(zones[0].a_i, 4.0 - w, 1e-10);
  EXPECT_NEAR(zones[0].b_j, 4.0 + w, 1e-10);
  EXPECT_TRUE(find_proximity_zones(crossing(0.61, 0.1, 0.3), delta, 1.0).empty());
  EXPECT_EQ(find_proximity_zones(crossing(0.59, 0.3, 0.1), delta, 1.0).size(), 1u);
  // criterion 1.5 (0.1 + 0.1) = 0.3
  EXPECT_TRUE(find_proximity_zones(crossing(0.5, 0.1, 0.1), delta, 1.0).empty());
}

INSTANTIATE_TEST_SUITE_P(Orders, ProximityZones, ::testing::Values(1, 2),
                         [](const auto& info) { return "order" + std::to_string(info.param); });

// ---------------------------------------------------------------------------
namespace
{
/// Wavy, curved (quadratic elements with off-chord middle nodes) random
/// fibres in a cube, some of them bending back near themselves.
Centrelines random_bundle(int num_fibres, int num_elements, double box, unsigned seed)
{
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  Centrelines c;
  c.order = 2;
  c.fibre_offsets.push_back(0);
  const double length = 5.0;
  for (int f = 0; f < num_fibres; ++f)
  {
    const Vec3 start(box * U(gen), box * U(gen), box * U(gen));
    Vec3 d(U(gen) - 0.5, U(gen) - 0.5, U(gen) - 0.5);
    d.normalize();
    Vec3 n = d.cross(Vec3(U(gen) - 0.5, U(gen) - 0.5, U(gen) - 0.5)).normalized();
    const double amp = 0.4 * U(gen), waves = 1.0 + 3.0 * U(gen);
    // a few fibres fold like a hairpin to have self contacts
    const bool fold = f % 10 == 0;
    const int nn = 2 * num_elements + 1;
    for (int k = 0; k < nn; ++k)
    {
      const double s = static_cast<double>(k) / (nn - 1);
      Vec3 p;
      if (fold)
      {
        const double th = 1.9 * std::numbers::pi * s;
        p = start + 0.8 * (std::sin(th) * d + (1 - std::cos(th)) * n) + 0.1 * s * d.cross(n);
      }
      else
        p = start + length * s * d + amp * std::sin(2 * std::numbers::pi * waves * s) * n;
      c.x.insert(c.x.end(), {p[0], p[1], p[2]});
    }
    c.fibre_offsets.push_back(static_cast<std::int64_t>(c.x.size() / 3));
    c.radius.push_back(0.03 + 0.05 * U(gen));
  }
  return c;
}
} // namespace

TEST(BroadPhase, SameCandidatesAsBruteForceBoxOverlap)
{
  const auto c = random_bundle(100, 20, 6.0, 7);
  const auto segs = make_segments(c);
  const double delta = 2.5, excl = 0.3;
  std::vector<double> reach(segs.size());
  for (std::size_t s = 0; s < segs.size(); ++s)
    reach[s] = delta * c.radius[segs[s].fibre] + segs[s].sag;
  const auto pairs = find_candidate_pairs(segs, reach, excl);

  std::vector<std::pair<int, int>> brute;
  const int n = static_cast<int>(segs.size());
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b)
    {
      bool overlap = true;
      for (int d = 0; d < 3; ++d)
      {
        const double lo_a = std::min(segs[a].p0[d], segs[a].p1[d]) - reach[a];
        const double hi_a = std::max(segs[a].p0[d], segs[a].p1[d]) + reach[a];
        const double lo_b = std::min(segs[b].p0[d], segs[b].p1[d]) - reach[b];
        const double hi_b = std::max(segs[b].p0[d], segs[b].p1[d]) + reach[b];
        overlap = overlap && lo_a <= hi_b && lo_b <= hi_a;
      }
      if (overlap && !self_excluded(segs[a], segs[b], excl))
        brute.emplace_back(a, b);
    }
  EXPECT_GT(brute.size(), 1000u);
  EXPECT_EQ(pairs, brute);
}

TEST(ProximityZonesRandom, GridFindsTheSameClosePairsAsBruteForce)
{
  const auto c = random_bundle(100, 20, 6.0, 11);
  const auto segs = make_segments(c);
  const double delta = 2.5, excl = 0.3;
  const auto grid = find_close_pairs(c, segs, delta, excl);

  std::vector<ClosePair> brute;
  const int n = static_cast<int>(segs.size());
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b)
      if (!self_excluded(segs[a], segs[b], excl))
        if (auto p = close_pair(c, segs, a, b, delta))
          brute.push_back(*p);
  ASSERT_GT(brute.size(), 100u);
  ASSERT_EQ(grid.size(), brute.size());
  int self_pairs = 0;
  for (std::size_t k = 0; k < grid.size(); ++k)
  {
    EXPECT_EQ(grid[k].seg_i, brute[k].seg_i);
    EXPECT_EQ(grid[k].seg_j, brute[k].seg_j);
    EXPECT_EQ(grid[k].distance, brute[k].distance);
    self_pairs += segs[grid[k].seg_i].fibre == segs[grid[k].seg_j].fibre;
  }
  EXPECT_GT(self_pairs, 0); // the folded fibres touch themselves

  // zones: deterministic, well formed, each holding its closest point
  const auto zones = find_proximity_zones(c, delta, excl);
  EXPECT_EQ(zones.size(), group_into_zones(segs, brute).size());
  ASSERT_FALSE(zones.empty());
  for (const auto& z : zones)
  {
    EXPECT_LE(z.fibre_i, z.fibre_j);
    EXPECT_LE(z.a_i, z.s_i);
    EXPECT_LE(z.s_i, z.b_i);
    EXPECT_LE(z.a_j, z.s_j);
    EXPECT_LE(z.s_j, z.b_j);
    const double limit = delta * (c.radius[z.fibre_i] + c.radius[z.fibre_j]);
    EXPECT_LT(z.min_distance, limit + 0.1); // + sags of curved elements
    if (z.fibre_i == z.fibre_j)
      EXPECT_LE(z.a_i, z.a_j);
  }
  const auto again = find_proximity_zones(c, delta, excl);
  ASSERT_EQ(again.size(), zones.size());
  for (std::size_t k = 0; k < zones.size(); ++k)
  {
    EXPECT_EQ(again[k].a_i, zones[k].a_i);
    EXPECT_EQ(again[k].b_j, zones[k].b_j);
  }
}

// A rank detects among the fibres it holds (Centrelines::present): the
// zones between two present fibres are exactly those of a pass over all
// fibres, whatever the absent fibres' coordinates.
TEST(ProximityZonesRandom, PresentFibresGiveTheZonesOfAllFibresBetweenThem)
{
  const auto all = random_bundle(100, 20, 6.0, 11);
  const double delta = 2.5, excl = 0.3;
  const auto zones = find_proximity_zones(all, delta, excl);
  auto part = all;
  part.present.assign(all.num_fibres(), 0);
  for (int f = 0; f < all.num_fibres(); f += 3)
    part.present[f] = part.present[f + 1 < all.num_fibres() ? f + 1 : f] = 1;
  for (int f = 0; f < part.num_fibres(); ++f)
    if (!part.has(f)) // not on this rank
      for (auto i = 3 * part.fibre_offsets[f]; i < 3 * part.fibre_offsets[f + 1]; ++i)
        part.x[i] = std::numeric_limits<double>::quiet_NaN();
  const auto found = find_proximity_zones(part, delta, excl);
  std::vector<ProximityZone> expected;
  for (const auto& z : zones)
    if (part.has(z.fibre_i) and part.has(z.fibre_j))
      expected.push_back(z);
  ASSERT_GT(expected.size(), 10u);
  ASSERT_LT(expected.size(), zones.size());
  ASSERT_EQ(found.size(), expected.size());
  for (std::size_t k = 0; k < found.size(); ++k)
  {
    EXPECT_EQ(found[k].fibre_i, expected[k].fibre_i);
    EXPECT_EQ(found[k].fibre_j, expected[k].fibre_j);
    // bit for bit: ranks that find a zone number it by these values
    EXPECT_EQ(found[k].a_i, expected[k].a_i);
    EXPECT_EQ(found[k].b_i, expected[k].b_i);
    EXPECT_EQ(found[k].a_j, expected[k].a_j);
    EXPECT_EQ(found[k].b_j, expected[k].b_j);
    EXPECT_EQ(found[k].s_i, expected[k].s_i);
    EXPECT_EQ(found[k].s_j, expected[k].s_j);
  }
  // a NaN on a present fibre is still a diverged state
  part.x[3 * part.fibre_offsets[0]] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(find_proximity_zones(part, delta, excl), textile::GeometryError);
  part.present.pop_back();
  EXPECT_THROW(part.validate(), std::invalid_argument);
}
