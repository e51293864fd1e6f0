// St Venant-Kirchhoff material of a fibre, with the section-split law that
// cures Poisson locking (see docs in beam_element.h).
#pragma once

#include <Eigen/Dense>

namespace textile::beam
{

/// Strains and stresses in Voigt order (11, 22, 33, 23, 13, 12), in the
/// local orthonormal frame (e1, e2, e3 = fibre tangent) of the reference
/// section. Shear strains are engineering strains (2 E_ij).
using Voigt = Eigen::Matrix<double, 6, 1>;
using VoigtMatrix = Eigen::Matrix<double, 6, 6>;

/// Isotropic St Venant-Kirchhoff material: Young's modulus E (Pa) and
/// Poisson ratio nu in (-1, 0.5).
struct Material
{
  double young = 0;
  double poisson = 0;

  double shear_modulus() const { return young / (2.0 * (1.0 + poisson)); }
  double lame_lambda() const
  {
    return young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
  }

  /// 3D elasticity tensor C (Voigt, engineering shear): S = C : E.
  VoigtMatrix elasticity() const
  {
    const double l = lame_lambda(), mu = shear_modulus();
    VoigtMatrix C = VoigtMatrix::Zero();
    C.topLeftCorner<3, 3>().setConstant(l);
    for (int i = 0; i < 3; ++i)
    {
      C(i, i) += 2.0 * mu;
      C(i + 3, i + 3) = mu;
    }
    return C;
  }

  /// Modulus applied to the strain fluctuation across a section (the part
  /// linear in xi1, xi2): uniaxial E on E33, shear mu on the axial shears
  /// 2E13, 2E23, nothing on the in-plane components (uniform by
  /// construction of the kinematics).
  VoigtMatrix fluctuation_elasticity() const
  {
    VoigtMatrix D = VoigtMatrix::Zero();
    D(2, 2) = young;
    D(3, 3) = shear_modulus();
    D(4, 4) = shear_modulus();
    return D;
  }
};

/// Throws std::invalid_argument unless E > 0 and -1 < nu < 0.5 (finite).
void validate(const Material& m);

} // namespace textile::beam
