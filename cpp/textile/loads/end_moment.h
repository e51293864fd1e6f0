// End moment applied to a beam node through its section vectors.
#pragma once

#include <span>

namespace textile::loads
{

/// Generalized forces on the section vectors (g1, g2) of a node that apply
/// the moment M (fixed in space, N m) to its section:
///     f_a = M* x g_a,   M* = M - 1/2 (M.n) n,   n = g1 x g2 / |g1 x g2|.
/// For an orthonormal section, sum_a g_a x f_a = M: the bending part of M
/// acts once through the vector that tilts, the twisting part twice (both
/// vectors turn about n), hence the factor 1/2 on M.n. Its virtual work is
/// M . dtheta for rigid section rotations dtheta.
///
/// @param M     moment vector (3)
/// @param g     current section vectors [g1, g2] (6)
/// @param f     output generalized force on [g1, g2] (6), overwritten
/// @param dfdg  if not empty: output df/dg, row-major 6x6, overwritten
///              (not symmetric: the moment is a follower in general)
void end_moment(std::span<const double> M, std::span<const double> g, std::span<double> f,
                std::span<double> dfdg);

} // namespace textile::loads
