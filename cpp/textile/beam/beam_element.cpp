#include "beam_element.h"
#include "../geometry_error.h"
#include "shape_functions.h"

#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace textile::beam
{
namespace
{
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

/// Shape functions of an N-node element at xi (see shape_functions.h).
template <int N>
void shape(double xi, std::array<double, N>& n, std::array<double, N>& dn)
{
  std::array<double, 3> n3, dn3;
  lagrange(N, xi, n3, dn3);
  for (int a = 0; a < N; ++a)
  {
    n[a] = n3[a];
    dn[a] = dn3[a];
  }
}

/// One section point's kinematic data: psi_j (j = local frame direction)
/// gives h_j = F e_j = sum_s psi_j[s] q_s, with q_s the 3-vector unknown
/// number s = 3*node + field (field 0: x0, 1: g1, 2: g2).
template <int N>
struct PointData
{
  Eigen::Matrix<double, 3, 3 * N> psi; // row j: psi_j
  double dV = 0;                       // weight x reference volume factor
};

/// Reference geometry at section point (xi1, xi2) of axial point xi:
/// B = F_ref^{-1} Q maps the local frame to convected directions, and
/// det F_ref is the volume factor.
template <int N>
PointData<N> point_data(std::span<const double> X, const std::array<double, N>& n,
                        const std::array<double, N>& dn, double xi1, double xi2, double w)
{
  Vec3 dX0 = Vec3::Zero(), G1 = Vec3::Zero(), G2 = Vec3::Zero(), dG1 = Vec3::Zero(),
       dG2 = Vec3::Zero();
  for (int a = 0; a < N; ++a)
  {
    const Eigen::Map<const Vec3> X0a(X.data() + 9 * a), G1a(X.data() + 9 * a + 3),
        G2a(X.data() + 9 * a + 6);
    dX0 += dn[a] * X0a;
    G1 += n[a] * G1a;
    G2 += n[a] * G2a;
    dG1 += dn[a] * G1a;
    dG2 += dn[a] * G2a;
  }
  Mat3 Fref;
  Fref.col(0) = G1;
  Fref.col(1) = G2;
  Fref.col(2) = dX0 + xi1 * dG1 + xi2 * dG2;
  const double det = Fref.determinant();
  if (!(det > 0))
    throw std::runtime_error("beam element: degenerate or inverted reference geometry "
                             "(section vectors must be independent and not along the tangent)");
  // local orthonormal frame of the reference section
  const Vec3 e3 = dX0.normalized();
  const Vec3 e1 = (G1 - G1.dot(e3) * e3).normalized();
  const Vec3 e2 = e3.cross(e1);
  Mat3 Q;
  Q << e1, e2, e3;
  const Mat3 B = Fref.inverse() * Q;

  PointData<N> p;
  for (int j = 0; j < 3; ++j)
    for (int a = 0; a < N; ++a)
    {
      p.psi(j, 3 * a + 0) = B(2, j) * dn[a];
      p.psi(j, 3 * a + 1) = B(0, j) * n[a] + B(2, j) * xi1 * dn[a];
      p.psi(j, 3 * a + 2) = B(1, j) * n[a] + B(2, j) * xi2 * dn[a];
    }
  p.dV = w * det;
  return p;
}

/// Green-Lagrange strain (Voigt) and its derivative with respect to the
/// element unknowns at one point; returns det F.
template <int N>
double strain(const PointData<N>& p, const Eigen::Matrix<double, 3, 3 * N>& q, Voigt& eps,
              Eigen::Matrix<double, 6, 9 * N>& Bv)
{
  // h_j = F e_j, as columns
  const Mat3 h = q * p.psi.transpose();
  const Mat3 C = h.transpose() * h;
  eps << 0.5 * (C(0, 0) - 1.0), 0.5 * (C(1, 1) - 1.0), 0.5 * (C(2, 2) - 1.0), C(1, 2), C(0, 2),
      C(0, 1);
  constexpr std::array<std::array<int, 2>, 6> jk = {{{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}}};
  for (int s = 0; s < 3 * N; ++s)
    for (int v = 0; v < 6; ++v)
    {
      const int j = jk[v][0], k = jk[v][1];
      Vec3 d;
      if (j == k)
        d = p.psi(j, s) * h.col(j);
      else
        d = p.psi(k, s) * h.col(j) + p.psi(j, s) * h.col(k);
      Bv.template block<1, 3>(v, 3 * s) = d.transpose();
    }
  // h = F Q with Q the (proper) local frame: det h = det F
  return h.determinant();
}

/// A folded or inverted point (det F <= 0, or not a number) is outside the
/// model's domain: St Venant-Kirchhoff gives a reversed fibre (stretch -1)
/// zero energy, so such a state may look like an equilibrium.
[[noreturn]] void throw_folded(double detF, std::size_t g, double xi_axial, double xi1,
                               double xi2)
{
  std::ostringstream msg;
  msg << "folded or inverted beam element: det F = " << detF << " <= 0 at axial point " << g
      << " (xi = " << xi_axial << "), section point (" << xi1 << ", " << xi2
      << "); the iterate reverses the fibre or flattens its section (load step too large?)";
  throw GeometryError(msg.str());
}

/// 1/2 h^T h in the Voigt order of the strain (engineering shears), for the
/// second-order part of the strain of an update: h_j = dF e_j.
Voigt half_gram(const Mat3& h)
{
  const Mat3 C = h.transpose() * h;
  Voigt v;
  v << 0.5 * C(0, 0), 0.5 * C(1, 1), 0.5 * C(2, 2), C(1, 2), C(0, 2), C(0, 1);
  return v;
}

Mat3 voigt_to_tensor(const Voigt& S)
{
  Mat3 T;
  T << S(0), S(5), S(4), S(5), S(1), S(3), S(4), S(3), S(2);
  return T;
}

template <int N>
double evaluate(const ElementRule& rule, const Material& mat, const SectionQuadrature& sec,
                std::span<const double> X, std::span<const double> x, std::span<double> r,
                std::span<double> K, std::span<const double> dx, ElementFields* fields)
{
  constexpr int ndof = 9 * N;
  using Dofs = Eigen::Matrix<double, ndof, 1>;
  using DofMat = Eigen::Matrix<double, ndof, ndof>;
  using BMat = Eigen::Matrix<double, 6, ndof>;

  // current unknowns as 3 x 3N (column s = q_s)
  const Eigen::Map<const Eigen::Matrix<double, 3, 3 * N>> q(x.data());
  const VoigtMatrix C = mat.elasticity();
  const VoigtMatrix D = mat.fluctuation_elasticity();
  const bool want_r = !r.empty(), want_K = !K.empty();
  const bool mip = want_K and !dx.empty();
  const Eigen::Map<const Eigen::Matrix<double, 3, 3 * N>> dq(mip ? dx.data() : x.data());

  Dofs re = Dofs::Zero();
  DofMat Ke = DofMat::Zero();
  Eigen::Matrix<double, 3 * N, 3 * N> Kg = Eigen::Matrix<double, 3 * N, 3 * N>::Zero();
  double energy = 0;

  const std::size_t nq = sec.size();
  std::vector<PointData<N>> pts(nq);
  std::vector<Voigt> eps(nq);
  // strain whose stress enters the geometric stiffness (MIP: extrapolated)
  std::vector<Voigt> eps_geo(nq);
  std::vector<BMat> Bv(nq);

  std::array<double, N> n, dn;
  for (std::size_t g = 0; g < rule.axial.points.size(); ++g)
  {
    shape<N>(rule.axial.points[g], n, dn);
    double W = 0;
    Voigt eps_bar = Voigt::Zero(), eps_geo_bar = Voigt::Zero();
    BMat B_bar = BMat::Zero();
    for (std::size_t i = 0; i < nq; ++i)
    {
      pts[i] = point_data<N>(X, n, dn, sec.xi1[i], sec.xi2[i],
                             rule.axial.weights[g] * sec.weights[i]);
      const double detF = strain<N>(pts[i], q, eps[i], Bv[i]);
      if (!(detF > 0))
        throw_folded(detF, g, rule.axial.points[g], sec.xi1[i], sec.xi2[i]);
      W += pts[i].dV;
      eps_bar += pts[i].dV * eps[i];
      eps_geo[i] = mip ? Voigt(eps[i] - half_gram(dq * pts[i].psi.transpose())) : eps[i];
      eps_geo_bar += pts[i].dV * eps_geo[i];
      if (want_K and rule.poisson_cure)
        B_bar += pts[i].dV * Bv[i];
    }
    eps_bar /= W;
    eps_geo_bar /= W;
    B_bar /= W;
    const Voigt S_bar = C * eps_bar;
    const Voigt S_geo_bar = C * eps_geo_bar;
    if (fields)
    {
      fields->strain += eps_bar / rule.axial.points.size();
      fields->stress += S_bar / rule.axial.points.size(); // fluctuation averages to zero
    }

    for (std::size_t i = 0; i < nq; ++i)
    {
      Voigt S, S_geo;
      if (rule.poisson_cure)
      {
        const Voigt de = eps[i] - eps_bar;
        S = S_bar + D * de;
        S_geo = S_geo_bar + D * (eps_geo[i] - eps_geo_bar);
        energy += pts[i].dV * 0.5 * (eps_bar.dot(S_bar) + de.dot(D * de));
      }
      else
      {
        S = C * eps[i];
        S_geo = C * eps_geo[i];
        energy += pts[i].dV * 0.5 * eps[i].dot(S);
      }
      if (want_r)
        re.noalias() += pts[i].dV * Bv[i].transpose() * S;
      if (want_K)
      {
        // geometric part: sum_jk S_jk psi_j psi_k^T (x) I3
        Kg.noalias() += pts[i].dV * pts[i].psi.transpose() * voigt_to_tensor(S_geo) * pts[i].psi;
        if (rule.poisson_cure)
        {
          const BMat dB = Bv[i] - B_bar;
          // D is diagonal on rows 2, 3, 4 only
          for (int v = 2; v <= 4; ++v)
            Ke.noalias() += (pts[i].dV * D(v, v)) * dB.row(v).transpose() * dB.row(v);
        }
        else
          Ke.noalias() += pts[i].dV * Bv[i].transpose() * C * Bv[i];
      }
    }
    if (want_K and rule.poisson_cure)
      Ke.noalias() += W * B_bar.transpose() * C * B_bar;
  }

  if (want_r)
  {
    Eigen::Map<Dofs> rout(r.data());
    rout += re;
  }
  if (want_K)
  {
    for (int s = 0; s < 3 * N; ++s)
      for (int t = 0; t < 3 * N; ++t)
        for (int c = 0; c < 3; ++c)
          Ke(3 * s + c, 3 * t + c) += Kg(s, t);
    Eigen::Map<Eigen::Matrix<double, ndof, ndof, Eigen::RowMajor>> Kout(K.data());
    Kout += Ke;
  }
  return energy;
}

void check_sizes(const ElementRule& rule, std::span<const double> X, std::span<const double> x,
                 std::span<double> r, std::span<double> K, std::span<const double> dx = {})
{
  if (rule.num_nodes != 2 and rule.num_nodes != 3)
    throw std::invalid_argument("beam element: num_nodes must be 2 or 3");
  const std::size_t n = 9 * rule.num_nodes;
  if (X.size() != n or x.size() != n or (!r.empty() and r.size() != n)
      or (!K.empty() and K.size() != n * n) or (!dx.empty() and dx.size() != n))
    throw std::invalid_argument("beam element: wrong local array size");
  if (rule.axial.points.empty())
    throw std::invalid_argument("beam element: empty axial quadrature");
}
} // namespace

double element_residual_tangent(const ElementRule& rule, const Material& mat,
                                const SectionQuadrature& section,
                                std::span<const double> X, std::span<const double> x,
                                std::span<double> r, std::span<double> K,
                                std::span<const double> dx)
{
  check_sizes(rule, X, x, r, K, dx);
  if (rule.num_nodes == 2)
    return evaluate<2>(rule, mat, section, X, x, r, K, dx, nullptr);
  return evaluate<3>(rule, mat, section, X, x, r, K, dx, nullptr);
}

ElementFields element_fields(const ElementRule& rule, const Material& mat,
                             const SectionQuadrature& section, std::span<const double> X,
                             std::span<const double> x)
{
  check_sizes(rule, X, x, {}, {});
  ElementFields f;
  if (rule.num_nodes == 2)
    evaluate<2>(rule, mat, section, X, x, {}, {}, {}, &f);
  else
    evaluate<3>(rule, mat, section, X, x, {}, {}, {}, &f);
  return f;
}

} // namespace textile::beam
