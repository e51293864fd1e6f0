// A material point of a fibre element, where contact forces act, and the
// patch of the fibre's centre line a contact element sees around it.
//
// A contact element's side is evaluated on a *patch*: the particle's own
// element, or (a crossing whose point moves within Newton, gap_function.h)
// that element and its neighbour across the nearer node. The patch's nodes
// are consecutive nodes of the fibre; its coordinate is xi in [-1, 1] on
// the first element and [1, 3] on the second (the shared node at xi = 1).
// Over two elements the centre line is smoothed to C1 across the shared
// node: within patch_smoothing of it (in element lengths) the two
// elements' polynomials are blended,
//     x(xi) = (1 - phi) x_A(xi) + phi x_B(xi - 2),  phi = 3 tau^2 - 2 tau^3,
// tau running from 0 to 1 across the window, each polynomial continued
// past the node. The fibre elements are only C0: a crossing pressing a
// fibre kinks it at the node under it (the section's shear), and on the
// kinked line the point where two fibres face each other, and the
// direction of the force there, jump as it passes the node: Newton cycles
// (a 3-fibre yarn's weaving stopped at 17% of its stage). The smoothed
// line passes through the node and stays within 0.086 w |d| of the fibre
// (w the window's half-width, d the jump of dx0/ds at the node: about a
// micron for a 10 deg kink of 0.3 mm elements). A window that depended on
// the kink would change with it from pass to pass, and with it the points
// the crossings settle at.
#pragma once

#include <Eigen/Core>
#include "tolerances.h"

#include <array>
#include <span>
#include <vector>

namespace textile::contact
{

/// Most nodes of a patch: two quadratic elements.
inline constexpr int max_patch_nodes = 5;

/// A material point of a fibre element: axial coordinate xi in [-1, 1] of
/// an element with num_nodes (2 or 3) nodes, section coordinates (xi1, xi2)
/// (length) along g1, g2; and the patch it is seen on (above).
struct Particle
{
  int num_nodes = 3;
  double xi = 0;
  double xi1 = 0, xi2 = 0;
  double radius = 0; ///< section radius R (length)
  int patch_elements = 1; ///< 1, or 2 (the particle's element and a neighbour)
  int patch_position = 0; ///< which of the patch's elements holds the particle (0, 1)
  /// Is the patch's first (last) node its fibre's end? Past an interior
  /// node the patch's line continued straight stands for the next element
  /// (PatchShape); past a fibre's end there is no fibre.
  bool fibre_end_below = false, fibre_end_above = false;

  /// Nodes of the patch (the element's first).
  int patch_nodes() const { return (num_nodes - 1) * patch_elements + 1; }
  /// Index within the patch of the particle element's first node.
  int node_offset() const { return (num_nodes - 1) * patch_position; }
  /// The particle's coordinate on the patch.
  double patch_xi() const { return xi + 2.0 * patch_position; }
  /// Bounds of the patch coordinate.
  double patch_min() const { return -1.0; }
  double patch_max() const { return 2.0 * patch_elements - 1.0; }
  /// Is patch coordinate xi beyond the fibre's end?
  bool past_fibre_end(double xi) const
  {
    return (fibre_end_below and xi < patch_min()) or (fibre_end_above and xi > patch_max());
  }
};

/// Shape functions of the patch's centre line at patch coordinate xi, and
/// their first and second derivatives in xi (patch_nodes() values each).
/// Past the patch's ends the line goes on straight along the end's tangent
/// (C1 across the end: a point moving within Newton may pass it,
/// gap_function.h).
struct PatchShape
{
  std::array<double, 5> n{}, dn{}, ddn{};
  PatchShape(const Particle& p, double xi);
};

/// Coefficients c_s, s = 3 a + f (patch node a, field f: x0, g1, g2), with
/// x(p) = sum_s c_s q_s: the particle's element's Lagrange functions, zero
/// on the patch's other nodes. Size 3 patch_nodes().
std::vector<double> particle_coefficients(const Particle& p);

/// Position of the particle from the patch's current nodal unknowns.
Eigen::Vector3d particle_position(const Particle& p, std::span<const double> x);

} // namespace textile::contact
