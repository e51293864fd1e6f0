#include "beam_element.h"
#include "../node_unknowns.h"
#include "../geometry_error.h"
#include "shape_functions.h"

#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

namespace textile::beam
{
namespace
{
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

/// Convected unknowns at an axial point: z = [x0', g1, g2, g1', g2'].
constexpr int nz = 5;
using ZMat = Eigen::Matrix<double, 3, nz>;
/// Derivative of the strain (Voigt) with respect to z (column 3 m + c:
/// component c of z_m).
using BzMat = Eigen::Matrix<double, 6, 3 * nz>;
using KzMat = Eigen::Matrix<double, 3 * nz, 3 * nz>;

/// Voigt index -> tensor indices (j, k).
constexpr std::array<std::array<int, 2>, 6> voigt_pairs
    = {{{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}}};

/// z at an axial point from the element's nodal vectors q (column 3a + f:
/// field f = x0, g1, g2 of node a) and the shape functions there.
template <int N>
ZMat convected(const Eigen::Map<const Eigen::Matrix<double, 3, 3 * N>>& q,
               const std::array<double, 3>& n, const std::array<double, 3>& dn)
{
  ZMat z = ZMat::Zero();
  for (int a = 0; a < N; ++a)
  {
    z.col(0) += dn[a] * q.col(3 * a);
    z.col(1) += n[a] * q.col(3 * a + 1);
    z.col(2) += n[a] * q.col(3 * a + 2);
    z.col(3) += dn[a] * q.col(3 * a + 1);
    z.col(4) += dn[a] * q.col(3 * a + 2);
  }
  return z;
}

/// h = F Q (column j: h_j = F e_j) at section point (xi1, xi2).
Mat3 deformation(const ZMat& z, const Mat3& B, double xi1, double xi2)
{
  Mat3 Fc;
  Fc << z.col(1), z.col(2), z.col(0) + xi1 * z.col(3) + xi2 * z.col(4);
  return Fc * B;
}

/// beta(j, m) = d h_j / d z_m (a scalar: h_j is linear in z).
ZMat convected_derivative(const Mat3& B, double xi1, double xi2)
{
  ZMat beta;
  beta.col(0) = B.row(2).transpose();
  beta.col(1) = B.row(0).transpose();
  beta.col(2) = B.row(1).transpose();
  beta.col(3) = xi1 * B.row(2).transpose();
  beta.col(4) = xi2 * B.row(2).transpose();
  return beta;
}

/// 1/2 h^T h in the Voigt order of the strain (engineering shears).
Voigt half_gram(const Mat3& h)
{
  const Mat3 C = h.transpose() * h;
  Voigt v;
  v << 0.5 * C(0, 0), 0.5 * C(1, 1), 0.5 * C(2, 2), C(1, 2), C(0, 2), C(0, 1);
  return v;
}

/// Green-Lagrange strain 1/2 (h^T h - I), Voigt.
Voigt green_lagrange(const Mat3& h)
{
  Voigt e = half_gram(h);
  e.head<3>().array() -= 0.5;
  return e;
}

/// d strain / d z: row (j, k) is sym(h_j . dh_k) with dh_k = beta(k, m) dz_m
/// (engineering shear: both terms).
BzMat strain_derivative(const Mat3& h, const ZMat& beta)
{
  BzMat Bz;
  for (int v = 0; v < 6; ++v)
  {
    const int j = voigt_pairs[v][0], k = voigt_pairs[v][1];
    for (int m = 0; m < nz; ++m)
    {
      if (j == k)
        Bz.block<1, 3>(v, 3 * m) = beta(j, m) * h.col(j).transpose();
      else
        Bz.block<1, 3>(v, 3 * m)
            = beta(k, m) * h.col(j).transpose() + beta(j, m) * h.col(k).transpose();
    }
  }
  return Bz;
}

Mat3 voigt_to_tensor(const Voigt& S)
{
  Mat3 T;
  T << S(0), S(5), S(4), S(5), S(1), S(3), S(4), S(3), S(2);
  return T;
}

/// K += A B^T on the 3x3 blocks on and above the diagonal (K symmetric: the
/// blocks below are filled at the end), with fixed-size products.
template <int Cols>
void add_product_upper(KzMat& K, const Eigen::Matrix<double, 3 * nz, Cols>& A,
                       const Eigen::Matrix<double, 3 * nz, Cols>& B)
{
  [&]<int... l>(std::integer_sequence<int, l...>)
  {
    ((K.template block<3 * (l + 1), 3>(0, 3 * l).noalias()
      += A.template topRows<3 * (l + 1)>().lazyProduct(
          B.template middleRows<3>(3 * l).transpose())),
     ...);
  }(std::make_integer_sequence<int, nz>{});
}

/// Geometric stiffness with respect to z, sum over section points of
/// dV beta^T S beta. beta(:, m) = f_m B(r_m, :)^T with r = (2, 0, 1, 2, 2)
/// and f = (1, 1, 1, xi1, xi2) (convected_derivative), so entry (m, l) is
/// f_m f_l M(r_m, r_l) with M = B S B^T: the sums of dV M and of its third
/// row weighted by xi1, xi2 and their products are all it needs.
class GeometricStiffness
{
public:
  void add(double dV, const Mat3& B, const Mat3& S, double xi1, double xi2)
  {
    const Mat3 M = dV * B * S * B.transpose();
    _M += M;
    _M1 += xi1 * M.row(2).transpose();
    _M2 += xi2 * M.row(2).transpose();
    _m11 += xi1 * xi1 * M(2, 2);
    _m12 += xi1 * xi2 * M(2, 2);
    _m22 += xi2 * xi2 * M(2, 2);
  }

  /// The 5 x 5 matrix (entry m, l multiplies dz_m . dz_l).
  Eigen::Matrix<double, nz, nz> matrix() const
  {
    constexpr std::array<int, 3> r = {2, 0, 1};
    Eigen::Matrix<double, nz, nz> K;
    for (int m = 0; m < 3; ++m)
    {
      for (int l = 0; l < 3; ++l)
        K(m, l) = _M(r[m], r[l]);
      K(m, 3) = K(3, m) = _M1(r[m]);
      K(m, 4) = K(4, m) = _M2(r[m]);
    }
    K(3, 3) = _m11;
    K(3, 4) = K(4, 3) = _m12;
    K(4, 4) = _m22;
    return K;
  }

private:
  Mat3 _M = Mat3::Zero();
  Vec3 _M1 = Vec3::Zero(), _M2 = Vec3::Zero();
  double _m11 = 0, _m12 = 0, _m22 = 0;
};

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

/// What the kernel keeps of one section point between its two passes.
struct SectionPoint
{
  Mat3 h;
  ZMat beta;
  BzMat Bz;
  Voigt eps, eps_geo; // strain, and the one whose stress enters K_geo
  double dV;
};

/// The section points' data, one scratch per thread: no allocation per
/// element.
std::vector<SectionPoint>& section_points(std::size_t nq)
{
  thread_local std::vector<SectionPoint> points;
  if (points.size() < nq)
    points.resize(nq);
  return points;
}

/// Element unknown s = 3a + f (field f of node a) in terms of z: two
/// (z index, shape coefficient) pairs. x0 enters z through x0' only; its
/// second pair has coefficient 0, so that every loop over pairs has two
/// terms and no branch.
struct ZTerms
{
  std::array<int, 2> m;
  std::array<double, 2> c;
};

template <int N>
std::array<ZTerms, 3 * N> z_terms(const std::array<double, 3>& n, const std::array<double, 3>& dn)
{
  std::array<ZTerms, 3 * N> t;
  for (int a = 0; a < N; ++a)
  {
    t[3 * a] = {{0, 0}, {dn[a], 0.0}};
    t[3 * a + 1] = {{1, 3}, {n[a], dn[a]}};
    t[3 * a + 2] = {{2, 4}, {n[a], dn[a]}};
  }
  return t;
}

template <int N>
double evaluate(const ElementRule& rule, const Material& mat, const SectionQuadrature& sec,
                std::span<const ReferencePoint> ref, std::span<const double> x,
                std::span<double> r, std::span<double> K, std::span<const double> dx,
                std::span<const double> dx_weights, ElementFields* fields)
{
  constexpr int ndof = dofs_per_node * N;
  using DofMat = Eigen::Matrix<double, ndof, ndof>;

  const Eigen::Map<const Eigen::Matrix<double, 3, 3 * N>> q(x.data());
  const bool want_r = !r.empty(), want_K = !K.empty();
  const bool mip = want_K and !dx.empty();
  // the MIP's updates (check_sizes: 1 to max_mip_updates of ndof values each)
  const int num_dx = mip ? static_cast<int>(dx.size()) / ndof : 0;
  const VoigtMatrix C = mat.elasticity();
  // the fluctuation law is diagonal (material.h): its moduli as a vector
  const Voigt D = mat.fluctuation_elasticity().diagonal();
  const bool cure = rule.poisson_cure;
  // the fluctuation law acts on E33, 2E23, 2E13 only (material.h)
  constexpr std::array<int, 3> fluct_rows = {2, 3, 4};

  const std::size_t nq = sec.size();
  std::vector<SectionPoint>& pts = section_points(nq);

  Eigen::Matrix<double, 3, 3 * N> rq = Eigen::Matrix<double, 3, 3 * N>::Zero();
  DofMat Ke;
  if (want_K)
    Ke.setZero();
  double energy = 0;

  std::array<double, 3> n, dn;
  for (std::size_t g = 0; g < rule.axial.points.size(); ++g)
  {
    lagrange(N, rule.axial.points[g], n, dn);
    const ZMat z = convected<N>(q, n, dn);
    std::array<ZMat, max_mip_updates> dz;
    for (int k = 0; k < num_dx; ++k)
      dz[k] = convected<N>(Eigen::Map<const Eigen::Matrix<double, 3, 3 * N>>(dx.data() + k * ndof),
                           n, dn);

    // pass 1: strains and their section averages
    double W = 0;
    Voigt eps_bar = Voigt::Zero(), eps_geo_bar = Voigt::Zero();
    BzMat Bz_bar = BzMat::Zero();
    for (std::size_t i = 0; i < nq; ++i)
    {
      const ReferencePoint& rp = ref[g * nq + i];
      const double xi1 = sec.xi1[i], xi2 = sec.xi2[i];
      SectionPoint& p = pts[i];
      p.h = deformation(z, rp.B, xi1, xi2);
      // h = F Q with Q a proper rotation: det h = det F
      const double detF = p.h.determinant();
      if (!(detF > 0))
        throw_folded(detF, g, rule.axial.points[g], xi1, xi2);
      p.dV = rp.dV;
      p.eps = green_lagrange(p.h);
      // MIP: E(x) - 1/2 h(dx)^T h(dx), the linear extrapolation of E from
      // the previous iterate (see beam_element.h)
      p.eps_geo = p.eps;
      for (int k = 0; k < num_dx; ++k)
        p.eps_geo -= (dx_weights.empty() ? 1.0 : dx_weights[k])
                     * half_gram(deformation(dz[k], rp.B, xi1, xi2));
      W += p.dV;
      eps_bar += p.dV * p.eps;
      eps_geo_bar += p.dV * p.eps_geo;
      if (want_r or want_K)
        p.beta = convected_derivative(rp.B, xi1, xi2);
      if (want_K)
      {
        p.Bz = strain_derivative(p.h, p.beta);
        if (cure)
          Bz_bar += p.dV * p.Bz;
      }
    }
    eps_bar /= W;
    eps_geo_bar /= W;
    Bz_bar /= W;
    const Voigt S_bar = C * eps_bar;
    const Voigt S_geo_bar = C * eps_geo_bar;
    if (fields)
    {
      fields->strain += eps_bar / rule.axial.points.size();
      fields->stress += S_bar / rule.axial.points.size(); // fluctuation averages to zero
    }
    if (!want_r and !want_K)
    {
      for (std::size_t i = 0; i < nq; ++i)
      {
        const Voigt de = pts[i].eps - eps_bar;
        energy += pts[i].dV * 0.5
                  * (cure ? eps_bar.dot(S_bar) + de.dot(D.cwiseProduct(de))
                          : pts[i].eps.dot(C * pts[i].eps));
      }
      continue;
    }

    // pass 2: stresses, force and tangent with respect to z
    ZMat rz = ZMat::Zero();
    KzMat Kz = KzMat::Zero(); // blocks on and above the diagonal
    GeometricStiffness Kg;
    for (std::size_t i = 0; i < nq; ++i)
    {
      const SectionPoint& p = pts[i];
      Voigt S, S_geo;
      if (cure)
      {
        const Voigt de = p.eps - eps_bar;
        S = S_bar + D.cwiseProduct(de);
        S_geo = S_geo_bar + D.cwiseProduct(p.eps_geo - eps_geo_bar);
        energy += p.dV * 0.5 * (eps_bar.dot(S_bar) + de.dot(D.cwiseProduct(de)));
      }
      else
      {
        S = C * p.eps;
        S_geo = C * p.eps_geo;
        energy += p.dV * 0.5 * p.eps.dot(S);
      }
      // S : dE = (h S) : dh = sum_m ((h S) beta)_m . dz_m
      if (want_r)
        rz.noalias() += p.dV * (p.h * voigt_to_tensor(S)) * p.beta;
      if (!want_K)
        continue;
      // geometric part: sum_jk S_jk dh_j . dh_k
      Kg.add(p.dV, ref[g * nq + i].B, voigt_to_tensor(S_geo), sec.xi1[i], sec.xi2[i]);
      if (cure)
      {
        // fluctuation: sum_v dV D_vv dB_v^T dB_v over the rows D acts on
        Eigen::Matrix<double, 3 * nz, 3> Gt;
        for (int k = 0; k < 3; ++k)
        {
          const int v = fluct_rows[k];
          Gt.col(k) = std::sqrt(p.dV * D(v)) * (p.Bz.row(v) - Bz_bar.row(v)).transpose();
        }
        add_product_upper<3>(Kz, Gt, Gt);
      }
      else
      {
        const Eigen::Matrix<double, 3 * nz, 6> Bt = p.Bz.transpose();
        add_product_upper<6>(Kz, Bt, p.dV * Bt * C);
      }
    }

    // map z -> element unknowns through the shape functions
    const auto terms = z_terms<N>(n, dn);
    if (want_r)
      for (int s = 0; s < 3 * N; ++s)
        rq.col(s) += terms[s].c[0] * rz.col(terms[s].m[0]) + terms[s].c[1] * rz.col(terms[s].m[1]);
    if (want_K)
    {
      if (cure) // the section average sees the 3D law
      {
        const Eigen::Matrix<double, 3 * nz, 6> Bt = Bz_bar.transpose();
        add_product_upper<6>(Kz, Bt, W * Bt * C);
      }
      const Eigen::Matrix<double, nz, nz> Kgz = Kg.matrix();
      for (int m = 0; m < nz; ++m)
        for (int l = m; l < nz; ++l)
          Kz.block<3, 3>(3 * m, 3 * l).diagonal().array() += Kgz(m, l);
      for (int m = 1; m < nz; ++m) // the blocks below the diagonal
        for (int l = 0; l < m; ++l)
          Kz.block<3, 3>(3 * m, 3 * l) = Kz.block<3, 3>(3 * l, 3 * m).transpose();
      // Ke += Nz^T Kz Nz, Nz the sparse map from element unknowns to z
      // (blocks on and above the diagonal; Ke is symmetric)
      Eigen::Matrix<double, 3 * nz, ndof> T; // Kz Nz
      for (int t = 0; t < 3 * N; ++t)
        T.template middleCols<3>(3 * t)
            = terms[t].c[0] * Kz.template middleCols<3>(3 * terms[t].m[0])
              + terms[t].c[1] * Kz.template middleCols<3>(3 * terms[t].m[1]);
      for (int s = 0; s < 3 * N; ++s)
        for (int t = s; t < 3 * N; ++t)
          Ke.template block<3, 3>(3 * s, 3 * t)
              += terms[s].c[0] * T.template block<3, 3>(3 * terms[s].m[0], 3 * t)
                 + terms[s].c[1] * T.template block<3, 3>(3 * terms[s].m[1], 3 * t);
    }
  }

  if (want_r)
  {
    Eigen::Map<Eigen::Matrix<double, 3, 3 * N>> rout(r.data());
    rout += rq;
  }
  if (want_K)
  {
    // Ke holds the blocks on and above the diagonal
    Eigen::Map<Eigen::Matrix<double, ndof, ndof, Eigen::RowMajor>> Kout(K.data());
    for (int s = 0; s < 3 * N; ++s)
      for (int t = 0; t < 3 * N; ++t)
        if (s <= t)
          Kout.template block<3, 3>(3 * s, 3 * t) += Ke.template block<3, 3>(3 * s, 3 * t);
        else
          Kout.template block<3, 3>(3 * s, 3 * t)
              += Ke.template block<3, 3>(3 * t, 3 * s).transpose();
  }
  return energy;
}

void check_sizes(const ElementRule& rule, const SectionQuadrature& section, std::size_t num_ref,
                 std::span<const double> x, std::span<double> r, std::span<double> K,
                 std::span<const double> dx, std::span<const double> dx_weights)
{
  if (rule.num_nodes != 2 and rule.num_nodes != 3)
    throw std::invalid_argument("beam element: num_nodes must be 2 or 3");
  if (rule.axial.points.empty())
    throw std::invalid_argument("beam element: empty axial quadrature");
  const std::size_t n = dofs_per_node * rule.num_nodes;
  if (x.size() != n or (!r.empty() and r.size() != n) or (!K.empty() and K.size() != n * n)
      or dx.size() % n != 0 or dx.size() > max_mip_updates * n
      or (!dx_weights.empty() and dx_weights.size() * n != dx.size())
      or num_ref != num_points(rule, section))
    throw std::invalid_argument("beam element: wrong local array size");
}

/// Reference data of an element evaluated on the fly (one element at a time).
std::vector<ReferencePoint> reference_of(const ElementRule& rule, const SectionQuadrature& section,
                                         std::span<const double> X)
{
  if (rule.num_nodes != 2 and rule.num_nodes != 3)
    throw std::invalid_argument("beam element: num_nodes must be 2 or 3");
  if (X.size() != static_cast<std::size_t>(dofs_per_node * rule.num_nodes))
    throw std::invalid_argument("beam element: wrong local array size");
  std::vector<ReferencePoint> ref(num_points(rule, section));
  reference_points(rule, section, X, ref);
  return ref;
}
} // namespace

double element_residual_tangent(const ElementRule& rule, const Material& mat,
                                const SectionQuadrature& section,
                                std::span<const ReferencePoint> ref, std::span<const double> x,
                                std::span<double> r, std::span<double> K,
                                std::span<const double> dx,
                                std::span<const double> dx_weights)
{
  check_sizes(rule, section, ref.size(), x, r, K, dx, dx_weights);
  if (rule.num_nodes == 2)
    return evaluate<2>(rule, mat, section, ref, x, r, K, dx, dx_weights, nullptr);
  return evaluate<3>(rule, mat, section, ref, x, r, K, dx, dx_weights, nullptr);
}

double element_residual_tangent(const ElementRule& rule, const Material& mat,
                                const SectionQuadrature& section,
                                std::span<const double> X, std::span<const double> x,
                                std::span<double> r, std::span<double> K,
                                std::span<const double> dx,
                                std::span<const double> dx_weights)
{
  return element_residual_tangent(rule, mat, section, reference_of(rule, section, X), x, r, K,
                                  dx, dx_weights);
}

ElementFields element_fields(const ElementRule& rule, const Material& mat,
                             const SectionQuadrature& section,
                             std::span<const ReferencePoint> ref, std::span<const double> x)
{
  check_sizes(rule, section, ref.size(), x, {}, {}, {}, {});
  ElementFields f;
  if (rule.num_nodes == 2)
    evaluate<2>(rule, mat, section, ref, x, {}, {}, {}, {}, &f);
  else
    evaluate<3>(rule, mat, section, ref, x, {}, {}, {}, {}, &f);
  return f;
}

ElementFields element_fields(const ElementRule& rule, const Material& mat,
                             const SectionQuadrature& section, std::span<const double> X,
                             std::span<const double> x)
{
  return element_fields(rule, mat, section, reference_of(rule, section, X), x);
}

} // namespace textile::beam
