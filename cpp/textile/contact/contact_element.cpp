#include "contact_element.h"
#include "../beam/shape_functions.h"

#include <array>
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

ContactResult contact_element(const Particle& pi, const Particle& pj,
                              const Eigen::Vector3d& N, const NormalLaw& law,
                              const RegularizedCoulomb* friction, const Eigen::Vector3d& stick,
                              std::span<const double> xi, std::span<const double> xj,
                              std::span<double> r, std::span<double> K)
{
  // Delta = sum_s b_s q_s over both elements: b = [c_i, -c_j]
  const auto ci = particle_coefficients(pi), cj = particle_coefficients(pj);
  std::vector<double> b(ci);
  for (double c : cj)
    b.push_back(-c);
  const std::size_t ns = b.size(), n = 3 * ns;
  if (xi.size() != 3 * ci.size() or xj.size() != 3 * cj.size() or r.size() != n
      or (!K.empty() and K.size() != n * n))
    throw std::invalid_argument("contact_element: wrong array size");

  ContactResult out;
  out.position_i = particle_position(pi, xi);
  out.position_j = particle_position(pj, xj);
  out.delta = out.position_i - out.position_j;
  out.gap = N.dot(out.delta);
  const double RN = law.reaction(out.gap), dRN = law.stiffness(out.gap);
  out.normal_force = RN;

  // force f on Delta (internal force conjugate to Delta) and its derivative
  // df/dDelta; then r_s += b_s f and K_st += b_s b_t df/dDelta
  Eigen::Vector3d f = -RN * N;
  Eigen::Matrix3d D = -dRN * N * N.transpose();
  if (friction and friction->mu > 0 and RN > 0)
  {
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - N * N.transpose();
    const Eigen::Vector3d uT = P * (out.delta - stick);
    const auto fr = friction->evaluate(RN, uT);
    f += fr.T;
    D += fr.dT_du * P + fr.dT_dRN * (dRN * N.transpose());
    out.tangential_force = fr.T;
    out.slip = fr.slip;
  }
  for (std::size_t s = 0; s < ns; ++s)
    for (int c = 0; c < 3; ++c)
      r[3 * s + c] += b[s] * f(c);
  if (!K.empty())
    for (std::size_t s = 0; s < ns; ++s)
      for (std::size_t t = 0; t < ns; ++t)
        for (int c = 0; c < 3; ++c)
          for (int d = 0; d < 3; ++d)
            K[(3 * s + c) * n + 3 * t + d] += b[s] * b[t] * D(c, d);
  return out;
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
