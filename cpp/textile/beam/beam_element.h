// Finite-strain beam element with deformable sections (Durville kinematics).
//
// A particle at section coordinates (xi1, xi2) and abscissa xi3 sits at
//     x = x0(xi3) + xi1 g1(xi3) + xi2 g2(xi3),
// with x0 the centroid line and g1, g2 the section vectors. Each node has 9
// unknowns, ordered [x0 (3), g1 (3), g2 (3)]. x0, g1, g2 are interpolated
// with Lagrange polynomials of degree num_nodes-1 (2: linear, 3: quadratic
// with the middle node at xi = 0). The full Green-Lagrange strain
// E = 1/2 (F^T F - I), F = dx/dX, is evaluated at axial Gauss points times
// section points and expressed in the local frame (e1, e2, e3) of the
// reference section (e3 the reference tangent).
//
// Poisson locking cure (docs/method.md §2.2): at each axial point the strain
// is split into its section average Ebar and the fluctuation dE = E - Ebar,
// and the stored energy density is
//     W = 1/2 Ebar : C : Ebar + 1/2 E (dE33)^2 + 2 mu (dE13^2 + dE23^2).
// Because g1, g2 only depend on xi3, the in-plane strains E_ab are uniform
// over a section: the linear kinematics cannot produce the transverse
// strains -nu E33 that vary across the section in bending, and the full 3D
// law would then see (lambda + 2 mu) instead of E. Giving the fluctuation
// the uniaxial (zero transverse stress) law recovers E I in bending while
// uniform states (tension, section deformation) keep the exact 3D law.
// The split is linear in the strains at the section points, so the tangent
// stays exact and symmetric. Chosen over enhanced assumed strains because
// it needs no extra element unknowns or static condensation.
//
// Evaluation: at an axial point the deformation of every section point
// depends on the 15 values z = [x0', g1, g2, g1', g2'] only
// (F Q = [g1, g2, x0' + xi1 g1' + xi2 g2'] B, reference_geometry.h). Force
// and tangent are integrated over the section with respect to z (15
// unknowns instead of 9 per node) and mapped to the nodes once per axial
// point through the shape functions.
//
// Units: any consistent set (e.g. N, m, Pa). Internal force r = dPi/dx,
// the derivative of the stored energy with respect to the nodal unknowns
// (positive in the direction the energy grows); tangent K = dr/dx.
#pragma once

#include "element_rule.h"
#include "material.h"
#include "quadrature.h"
#include "reference_geometry.h"

#include <span>

namespace textile::beam
{

/// Stored energy, internal force and tangent of one element.
///
/// @param rule  Element type and axial quadrature.
/// @param mat   Fibre material.
/// @param section  Section quadrature (carries the radius).
/// @param X     Reference nodal unknowns, 9*num_nodes values.
/// @param x     Current nodal unknowns, same layout.
/// @param r     If not empty: += internal force (9*num_nodes).
/// @param K     If not empty: += tangent, row-major (9n x 9n).
/// @param dx    Empty: K is the exact tangent dr/dx. Else the last Newton
///              update of the nodal unknowns (same layout), and K is the
///              MIP Newton tangent (Magisano, Leonetti & Garcea, IJNME
///              2017): Newton on the mixed problem (x, S), whose stress
///              at each quadrature point is the linear extrapolation
///              S = C (E(x - dx) + dE(x - dx)[dx]). E is quadratic in x,
///              so that is the stress of
///                  E_mip = E(x) - 1/2 h(dx)^T h(dx)   (h_j = F e_j),
///              which the geometric stiffness uses instead of the stress
///              of E(x); the material stiffness is the exact one and r,
///              the energy are unchanged. It keeps a large-rotation update
///              from feeding the spurious quadratic strain of the update
///              into the next geometric stiffness. dx = 0 gives the exact
///              tangent. dx may also hold k <= max_mip_updates updates
///              one after another, with dx_weights their k weights c_k
///              (empty: all 1): E_mip = E(x) - 1/2 sum_k c_k h(dx_k)^T
///              h(dx_k), the form a predicted state's extrapolated stress
///              takes (textile/solver/contact_loop.py).
/// @return The element's stored energy.
/// @throws GeometryError if det F <= 0 (folded element) at a point.
/// Most updates a MIP tangent's strain correction may combine (dx above).
inline constexpr int max_mip_updates = 6;

double element_residual_tangent(const ElementRule& rule, const Material& mat,
                                const SectionQuadrature& section,
                                std::span<const double> X, std::span<const double> x,
                                std::span<double> r, std::span<double> K,
                                std::span<const double> dx = {},
                                std::span<const double> dx_weights = {});

/// The same with the element's reference data already evaluated
/// (reference_points(rule, section, X, ref)): what an assembler calls.
double element_residual_tangent(const ElementRule& rule, const Material& mat,
                                const SectionQuadrature& section,
                                std::span<const ReferencePoint> ref, std::span<const double> x,
                                std::span<double> r, std::span<double> K,
                                std::span<const double> dx = {},
                                std::span<const double> dx_weights = {});

/// Section-averaged Green-Lagrange strain and second Piola-Kirchhoff stress
/// (Voigt, local frame), averaged over the element's axial points.
struct ElementFields
{
  Voigt strain = Voigt::Zero();
  Voigt stress = Voigt::Zero();
};

ElementFields element_fields(const ElementRule& rule, const Material& mat,
                             const SectionQuadrature& section,
                             std::span<const double> X, std::span<const double> x);

ElementFields element_fields(const ElementRule& rule, const Material& mat,
                             const SectionQuadrature& section,
                             std::span<const ReferencePoint> ref, std::span<const double> x);

} // namespace textile::beam
