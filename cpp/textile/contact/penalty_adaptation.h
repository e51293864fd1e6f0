// Retuning of the zone penalties (docs/method.md §4.4).
//
// Each proximity zone has one penalty k_c (per unit length, contact_set.h),
// tuned so that the zone's largest penetration p stays near a target p_t,
// a small multiple of g_r. At a fixed zone force F, R_N = k_c phi(p) with
// phi the regularized law's shape (RegularizedPenalty with k = 1), so the
// penalty that puts the penetration at the target is
//     k' = k_c phi(p) / phi(p_t).
// Retuning moves the equilibrium: where it happens decides what it costs.
// - Between steps (at a step's commit, for the next step), for zones whose
//   penetration is below band_low p_t or above retune_high p_t (hysteresis:
//   zones in between keep their penalty; retune_high < band_high stiffens a
//   zone whose load grows before it leaves the band), with k'/k_c bounded
//   by max_change per retune: no Newton solve is added.
// - Within a step only as an emergency, when a converged state penetrates
//   beyond band_high p_t (the bound the band guarantees at every converged
//   step): then another Newton solve is needed, and the caller counts it.
// Penalties never leave [k_min, k_max].
#pragma once

#include <span>
#include <vector>

namespace textile::contact
{

struct PenaltyAdaptation
{
  double target = 0;         ///< p_t (length)
  double regularization = 0; ///< g_r (length)
  double band_low = 0.5;     ///< between steps, zones below band_low p_t are softened
  double retune_high = 1.5;  ///< between steps, zones above retune_high p_t are stiffened
  double band_high = 2.0;    ///< in-step (emergency) retune above band_high p_t
  double max_change = 1e3;   ///< bound on k'/k and k/k' per retune
  double k_min = 0, k_max = 0; ///< bounds of a penalty (force/length^2)

  /// Throws std::invalid_argument for inconsistent parameters.
  void validate() const;

  /// k_c phi(p) / phi(p_t) bounded by max_change and [k_min, k_max]: the
  /// penalty that would put the penetration p at the target.
  double towards_target(double k, double p) const;

  /// Between steps: towards_target for p below band_low p_t or above
  /// retune_high p_t (p > 0: open zones keep their penalty), else k.
  double between_steps(double k, double p) const;

  /// Within a step: towards_target for p > band_high p_t only, else k.
  double in_step(double k, double p) const;
};

} // namespace textile::contact
