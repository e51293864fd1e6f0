#include "contact_element.h"
#include "tolerances.h"

#include <cmath>
#include <stdexcept>

namespace textile::contact
{
namespace
{
using RowMajorMap = Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>;
} // namespace

ContactResult contact_element(const Particle& pi, const Particle& pj,
                              const Eigen::Vector3d& N, const NormalLaw& law,
                              const RegularizedCoulomb* friction, const Eigen::Vector3d& stick,
                              std::span<const double> xi, std::span<const double> xj,
                              std::span<double> r, std::span<double> K, double gap_offset,
                              const GapMotion& motion, bool motion_tangent)
{
  // Delta = sum_s b_s q_s over both elements: b = [c_i, -c_j] (friction)
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

  // the normal part: R_N(gap) along the gap's gradient (gap_function.h)
  const GapFunction gap(pi, pj, N, motion, xi, xj, gap_offset, true);
  const Eigen::VectorXd& G = gap.gradient();
  out.separation = gap.separation();
  out.gap = gap.gap();
  out.gap_xi = {gap.patch_xi_i(), gap.patch_xi_j()};
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
    gap.add_hessian(-RN, Km, motion_tangent);
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
                   std::span<const double> xi, std::span<const double> xj, double gap_offset,
                   const GapMotion& motion)
{
  // the same function as contact_element's, to the last bit
  return GapFunction(pi, pj, N, motion, xi, xj, gap_offset, false).gap();
}

Eigen::Vector3d updated_stick(const Eigen::Vector3d& N, const RegularizedCoulomb& friction,
                              const Eigen::Vector3d& delta, const Eigen::Vector3d& stick)
{
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - N * N.transpose();
  const Eigen::Vector3d uT = P * (delta - stick);
  const double n = uT.norm();
  if (n <= friction.u_rev)
    return stick;
  // keep the elastic part u_rev along the slip direction, just inside the
  // stick cone (stick_margin, tolerances.h)
  return stick + (1.0 - (1.0 - stick_margin) * friction.u_rev / n) * uT;
}
} // namespace textile::contact
