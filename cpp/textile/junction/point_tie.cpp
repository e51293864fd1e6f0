#include "point_tie.h"

#include <cmath>
#include <stdexcept>

namespace textile::junction
{
double point_tie(double k, std::span<const double> phi, std::span<const double> u_a,
                 std::span<const double> u_cell, std::span<const double> gap0,
                 std::span<double> r, std::span<double> K)
{
  const std::size_t n = phi.size(), m = 3 + 3 * n;
  if (u_a.size() != 3 or u_cell.size() != 3 * n or gap0.size() != 3 or r.size() != m
      or (!K.empty() and K.size() != m * m))
    throw std::invalid_argument("point_tie: wrong array size");
  double gap[3];
  for (int c = 0; c < 3; ++c)
  {
    gap[c] = u_a[c] + gap0[c];
    for (std::size_t i = 0; i < n; ++i)
      gap[c] -= phi[i] * u_cell[3 * i + c];
  }
  // coefficient of each of the 1 + n points in gap: +1 for a, -phi_i
  auto coef = [&](std::size_t p) { return p == 0 ? 1.0 : -phi[p - 1]; };
  for (std::size_t p = 0; p < 1 + n; ++p)
    for (int c = 0; c < 3; ++c)
      r[3 * p + c] += k * coef(p) * gap[c];
  if (!K.empty())
    for (std::size_t p = 0; p < 1 + n; ++p)
      for (std::size_t q = 0; q < 1 + n; ++q)
        for (int c = 0; c < 3; ++c)
          K[(3 * p + c) * m + 3 * q + c] += k * coef(p) * coef(q);
  return std::sqrt(gap[0] * gap[0] + gap[1] * gap[1] + gap[2] * gap[2]);
}
} // namespace textile::junction
