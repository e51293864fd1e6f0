// Quadratically regularized penalty law (METHOD.md section 3).
#pragma once

#include "normal_law.h"

namespace textile::contact
{

/// R_N = 0                          for gap >= 0,
/// R_N = k gap^2 / (2 g_r)           for -g_r < gap < 0,
/// R_N = k (-gap - g_r / 2)          for gap <= -g_r,
/// continuous with a continuous slope: the contact force starts smoothly,
/// which keeps Newton quadratic when contacts open and close.
/// k (force/length) is the penalty, g_r (length) the regularization depth.
class RegularizedPenalty final : public NormalLaw
{
public:
  /// Throws std::invalid_argument unless k > 0 and g_r > 0 (finite).
  RegularizedPenalty(double k, double g_r);
  double reaction(double gap) const override;
  double stiffness(double gap) const override;
  double penalty() const { return _k; }
  double regularization() const { return _gr; }

  /// Penetration (-gap >= 0) at which the reaction equals R (inverse law).
  double penetration(double R) const;

private:
  double _k, _gr;
};

} // namespace textile::contact
