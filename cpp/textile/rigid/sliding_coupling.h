// A section or point that follows a rigid body only along body-fixed
// directions: a frictionless plate.
//
// A fully held point (rigid_coupling.h) follows the body in all three
// directions, so a matrix face held that way cannot contract by Poisson's
// effect. A *sliding* coupling keeps only chosen components: each row k
// holds one vector v_k of the coupled unknowns (x0, g1 or g2) along a
// direction d_k fixed in the body,
//     c_k = d_k . (q_v - phi_v(w)),   d_k = exp([theta]) D_k,
// with phi_v the fully held target of rigid_coupling.h (C + u + R offset for
// x0, R G for g1, g2) and D_k the direction in the body's frame at the step
// start (R_n times its reference). The rest of q moves freely: a plate of
// normal n holding a point with the row (x0, n) lets it slide in the plate.
//
// Energy, residual and tangent as in rigid_coupling.h: L = sum_k s_k lambda_k
// c_k, residual [q, u, theta, lambda] = dL/d(...), exact tangent (first and
// second derivatives in theta by automatic differentiation), symmetric.
#pragma once

#include "rigid_coupling.h"

#include <Eigen/Dense>

#include <span>

namespace textile::rigid
{

/// One row of a sliding coupling: which held vector, along which direction.
struct SlidingRow
{
  int vector = 0;                                       ///< 0: x0, 1: g1, 2: g2
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX(); ///< D, at the step start
};

/// Residual and tangent of one sliding coupling.
///
/// @param base    reference offset and section vectors (body frame, step start);
///                base.section says whether q holds 9 (x0, g1, g2) or 3 (x0) values
/// @param rows    the constrained components (m rows)
/// @param q       current unknowns (positions): 9 or 3
/// @param centre  the body's current centre C + u (3)
/// @param theta   the body's incremental rotation vector (3)
/// @param lambda  multipliers (m)
/// @param scale   s per row (m)
/// @param r       += residual, [q (9 or 3), u (3), theta (3), lambda (m)]
/// @param K       += tangent, row-major, same ordering (optional)
void sliding_coupling(const CouplingBase& base, std::span<const SlidingRow> rows,
                      std::span<const double> q, std::span<const double> centre,
                      std::span<const double> theta, std::span<const double> lambda,
                      std::span<const double> scale, std::span<double> r, std::span<double> K);

} // namespace textile::rigid
