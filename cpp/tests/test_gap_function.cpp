// The gap function of a contact element (gap_function.h): its gradient and
// Hessian against central finite differences for each gap kind, and what
// each kind measures.
#include "fd.h"
#include <textile/contact/contact_element.h>
#include <textile/contact/closest_points.h>
#include <textile/contact/gap_function.h>
#include <textile/beam/shape_functions.h>
#include <textile/contact/regularized_penalty.h>
#include <textile/geometry_error.h>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace textile;
using namespace textile::contact;

namespace
{
/// Nodal unknowns of an element of num_nodes nodes along t through c, bent
/// by `bow` (the middle node moved along b), sections of radius 1 in
/// (g1, g2) = (b, t x b) perturbed by `noise` (relative).
std::vector<double> element(int num_nodes, const Eigen::Vector3d& c, const Eigen::Vector3d& t,
                            const Eigen::Vector3d& b, double len, double bow, std::mt19937& gen,
                            double noise)
{
  std::uniform_real_distribution<double> U(-1, 1);
  std::vector<double> x;
  const Eigen::Vector3d g1 = b.normalized(), g2 = t.cross(g1).normalized();
  for (int a = 0; a < num_nodes; ++a)
  {
    const double xi = num_nodes == 3 ? a - 1.0 : 2.0 * a - 1.0;
    const Eigen::Vector3d p = c + xi * 0.5 * len * t + (1 - xi * xi) * bow * b;
    for (const Eigen::Vector3d& v : {p, g1, g2})
      for (int k = 0; k < 3; ++k)
        x.push_back(v(k) + noise * len * U(gen));
  }
  return x;
}

struct Case
{
  const char* name;
  GapKind kind;
  int num_nodes;
  double angle; // between the fibres (deg)
};

class GapDerivatives : public ::testing::TestWithParam<Case>
{
};
} // namespace

TEST_P(GapDerivatives, MatchCentralFiniteDifferences)
{
  const Case cs = GetParam();
  std::mt19937 gen(11);
  const double R = 0.01, a = cs.angle * M_PI / 180.0, len = 0.1;
  const Eigen::Vector3d ti(1, 0, 0), tj(std::cos(a), std::sin(a), 0);
  // fibre i above fibre j, interpenetrating, both bent
  const auto xi = element(cs.num_nodes, Eigen::Vector3d(0.003, 0.002, 1.2 * R), ti,
                          Eigen::Vector3d(0, 0.3, 1), len, 0.2 * R, gen, 1e-3);
  const auto xj = element(cs.num_nodes, Eigen::Vector3d(0, 0, 0), tj, Eigen::Vector3d(0.2, 0, 1),
                          len, -0.3 * R, gen, 1e-3);
  const Eigen::Vector3d N = Eigen::Vector3d(0.05, -0.02, 1).normalized();
  const Particle pi{cs.num_nodes, 0.1, 0.0, -R, R}, pj{cs.num_nodes, -0.05, 0.0, R, R};
  const GapMotion motion{cs.kind, ti, tj};
  std::vector<double> x(xi);
  x.insert(x.end(), xj.begin(), xj.end());
  const std::size_t n = x.size(), ni = xi.size();
  auto gap_of = [&](const std::vector<double>& y)
  {
    return GapFunction(pi, pj, N, motion, std::span(y.data(), ni),
                       std::span(y.data() + ni, n - ni), 2e-4, false)
        .gap();
  };
  auto gradient_of = [&](const std::vector<double>& y)
  {
    const GapFunction g(pi, pj, N, motion, std::span(y.data(), ni),
                        std::span(y.data() + ni, n - ni), 2e-4, true);
    return std::vector<double>(g.gradient().data(), g.gradient().data() + n);
  };
  const GapFunction g(pi, pj, N, motion, std::span(x.data(), ni), std::span(x.data() + ni, n - ni),
                      2e-4, true);
  ASSERT_LT(g.gap(), 0.0);
  // facing and following move both points, held none
  EXPECT_EQ(g.patch_xi_i() != pi.xi, cs.kind != GapKind::held);
  EXPECT_EQ(g.patch_xi_j() != pj.xi, cs.kind != GapKind::held);
  // gradient: central differences of the gap
  std::vector<double> fd_gradient(n);
  for (std::size_t k = 0; k < n; ++k)
  {
    auto yp = x, ym = x;
    yp[k] += 1e-7;
    ym[k] -= 1e-7;
    fd_gradient[k] = (gap_of(yp) - gap_of(ym)) / 2e-7;
  }
  const std::vector<double> G(g.gradient().data(), g.gradient().data() + n);
  EXPECT_LT(test::relative_error(G, fd_gradient), 1e-7);
  // Hessian: central differences of the gradient
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> H
      = Eigen::MatrixXd::Zero(n, n);
  g.add_hessian(1.0, H);
  const std::vector<double> Hv(H.data(), H.data() + n * n);
  EXPECT_LT(test::relative_error(Hv, test::fd_jacobian(gradient_of, x, 1e-7)), 1e-6);
  // symmetric: the second derivative of one function
  EXPECT_LT((H - H.transpose()).norm(), 1e-9 * H.norm());
}

INSTANTIATE_TEST_SUITE_P(
    Kinds, GapDerivatives,
    ::testing::Values(Case{"held_crossing", GapKind::held, 3, 70.0},
                      Case{"facing_crossing", GapKind::facing, 3, 70.0},
                      Case{"facing_linear_elements", GapKind::facing, 2, 40.0},
                      Case{"facing_shallow", GapKind::facing, 3, 15.0},
                      Case{"following_parallel", GapKind::following, 3, 0.0},
                      Case{"following_at_an_angle", GapKind::following, 3, 8.0},
                      Case{"following_linear_elements", GapKind::following, 2, 3.0}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(GapFunction, FollowingMeasuresTheDistanceInTheSectionPlane)
{
  // fibre i parallel to j, R = 1 each, centre lines 1.9 apart along a
  // direction 30 deg off the held normal N = z: held measures along z,
  // following measures the true distance
  const double R = 1.0, d = 1.9, phi = M_PI / 6;
  const Eigen::Vector3d t(1, 0, 0), off(0, d * std::sin(phi), d * std::cos(phi));
  std::mt19937 gen(3);
  const auto xi = element(3, off, t, Eigen::Vector3d(0, 0, 1), 10.0, 0.0, gen, 0.0);
  const auto xj = element(3, Eigen::Vector3d::Zero(), t, Eigen::Vector3d(0, 0, 1), 10.0, 0.0, gen, 0.0);
  const Particle pi{3, 0.2, 0, -R, R}, pj{3, 0.2, 0, R, R};
  const Eigen::Vector3d N = Eigen::Vector3d::UnitZ();
  const GapFunction held(pi, pj, N, {GapKind::held}, xi, xj, 0.0, false);
  const GapFunction following(pi, pj, N, {GapKind::following, t, t}, xi, xj, 0.0, false);
  EXPECT_NEAR(held.gap(), d * std::cos(phi) - 2 * R, 1e-12);
  EXPECT_NEAR(following.gap(), d - 2 * R, 1e-12);
  EXPECT_NEAR(following.separation(), d * std::cos(phi), 1e-12); // along N: the side kept
}

TEST(GapFunction, FacingFindsWhereTheCentreLinesFaceEachOther)
{
  // two straight fibres crossing at right angles, 1.8 apart vertically:
  // from particles placed off the crossing, the facing point is at it
  const double R = 1.0;
  std::mt19937 gen(3);
  const auto xi = element(3, Eigen::Vector3d(0.3, 0, 1.8), Eigen::Vector3d(1, 0, 0),
                          Eigen::Vector3d(0, 0, 1), 4.0, 0.0, gen, 0.0);
  const auto xj = element(3, Eigen::Vector3d(0, -0.5, 0), Eigen::Vector3d(0, 1, 0),
                          Eigen::Vector3d(0, 0, 1), 4.0, 0.0, gen, 0.0);
  const Particle pi{3, 0.4, 0, -R, R}, pj{3, -0.3, 0, R, R};
  const GapFunction g(pi, pj, Eigen::Vector3d::UnitZ(), {GapKind::facing}, xi, xj, 0.0, false);
  EXPECT_NEAR(g.patch_xi_i(), -0.15, 1e-12); // x = 0.3 + 2 xi = 0
  EXPECT_NEAR(g.patch_xi_j(), 0.25, 1e-12);  // y = -0.5 + 2 xi = 0
  EXPECT_NEAR(g.gap(), 1.8 - 2 * R, 1e-12);
}

TEST(GapFunction, FacingBetweenParallelCentreLinesIsMeasuredAtTheParticles)
{
  // no single facing point: the gap is the held one
  const double R = 1.0;
  std::mt19937 gen(3);
  const auto xi = element(3, Eigen::Vector3d(0, 0, 1.8), Eigen::Vector3d(1, 0, 0),
                          Eigen::Vector3d(0, 0, 1), 4.0, 0.0, gen, 0.0);
  const auto xj = element(3, Eigen::Vector3d(0, 0.1, 0), Eigen::Vector3d(1, 0.01, 0).normalized(),
                          Eigen::Vector3d(0, 0, 1), 4.0, 0.0, gen, 0.0);
  const Particle pi{3, 0.2, 0, -R, R}, pj{3, -0.1, 0, R, R};
  const GapFunction facing(pi, pj, Eigen::Vector3d::UnitZ(), {GapKind::facing}, xi, xj, 0.0, false);
  const GapFunction held(pi, pj, Eigen::Vector3d::UnitZ(), {GapKind::held}, xi, xj, 0.0, false);
  EXPECT_EQ(facing.gap(), held.gap());
  EXPECT_EQ(facing.patch_xi_i(), 0.2);
}

TEST(GapFunction, ContactElementTangentWithFrictionForEachKind)
{
  // the whole element (normal law, friction at the material particles) on
  // top of the moving gap: its tangent is still the residual's derivative
  std::mt19937 gen(5);
  const double R = 0.01;
  const RegularizedPenalty law(1.0e4, 0.05 * R);
  const RegularizedCoulomb fr{0.3, 1e-4};
  for (const GapKind kind : {GapKind::held, GapKind::following, GapKind::facing})
  {
    const double a = kind == GapKind::following ? 0.05 : 1.2;
    const Eigen::Vector3d ti(1, 0, 0), tj(std::cos(a), std::sin(a), 0);
    const auto xi = element(3, Eigen::Vector3d(0.002, 0, 1.7 * R), ti,
                            Eigen::Vector3d(0, 0, 1), 0.1, 0.1 * R, gen, 1e-3);
    const auto xj = element(3, Eigen::Vector3d(0, 0, 0), tj, Eigen::Vector3d(0, 0, 1), 0.1,
                            0.0, gen, 1e-3);
    const Eigen::Vector3d N = Eigen::Vector3d(0.05, -0.02, 1).normalized();
    const Particle pi{3, 0.1, 0.0, -R, R}, pj{3, -0.05, 0.0, R, R};
    const GapMotion motion{kind, ti, tj};
    const Eigen::Vector3d delta = particle_position(pi, xi) - particle_position(pj, xj);
    const Eigen::Vector3d stick = delta - 0.5 * fr.u_rev * N.unitOrthogonal(); // sticking
    std::vector<double> x(xi);
    x.insert(x.end(), xj.begin(), xj.end());
    const std::size_t n = x.size();
    auto res = [&](const std::vector<double>& y)
    {
      std::vector<double> r(n, 0.0);
      contact_element(pi, pj, N, law, &fr, stick, std::span(y.data(), 27),
                      std::span(y.data() + 27, 27), r, {}, 0.0, motion);
      return r;
    };
    std::vector<double> r(n), K(n * n);
    const auto out = contact_element(pi, pj, N, law, &fr, stick, std::span(x.data(), 27),
                                     std::span(x.data() + 27, 27), r, K, 0.0, motion);
    ASSERT_GT(out.normal_force, 0.0);
    EXPECT_LT(test::relative_error(K, test::fd_jacobian(res, x, 1e-8)), 1e-6)
        << static_cast<int>(kind);
    // the gap the assembler uses to skip open elements is the element's
    EXPECT_EQ(contact_gap(pi, pj, N, std::span(x.data(), 27), std::span(x.data() + 27, 27), 0.0,
                          motion),
              out.gap);
  }
}

namespace
{
/// Nodal unknowns of two quadratic elements (5 nodes) along x from x0, each
/// element `len` long, kinked at the shared node by `kink` (rad, about y),
/// at height z0; sections (g1, g2) = (y, z) of unit length.
std::vector<double> kinked_patch(double x0, double z0, double len, double kink)
{
  std::vector<double> x;
  const Eigen::Vector3d t2(std::cos(kink), 0, std::sin(kink));
  for (int a = 0; a < 5; ++a)
  {
    const Eigen::Vector3d p = a <= 2 ? Eigen::Vector3d(x0 + 0.5 * len * a, 0, z0)
                                     : Eigen::Vector3d(x0 + len, 0, z0) + 0.5 * len * (a - 2) * t2;
    for (const Eigen::Vector3d& v : {p, Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1)})
      for (int k = 0; k < 3; ++k)
        x.push_back(v(k));
  }
  return x;
}
} // namespace

TEST(ContactPatch, TwoElementsSmoothedAcrossTheirNode)
{
  // a patch of two quadratic elements: partition of unity, the fibre
  // itself outside the window, C1 at the window's ends, through the node
  const Particle p{3, 0.0, 0, 0, 1.0, 2, 0};
  ASSERT_EQ(p.patch_nodes(), 5);
  for (double xi : {-1.0, -0.3, 0.0, 0.4, 1.0, 1.7, 2.0, 2.5, 3.0})
  {
    const PatchShape s(p, xi);
    double sum = 0, dsum = 0, ddsum = 0;
    for (int a = 0; a < 5; ++a)
      sum += s.n[a], dsum += s.dn[a], ddsum += s.ddn[a];
    EXPECT_NEAR(sum, 1.0, 1e-14) << xi;
    EXPECT_NEAR(dsum, 0.0, 1e-13) << xi;
    EXPECT_NEAR(ddsum, 0.0, 1e-12) << xi;
  }
  const PatchShape at_node(p, 1.0), left(p, -0.5), right(p, 2.5);
  EXPECT_NEAR(at_node.n[2], 1.0, 1e-14); // the shared node
  std::array<double, 3> n, dn;
  beam::lagrange(3, -0.5, n, dn); // outside the window: element A's functions
  for (int a = 0; a < 3; ++a)
    EXPECT_NEAR(left.n[a], n[a], 1e-14);
  beam::lagrange(3, 0.5, n, dn); // and B's
  for (int a = 0; a < 3; ++a)
    EXPECT_NEAR(right.n[2 + a], n[a], 1e-14);
  // C1 at the window's ends (xi = 0 and 2 for patch_smoothing = 0.5)
  const double w = 2 * patch_smoothing;
  for (double edge : {1.0 - w, 1.0 + w})
  {
    const PatchShape a(p, edge - 1e-9), b(p, edge + 1e-9);
    for (int k = 0; k < 5; ++k)
    {
      EXPECT_NEAR(a.n[k], b.n[k], 1e-8);
      EXPECT_NEAR(a.dn[k], b.dn[k], 1e-7);
    }
  }
}

TEST(ContactPatch, FacingAcrossAKinkedNodeIsSmoothAndExact)
{
  // fibre i: two elements kinked by 10 deg at their node (x = 0.2); fibre
  // j: one straight element across it along y, 1.9 R below. As j slides
  // along x past the node, the gap and its gradient change continuously
  // (the kinked line's facing point would jump its force direction by
  // the kink angle), and the tangent stays exact.
  const double R = 0.01, len = 0.2, kink = 10 * M_PI / 180;
  const auto xi = kinked_patch(0.0, 1.9 * R, len, kink);
  const Particle pi{3, 0.8, 0, -R, R, 2, 0}, pj{3, 0.0, 0, R, R};
  const GapMotion motion{GapKind::facing, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0)};
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  double previous_gap = 0;
  for (int k = 0; k <= 40; ++k)
  {
    const double xc = len - 0.04 + 0.002 * k; // fibre j's position along x
    std::mt19937 gen(1);
    const auto xj = element(3, Eigen::Vector3d(xc, 0, 0), Eigen::Vector3d(0, 1, 0),
                            Eigen::Vector3d(1, 0, 0), 0.1, 0.0, gen, 0.0);
    const GapFunction g(pi, pj, Eigen::Vector3d::UnitZ(), motion, xi, xj, 0.0, true);
    ASSERT_GT(g.patch_xi_i(), -1.0);
    ASSERT_LT(g.patch_xi_i(), 3.0);
    // the force direction (on the shared node's centroid)
    const Eigen::Vector3d m = g.gradient().segment<3>(9 * 2).normalized();
    if (k > 0)
    {
      // a step of 0.002 (1% of an element) turns the force by a few percent
      // of the kink angle (it turns by the kink over the window, 1 element)
      EXPECT_LT(std::acos(std::min(1.0, m.dot(previous))), 0.05 * kink) << xc;
      // the gap's slope stays near the fibre's (tan of the kink beyond the
      // node; 10% for the blend's own slope in the window)
      EXPECT_LT(std::abs(g.gap() - previous_gap), 0.002 * std::tan(kink) * 1.1) << xc;
    }
    previous = m;
    previous_gap = g.gap();
  }
  // the exact tangent on the patch, in the window
  std::mt19937 gen(7);
  auto xj = element(3, Eigen::Vector3d(len + 0.01, 0, 0), Eigen::Vector3d(0, 1, 0),
                    Eigen::Vector3d(1, 0, 0), 0.1, 0.0, gen, 1e-3);
  std::vector<double> x(xi);
  x.insert(x.end(), xj.begin(), xj.end());
  const std::size_t n = x.size(), ni = xi.size();
  auto gradient_of = [&](const std::vector<double>& y)
  {
    const GapFunction g(pi, pj, Eigen::Vector3d::UnitZ(), motion, std::span(y.data(), ni),
                        std::span(y.data() + ni, n - ni), 0.0, true);
    return std::vector<double>(g.gradient().data(), g.gradient().data() + n);
  };
  const GapFunction g(pi, pj, Eigen::Vector3d::UnitZ(), motion, std::span(x.data(), ni),
                      std::span(x.data() + ni, n - ni), 0.0, true);
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> H
      = Eigen::MatrixXd::Zero(n, n);
  g.add_hessian(1.0, H);
  const std::vector<double> Hv(H.data(), H.data() + n * n);
  EXPECT_LT(test::relative_error(Hv, test::fd_jacobian(gradient_of, x, 1e-7)), 1e-6);
}

TEST(ContactPatch, APointLeavingItsPatchStopsAtItsEndContinuously)
{
  // fibre j slides along fibre i past the end of i's one-element patch:
  // the gap stays continuous as i's point stops at the end node, and the
  // tangent is exact on both sides
  const double R = 0.01;
  std::mt19937 gen(3);
  const auto xi = element(3, Eigen::Vector3d(0, 0, 1.8 * R), Eigen::Vector3d(1, 0, 0.2).normalized(),
                          Eigen::Vector3d(0, 0, 1), 0.1, 0.05 * R, gen, 0.0);
  const Particle pi{3, 0.5, 0, -R, R}, pj{3, 0.0, 0, R, R};
  const GapMotion motion{GapKind::facing, Eigen::Vector3d(1, 0, 0.2).normalized(),
                         Eigen::Vector3d(0, 1, 0)};
  auto gap_at = [&](double xc, std::vector<double>* out = nullptr)
  {
    std::mt19937 g2(4);
    auto xj = element(3, Eigen::Vector3d(xc, 0, 0), Eigen::Vector3d(0, 1, 0),
                      Eigen::Vector3d(1, 0, 0), 0.1, 0.0, g2, 0.0);
    if (out)
      *out = xj;
    return GapFunction(pi, pj, Eigen::Vector3d::UnitZ(), motion, xi, xj, 0.0, false);
  };
  // the end of i's element is at x = 0.05 / |(1, 0, 0.2)|
  const double end = 0.05 / std::sqrt(1.04);
  const auto before = gap_at(end - 1e-9), after = gap_at(end + 1e-9);
  EXPECT_NEAR(before.patch_xi_i(), 1.0, 1e-6);
  EXPECT_EQ(after.patch_xi_i(), 1.0); // stopped
  EXPECT_NEAR(before.gap(), after.gap(), 1e-9);
  for (double xc : {end - 0.01, end + 0.01})
  {
    std::vector<double> xj;
    gap_at(xc, &xj);
    std::vector<double> x(xi);
    x.insert(x.end(), xj.begin(), xj.end());
    const std::size_t n = x.size(), ni = xi.size();
    auto gradient_of = [&](const std::vector<double>& y)
    {
      const GapFunction g(pi, pj, Eigen::Vector3d::UnitZ(), motion, std::span(y.data(), ni),
                          std::span(y.data() + ni, n - ni), 0.0, true);
      return std::vector<double>(g.gradient().data(), g.gradient().data() + n);
    };
    const GapFunction g(pi, pj, Eigen::Vector3d::UnitZ(), motion, std::span(x.data(), ni),
                        std::span(x.data() + ni, n - ni), 0.0, true);
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> H
        = Eigen::MatrixXd::Zero(n, n);
    g.add_hessian(1.0, H);
    const std::vector<double> Hv(H.data(), H.data() + n * n);
    EXPECT_LT(test::relative_error(Hv, test::fd_jacobian(gradient_of, x, 1e-7)), 1e-6) << xc;
  }
}

TEST(ContactPatch, AFollowingPointPastItsPatchEndFollowsTheContinuedCentreLine)
{
  // fibre j, parallel to a bent fibre i, slides along it: i's point in
  // their section plane passes the end of its one-element patch. It goes
  // on along the patch's line continued straight past the end node (C1),
  // so the gap's gradient has no kink there (stopping it at the end turned the
  // contact force abruptly, and Newton cycled across that kink:
  // benchmarks/README.md, "A line contact's point past its patch"), and
  // the tangent stays exact past the end.
  const double R = 0.01;
  std::mt19937 gen(5);
  const Eigen::Vector3d t(1, 0, 0);
  const auto xi = element(3, Eigen::Vector3d(0, 0, 1.8 * R), t, Eigen::Vector3d(0, 0.4, 1),
                          0.1, 0.3 * R, gen, 0.0);
  const Particle pi{3, 0.8, 0, -R, R}, pj{3, 0.8, 0, R, R};
  const GapMotion motion{GapKind::following, 0.05 * t, 0.05 * t};
  auto state = [&](double xc)
  {
    std::mt19937 g2(6);
    auto x = xi;
    const auto xj = element(3, Eigen::Vector3d(xc, 0, 0), t, Eigen::Vector3d(0, 1, 0), 0.1,
                            -0.2 * R, g2, 0.0);
    x.insert(x.end(), xj.begin(), xj.end());
    return x;
  };
  const std::size_t ni = xi.size();
  auto gap_at = [&](const std::vector<double>& x, bool derivatives)
  {
    return GapFunction(pi, pj, Eigen::Vector3d::UnitZ(), motion, std::span(x.data(), ni),
                       std::span(x.data() + ni, x.size() - ni), 0.0, derivatives);
  };
  // where i's point reaches its patch's end (xi = 1), by bisection over
  // j's slide
  double lo = 0.0, hi = 0.05;
  ASSERT_LT(gap_at(state(lo), false).patch_xi_i(), 1.0);
  ASSERT_GE(gap_at(state(hi), false).patch_xi_i(), 1.0);
  for (int it = 0; it < 60; ++it)
  {
    const double mid = 0.5 * (lo + hi);
    (gap_at(state(mid), false).patch_xi_i() < 1.0 ? lo : hi) = mid;
  }
  const double d = 1e-6;
  const auto before = gap_at(state(lo - d), true), after = gap_at(state(lo + d), true);
  EXPECT_LT(before.patch_xi_i(), 1.0);
  EXPECT_GT(after.patch_xi_i(), 1.0); // past the end: not stopped
  // continuous gradient: it changes by the Hessian times 2e-6 of slide,
  // measured 4.7e-5 of itself (stopped at the end it jumped by 6%)
  EXPECT_LT((before.gradient() - after.gradient()).norm(), 1e-4 * before.gradient().norm());
  // exact past the end (as MatchCentralFiniteDifferences)
  const auto x = state(lo + 0.01);
  const auto g = gap_at(x, true);
  ASSERT_GT(g.patch_xi_i(), 1.05);
  const std::size_t n = x.size();
  std::vector<double> fd(n);
  for (std::size_t k = 0; k < n; ++k)
  {
    auto yp = x, ym = x;
    yp[k] += 1e-7;
    ym[k] -= 1e-7;
    fd[k] = (gap_at(yp, false).gap() - gap_at(ym, false).gap()) / 2e-7;
  }
  EXPECT_LT(test::relative_error(std::vector<double>(g.gradient().data(), g.gradient().data() + n), fd),
            1e-7);
  auto gradient_of = [&](const std::vector<double>& y)
  {
    const auto gy = gap_at(y, true);
    return std::vector<double>(gy.gradient().data(), gy.gradient().data() + n);
  };
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> H
      = Eigen::MatrixXd::Zero(n, n);
  g.add_hessian(1.0, H);
  EXPECT_LT(test::relative_error(std::vector<double>(H.data(), H.data() + n * n),
                                 test::fd_jacobian(gradient_of, x, 1e-7)),
            1e-6);
  // where the patch's end is i's fibre's end, nothing lies beyond: the
  // points stop there (held)
  Particle end = pi;
  end.fibre_end_above = true;
  const GapFunction stopped(end, pj, Eigen::Vector3d::UnitZ(), motion, std::span(x.data(), ni),
                            std::span(x.data() + ni, n - ni), 0.0, false);
  EXPECT_EQ(stopped.patch_xi_i(), 1.0);
}

TEST(ContactPatch, ACrossingAtAKinkedNodeIsDetectedWhereNewtonsLinesAreClosest)
{
  // Fibre i: two elements kinked by 10 deg at their node (x = len), bent
  // away from fibre j, which runs along y 1.9 R below, 0.05 element past
  // the node. Newton moves a crossing's facing point on its patch's line,
  // smoothed across the node (particle.h); detection must search that same
  // line: its points are where the patch line is closest to j, and the gap
  // Newton starts from is their distance. (Searched on the C0 line, the
  // crossing sat 0.007 element off, its gap 5e-3 R too large; in a woven
  // bundle the C0 search locked at a kinked node in one pass and found the
  // point 0.1 element away in the next, and the contact loop cycled.)
  const double R = 0.01, len = 0.2, kink = 10 * M_PI / 180, xc = len + 0.01;
  const auto xi = kinked_patch(0.0, 1.9 * R, len, kink);
  std::mt19937 gen(1);
  const auto xj = element(3, Eigen::Vector3d(xc, 0, 0), Eigen::Vector3d(0, 1, 0),
                          Eigen::Vector3d(1, 0, 0), 0.1, 0.0, gen, 0.0);
  Centrelines c;
  for (const auto* x : {&xi, &xj})
    for (std::size_t a = 0; a < x->size(); a += 9)
      c.x.insert(c.x.end(), x->begin() + a, x->begin() + a + 3);
  c.fibre_offsets = {0, 5, 8};
  c.order = 2;
  c.radius = {R, R};
  c.validate();
  // the patch's line (particle.h), independently of Centrelines
  const Particle patch{3, 0.0, 0, 0, R, 2, 0};
  auto patch_line = [&](double u)
  {
    const PatchShape shape(patch, u);
    Eigen::Vector3d p = Eigen::Vector3d::Zero(), dp = Eigen::Vector3d::Zero();
    for (int a = 0; a < 5; ++a)
    {
      p += shape.n[a] * Eigen::Map<const Eigen::Vector3d>(xi.data() + 9 * a);
      dp += shape.dn[a] * Eigen::Map<const Eigen::Vector3d>(xi.data() + 9 * a);
    }
    return std::pair{p, dp};
  };
  // the smoothed centre line is the patch's (s = (u + 1) / 2, d/ds = 2 d/du)
  for (double s : {0.2, 0.6, 0.9, 1.0, 1.1, 1.45, 1.8})
  {
    const auto [p, dp] = patch_line(2 * s - 1);
    EXPECT_LT((p - c.smooth_position(0, s)).norm(), 1e-15) << s;
    EXPECT_LT((2 * dp - c.smooth_tangent(0, s)).norm(), 1e-13) << s;
  }
  // the patch line's closest approach to j's straight centre line, by a
  // scan of u and a golden-section refinement
  auto distance = [&](double u)
  {
    const Eigen::Vector3d p = patch_line(u).first;
    return std::hypot(p.x() - xc, p.z());
  };
  double lo = -1, best = distance(lo);
  for (int k = 1; k <= 4000; ++k)
    if (distance(-1 + 4e-3 * k) < best)
      best = distance(-1 + 4e-3 * k), lo = -1 + 4e-3 * k;
  double a = lo - 4e-3, b = lo + 4e-3;
  const double ratio = (std::sqrt(5.0) - 1) / 2;
  while (b - a > 1e-12)
  {
    const double m1 = b - ratio * (b - a), m2 = a + ratio * (b - a);
    (distance(m1) < distance(m2) ? b : a) = distance(m1) < distance(m2) ? m2 : m1;
  }
  const double u_min = 0.5 * (a + b);
  const auto [s, t] = closest_points(c, 0, 1.3, 1, 0.4);
  EXPECT_NEAR(2 * s - 1, u_min, 1e-6);
  EXPECT_GT(std::abs(s - 1.0), 1e-3); // not at the node
  const Eigen::Vector3d r = c.smooth_position(0, s) - c.smooth_position(1, t);
  EXPECT_NEAR(r.norm(), distance(u_min), 1e-12);
  // Newton's facing point along the detected normal stays there, and its
  // gap is that distance less the sections' supports along N
  const Eigen::Vector3d N = r.normalized();
  const int position = s < 1.0 ? 0 : 1;
  const Particle pi{3, 2 * (s - position) - 1, 0, -R, R, 2, position}, pj{3, 2 * t - 1, 0, R, R};
  const GapMotion motion{GapKind::facing, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0)};
  const GapFunction g(pi, pj, N, motion, xi, xj, 0.0, false);
  EXPECT_NEAR(g.patch_xi_i(), 2 * s - 1, 1e-9);
  const double supports = R * std::hypot(N.y(), N.z()) + R * std::hypot(N.x(), N.z());
  EXPECT_NEAR(g.gap(), distance(u_min) - supports, 1e-12);
}
