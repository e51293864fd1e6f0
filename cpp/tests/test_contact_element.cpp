// Contact kernels: penalty law, Coulomb law, and the exact tangent of a
// contact element against central finite differences.
#include "fd.h"
#include <textile/contact/contact_element.h>
#include <textile/contact/tolerances.h>
#include <textile/contact/regularized_penalty.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

using namespace textile;
using namespace textile::contact;

TEST(RegularizedPenalty, ContinuousWithContinuousSlope)
{
  const RegularizedPenalty law(2.0e3, 1e-4);
  EXPECT_EQ(law.reaction(1e-6), 0.0);
  EXPECT_EQ(law.stiffness(0.0), 0.0);
  for (double g : {-1e-4, -3e-5})
  {
    const double h = 1e-10;
    // continuous: a jump would not shrink with h (slope is at most k)
    EXPECT_LE(std::abs(law.reaction(g - h) - law.reaction(g + h)), 2.0001 * 2.0e3 * h);
    EXPECT_NEAR((law.reaction(g + h) - law.reaction(g - h)) / (2 * h), law.stiffness(g), 1e-3);
  }
  EXPECT_NEAR(law.reaction(-3e-4), 2.0e3 * (3e-4 - 0.5e-4), 1e-12); // linear part
  // the inverse law against the closed forms, not against reaction():
  // k p^2 / (2 g_r) = R in the quadratic part (R < k g_r / 2 = 0.1), k (p -
  // g_r / 2) = R beyond
  EXPECT_NEAR(law.penetration(1e-3), std::sqrt(2 * 1e-4 * 1e-3 / 2.0e3), 1e-15);
  EXPECT_NEAR(law.penetration(0.05), std::sqrt(2 * 1e-4 * 0.05 / 2.0e3), 1e-15);
  EXPECT_NEAR(law.penetration(1.0), 1.0 / 2.0e3 + 0.5e-4, 1e-15);
  EXPECT_NEAR(law.reaction(-5e-5), 2.0e3 * 5e-5 * 5e-5 / (2 * 1e-4), 1e-15); // quadratic part
  EXPECT_THROW(RegularizedPenalty(0.0, 1e-4), std::invalid_argument);
  EXPECT_THROW(RegularizedPenalty(1.0, -1.0), std::invalid_argument);
}

TEST(RegularizedPenalty, TangentFloorNearZeroGapOnly)
{
  const double k = 2.0e3, g_r = 1e-4;
  const RegularizedPenalty exact(k, g_r), floored(k, g_r, 0.5);
  for (double g : {-3e-4, -1e-4, -5e-5, -1e-5, 0.0, 5e-5, 1e-4, 2e-4})
  {
    EXPECT_EQ(floored.reaction(g), exact.reaction(g)); // the residual is the law's
    EXPECT_EQ(floored.stiffness(g), exact.stiffness(g));
    // Newton's tangent: at least half the penalty closed by less than g_r
    // or open by less than g_r, the exact stiffness elsewhere
    const double expected = g < g_r ? std::min(exact.stiffness(g), -0.5 * k) : 0.0;
    EXPECT_EQ(floored.newton_stiffness(g), g <= -g_r ? -k : expected) << g;
    EXPECT_EQ(exact.newton_stiffness(g), exact.stiffness(g));
  }
  EXPECT_THROW(RegularizedPenalty(k, g_r, 1.5), std::invalid_argument);
}

namespace
{
/// Nodal unknowns of a quadratic element along direction t through point c.
std::vector<double> element(const Eigen::Vector3d& c, const Eigen::Vector3d& t, double len,
                            std::mt19937& gen, double noise)
{
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::Vector3d g1 = t.unitOrthogonal(), g2 = t.cross(g1);
  std::vector<double> x;
  for (int a = 0; a < 3; ++a)
  {
    const Eigen::Vector3d p = c + (a - 1) * 0.5 * len * t;
    for (const Eigen::Vector3d& v : {p, Eigen::Vector3d(g1), Eigen::Vector3d(g2)})
      for (int k = 0; k < 3; ++k)
        x.push_back(v(k) + noise * U(gen));
  }
  return x;
}

struct Config
{
  const char* name;
  double angle;     // between the fibres (deg)
  bool friction;
  double stick_offset; // |u_T| relative to u_rev
};
} // namespace

class ContactTangent : public ::testing::TestWithParam<Config>
{
};

TEST_P(ContactTangent, MatchesCentralFiniteDifferences)
{
  const Config cf = GetParam();
  std::mt19937 gen(5);
  const double R = 0.01, a = cf.angle * M_PI / 180.0;
  const Eigen::Vector3d ti(1, 0, 0), tj(std::cos(a), std::sin(a), 0);
  // fibre i above fibre j, interpenetrating by ~R/10
  auto xi = element(Eigen::Vector3d(0, 0, 2 * R - 0.1 * R), ti, 0.1, gen, 1e-3);
  auto xj = element(Eigen::Vector3d(0, 0, 0), tj, 0.1, gen, 1e-3);
  const Eigen::Vector3d N = Eigen::Vector3d(0.05, -0.02, 1).normalized();
  const Particle pi{3, 0.1, 0.0, -R, R}, pj{3, -0.05, 0.0, R, R};
  const RegularizedPenalty law(1.0e4, 0.05 * R);
  const RegularizedCoulomb fr{0.3, 1e-4};
  // a stick point placed so that |u_T| = stick_offset * u_rev
  const Eigen::Vector3d delta
      = particle_position(pi, xi) - particle_position(pj, xj);
  const Eigen::Vector3d tdir = N.unitOrthogonal();
  const Eigen::Vector3d stick = delta - cf.stick_offset * fr.u_rev * tdir;
  const RegularizedCoulomb* f = cf.friction ? &fr : nullptr;

  std::vector<double> x(xi);
  x.insert(x.end(), xj.begin(), xj.end());
  const std::size_t n = x.size();
  auto res = [&](const std::vector<double>& y)
  {
    std::vector<double> r(n, 0.0);
    contact_element(pi, pj, N, law, f, stick, std::span(y.data(), 27), std::span(y.data() + 27, 27),
                    r, {});
    return r;
  };
  std::vector<double> r(n, 0.0), K(n * n, 0.0);
  const auto out = contact_element(pi, pj, N, law, f, stick, std::span(x.data(), 27),
                                   std::span(x.data() + 27, 27), r, K);
  ASSERT_LT(out.gap, 0.0);
  ASSERT_GT(out.normal_force, 0.0);
  if (cf.friction)
    ASSERT_EQ(out.slip, cf.stick_offset > 1.0);
  // the step h must stay inside one branch of the laws: h << |u_T| - u_rev
  EXPECT_LT(test::relative_error(K, test::fd_jacobian(res, x, 1e-8)), 1e-6);
  // action = reaction: the forces on the two fibres balance
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  const auto ci = particle_coefficients(pi), cj = particle_coefficients(pj);
  double si = 0, sj = 0;
  for (int a = 0; a < 3; ++a)
  {
    si += ci[3 * a];
    sj += cj[3 * a];
  }
  for (int a = 0; a < 3; ++a)
    for (int k = 0; k < 3; ++k)
      sum(k) += r[9 * a + k] + r[27 + 9 * a + k];
  EXPECT_NEAR(si, 1.0, 1e-14);
  EXPECT_LT(sum.norm(), 1e-12 * (out.normal_force + 1.0));
}

INSTANTIATE_TEST_SUITE_P(
    Configurations, ContactTangent,
    ::testing::Values(Config{"crossing_frictionless", 90, false, 0}, Config{"oblique_stick", 30, true, 0.5},
                      Config{"oblique_slip", 30, true, 3.0}, Config{"crossing_stick", 90, true, 0.3},
                      Config{"crossing_slip", 90, true, 2.0}, Config{"parallel_stick", 0, true, 0.7},
                      Config{"parallel_slip", 0, true, 5.0}, Config{"shallow_slip", 5, true, 1.5}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(RegularizedCoulomb, StickPointUpdateKeepsReversibleSlip)
{
  const RegularizedCoulomb fr{0.4, 1e-3};
  const Eigen::Vector3d N(0, 0, 1), stick(0, 0, 0), delta(5e-3, -2e-3, -1e-4);
  const Eigen::Vector3d s = updated_stick(N, fr, delta, stick);
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - N * N.transpose();
  // on the slip surface, just inside it (stick_margin): evaluated again
  // at the same positions the element sticks, whatever the round-off
  EXPECT_NEAR((P * (delta - s)).norm(), (1.0 - textile::contact::stick_margin) * fr.u_rev,
              1e-15);
  EXPECT_FALSE(fr.evaluate(2.0, P * (delta - s)).slip);
  // in stick nothing moves
  EXPECT_EQ(updated_stick(N, fr, Eigen::Vector3d(1e-4, 0, 0), stick), stick);
  // slip force magnitude is mu R_N, direction of the slip
  const auto res = fr.evaluate(2.0, P * delta);
  EXPECT_NEAR(res.T.norm(), 0.8, 1e-14);
  EXPECT_TRUE(res.slip);
}
