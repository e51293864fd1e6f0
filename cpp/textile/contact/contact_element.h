// Contact element: a pair of particles on the section borders of two fibres.
//
// Within a Newton solve the element is fixed: each particle is a material
// point (element abscissa xi and section coordinates xi1, xi2) and the
// normal N is held constant (docs/method.md §9.2, loops 1-2 update them).
// The gap is the distance along N between the two deformed sections at
// the particles' abscissas,
//     gap = N . (x0_i - x0_j) - h_i(N) - h_j(N),  h(N) = R |(g1.N, g2.N)|,
// h being the extent of the section x0 + xi1 g1 + xi2 g2, |xi| <= R, along
// N: the normal force acts at the sections' support points, so a section
// turning about its axis does not change the gap (a material point would
// turn away from the contact and feed back a spurious torsion). Friction
// acts at the material particles x(p) = sum_a N_a(xi)(x0_a + xi1 g1_a +
// xi2 g2_a), whose relative position Delta = x_i(p_i) - x_j(p_j) is linear
// in the unknowns. Residual and tangent below are exact.
//
// How much of this moves with the unknowns within Newton is the element's
// gap kind (gap_function.h): held as above, a normal that follows the
// centre lines in the section plane (line contacts), or particles that move
// to where the centre lines face each other along N (crossings).
//
// Signs: N points from fibre j towards fibre i, gap < 0 when they
// interpenetrate. The residual is the internal force: the normal part is
// -R_N(gap) dgap/dq (pushes the sections apart), the friction part is
// T . dDelta/dq with T the tangential reaction (resists relative sliding).
#pragma once

#include "gap_function.h"
#include "normal_law.h"
#include "particle.h"
#include "regularized_coulomb.h"

#include <Eigen/Dense>

#include <array>
#include <span>
#include <vector>

namespace textile::contact
{

/// What one evaluation found.
struct ContactResult
{
  double gap = 0;                             ///< section distance along N (length)
  /// N . (x0_i - x0_j) (length; with a following normal, N . P (x0_i - x0_j)):
  /// negative when the centre lines lie on the wrong side of each other
  /// along N (the fibres have passed through)
  double separation = 0;
  double normal_force = 0;                    ///< R_N >= 0
  Eigen::Vector3d tangential_force = Eigen::Vector3d::Zero(); ///< T
  Eigen::Vector3d delta = Eigen::Vector3d::Zero();            ///< Delta
  Eigen::Vector3d position_i = Eigen::Vector3d::Zero();       ///< x_i(p_i)
  Eigen::Vector3d position_j = Eigen::Vector3d::Zero();       ///< x_j(p_j)
  bool slip = false;
  /// patch coordinates (particle.h) of the points the gap is measured at
  std::array<double, 2> gap_xi{0.0, 0.0};
};

/// Residual and tangent of one contact element. The tangent's normal
/// stiffness is the law's newton_stiffness (normal_law.h), the friction's
/// dependence on R_N its exact stiffness.
///
/// @param pi, pj    particles on fibres i and j
/// @param normal    unit normal N (from j towards i), fixed
/// @param law       normal law R_N(gap)
/// @param friction  nullptr for frictionless contact
/// @param stick     Delta at the stick point (ignored without friction)
/// @param xi, xj    current nodal unknowns of the two elements (9 n each)
/// @param r         the residual, 9 (n_i + n_j) values ([element i, element j]),
///                  overwritten (zero for an open element)
/// @param K         the tangent, row-major, if not empty (not symmetric with
///                  friction), overwritten: callers need not clear it
/// @param gap_offset    see contact_gap
/// @param motion        the element's gap kind (gap_function.h)
/// @param motion_tangent false: the tangent without the terms of the
///                      points' motion (GapFunction::add_hessian)
ContactResult contact_element(const Particle& pi, const Particle& pj,
                              const Eigen::Vector3d& normal, const NormalLaw& law,
                              const RegularizedCoulomb* friction, const Eigen::Vector3d& stick,
                              std::span<const double> xi, std::span<const double> xj,
                              std::span<double> r, std::span<double> K,
                              double gap_offset = 0.0, const GapMotion& motion = {},
                              bool motion_tangent = true);

/// The gap alone, as contact_element computes it, without derivatives or
/// allocation: lets an assembler skip open elements (R_N = 0 and
/// dR_N = 0, so neither force nor tangent) before running the kernel.
///
/// `gap_offset` (length, constant in q: no tangent term) is added to the
/// gap the law sees and reports: the weaving stage uses it to make up the
/// yarns' initial interpenetration progressively (contact_set.h).
double contact_gap(const Particle& pi, const Particle& pj, const Eigen::Vector3d& normal,
                   std::span<const double> xi, std::span<const double> xj,
                   double gap_offset = 0.0, const GapMotion& motion = {});

/// Stick point after a converged step (return mapping): unchanged in stick;
/// in slip moved along the slip so that the elastic part is u_rev.
Eigen::Vector3d updated_stick(const Eigen::Vector3d& normal, const RegularizedCoulomb& friction,
                              const Eigen::Vector3d& delta, const Eigen::Vector3d& stick);

} // namespace textile::contact
