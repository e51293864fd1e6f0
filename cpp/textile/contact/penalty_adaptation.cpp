#include "penalty_adaptation.h"
#include "regularized_penalty.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace textile::contact
{
void PenaltyAdaptation::validate() const
{
  if (!(target > 0) or !(regularization > 0) or !std::isfinite(target)
      or !std::isfinite(regularization))
    throw std::invalid_argument("PenaltyAdaptation: target and regularization must be positive");
  if (!(0 < band_low and band_low <= 1 and 1 <= retune_high and retune_high <= band_high
        and std::isfinite(band_high)))
    throw std::invalid_argument(
        "PenaltyAdaptation: need 0 < band_low <= 1 <= retune_high <= band_high");
  if (!(max_change >= 1) or !std::isfinite(max_change))
    throw std::invalid_argument("PenaltyAdaptation: max_change must be >= 1");
  if (!(0 < k_min and k_min <= k_max and std::isfinite(k_max)))
    throw std::invalid_argument("PenaltyAdaptation: need 0 < k_min <= k_max");
}

double PenaltyAdaptation::towards_target(double k, double p) const
{
  const RegularizedPenalty shape(1.0, regularization); // phi(p) = shape.reaction(-p)
  const double wanted = k * shape.reaction(-p) / shape.reaction(-target);
  const double bounded = std::clamp(wanted, k / max_change, k * max_change);
  return std::clamp(bounded, k_min, k_max);
}

double PenaltyAdaptation::between_steps(double k, double p) const
{
  if (p <= 0 or (p >= band_low * target and p <= retune_high * target))
    return k;
  return towards_target(k, p);
}

double PenaltyAdaptation::in_step(double k, double p) const
{
  return p > band_high * target ? towards_target(k, p) : k;
}
} // namespace textile::contact
