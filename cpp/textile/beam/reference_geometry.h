// Reference geometry of a beam element at its quadrature points.
//
// At section point (xi1, xi2) of axial point xi (' = d/dxi) the convected
// basis of the reference configuration is
//     F_ref = [G1, G2, X0' + xi1 G1' + xi2 G2'],
// and Q = [e1, e2, e3] is the local orthonormal frame of the reference
// section (e3 along X0', e1 along the part of G1 normal to it). The current
// configuration gives F Q = [g1, g2, x0' + xi1 g1' + xi2 g2'] B with
//     B = F_ref^{-1} Q,
// and the point's volume weight is dV = w det F_ref (w: axial times section
// quadrature weight). B and dV depend on the reference only: an assembler
// computes them once per element instead of at every evaluation.
#pragma once

#include "element_rule.h"

#include <Eigen/Dense>

#include <span>

namespace textile::beam
{

/// Reference data of one quadrature point.
struct ReferencePoint
{
  Eigen::Matrix3d B; ///< F_ref^{-1} Q
  double dV = 0;     ///< weight x det F_ref (reference volume of the point)
};

/// Number of quadrature points of an element: axial x section.
inline std::size_t num_points(const ElementRule& rule, const SectionQuadrature& section)
{
  return rule.axial.points.size() * section.size();
}

/// Reference data at every quadrature point of one element, axial point
/// major: out[g * section.size() + i].
/// @param X  reference nodal unknowns [X0, G1, G2] of the element's nodes
/// @throws std::runtime_error if F_ref is degenerate or inverted (section
///         vectors not independent, or along the tangent)
void reference_points(const ElementRule& rule, const SectionQuadrature& section,
                      std::span<const double> X, std::span<ReferencePoint> out);

} // namespace textile::beam
