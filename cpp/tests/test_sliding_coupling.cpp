// A section or point held by a rigid body only along body-fixed directions
// (a frictionless plate): exact tangent, and free motion in the plate.
#include "../textile/rigid/rotation.h"
#include "../textile/rigid/sliding_coupling.h"
#include "coupling_case.h"
#include "fd.h"
#include "symmetric_tangent_check.h"

#include <gtest/gtest.h>

#include <vector>

using namespace textile::rigid;
using Vec3 = Eigen::Vector3d;

namespace
{
/// A coupling and the rows of its plate.
struct Case : textile::test::CouplingCase
{
  std::vector<SlidingRow> rows;
};

/// A plate of normal n holding a section (rows x0.n, g1.n, g2.n, g1.G2:
/// the plate's own sliding-section rows) or a point (x0.n).
Case plate_case(bool section, double angle, Vec3 n = Vec3(1, 2, -0.5).normalized())
{
  Case c{textile::test::coupling_case(section, angle), {}};
  c.rows.push_back({0, n});
  if (section)
  {
    c.rows.push_back({1, n});
    c.rows.push_back({2, n});
    c.rows.push_back({1, c.base.g2});
  }
  textile::test::set_multipliers(c, c.rows.size());
  return c;
}

std::vector<double> evaluate(const Case& c, const std::vector<double>& x, std::vector<double>* K)
{
  const int nq = c.base.rows(), m = static_cast<int>(c.rows.size());
  std::vector<double> r(nq + 6 + m, 0.0);
  if (K)
    K->assign(r.size() * r.size(), 0.0);
  sliding_coupling(c.base, c.rows, std::span(x).subspan(0, nq), std::span(x).subspan(nq, 3),
                   std::span(x).subspan(nq + 3, 3), std::span(x).subspan(nq + 6, m), c.scale, r,
                   K ? std::span<double>(*K) : std::span<double>());
  return r;
}
} // namespace

class SlidingCouplingTangent : public ::testing::TestWithParam<std::tuple<bool, double>>
{
};

TEST_P(SlidingCouplingTangent, MatchesFiniteDifferencesAndIsSymmetric)
{
  const auto [section, angle] = GetParam();
  const Case c = plate_case(section, angle);
  const std::vector<double> x = textile::test::pack(c);
  std::vector<double> K;
  evaluate(c, x, &K);
  const auto Kfd = textile::test::fd_jacobian(
      [&](const std::vector<double>& y) { return evaluate(c, y, nullptr); }, x, 1e-6);
  const std::size_t n = x.size();
  // central differences at h = 1e-6: truncation ~1e-12 relative
  textile::test::expect_symmetric_tangent(K, Kfd, n, 1e-8, 1e-14);
}

INSTANTIATE_TEST_SUITE_P(SectionsAndPoints, SlidingCouplingTangent,
                         ::testing::Combine(::testing::Bool(),
                                            ::testing::Values(0.0, 1e-4, 0.3, 2.5)));

TEST(SlidingCoupling, SectionSlidesAndContractsInThePlateFreely)
{
  // a section in the plate (G1, G2 normal to n) moved in the (turned)
  // plate and contracted: every row is satisfied; moved along the normal
  // by e: the x0 row is s e
  Case c = plate_case(true, 0.7, Vec3::UnitX());
  const Vec3 th(c.theta.data()), ctr(c.centre.data());
  const Vec3 n = rotate<double>(th, c.rows[0].direction);
  const Vec3 inplane = n.cross(Vec3(0.3, -0.2, 0.9)).normalized();
  const Vec3 x0 = ctr + rotate<double>(th, c.base.offset) + 0.37 * inplane;
  const Vec3 g1 = 0.9 * rotate<double>(th, c.base.g1), g2 = 0.8 * rotate<double>(th, c.base.g2);
  for (int k = 0; k < 3; ++k)
  {
    c.q[k] = x0(k);
    c.q[3 + k] = g1(k);
    c.q[6 + k] = g2(k);
  }
  auto r = evaluate(c, textile::test::pack(c), nullptr);
  for (std::size_t k = 0; k < c.rows.size(); ++k)
    EXPECT_NEAR(r[15 + k], 0.0, 1e-15) << k;
  for (int k = 0; k < 3; ++k)
    c.q[k] += 1e-3 * n(k);
  r = evaluate(c, textile::test::pack(c), nullptr);
  EXPECT_NEAR(r[15], c.scale[0] * 1e-3, 1e-15);
}
