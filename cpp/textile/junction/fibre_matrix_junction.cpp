#include "fibre_matrix_junction.h"
#include "../node_unknowns.h"
#include "../beam/shape_functions.h"

#include <array>
#include <stdexcept>

namespace textile::junction
{
double fibre_matrix_junction(double k, double w, int num_fibre_nodes, double xi,
                             std::span<const double> c, std::span<const double> X_f,
                             std::span<const double> u_f, std::span<const double> X_m,
                             std::span<const double> phi, std::span<const double> u_m,
                             std::span<double> gap, std::span<double> r, std::span<double> K)
{
  std::array<double, 3> N, dN;
  beam::lagrange(num_fibre_nodes, xi, N, dN); // throws unless 2 or 3 nodes
  const std::size_t nf = static_cast<std::size_t>(num_fibre_nodes), nm = phi.size();
  // "points": 3 per fibre node (x0, g1, g2) and 1 per matrix node, each a
  // 3-vector entering the gap with a scalar coefficient
  const std::size_t np = 3 * nf + nm, m = 3 * np;
  const std::size_t nq = dofs_per_node * nf; // the fibre nodes' unknowns
  if (c.size() != 2 or X_f.size() != nq or u_f.size() != nq or X_m.size() != 3
      or u_m.size() != 3 * nm or (!gap.empty() and gap.size() != 3)
      or (!r.empty() and r.size() != m) or (!K.empty() and K.size() != m * m))
    throw std::invalid_argument("fibre_matrix_junction: wrong array size");
  const double cs[3] = {1.0, c[0], c[1]};
  // d gap / d u of each point p, times I3
  auto coef = [&](std::size_t p) { return p < 3 * nf ? N[p / 3] * cs[p % 3] : -phi[p - 3 * nf]; };
  double g[3];
  for (int d = 0; d < 3; ++d)
  {
    g[d] = -X_m[d];
    for (std::size_t p = 0; p < 3 * nf; ++p)
      g[d] += coef(p) * (X_f[3 * p + d] + u_f[3 * p + d]);
    for (std::size_t b = 0; b < nm; ++b)
      g[d] -= phi[b] * u_m[3 * b + d];
  }
  const double kw = k * w;
  if (!gap.empty())
    for (int d = 0; d < 3; ++d)
      gap[d] = g[d];
  if (!r.empty())
    for (std::size_t p = 0; p < np; ++p)
      for (int d = 0; d < 3; ++d)
        r[3 * p + d] += kw * coef(p) * g[d];
  if (!K.empty())
    for (std::size_t p = 0; p < np; ++p)
    {
      const double cp = coef(p);
      if (cp == 0.0)
        continue; // centre-line particles: no section-vector rows
      for (std::size_t q = 0; q < np; ++q)
      {
        const double v = kw * (cp * coef(q)); // bitwise symmetric
        for (int d = 0; d < 3; ++d)
          K[(3 * p + d) * m + 3 * q + d] += v;
      }
    }
  return 0.5 * kw * (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
}
} // namespace textile::junction
