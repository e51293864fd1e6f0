#include "fd.h"
#include <textile/beam/shape_functions.h>
#include <textile/junction/fibre_matrix_junction.h>
#include <textile/junction/junction_set.h>

#include <gtest/gtest.h>

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
// residual, for linear and quadratic fibre elements and P1 (4) and P2 (10)
// matrix cells
class JunctionKernel : public ::testing::TestWithParam<std::pair<int, int>>
{
};

TEST_P(JunctionKernel, ResidualAndTangentMatchFiniteDifferences)
{
  const auto [nf, nm] = GetParam();
  std::mt19937 gen(42 + nf + nm);
  const double k = 3.0e3, w = 0.07, xi = 0.37;
  const auto X_f = random_vector(3 * nf, gen, 1.0);
  const auto X_m = random_vector(3, gen, 1.0);
  auto phi = random_vector(nm, gen, 1.0); // partition of unity
  double s = 0;
  for (int b = 0; b < nm - 1; ++b)
    s += phi[b];
  phi[nm - 1] = 1.0 - s;
  const auto u = random_vector(3 * (nf + nm), gen, 0.1);
  const std::size_t m = u.size();
  auto energy = [&](const std::vector<double>& v)
  {
    return std::vector<double>{junction::fibre_matrix_junction(
        k, w, nf, xi, X_f, std::span(v.data(), 3 * nf), X_m, phi,
        std::span(v.data() + 3 * nf, 3 * nm), {}, {}, {})};
  };
  auto residual = [&](const std::vector<double>& v)
  {
    std::vector<double> r(m, 0.0);
    junction::fibre_matrix_junction(k, w, nf, xi, X_f, std::span(v.data(), 3 * nf), X_m, phi,
                                    std::span(v.data() + 3 * nf, 3 * nm), {}, r, {});
    return r;
  };
  std::vector<double> r(m, 0.0), K(m * m, 0.0), gap(3);
  junction::fibre_matrix_junction(k, w, nf, xi, X_f, std::span(u.data(), 3 * nf), X_m, phi,
                                  std::span(u.data() + 3 * nf, 3 * nm), gap, r, K);
  // quadratic energy: central differences are exact up to round-off
  // (measured 4e-12 to 7e-12 with h = 1e-5), hence 5e-11
  EXPECT_LT(test::relative_error(r, test::fd_jacobian(energy, u, 1e-5)), 5e-11);
  EXPECT_LT(test::relative_error(K, test::fd_jacobian(residual, u, 1e-5)), 5e-11);
  // symmetric tangent, and forces in balance (sum N = sum phi = 1)
  for (std::size_t i = 0; i < m; ++i)
    for (std::size_t j = 0; j < m; ++j)
      EXPECT_EQ(K[i * m + j], K[j * m + i]);
  for (int c = 0; c < 3; ++c)
  {
    double f = 0;
    for (int p = 0; p < nf + nm; ++p)
      f += r[3 * p + c];
    EXPECT_NEAR(f, 0.0, 1e-12 * k * w);
  }
  // the force on the matrix nodes is k w gap, distributed by phi
  for (int b = 0; b < nm; ++b)
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(r[3 * (nf + b) + c], -k * w * phi[b] * gap[c], 1e-12 * k * w);
}

INSTANTIATE_TEST_SUITE_P(Elements, JunctionKernel,
                         ::testing::Values(std::pair{2, 4}, std::pair{3, 4}, std::pair{3, 10},
                                           std::pair{2, 10}));

TEST(JunctionKernel, ZeroGapWhereParticleSits)
{
  // the particle at xi of a bent quadratic element, tied where it sits
  const std::vector<double> X_f = {0, 0, 0, 1, 0.2, 0, 2, 0, 0.1};
  const double xi = -0.4;
  std::array<double, 3> N, dN;
  beam::lagrange(3, xi, N, dN);
  std::vector<double> X_m(3, 0.0);
  for (int a = 0; a < 3; ++a)
    for (int c = 0; c < 3; ++c)
      X_m[c] += N[a] * X_f[3 * a + c];
  const std::vector<double> phi = {0.25, 0.25, 0.25, 0.25}, zf(9, 0.0), zm(12, 0.0);
  // a rigid translation of everything keeps the gap zero
  std::vector<double> uf(9), um(12);
  for (std::size_t i = 0; i < uf.size(); ++i)
    uf[i] = (i % 3 == 0) ? 0.3 : (i % 3 == 1 ? -0.2 : 0.1);
  for (std::size_t i = 0; i < um.size(); ++i)
    um[i] = (i % 3 == 0) ? 0.3 : (i % 3 == 1 ? -0.2 : 0.1);
  std::vector<double> gap(3), r(21, 0.0);
  const double e = junction::fibre_matrix_junction(5.0, 1.0, 3, xi, X_f, uf, X_m, phi, um, gap,
                                                   r, {});
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(gap[c], 0.0, 1e-15);
  EXPECT_NEAR(e, 0.0, 1e-28);
}

TEST(JunctionSet, VectorMatchesKernelsAndForces)
{
  // two junctions on a 2-element linear fibre (3 nodes) and a matrix of 5
  // nodes (two P1 cells sharing a face)
  const std::vector<double> Xf = {0, 0, 0, 1, 0, 0, 2, 0, 0};
  const std::vector<std::int32_t> elem = {0, 1, 1, 2}, cells = {0, 1, 2, 3, 1, 2, 3, 4};
  const std::vector<double> xi = {-0.5, 0.5}, w = {0.5, 0.25};
  const std::vector<double> phi = {0.1, 0.2, 0.3, 0.4, 0.4, 0.3, 0.2, 0.1};
  const std::vector<double> Xm = {0.25, 0, 0, 1.75, 0, 0};
  junction::JunctionSet set(2.0, 2, elem, xi, w, Xf, Xm, cells, phi);
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
  EXPECT_THROW(junction::JunctionSet(2.0, 4, elem, xi, w, Xf, Xm, cells, phi),
               std::invalid_argument);
}
