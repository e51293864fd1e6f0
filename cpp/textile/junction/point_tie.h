// Penalty tie between a point carried by a node and a point of a solid cell.
#pragma once

#include <span>

namespace textile::junction
{

/// Stored energy 1/2 k |gap|^2 of a linear penalty tie, with
///     gap = u_a - sum_i phi_i u_i + gap0,
/// u_a the displacement of the tied node (3), u_i the displacements of the
/// cell's nodes (3 each, phi_i their basis values at the tied point) and
/// gap0 the initial offset (zero when tied where they coincide).
/// k in N/m. Residual order: [a (3), cell nodes (3 n)].
///
/// @param r  += dEnergy/du (3 + 3n)
/// @param K  += tangent, row-major, if not empty
/// @return the gap vector's norm
double point_tie(double k, std::span<const double> phi, std::span<const double> u_a,
                 std::span<const double> u_cell, std::span<const double> gap0,
                 std::span<double> r, std::span<double> K);

} // namespace textile::junction
