// One fibre-matrix junction: a material particle of a fibre element tied to
// the matrix point at the same place (docs/method.md §8.2).
#pragma once

#include <span>

namespace textile::junction
{

/// Stored energy of one junction,
///     E = 1/2 k w |x_f - x_m|^2,
///     x_f = sum_a N_a(xi) (x0_a + c1 g1_a + c2 g2_a)   (fibre material particle),
///     x_m = X_m + sum_b phi_b u_b                       (matrix point),
/// with N_a the fibre element's Lagrange shape functions (2 or 3 nodes,
/// beam/shape_functions.h) at the particle's coordinate xi in [-1, 1],
/// (c1, c2) the particle's section coordinates (0, 0 for the centre line;
/// docs/method.md §1.1), x0_a, g1_a, g2_a = X_a + u_a the element nodes'
/// current centroid and section vectors (9 unknowns a node), X_m the matrix
/// point's reference position, phi_b the matrix cell's basis values there
/// (any number of cell nodes: 4 for P1, 10 for P2, ...) and u_b their
/// displacements.
///
/// x_f is linear in the fibre unknowns: d x_f / d(x0_a, g1_a, g2_a) =
/// N_a (1, c1, c2) I3. k is the stiffness per unit fibre length (N/m^2) and
/// w the fibre length the particle stands for (m), so k w is the spring
/// constant (N/m). The energy is quadratic in the unknowns: the tangent is
/// constant.
///
/// Residual order: [fibre nodes (9 per node: x0, g1, g2), matrix nodes (3
/// per node)], length m = 9 num_fibre_nodes + 3 phi.size().
///
/// @param c     section coordinates (c1, c2) of the particle (2)
/// @param X_f   reference unknowns of the element's nodes (9 each)
/// @param u_f   their displacements (9 each)
/// @param X_m   reference position of the matrix point (3)
/// @param phi   basis values of the matrix cell's nodes at X_m
/// @param u_m   displacements of the matrix cell's nodes (3 each)
/// @param gap   if not empty, set to x_f - x_m (3)
/// @param r     += dE/du (m), if not empty
/// @param K     += d2E/du2, row-major m x m, if not empty
/// @return the energy
double fibre_matrix_junction(double k, double w, int num_fibre_nodes, double xi,
                             std::span<const double> c, std::span<const double> X_f,
                             std::span<const double> u_f, std::span<const double> X_m,
                             std::span<const double> phi, std::span<const double> u_m,
                             std::span<double> gap, std::span<double> r, std::span<double> K);

} // namespace textile::junction
