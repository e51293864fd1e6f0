#include "regularized_penalty.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace textile::contact
{
RegularizedPenalty::RegularizedPenalty(double k, double g_r, double floor)
    : _k(k), _gr(g_r), _floor(floor)
{
  if (!(floor >= 0 and floor <= 1))
    throw std::invalid_argument("RegularizedPenalty: the tangent floor must be in [0, 1]");
  if (!(k > 0) or !std::isfinite(k))
    throw std::invalid_argument("RegularizedPenalty: penalty must be positive and finite");
  if (!(g_r > 0) or !std::isfinite(g_r))
    throw std::invalid_argument("RegularizedPenalty: regularization depth must be positive");
}

double RegularizedPenalty::reaction(double gap) const
{
  if (gap >= 0)
    return 0.0;
  if (gap > -_gr)
    return _k * gap * gap / (2.0 * _gr);
  return _k * (-gap - 0.5 * _gr);
}

double RegularizedPenalty::stiffness(double gap) const
{
  if (gap >= 0)
    return 0.0;
  if (gap > -_gr)
    return _k * gap / _gr;
  return -_k;
}

double RegularizedPenalty::newton_stiffness(double gap) const
{
  const double exact = stiffness(gap);
  return gap < _gr ? std::min(exact, -_floor * _k) : exact;
}

double RegularizedPenalty::penetration(double R) const
{
  if (R <= 0)
    return 0.0;
  if (R < 0.5 * _k * _gr) // inside the quadratic part
    return std::sqrt(2.0 * _gr * R / _k);
  return R / _k + 0.5 * _gr;
}
} // namespace textile::contact
