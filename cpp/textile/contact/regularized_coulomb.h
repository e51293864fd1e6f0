// Regularized Coulomb friction with an elastic (reversible) slip.
#pragma once

#include <Eigen/Dense>

namespace textile::contact
{

/// Tangential reaction T (force, 3-vector in the contact plane) from the
/// tangential relative displacement u_T measured since the stick point:
///   stick, |u_T| <= u_rev:  T = mu R_N u_T / u_rev
///   slip,  |u_T| >  u_rev:  T = mu R_N u_T / |u_T|
/// T is the force that resists the relative motion (a spring in stick).
/// The return mapping moves the stick point so that |u_T| = u_rev after a
/// slip step (see ContactElement::commit).
struct RegularizedCoulomb
{
  double mu = 0;     ///< friction coefficient (-)
  double u_rev = 0;  ///< reversible slip (length)

  struct Result
  {
    Eigen::Vector3d T;       ///< tangential reaction
    Eigen::Matrix3d dT_du;   ///< dT/du_T (in the contact plane)
    Eigen::Vector3d dT_dRN;  ///< dT/dR_N
    bool slip = false;
  };

  Result evaluate(double R_N, const Eigen::Vector3d& u_T) const;
};

} // namespace textile::contact
