#include "particle.h"
#include "../beam/shape_functions.h"

#include <algorithm>
#include <array>
#include <stdexcept>

namespace textile::contact
{
namespace
{
/// Lagrange functions of an element (num_nodes 2 or 3) at xi, continued
/// past [-1, 1], with their first and second derivatives.
void lagrange2(int num_nodes, double xi, std::array<double, 3>& n, std::array<double, 3>& dn,
               std::array<double, 3>& ddn)
{
  beam::lagrange(num_nodes, xi, n, dn);
  ddn = num_nodes == 3 ? std::array<double, 3>{1.0, -2.0, 1.0} : std::array<double, 3>{};
}
} // namespace

PatchShape::PatchShape(const Particle& p, double xi)
{
  if (p.num_nodes < 2 or p.num_nodes > 3 or p.patch_elements < 1 or p.patch_elements > 2)
    throw std::invalid_argument("PatchShape: elements of 2 or 3 nodes, patches of 1 or 2");
  // past an end: the straight line along the end's tangent (C1 there)
  const double end = std::clamp(xi, p.patch_min(), p.patch_max());
  if (xi != end)
  {
    *this = PatchShape(p, end);
    for (int k = 0; k < p.patch_nodes(); ++k)
      n[k] += (xi - end) * dn[k], ddn[k] = 0.0;
    return;
  }
  std::array<double, 3> a, da, dda;
  if (p.patch_elements == 1)
  {
    lagrange2(p.num_nodes, xi, a, da, dda);
    for (int k = 0; k < p.num_nodes; ++k)
      n[k] = a[k], dn[k] = da[k], ddn[k] = dda[k];
    return;
  }
  // two elements A (xi in [-1, 1]) and B (xi in [1, 3]), blended across
  // the shared node (xi = 1) over |xi - 1| < w, w in xi units
  const int shift = p.num_nodes - 1; // B's first node in the patch
  const double w = 2.0 * patch_smoothing;
  const double tau = (xi - (1.0 - w)) / (2.0 * w);
  double phi = 0, dphi = 0, ddphi = 0; // blend and its derivatives in xi
  if (tau >= 1)
    phi = 1;
  else if (tau > 0)
  {
    phi = tau * tau * (3.0 - 2.0 * tau);
    dphi = 6.0 * tau * (1.0 - tau) / (2.0 * w);
    ddphi = (6.0 - 12.0 * tau) / (4.0 * w * w);
  }
  std::array<double, 3> b, db, ddb;
  lagrange2(p.num_nodes, xi, a, da, dda);
  lagrange2(p.num_nodes, xi - 2.0, b, db, ddb);
  for (int k = 0; k < p.num_nodes; ++k)
  {
    n[k] += (1.0 - phi) * a[k];
    dn[k] += (1.0 - phi) * da[k] - dphi * a[k];
    ddn[k] += (1.0 - phi) * dda[k] - 2.0 * dphi * da[k] - ddphi * a[k];
    n[shift + k] += phi * b[k];
    dn[shift + k] += phi * db[k] + dphi * b[k];
    ddn[shift + k] += phi * ddb[k] + 2.0 * dphi * db[k] + ddphi * b[k];
  }
}

std::vector<double> particle_coefficients(const Particle& p)
{
  std::array<double, 3> n, dn;
  beam::lagrange(p.num_nodes, p.xi, n, dn);
  std::vector<double> c(3 * p.patch_nodes(), 0.0);
  const int o = p.node_offset();
  for (int a = 0; a < p.num_nodes; ++a)
  {
    c[3 * (o + a) + 0] = n[a];
    c[3 * (o + a) + 1] = n[a] * p.xi1;
    c[3 * (o + a) + 2] = n[a] * p.xi2;
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
} // namespace textile::contact
