#include "fd.h"
#include <textile/beam/shape_functions.h>
#include <textile/junction/fibre_matrix_junction.h>
#include <textile/junction/junction_set.h>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace textile;

namespace
{
std::vector<double> random_vector(std::size_t n, std::mt19937& gen, double scale)
{
  std::uniform_real_distribution<double> d(-scale, scale);
  std::vector<double> v(n);
  for (auto& x : v)
    x = d(gen);
  return v;
}
} // namespace

// residual and tangent against central differences of the energy and the
// residual, for linear and quadratic fibre elements, P1 (4) and P2 (10)
// matrix cells, and particles on the centre line and off it in the section
struct KernelCase
{
  int nf, nm;
  double c1, c2;
};

class JunctionKernel : public ::testing::TestWithParam<KernelCase>
{
};

TEST_P(JunctionKernel, ResidualAndTangentMatchFiniteDifferences)
{
  const auto [nf, nm, c1, c2] = GetParam();
  std::mt19937 gen(42 + nf + nm);
  const double k = 3.0e3, w = 0.07, xi = 0.37;
  const std::vector<double> c = {c1, c2};
  const auto X_f = random_vector(9 * nf, gen, 1.0);
  const auto X_m = random_vector(3, gen, 1.0);
  auto phi = random_vector(nm, gen, 1.0); // partition of unity
  double s = 0;
  for (int b = 0; b < nm - 1; ++b)
    s += phi[b];
  phi[nm - 1] = 1.0 - s;
  const auto u = random_vector(9 * nf + 3 * nm, gen, 0.1);
  const std::size_t m = u.size();
  auto energy = [&](const std::vector<double>& v)
  {
    return std::vector<double>{junction::fibre_matrix_junction(
        k, w, nf, xi, c, X_f, std::span(v.data(), 9 * nf), X_m, phi,
        std::span(v.data() + 9 * nf, 3 * nm), {}, {}, {})};
  };
  auto residual = [&](const std::vector<double>& v)
  {
    std::vector<double> r(m, 0.0);
    junction::fibre_matrix_junction(k, w, nf, xi, c, X_f, std::span(v.data(), 9 * nf), X_m, phi,
                                    std::span(v.data() + 9 * nf, 3 * nm), {}, r, {});
    return r;
  };
  std::vector<double> r(m, 0.0), K(m * m, 0.0), gap(3);
  junction::fibre_matrix_junction(k, w, nf, xi, c, X_f, std::span(u.data(), 9 * nf), X_m, phi,
                                  std::span(u.data() + 9 * nf, 3 * nm), gap, r, K);
  // quadratic energy: central differences are exact up to round-off
  // (measured with h = 1e-5: residual 3e-12 to 2.4e-11, tangent 2e-12 to
  // 1e-11, section particles included), hence 1e-10
  EXPECT_LT(test::relative_error(r, test::fd_jacobian(energy, u, 1e-5)), 1e-10);
  EXPECT_LT(test::relative_error(K, test::fd_jacobian(residual, u, 1e-5)), 1e-10);
  // symmetric tangent, and forces in balance (sum N = sum phi = 1): the
  // x0 rows of the fibre nodes carry the force, the g rows c1, c2 times it
  for (std::size_t i = 0; i < m; ++i)
    for (std::size_t j = 0; j < m; ++j)
      EXPECT_EQ(K[i * m + j], K[j * m + i]);
  for (int d = 0; d < 3; ++d)
  {
    double f = 0, f1 = 0, f2 = 0;
    for (int a = 0; a < nf; ++a)
    {
      f += r[9 * a + d];
      f1 += r[9 * a + 3 + d];
      f2 += r[9 * a + 6 + d];
    }
    for (int b = 0; b < nm; ++b)
      f += r[9 * nf + 3 * b + d];
    EXPECT_NEAR(f, 0.0, 1e-12 * k * w);
    EXPECT_NEAR(f1, c1 * k * w * gap[d], 1e-12 * k * w);
    EXPECT_NEAR(f2, c2 * k * w * gap[d], 1e-12 * k * w);
  }
  // the force on the matrix nodes is k w gap, distributed by phi
  for (int b = 0; b < nm; ++b)
    for (int d = 0; d < 3; ++d)
      EXPECT_NEAR(r[9 * nf + 3 * b + d], -k * w * phi[b] * gap[d], 1e-12 * k * w);
}

INSTANTIATE_TEST_SUITE_P(Elements, JunctionKernel,
                         ::testing::Values(KernelCase{2, 4, 0, 0}, KernelCase{3, 4, 0, 0},
                                           KernelCase{3, 10, 0, 0}, KernelCase{2, 10, 0, 0},
                                           KernelCase{2, 4, 0.03, -0.02},
                                           KernelCase{3, 4, -0.04, 0.0},
                                           KernelCase{3, 10, 0.0, 0.035},
                                           KernelCase{2, 10, 0.021, 0.029}));

TEST(JunctionKernel, ZeroGapWhereParticleSitsAndTwistStretchesIt)
{
  // a section particle at xi of a bent quadratic element (section vectors
  // along y and z), tied where it sits
  std::vector<double> X_f(27, 0.0);
  const double pos[9] = {0, 0, 0, 1, 0.2, 0, 2, 0, 0.1};
  for (int a = 0; a < 3; ++a)
    for (int d = 0; d < 3; ++d)
    {
      X_f[9 * a + d] = pos[3 * a + d];
      X_f[9 * a + 3 + d] = d == 1 ? 1.0 : 0.0;
      X_f[9 * a + 6 + d] = d == 2 ? 1.0 : 0.0;
    }
  const double xi = -0.4, rho = 0.05;
  const std::vector<double> c = {rho, 0.0};
  std::array<double, 3> N, dN;
  beam::lagrange(3, xi, N, dN);
  std::vector<double> X_m(3, 0.0);
  for (int a = 0; a < 3; ++a)
    for (int d = 0; d < 3; ++d)
      X_m[d] += N[a] * (X_f[9 * a + d] + rho * X_f[9 * a + 3 + d]);
  const std::vector<double> phi = {0.25, 0.25, 0.25, 0.25};
  // a rigid translation of everything keeps the gap zero
  std::vector<double> uf(27, 0.0), um(12);
  for (int a = 0; a < 3; ++a)
    for (int d = 0; d < 3; ++d)
      uf[9 * a + d] = d == 0 ? 0.3 : (d == 1 ? -0.2 : 0.1);
  for (std::size_t i = 0; i < um.size(); ++i)
    um[i] = (i % 3 == 0) ? 0.3 : (i % 3 == 1 ? -0.2 : 0.1);
  std::vector<double> gap(3), r(39, 0.0);
  double e = junction::fibre_matrix_junction(5.0, 1.0, 3, xi, c, X_f, uf, X_m, phi, um, gap, r,
                                             {});
  for (int d = 0; d < 3; ++d)
    EXPECT_NEAR(gap[d], 0.0, 1e-15);
  EXPECT_NEAR(e, 0.0, 1e-28);
  // turning the sections by theta about x (g1 = (0, cos, sin)) moves the
  // particle by rho (0, cos - 1, sin): the gap the centre line cannot see
  const double theta = 0.1;
  std::fill(um.begin(), um.end(), 0.0);
  std::fill(uf.begin(), uf.end(), 0.0);
  for (int a = 0; a < 3; ++a)
  {
    uf[9 * a + 4] = std::cos(theta) - 1, uf[9 * a + 5] = std::sin(theta);
    uf[9 * a + 7] = -std::sin(theta), uf[9 * a + 8] = std::cos(theta) - 1;
  }
  e = junction::fibre_matrix_junction(5.0, 1.0, 3, xi, c, X_f, uf, X_m, phi, um, gap, {}, {});
  EXPECT_NEAR(gap[0], 0.0, 1e-15);
  EXPECT_NEAR(gap[1], rho * (std::cos(theta) - 1), 1e-15);
  EXPECT_NEAR(gap[2], rho * std::sin(theta), 1e-15);
  EXPECT_NEAR(e, 0.5 * 5.0 * rho * rho * 2 * (1 - std::cos(theta)), 1e-15);
}

TEST(JunctionSet, VectorMatchesKernelsAndForces)
{
  // two junctions on a 2-element linear fibre (3 nodes) and a matrix of 5
  // nodes (two P1 cells sharing a face)
  const std::vector<double> Xf = {0, 0, 0, 0, 1, 0, 0, 0, 1, 1, 0, 0, 0, 1, 0,
                                  0, 0, 1, 2, 0, 0, 0, 1, 0, 0, 0, 1};
  const std::vector<std::int32_t> elem = {0, 1, 1, 2}, cells = {0, 1, 2, 3, 1, 2, 3, 4};
  const std::vector<double> xi = {-0.5, 0.5}, w = {0.5, 0.25}, centre = {0, 0, 0, 0};
  const std::vector<double> phi = {0.1, 0.2, 0.3, 0.4, 0.4, 0.3, 0.2, 0.1};
  const std::vector<double> Xm = {0.25, 0, 0, 1.75, 0, 0};
  junction::JunctionSet set(2.0, 2, elem, xi, centre, w, Xf, Xm, cells, phi);
  EXPECT_EQ(set.num_blocks(), 2u);
  std::mt19937 gen(7);
  const auto uf = random_vector(27, gen, 0.1), um = random_vector(15, gen, 0.1);
  std::vector<double> bf(27, 0.0), bm(15, 0.0);
  set.assemble_vector(uf, um, bf, bm);
  const auto f = set.forces(uf, um);
  const auto total = set.total_force(uf, um);
  // the matrix nodes receive minus the junction forces, the fibre nodes'
  // position rows the forces, their section rows nothing
  for (int c = 0; c < 3; ++c)
  {
    double sm = 0, sf = 0;
    for (int b = 0; b < 5; ++b)
      sm += bm[3 * b + c];
    for (int a = 0; a < 3; ++a)
      sf += bf[9 * a + c];
    EXPECT_NEAR(sm, -total[c], 1e-14);
    EXPECT_NEAR(sf, total[c], 1e-14);
    EXPECT_NEAR(total[c], f[c] + f[3 + c], 1e-15);
  }
  for (int a = 0; a < 3; ++a)
    for (int d = 3; d < 9; ++d)
      EXPECT_EQ(bf[9 * a + d], 0.0);
  EXPECT_THROW(junction::JunctionSet(2.0, 4, elem, xi, centre, w, Xf, Xm, cells, phi),
               std::invalid_argument);
  EXPECT_THROW(junction::JunctionSet(2.0, 2, elem, xi, {0, 0}, w, Xf, Xm, cells, phi),
               std::invalid_argument);

  // section particles: the section rows of a node receive c1, c2 times the
  // force its x0 rows receive; junctions sharing (element, cell) share a block
  const std::vector<double> section = {0.05, 0.0, -0.03, 0.04, 0.0, 0.05};
  const std::vector<std::int32_t> elem3 = {0, 1, 1, 2, 0, 1};
  const std::vector<std::int32_t> cells3 = {0, 1, 2, 3, 1, 2, 3, 4, 0, 1, 2, 3};
  const std::vector<double> xi3 = {-0.5, 0.5, 0.2}, w3 = {0.5, 0.25, 0.3};
  const std::vector<double> phi3 = {0.1, 0.2, 0.3, 0.4, 0.4, 0.3, 0.2, 0.1, 0.25, 0.25, 0.25, 0.25};
  const std::vector<double> Xm3 = {0.25, 0.05, 0, 1.75, -0.03, 0.04, 0.6, 0, 0.05};
  junction::JunctionSet sec(2.0, 2, elem3, xi3, section, w3, Xf, Xm3, cells3, phi3);
  EXPECT_EQ(sec.num_blocks(), 2u);
  std::fill(bf.begin(), bf.end(), 0.0);
  std::fill(bm.begin(), bm.end(), 0.0);
  sec.assemble_vector(uf, um, bf, bm);
  const auto fs = sec.forces(uf, um);
  for (int d = 0; d < 3; ++d)
  {
    double s1 = 0, s2 = 0, e1 = 0, e2 = 0;
    for (int a = 0; a < 3; ++a)
      s1 += bf[9 * a + 3 + d], s2 += bf[9 * a + 6 + d];
    for (int j = 0; j < 3; ++j)
      e1 += section[2 * j] * fs[3 * j + d], e2 += section[2 * j + 1] * fs[3 * j + d];
    EXPECT_NEAR(s1, e1, 1e-15);
    EXPECT_NEAR(s2, e2, 1e-15);
  }
}
