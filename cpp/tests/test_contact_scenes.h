// Small contact scenes shared by the contact unit tests.
#pragma once

#include <textile/contact/centreline.h>

#include <Eigen/Dense>

#include <cmath>
#include <utility>
#include <vector>

namespace textile::contact::scenes
{
/// Two straight fibres of ne quadratic elements and length `length`
/// centred on the z axis: fibre 0 along x at z = 0, fibre 1 at `angle`
/// (radians) to it in a plane z = height (default: touching minus `gap`).
inline Centrelines two_lines(double angle, int ne, double length, double radius, double gap)
{
  Centrelines c;
  c.order = 2;
  c.radius = {radius, radius};
  c.fibre_offsets = {0};
  const Eigen::Vector3d ti(1, 0, 0), tj(std::cos(angle), std::sin(angle), 0);
  for (const auto& [t, z] : {std::pair{ti, 0.0}, std::pair{tj, 2 * radius - gap}})
  {
    for (int k = 0; k <= 2 * ne; ++k)
    {
      const Eigen::Vector3d p = (k / (2.0 * ne) - 0.5) * length * t + Eigen::Vector3d(0, 0, z);
      c.x.insert(c.x.end(), {p[0], p[1], p[2]});
    }
    c.fibre_offsets.push_back(c.x.size() / 3);
  }
  return c;
}

/// Section vectors [g1, g2] of every node of two_lines: g1 = e_z, g2 =
/// t x g1.
inline std::vector<double> section_vectors_along(const Centrelines& c)
{
  std::vector<double> g;
  for (std::size_t n = 0; n < c.x.size() / 3; ++n)
  {
    const Eigen::Vector3d t = n < static_cast<std::size_t>(c.fibre_offsets[1])
                                  ? Eigen::Vector3d(c.x[3] - c.x[0], c.x[4] - c.x[1], 0)
                                  : Eigen::Vector3d(c.x.end()[-3] - c.x.end()[-6],
                                                    c.x.end()[-2] - c.x.end()[-5], 0);
    const Eigen::Vector3d g1 = Eigen::Vector3d::UnitZ(), g2 = t.normalized().cross(g1);
    g.insert(g.end(), {g1[0], g1[1], g1[2], g2[0], g2[1], g2[2]});
  }
  return g;
}
} // namespace textile::contact::scenes
