// A fibre end section (or a point) held by a rigid body, exactly, through
// Lagrange multipliers.
//
// Body unknowns w = (u, theta): displacement u of its reference centre C
// and incremental rotation vector theta (rotation.h), R = exp([theta]) R_n.
// A coupled *section* (a fibre end node with reference X, G1, G2) follows
// the body in position and in its section vectors:
//     x0 = C + u + R (X - C),   g1 = R G1,   g2 = R G2,
// so the section turns with the body and keeps its reference shape: the
// end cannot contract by Poisson's effect, which stiffens the fibre over a
// length of about its radius next to the body (docs/references.md, caveats). A
// coupled *point* (e.g. a matrix node) follows in position only.
//
// With the constraint C(q, w) = q - phi(w) (9 or 3 rows) and multipliers
// lambda, the coupling adds L = (s . lambda) . C to the energy, s a scale
// per row (a stiffness) that keeps the saddle-point system balanced; the
// physical constraint force on q is f = -(s . lambda). Residual and tangent
// are exact (second derivatives of the rotation by automatic
// differentiation) and symmetric; the system gains one negative eigenvalue
// per constraint row (saddle point), which the stability check discounts.
#pragma once

#include <Eigen/Dense>

#include <span>

namespace textile::rigid
{

/// A coupled section or point, in the body's frame at the step start:
/// offset = R_n (X - C), and (sections) g1 = R_n G1, g2 = R_n G2.
struct CouplingBase
{
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  Eigen::Vector3d g1 = Eigen::Vector3d::Zero(), g2 = Eigen::Vector3d::Zero();
  bool section = true; ///< 9 constraint rows (x0, g1, g2); false: 3 (x0)

  int rows() const { return section ? 9 : 3; }
};

/// Residual and tangent of one coupling.
///
/// @param base    the coupled section or point
/// @param q       its current unknowns (positions, not displacements): 9 or 3
/// @param centre  the body's current centre C + u (3)
/// @param theta   the body's incremental rotation vector (3)
/// @param lambda  multipliers (rows)
/// @param scale   s per row (rows)
/// @param r       += residual, [q (rows), body u (3), body theta (3), lambda (rows)]
/// @param K       += tangent, row-major, same ordering (optional)
void rigid_coupling(const CouplingBase& base, std::span<const double> q,
                    std::span<const double> centre, std::span<const double> theta,
                    std::span<const double> lambda, std::span<const double> scale,
                    std::span<double> r, std::span<double> K);

/// Generalized force on theta of a moment M (fixed in space) applied to a
/// body, -J_l(theta)^T M (residual = internal - external), and its
/// derivative (not symmetric): r += f, K += df/dtheta (3 x 3, row-major).
void body_moment(std::span<const double> theta, std::span<const double> moment,
                 std::span<double> r, std::span<double> K);

} // namespace textile::rigid
