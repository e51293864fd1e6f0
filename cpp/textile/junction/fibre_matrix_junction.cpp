#include "fibre_matrix_junction.h"
#include "../beam/shape_functions.h"

#include <array>
#include <stdexcept>

namespace textile::junction
{
double fibre_matrix_junction(double k, double w, int num_fibre_nodes, double xi,
                             std::span<const double> X_f, std::span<const double> u_f,
                             std::span<const double> X_m, std::span<const double> phi,
                             std::span<const double> u_m, std::span<double> gap,
                             std::span<double> r, std::span<double> K)
{
  std::array<double, 3> N, dN;
  beam::lagrange(num_fibre_nodes, xi, N, dN); // throws unless 2 or 3 nodes
  const std::size_t nf = static_cast<std::size_t>(num_fibre_nodes), nm = phi.size();
  const std::size_t m = 3 * (nf + nm);
  if (X_f.size() != 3 * nf or u_f.size() != 3 * nf or X_m.size() != 3 or u_m.size() != 3 * nm
      or (!gap.empty() and gap.size() != 3) or (!r.empty() and r.size() != m)
      or (!K.empty() and K.size() != m * m))
    throw std::invalid_argument("fibre_matrix_junction: wrong array size");
  double g[3];
  for (int c = 0; c < 3; ++c)
  {
    g[c] = -X_m[c];
    for (std::size_t a = 0; a < nf; ++a)
      g[c] += N[a] * (X_f[3 * a + c] + u_f[3 * a + c]);
    for (std::size_t b = 0; b < nm; ++b)
      g[c] -= phi[b] * u_m[3 * b + c];
  }
  const double kw = k * w;
  // d gap / d u of each point p (fibre nodes, then matrix nodes), times I3
  auto coef = [&](std::size_t p) { return p < nf ? N[p] : -phi[p - nf]; };
  if (!gap.empty())
    for (int c = 0; c < 3; ++c)
      gap[c] = g[c];
  if (!r.empty())
    for (std::size_t p = 0; p < nf + nm; ++p)
      for (int c = 0; c < 3; ++c)
        r[3 * p + c] += kw * coef(p) * g[c];
  if (!K.empty())
    for (std::size_t p = 0; p < nf + nm; ++p)
    {
      const double cp = coef(p);
      for (std::size_t q = 0; q < nf + nm; ++q)
      {
        const double v = kw * (cp * coef(q)); // bitwise symmetric
        for (int c = 0; c < 3; ++c)
          K[(3 * p + c) * m + 3 * q + c] += v;
      }
    }
  return 0.5 * kw * (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
}
} // namespace textile::junction
