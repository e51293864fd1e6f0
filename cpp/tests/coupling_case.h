// A fibre end held by a rigid body, as the coupling tests set it up: a
// section (x0, g1, g2) or a point, off the centre of a body turned by a
// given angle, with values that satisfy no row (so every row is tested).
#pragma once

#include "../textile/rigid/rigid_coupling.h"

#include <Eigen/Dense>

#include <cstddef>
#include <vector>

namespace textile::test
{
/// The coupling's reference vectors and the values of its unknowns.
struct CouplingCase
{
  rigid::CouplingBase base;
  std::vector<double> q, centre, theta, lambda, scale;
};

/// A section (or a point) coupled to a body with its centre off the origin,
/// turned by `angle` about a skew axis; no multipliers yet (their number
/// depends on the coupling: see set_multipliers).
inline CouplingCase coupling_case(bool section, double angle)
{
  CouplingCase c;
  c.base.offset = Eigen::Vector3d(0.2, -0.1, 0.05);
  c.base.g1 = Eigen::Vector3d(0, 1, 0);
  c.base.g2 = Eigen::Vector3d(0, 0, 1);
  c.base.section = section;
  for (int k = 0; k < c.base.rows(); ++k)
    c.q.push_back(0.1 * k - 0.3);
  c.centre = {0.3, 0.1, -0.2};
  const Eigen::Vector3d th = angle * Eigen::Vector3d(0.3, -0.6, 0.74).normalized();
  c.theta = {th(0), th(1), th(2)};
  return c;
}

/// m multipliers and row scales, all different so that rows mixed up show.
inline void set_multipliers(CouplingCase& c, std::size_t m)
{
  c.lambda.clear();
  c.scale.clear();
  for (std::size_t k = 0; k < m; ++k)
  {
    c.lambda.push_back(0.5 - 0.2 * k);
    c.scale.push_back(1.0 + 0.5 * k);
  }
}

/// The unknowns [q, u, theta, lambda] as one vector (u moves the centre).
inline std::vector<double> pack(const CouplingCase& c)
{
  std::vector<double> x = c.q;
  x.insert(x.end(), c.centre.begin(), c.centre.end());
  x.insert(x.end(), c.theta.begin(), c.theta.end());
  x.insert(x.end(), c.lambda.begin(), c.lambda.end());
  return x;
}
} // namespace textile::test
