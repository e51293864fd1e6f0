#include "weaving_order.h"

#include <stdexcept>
#include <string>

namespace textile::contact
{
WeavingOrder::WeavingOrder(std::vector<int> fibre_yarn, std::vector<std::int8_t> above,
                           int num_yarns, bool pass_through)
    : _fibre_yarn(std::move(fibre_yarn)), _above(std::move(above)), _num_yarns(num_yarns),
      _pass_through(pass_through)
{
  const std::size_t n = num_yarns;
  if (num_yarns < 0 or _above.size() != n * n)
    throw std::invalid_argument("WeavingOrder: yarn_above must be (yarns x yarns)");
  for (std::size_t f = 0; f < _fibre_yarn.size(); ++f)
    if (_fibre_yarn[f] < 0 or _fibre_yarn[f] >= num_yarns)
      throw std::invalid_argument("WeavingOrder: fibre " + std::to_string(f) + " has yarn "
                                  + std::to_string(_fibre_yarn[f]) + ", outside 0.."
                                  + std::to_string(num_yarns - 1));
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = 0; b < n; ++b)
    {
      const int v = _above[a * n + b];
      if (v < -1 or v > 1)
        throw std::invalid_argument("WeavingOrder: yarn_above values must be -1, 0 or +1");
      if (v != -_above[b * n + a])
        throw std::invalid_argument("WeavingOrder: yarn_above must be antisymmetric (yarns "
                                    + std::to_string(a) + " and " + std::to_string(b) + ")");
    }
}

int WeavingOrder::sign(int fibre_i, int fibre_j) const
{
  if (fibre_i < 0 or fibre_j < 0 or fibre_i >= num_fibres() or fibre_j >= num_fibres())
    throw std::invalid_argument("WeavingOrder: fibre outside the order's fibres");
  return _above[static_cast<std::size_t>(_fibre_yarn[fibre_i]) * _num_yarns
                + _fibre_yarn[fibre_j]];
}

Eigen::Vector3d WeavingOrder::normal(int fibre_i, int fibre_j) const
{
  return sign(fibre_i, fibre_j) * Eigen::Vector3d::UnitZ();
}
} // namespace textile::contact
