#include "regularized_coulomb.h"

namespace textile::contact
{
RegularizedCoulomb::Result RegularizedCoulomb::evaluate(double R_N,
                                                        const Eigen::Vector3d& u_T) const
{
  Result r;
  const double n = u_T.norm();
  if (n <= u_rev)
  {
    r.T = (mu * R_N / u_rev) * u_T;
    r.dT_du = (mu * R_N / u_rev) * Eigen::Matrix3d::Identity();
    r.dT_dRN = (mu / u_rev) * u_T;
    r.slip = false;
  }
  else
  {
    const Eigen::Vector3d e = u_T / n;
    r.T = mu * R_N * e;
    r.dT_du = (mu * R_N / n) * (Eigen::Matrix3d::Identity() - e * e.transpose());
    r.dT_dRN = mu * e;
    r.slip = true;
  }
  return r;
}
} // namespace textile::contact
