// Interface of a normal contact law: reaction as a function of the gap.
#pragma once

namespace textile::contact
{

/// Normal contact law R_N(gap) >= 0, with gap (length) negative when the
/// bodies interpenetrate and R_N the compressive reaction (force). A new law
/// is a new class implementing this interface.
class NormalLaw
{
public:
  virtual ~NormalLaw() = default;
  /// Reaction R_N(gap) >= 0 (force).
  virtual double reaction(double gap) const = 0;
  /// dR_N/dgap <= 0 (force per length).
  virtual double stiffness(double gap) const = 0;
  /// The stiffness Newton's tangent uses (<= stiffness(gap) <= 0): a law
  /// may make it stiffer than the exact one where that is near zero (first
  /// contact), which changes Newton's path, never the converged answer.
  virtual double newton_stiffness(double gap) const { return stiffness(gap); }
};

} // namespace textile::contact
