// Unit tests of the beam element kernel: exact tangent, invariance, and the
// uniform states that the kinematics must reproduce exactly.
#include "fd.h"
#include <textile/beam/beam_element.h>
#include <textile/geometry_error.h>

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

using namespace textile;
using namespace textile::beam;

namespace
{
/// Reference data of an element: straight along x, or on a circle arc
/// (curvature kappa) in the xy-plane. Section vectors G1 in-plane normal,
/// G2 = z.
std::vector<double> reference(int nn, double length, double kappa)
{
  std::vector<double> X(9 * nn);
  for (int a = 0; a < nn; ++a)
  {
    const double s = length * a / (nn - 1);
    Eigen::Vector3d x0, t;
    if (kappa == 0)
    {
      x0 << s, 0, 0;
      t << 1, 0, 0;
    }
    else
    {
      x0 << std::sin(kappa * s) / kappa, (1 - std::cos(kappa * s)) / kappa, 0;
      t << std::cos(kappa * s), std::sin(kappa * s), 0;
    }
    const Eigen::Vector3d g2(0, 0, 1), g1 = g2.cross(t);
    for (int k = 0; k < 3; ++k)
    {
      X[9 * a + k] = x0(k);
      X[9 * a + 3 + k] = g1(k);
      X[9 * a + 6 + k] = g2(k);
    }
  }
  return X;
}

struct Case
{
  int num_nodes;
  int axial_points;
  bool cure;
  double kappa;
};

std::vector<double> residual(const ElementRule& rule, const Material& m,
                             const SectionQuadrature& s, const std::vector<double>& X,
                             const std::vector<double>& x)
{
  std::vector<double> r(X.size(), 0.0);
  element_residual_tangent(rule, m, s, X, x, r, {});
  return r;
}
} // namespace

class BeamTangent : public ::testing::TestWithParam<Case>
{
};

TEST_P(BeamTangent, MatchesCentralFiniteDifferences)
{
  const Case c = GetParam();
  const ElementRule rule{c.num_nodes, gauss_legendre(c.axial_points), c.cure};
  const Material mat{2.0e3, 0.3};
  const auto sec = disk_quadrature(0.05, 4);
  const auto X = reference(c.num_nodes, 0.4, c.kappa);
  std::mt19937 gen(11 + c.num_nodes);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int trial = 0; trial < 3; ++trial)
  {
    // random finite deformation: stretch, bend, twist, section distortion
    std::vector<double> x = X;
    for (auto& v : x)
      v += 0.08 * U(gen);
    const std::size_t n = x.size();
    std::vector<double> r(n, 0.0), K(n * n, 0.0);
    element_residual_tangent(rule, mat, sec, X, x, r, K);
    auto f = [&](const std::vector<double>& y) { return residual(rule, mat, sec, X, y); };
    const auto Kfd = test::fd_jacobian(f, x, 1e-6);
    // central differences: truncation O(h^2 * r''') ~ 1e-10 relative
    EXPECT_LT(test::relative_error(K, Kfd), 1e-6);
    // symmetric: the element is hyperelastic
    double asym = 0, norm = 0;
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < n; ++j)
      {
        asym = std::max(asym, std::abs(K[i * n + j] - K[j * n + i]));
        norm = std::max(norm, std::abs(K[i * n + j]));
      }
    EXPECT_LT(asym, 1e-12 * norm); // round-off only
    // residual is the gradient of the energy
    auto energy = [&](const std::vector<double>& y)
    { return std::vector<double>{element_residual_tangent(rule, mat, sec, X, y, {}, {})}; };
    const auto g = test::fd_jacobian(energy, x, 1e-6);
    EXPECT_LT(test::relative_error(r, g), 1e-6);
  }
}

INSTANTIATE_TEST_SUITE_P(ElementTypes, BeamTangent,
                         ::testing::Values(Case{2, 1, true, 0.0}, Case{2, 2, true, 0.0},
                                           Case{3, 2, true, 0.0}, Case{3, 3, true, 0.0},
                                           Case{3, 3, false, 0.0}, Case{3, 2, true, 2.0},
                                           Case{2, 2, false, 2.0}, Case{3, 3, true, 2.0}));

TEST(BeamElement, RigidMotionIsStressFree)
{
  for (int nn : {2, 3})
    for (double kappa : {0.0, 2.0})
    {
      const ElementRule rule{nn, gauss_legendre(3), true};
      const Material mat{1.0, 0.3};
      const auto sec = disk_quadrature(0.05, 4);
      const auto X = reference(nn, 0.4, kappa);
      const Eigen::Matrix3d R
          = Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.3, -1, 2).normalized()).toRotationMatrix();
      std::vector<double> x(X.size());
      for (int a = 0; a < nn; ++a)
      {
        const Eigen::Map<const Eigen::Vector3d> X0(&X[9 * a]), G1(&X[9 * a + 3]),
            G2(&X[9 * a + 6]);
        Eigen::Map<Eigen::Vector3d> x0(&x[9 * a]), g1(&x[9 * a + 3]), g2(&x[9 * a + 6]);
        x0 = R * X0 + Eigen::Vector3d(1, 2, 3);
        g1 = R * G1;
        g2 = R * G2;
      }
      std::vector<double> r(X.size(), 0.0);
      const double e = element_residual_tangent(rule, mat, sec, X, x, r, {});
      EXPECT_NEAR(e, 0.0, 1e-16); // exact invariance, round-off only
      for (double v : r)
        EXPECT_NEAR(v, 0.0, 1e-13);
    }
}

TEST(BeamElement, UniaxialTensionIsExact)
{
  // docs/references.md §1: N = E A lambda (lambda^2 - 1)/2, |g| = sqrt(1 - nu (lambda^2 - 1))
  for (int nn : {2, 3})
    for (double lambda : {1.01, 1.10})
    {
      const double E = 3.0, nu = 0.3, R = 0.1, L = 0.7;
      const ElementRule rule{nn, gauss_legendre(2), true};
      const Material mat{E, nu};
      const auto sec = disk_quadrature(R, 4);
      const auto X = reference(nn, L, 0.0);
      const double gl = std::sqrt(1 - nu * (lambda * lambda - 1));
      std::vector<double> x = X;
      for (int a = 0; a < nn; ++a)
      {
        x[9 * a] *= lambda;
        for (int k = 3; k < 9; ++k)
          x[9 * a + k] *= gl;
      }
      std::vector<double> r(X.size(), 0.0);
      element_residual_tangent(rule, mat, sec, X, x, r, {});
      const double A = std::numbers::pi * R * R;
      const double N = E * A * lambda * (lambda * lambda - 1) / 2;
      // axial end force on the last node, nothing on the section vectors
      EXPECT_NEAR(r[9 * (nn - 1)], N, 1e-12 * N);
      EXPECT_NEAR(r[0], -N, 1e-12 * N);
      for (int a = 0; a < nn; ++a)
        for (int k = 3; k < 9; ++k)
          EXPECT_NEAR(r[9 * a + k], 0.0, 1e-13 * N);
    }
}

TEST(BeamElement, OnlyRigidZeroEnergyModes)
{
  // a free element must have exactly the 6 rigid-body zero-energy modes
  for (auto [nn, ng] : {std::pair{2, 1}, std::pair{2, 2}, std::pair{3, 2}, std::pair{3, 3}})
  {
    const ElementRule rule{nn, gauss_legendre(ng), true};
    const Material mat{1.0, 0.3};
    const auto sec = disk_quadrature(0.02, 4);
    const auto X = reference(nn, 0.1, 0.0);
    const std::size_t n = X.size();
    std::vector<double> K(n * n, 0.0);
    element_residual_tangent(rule, mat, sec, X, X, {}, K);
    const Eigen::Map<Eigen::MatrixXd> Km(K.data(), n, n);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Km);
    const auto ev = es.eigenvalues();
    const double tol = 1e-10 * ev.maxCoeff();
    int zeros = 0;
    for (int i = 0; i < ev.size(); ++i)
      zeros += std::abs(ev(i)) < tol;
    // even the one-point linear element: the section vectors' values and
    // slopes are both sampled, so no hourglass mode appears
    EXPECT_EQ(zeros, 6) << "num_nodes=" << nn << " axial_points=" << ng;
  }
}

TEST(BeamElement, RejectsDegenerateReference)
{
  const ElementRule rule{2, gauss_legendre(2), true};
  const Material mat{1.0, 0.3};
  const auto sec = disk_quadrature(0.02, 4);
  auto X = reference(2, 0.1, 0.0);
  for (int k = 3; k < 6; ++k) // g1 along the tangent
    X[k] = X[9 + k] = (k == 3);
  std::vector<double> r(18, 0.0);
  EXPECT_THROW(element_residual_tangent(rule, mat, sec, X, X, r, {}), std::runtime_error);
}

TEST(BeamElement, FoldedElementIsAGeometryError)
{
  // mid node pushed beyond the tip: the centre line reverses between the
  // Gauss points (the spurious St Venant-Kirchhoff equilibrium at stretch -1)
  const ElementRule rule{3, gauss_legendre(2), true};
  const Material mat{1.0, 0.3};
  const auto sec = disk_quadrature(0.01, 4);
  const auto X = reference(3, 0.2, 0.0);
  auto x = X;
  x[9] = 0.24;
  std::vector<double> r(27, 0.0), K(27 * 27, 0.0);
  EXPECT_THROW(element_residual_tangent(rule, mat, sec, X, x, r, {}), GeometryError);
  EXPECT_THROW(element_residual_tangent(rule, mat, sec, X, x, {}, K), GeometryError);
  EXPECT_THROW(element_fields(rule, mat, sec, X, x), GeometryError);
  try
  {
    element_residual_tangent(rule, mat, sec, X, x, r, {});
  }
  catch (const GeometryError& e)
  {
    EXPECT_NE(std::string(e.what()).find("det F = -"), std::string::npos) << e.what();
  }
  // a section flattened onto a line (g2 = g1 at every node): det F = 0
  x = X;
  for (int a = 0; a < 3; ++a)
    for (int k = 0; k < 3; ++k)
      x[9 * a + 6 + k] = x[9 * a + 3 + k];
  EXPECT_THROW(element_residual_tangent(rule, mat, sec, X, x, r, {}), GeometryError);
  // a strongly compressed but unfolded element (stretch 0.2) is in the domain
  x = X;
  for (int a = 0; a < 3; ++a)
    x[9 * a] *= 0.2;
  EXPECT_NO_THROW(element_residual_tangent(rule, mat, sec, X, x, r, K));
}

namespace
{
/// Tangent of one element, optionally the MIP Newton tangent for update dx.
Eigen::MatrixXd tangent(const ElementRule& rule, const Material& mat,
                        const SectionQuadrature& sec, const std::vector<double>& X,
                        const std::vector<double>& x, const std::vector<double>& dx = {},
                        const std::vector<double>& weights = {})
{
  const std::size_t n = X.size();
  std::vector<double> K(n * n, 0.0);
  element_residual_tangent(rule, mat, sec, X, x, {}, K, dx, weights);
  return Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      K.data(), n, n);
}

/// Every 3-vector (position, g1, g2 of each node) multiplied by A.
std::vector<double> map_vectors(const Eigen::Matrix3d& A, const std::vector<double>& v)
{
  std::vector<double> out(v.size());
  for (std::size_t s = 0; s < v.size(); s += 3)
    Eigen::Map<Eigen::Vector3d>{&out[s]} = A * Eigen::Map<const Eigen::Vector3d>(&v[s]);
  return out;
}

std::vector<double> random_state(const std::vector<double>& X, double scale, std::mt19937& gen)
{
  std::uniform_real_distribution<double> U(-1, 1);
  std::vector<double> x = X;
  for (auto& v : x)
    v += scale * U(gen);
  return x;
}

} // namespace

/// MIP tangents of one element type at random states (reference data, the
/// exact tangent's material and section, a random generator).
class MipTangent : public ::testing::TestWithParam<Case>
{
protected:
  const Case c = GetParam();
  const ElementRule rule{c.num_nodes, gauss_legendre(c.axial_points), c.cure};
  const Material mat{2.0e3, 0.3};
  const SectionQuadrature sec = disk_quadrature(0.05, 4);
  const std::vector<double> X = reference(c.num_nodes, 0.4, c.kappa);
  const std::vector<double> zero = std::vector<double>(X.size(), 0.0);
  std::mt19937 gen{5};

  Eigen::MatrixXd K(const std::vector<double>& x, const std::vector<double>& dx = {},
                    const std::vector<double>& weights = {})
  {
    return tangent(rule, mat, sec, X, x, dx, weights);
  }
};

TEST_P(MipTangent, ZeroOrTranslationUpdateGivesTheExactTangent)
{
  const auto x = random_state(X, 0.08, gen);
  const Eigen::MatrixXd K0 = K(x);
  // du = 0: bit for bit the exact tangent (checked against finite
  // differences in BeamTangent)
  EXPECT_EQ((K(x, zero) - K0).norm(), 0.0);
  // a translation of the centre line strains nothing: h(du) = 0 up to the
  // round-off of sum_a dN_a = 0 (measured 0)
  std::vector<double> du = zero;
  for (int a = 0; a < c.num_nodes; ++a)
    for (int k = 0; k < 3; ++k)
      du[9 * a + k] = 0.3 * (k + 1);
  EXPECT_LT((K(x, du) - K0).norm(), 1e-15 * K0.norm());
}

TEST_P(MipTangent, IsSymmetric)
{
  const auto x = random_state(X, 0.08, gen);
  const Eigen::MatrixXd Km = K(x, random_state(zero, 0.1, gen));
  // the geometric stiffness of any stress field is symmetric; round-off
  // only (measured 6e-17)
  EXPECT_LT((Km - Km.transpose()).norm(), 1e-15 * Km.norm());
}

TEST_P(MipTangent, DiffersByTheGeometricStiffnessOfTheUpdatesQuadraticStrain)
{
  // K_exact(x) - K_mip(x, du) = K_geo(stress of 1/2 h(du)^T h(du)).
  // (1) It depends on du only, not on x, and is quadratic in du.
  // (2) For du = M X (every position and section vector mapped by a fixed
  //     M), h(du) = M Q is uniform and 1/2 h^T h is the Green-Lagrange
  //     strain of the uniform state y = P X with P = sqrt(I + M^T M). There
  //     K_exact(y) = K_mat(y) + K_geo(that stress), and K_mat(y) = T K(X) T^T
  //     (T = P on every 3-vector; K(X) is purely material), which gives the
  //     geometric stiffness through exact tangents only.
  const std::size_t n = X.size();
  const auto x1 = random_state(X, 0.08, gen), x2 = random_state(X, 0.08, gen);
  const auto du = random_state(zero, 0.1, gen);
  std::vector<double> du2(n);
  for (std::size_t i = 0; i < n; ++i)
    du2[i] = 2 * du[i];
  const Eigen::MatrixXd D1 = K(x1) - K(x1, du), D2 = K(x2) - K(x2, du),
                        D4 = K(x1) - K(x1, du2);
  ASSERT_GT(D1.norm(), 1e-3 * K(x1).norm()); // not a vacuous test
  // round-off of differences of larger tangents (measured 5e-16)
  EXPECT_LT((D1 - D2).norm(), 3e-15 * D1.norm());
  EXPECT_LT((D4 - 4 * D1).norm(), 3e-15 * D4.norm());

  Eigen::Matrix3d M;
  M << 0.2, -0.1, 0.05, 0.07, 0.15, -0.12, -0.03, 0.11, 0.25;
  const Eigen::Matrix3d P
      = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(Eigen::Matrix3d::Identity()
                                                       + M.transpose() * M)
            .operatorSqrt();
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(n, n);
  for (std::size_t s = 0; s < n; s += 3)
    T.block<3, 3>(s, s) = P;
  const Eigen::MatrixXd Kgeo = K(map_vectors(P, X)) - T * K(X) * T.transpose();
  const Eigen::MatrixXd D = K(x1) - K(x1, map_vectors(M, X));
  ASSERT_GT(Kgeo.norm(), 1e-3 * K(x1).norm());
  EXPECT_LT((D - Kgeo).norm(), 1e-13 * Kgeo.norm()); // round-off, measured 2.3e-14
}

TEST_P(MipTangent, WeightedUpdatesAddTheirGeometricStiffnesses)
{
  // k updates with weights c_k (a predicted state's extrapolated stress):
  // K_exact - K_mip = sum_k c_k (K_exact - K_mip(du_k)), the strain
  // correction being linear in each quadratic form.
  const std::size_t n = X.size();
  const auto x = random_state(X, 0.08, gen);
  const auto du1 = random_state(zero, 0.1, gen), du2 = random_state(zero, 0.1, gen);
  std::vector<double> both(du1);
  both.insert(both.end(), du2.begin(), du2.end());
  const Eigen::MatrixXd K0 = K(x), D1 = K0 - K(x, du1), D2 = K0 - K(x, du2);
  const Eigen::MatrixXd D = K0 - K(x, both, {1.5, -0.5});
  ASSERT_GT(D.norm(), 1e-3 * K0.norm()); // not a vacuous test
  // round-off of three differences of larger tangents (measured 5.6e-15)
  EXPECT_LT((D - 1.5 * D1 + 0.5 * D2).norm(), 2e-14 * D.norm());
  // one update of weight 4 is the update doubled, weight 1 the plain MIP
  std::vector<double> twice(n);
  for (std::size_t i = 0; i < n; ++i)
    twice[i] = 2 * du1[i];
  EXPECT_LT((K(x, du1, {4.0}) - K(x, twice)).norm(), 3e-15 * K0.norm());
  EXPECT_EQ((K(x, du1, {1.0}) - K(x, du1)).norm(), 0.0);
  // sizes: weights must match the updates, at most max_mip_updates of them
  EXPECT_THROW(K(x, both, {1.0}), std::invalid_argument);
  std::vector<double> too_many;
  for (int k = 0; k <= max_mip_updates; ++k)
    too_many.insert(too_many.end(), du1.begin(), du1.end());
  EXPECT_THROW(K(x, too_many), std::invalid_argument);
}

INSTANTIATE_TEST_SUITE_P(ElementTypes, MipTangent,
                         ::testing::Values(Case{2, 1, true, 0.0}, Case{3, 2, true, 0.0},
                                           Case{3, 2, true, 2.0}, Case{3, 3, false, 2.0}));
