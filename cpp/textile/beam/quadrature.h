// Quadrature rules for the beam: Gauss-Legendre along the axis and a
// polar product rule over the round cross-section.
#pragma once

#include <vector>

namespace textile::beam
{

/// Gauss-Legendre points and weights on [-1, 1]; exact for polynomials of
/// degree 2n-1.
struct GaussLegendre
{
  std::vector<double> points;
  std::vector<double> weights;
};

/// Return the n-point Gauss-Legendre rule on [-1, 1] (n >= 1).
GaussLegendre gauss_legendre(int n);

/// Quadrature over a disk of radius R centred at the origin, in section
/// coordinates (xi1, xi2). Weights sum to the area pi R^2.
struct SectionQuadrature
{
  double radius = 0;
  int order = 0;
  std::vector<double> xi1, xi2, weights;
  std::size_t size() const { return weights.size(); }
};

/// A rule exact for polynomials in (xi1, xi2) of total degree <= order
/// (order >= 2 so that both bending directions are integrated exactly,
/// I = pi R^4 / 4):
///  - orders 4 and 5: Radon's 7-point rule (Stroud S2 5-1), exact to
///    degree 5: the centre with weight A/4 and a regular hexagon at
///    r = R sqrt(2/3) with weights A/8. A straight beam's energy, force and
///    tangent are polynomials of degree 4 over the section, so it gives them
///    exactly with half the points of the polar rule (15);
///  - other orders: polar product rule, floor(order/2)+1 Gauss points in r
///    (with the weight r dr) times order+1 equally spaced angles.
SectionQuadrature disk_quadrature(double radius, int order);

} // namespace textile::beam
