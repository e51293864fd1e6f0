// Quadratically regularized penalty law (docs/method.md §4.3).
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
///
/// Tangent floor (first contact, stability issue item 5). The law has no
/// stiffness at gap = 0: a fibre pushed by a dead force onto another it
/// just touches sees nothing in Newton's first tangent, and the first
/// iterate goes as deep as the rest of the structure lets it (a residual
/// of 1e13 after 3e-3). Newton's tangent therefore uses at least `floor` x k
/// for gaps below g_r (closed, or open by less than g_r), i.e. over the
/// quadratic part's first floor x g_r of penetration and just before
/// contact: the first iterate goes about 1 / floor times the linear law's
/// penetration deep, not arbitrarily deep. The residual is the law's, so
/// the converged answer does not change.
class RegularizedPenalty final : public NormalLaw
{
public:
  /// Throws std::invalid_argument unless k > 0 and g_r > 0 (finite) and
  /// 0 <= floor <= 1.
  RegularizedPenalty(double k, double g_r, double floor = 0.0);
  double reaction(double gap) const override;
  double stiffness(double gap) const override;
  double newton_stiffness(double gap) const override;
  double penalty() const { return _k; }
  double regularization() const { return _gr; }

  /// Penetration (-gap >= 0) at which the reaction equals R (inverse law).
  double penetration(double R) const;

private:
  double _k, _gr, _floor;
};

} // namespace textile::contact
