// Lagrange shape functions of the fibre elements along their axis.
#pragma once

#include <array>
#include <stdexcept>

namespace textile::beam
{

/// Values n and derivatives dn/dxi at xi in [-1, 1] of the Lagrange shape
/// functions of an element with num_nodes = 2 (linear) or 3 (quadratic,
/// middle node at xi = 0) nodes. Unused entries are zero.
inline void lagrange(int num_nodes, double xi, std::array<double, 3>& n,
                     std::array<double, 3>& dn)
{
  if (num_nodes == 2)
  {
    n = {0.5 * (1.0 - xi), 0.5 * (1.0 + xi), 0.0};
    dn = {-0.5, 0.5, 0.0};
  }
  else if (num_nodes == 3)
  {
    n = {0.5 * xi * (xi - 1.0), 1.0 - xi * xi, 0.5 * xi * (xi + 1.0)};
    dn = {xi - 0.5, -2.0 * xi, xi + 0.5};
  }
  else
    throw std::invalid_argument("lagrange: num_nodes must be 2 or 3");
}

} // namespace textile::beam
