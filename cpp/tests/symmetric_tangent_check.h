// The check an exact tangent of a potential passes: it equals central
// differences of its residual and its own transpose, to tolerances relative
// to its largest entry (entries of different units share one scale).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace textile::test
{
/// Expects the n x n row-major tangent K to match Kfd to fd_tol and K^T to
/// symmetry_tol, both times max |K_ij|; a failure names the entry (i, j).
inline void expect_symmetric_tangent(const std::vector<double>& K, const std::vector<double>& Kfd,
                                     std::size_t n, double fd_tol, double symmetry_tol)
{
  double scale = 0;
  for (double v : K)
    scale = std::max(scale, std::abs(v));
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j)
    {
      EXPECT_NEAR(K[i * n + j], Kfd[i * n + j], fd_tol * scale) << i << " " << j;
      EXPECT_NEAR(K[i * n + j], K[j * n + i], symmetry_tol * scale) << i << " " << j;
    }
}
} // namespace textile::test
