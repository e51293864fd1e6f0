#include "contact_element.h"
#include "../beam/shape_functions.h"

#include <array>
#include <cmath>
#include <stdexcept>

namespace textile::contact
{
std::vector<double> particle_coefficients(const Particle& p)
{
  std::array<double, 3> n, dn;
  beam::lagrange(p.num_nodes, p.xi, n, dn);
  std::vector<double> c(3 * p.num_nodes);
  for (int a = 0; a < p.num_nodes; ++a)
  {
    c[3 * a + 0] = n[a];
    c[3 * a + 1] = n[a] * p.xi1;
    c[3 * a + 2] = n[a] * p.xi2;
  }
  return c;
}

Eigen::Vector3d particle_position(const Particle& p, std::span<const double> x)
{
  const auto c = particle_coefficients(p);
  if (x.size() != 3 * c.size())
    throw std::invalid_argument("particle_position: wrong nodal array size");
  Eigen::Vector3d pos = Eigen::Vector3d::Zero();
  for (std::size_t s = 0; s < c.size(); ++s)
    pos += c[s] * Eigen::Map<const Eigen::Vector3d>(x.data() + 3 * s);
  return pos;
}

namespace
{
/// Section vectors g1, g2 at the particle's abscissa.
std::array<Eigen::Vector3d, 2> section_vectors(const Particle& p, std::span<const double> x,
                                               const std::array<double, 3>& n)
{
  std::array<Eigen::Vector3d, 2> g = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  for (int a = 0; a < p.num_nodes; ++a)
    for (int al = 0; al < 2; ++al)
      g[al] += n[a] * Eigen::Map<const Eigen::Vector3d>(x.data() + 9 * a + 3 + 3 * al);
  return g;
}

/// (g1.N, g2.N), or zero when the section is edge-on to N (fibre along the
/// normal): no extent, and no direction to differentiate.
Eigen::Vector2d support_direction(const std::array<Eigen::Vector3d, 2>& g,
                                  const Eigen::Vector3d& N)
{
  const Eigen::Vector2d c(g[0].dot(N), g[1].dot(N));
  if (c.norm() < 1e-12 * (g[0].norm() + g[1].norm()))
    return Eigen::Vector2d::Zero();
  return c;
}

using RowMajorMap = Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>;

/// Support of a section in direction N: h = R |(g1.N, g2.N)|, the extent of
/// the (deformed) disk x0 + xi1 g1 + xi2 g2, |xi| <= R, along +-N. Adds its
/// gradient (times `sign`) into G and, if H is given, its Hessian (times
/// `sign` x `h_scale`) into H, for the element whose dofs start at
/// `offset`; returns h.
double support(const Particle& p, std::span<const double> x, const Eigen::Vector3d& N,
               double sign, std::size_t offset, Eigen::VectorXd& G, RowMajorMap* H = nullptr,
               double h_scale = 1.0)
{
  std::array<double, 3> n, dn;
  beam::lagrange(p.num_nodes, p.xi, n, dn);
  const Eigen::Vector2d c = support_direction(section_vectors(p, x, n), N);
  const double nc = c.norm();
  if (nc == 0)
    return 0.0;
  const double h = p.radius * nc;
  for (int a = 0; a < p.num_nodes; ++a)
    for (int al = 0; al < 2; ++al)
      G.segment<3>(offset + 9 * a + 3 + 3 * al) += sign * n[a] * p.radius * c(al) / nc * N;
  if (H)
  {
    const Eigen::Matrix2d M = h_scale * p.radius
                              * (Eigen::Matrix2d::Identity() / nc - c * c.transpose() / (nc * nc * nc));
    const Eigen::Matrix3d NN = N * N.transpose();
    for (int a = 0; a < p.num_nodes; ++a)
      for (int b = 0; b < p.num_nodes; ++b)
        for (int al = 0; al < 2; ++al)
          for (int be = 0; be < 2; ++be)
            H->block<3, 3>(offset + 9 * a + 3 + 3 * al, offset + 9 * b + 3 + 3 * be)
                += sign * n[a] * n[b] * M(al, be) * NN;
  }
  return h;
}

/// Centroid x0 at the particle's abscissa, and the gap gradient of x0 (times sign).
Eigen::Vector3d centroid(const Particle& p, std::span<const double> x, const Eigen::Vector3d& N,
                         double sign, std::size_t offset, Eigen::VectorXd& G)
{
  std::array<double, 3> n, dn;
  beam::lagrange(p.num_nodes, p.xi, n, dn);
  Eigen::Vector3d x0 = Eigen::Vector3d::Zero();
  for (int a = 0; a < p.num_nodes; ++a)
  {
    x0 += n[a] * Eigen::Map<const Eigen::Vector3d>(x.data() + 9 * a);
    G.segment<3>(offset + 9 * a) += sign * n[a] * N;
  }
  return x0;
}
} // namespace

ContactResult contact_element(const Particle& pi, const Particle& pj,
                              const Eigen::Vector3d& N, const NormalLaw& law,
                              const RegularizedCoulomb* friction, const Eigen::Vector3d& stick,
                              std::span<const double> xi, std::span<const double> xj,
                              std::span<double> r, std::span<double> K, double gap_offset)
{
  // Delta = sum_s b_s q_s over both elements: b = [c_i, -c_j] (friction)
  const auto ci = particle_coefficients(pi), cj = particle_coefficients(pj);
  std::vector<double> b(ci);
  for (double c : cj)
    b.push_back(-c);
  const std::size_t ns = b.size(), n = 3 * ns, off_j = 3 * ci.size();
  if (xi.size() != 3 * ci.size() or xj.size() != 3 * cj.size() or r.size() != n
      or (!K.empty() and K.size() != n * n))
    throw std::invalid_argument("contact_element: wrong array size");

  ContactResult out;
  out.position_i = particle_position(pi, xi);
  out.position_j = particle_position(pj, xj);
  out.delta = out.position_i - out.position_j;

  // gap = N.(x0_i - x0_j) - h_i(N) - h_j(N): distance of the two deformed
  // sections along N. The supports follow the sections' rotation, so a
  // section turning about its axis under load does not change the gap
  // (material particles would, and feed a spurious torsion back).
  Eigen::VectorXd G = Eigen::VectorXd::Zero(n);
  const Eigen::Vector3d x0i = centroid(pi, xi, N, 1.0, 0, G);
  const Eigen::Vector3d x0j = centroid(pj, xj, N, -1.0, off_j, G);
  const double hi = support(pi, xi, N, -1.0, 0, G);
  const double hj = support(pj, xj, N, -1.0, off_j, G);
  // the weaving stage's offset moves the centre lines apart virtually
  out.separation = N.dot(x0i - x0j) + gap_offset;
  out.gap = out.separation - hi - hj;
  const double RN = law.reaction(out.gap), dRN = law.stiffness(out.gap);
  const double dRN_newton = law.newton_stiffness(out.gap); // the tangent's (a floor)
  out.normal_force = RN;
  Eigen::Map<Eigen::VectorXd> rv(r.data(), n);
  RowMajorMap Km(K.data(), K.empty() ? 0 : n, K.empty() ? 0 : n);
  rv.setZero();
  if (!K.empty())
    Km.setZero();
  if (RN == 0 and dRN_newton == 0)
    return out; // open: no force, no stiffness (friction needs R_N > 0)
  rv = -RN * G;
  if (!K.empty())
  {
    Km.noalias() = -dRN_newton * G * G.transpose();
    // minus R_N times the supports' Hessian (the gradient is already in G)
    Eigen::VectorXd scratch = Eigen::VectorXd::Zero(n);
    support(pi, xi, N, -1.0, 0, scratch, &Km, -RN);
    support(pj, xj, N, -1.0, off_j, scratch, &Km, -RN);
  }

  // friction at the material particles: T . dDelta/dq, Delta = sum b_s q_s
  if (friction and friction->mu > 0 and RN > 0)
  {
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - N * N.transpose();
    const Eigen::Vector3d uT = P * (out.delta - stick);
    const auto fr = friction->evaluate(RN, uT);
    out.tangential_force = fr.T;
    out.slip = fr.slip;
    const Eigen::Matrix3d D = fr.dT_du * P;
    const Eigen::Vector3d dTdR = fr.dT_dRN * dRN;
    for (std::size_t s = 0; s < ns; ++s)
      for (int c = 0; c < 3; ++c)
      {
        rv(3 * s + c) += b[s] * fr.T(c);
        if (K.empty())
          continue;
        for (std::size_t t = 0; t < ns; ++t)
          for (int d = 0; d < 3; ++d)
            Km(3 * s + c, 3 * t + d) += b[s] * b[t] * D(c, d);
        Km.row(3 * s + c) += (b[s] * dTdR(c)) * G.transpose();
      }
  }
  return out;
}

double contact_gap(const Particle& pi, const Particle& pj, const Eigen::Vector3d& N,
                   std::span<const double> xi, std::span<const double> xj, double gap_offset)
{
  // the same expression as contact_element's, to the last bit
  Eigen::Vector3d x0[2];
  double h[2];
  for (int side = 0; side < 2; ++side)
  {
    const Particle& p = side == 0 ? pi : pj;
    const std::span<const double> x = side == 0 ? xi : xj;
    std::array<double, 3> n, dn;
    beam::lagrange(p.num_nodes, p.xi, n, dn);
    x0[side] = Eigen::Vector3d::Zero();
    for (int a = 0; a < p.num_nodes; ++a)
      x0[side] += n[a] * Eigen::Map<const Eigen::Vector3d>(x.data() + 9 * a);
    h[side] = p.radius * support_direction(section_vectors(p, x, n), N).norm();
  }
  return N.dot(x0[0] - x0[1]) - h[0] - h[1] + gap_offset;
}

Eigen::Vector3d updated_stick(const Eigen::Vector3d& N, const RegularizedCoulomb& friction,
                              const Eigen::Vector3d& delta, const Eigen::Vector3d& stick)
{
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - N * N.transpose();
  const Eigen::Vector3d uT = P * (delta - stick);
  const double n = uT.norm();
  if (n <= friction.u_rev)
    return stick;
  // keep the elastic part u_rev along the slip direction
  return stick + (1.0 - friction.u_rev / n) * uT;
}
} // namespace textile::contact
