// Central finite differences for tangent checks.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

namespace textile::test
{
/// Jacobian of f: R^n -> R^m at x by central differences (row-major m x n).
inline std::vector<double> fd_jacobian(const std::function<std::vector<double>(const std::vector<double>&)>& f,
                                       std::vector<double> x, double h)
{
  const std::size_t n = x.size();
  const std::size_t m = f(x).size();
  std::vector<double> J(m * n);
  for (std::size_t j = 0; j < n; ++j)
  {
    const double xj = x[j];
    x[j] = xj + h;
    const auto fp = f(x);
    x[j] = xj - h;
    const auto fm = f(x);
    x[j] = xj;
    for (std::size_t i = 0; i < m; ++i)
      J[i * n + j] = (fp[i] - fm[i]) / (2 * h);
  }
  return J;
}

/// ||a - b|| / ||b|| in the Frobenius norm.
inline double relative_error(const std::vector<double>& a, const std::vector<double>& b)
{
  double d = 0, nb = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
  {
    d += (a[i] - b[i]) * (a[i] - b[i]);
    nb += b[i] * b[i];
  }
  return std::sqrt(d / nb);
}
} // namespace textile::test
