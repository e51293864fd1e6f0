// The contact elements of a load step and their assembly into PETSc.
//
// Penalty units (the one place they are stated for all of contact). Every
// contact element stands for a length of contact, `length` (length): its
// share of a line contact's intermediate geometry (intermediate_geometry.h,
// contact_points), or crossing_length(r_i, r_j) = r_i + r_j for the single
// element of a crossing. The penalty k_c is a stiffness per unit length of
// contact: force per unit length per unit penetration (force/length^2, a
// pressure). The normal law gives the reaction per unit length R_N(gap)
// (force/length), and an element's force is length x R_N (force), as are
// its friction force (mu length R_N at most), residual and tangent. So a
// line contact's stiffness per length is k_c whatever the element spacing,
// and a crossing's stiffness is k_c (r_i + r_j).
#pragma once

#include "contact_element.h"
#include "regularized_coulomb.h"

#include <petscmat.h>
#include <petscvec.h>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace textile::contact
{

/// One contact element with everything held fixed during a Newton solve
/// (particles, normal, penalty) and its friction history (stick point).
struct ContactElementState
{
  int fibre_i = 0, fibre_j = 0;  ///< fibres of the two particles
  double s_i = 0, s_j = 0;       ///< their abscissas (element coordinates)
  int zone = 0;                  ///< proximity zone of this pass
  bool crossing = false;         ///< the element of a crossing (else of a line contact)
  std::array<std::int64_t, 3> nodes_i{-1, -1, -1}; ///< global nodes of the element on fibre i
  std::array<std::int64_t, 3> nodes_j{-1, -1, -1}; ///< and on fibre j
  Particle particle_i, particle_j;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ(); ///< from j towards i
  double length = 0;         ///< contact length it stands for (length, see above)
  double penalty = 0;        ///< k_c per unit length (force/length^2, see above)
  double regularization = 0; ///< g_r (length)
  RegularizedCoulomb friction{0.0, 1.0};
  Eigen::Vector3d stick = Eigen::Vector3d::Zero(); ///< Delta at the stick point
  // last evaluation (forces are the element's: length x per-length values)
  ContactResult result;
};

/// A set of contact elements evaluated together.
///
/// Unknowns are addressed globally: q holds the current [x0, g1, g2] of
/// every fibre node (9 per global node), dofs the global index in the PETSc
/// system of each of those unknowns (-1 where constrained). Each rank
/// evaluates the elements it was given; insertion uses global indices, so
/// an element may touch nodes owned by other ranks.
class ContactSet
{
public:
  std::vector<ContactElementState> elements;

  /// b[dofs] += contact residual; updates each element's result.
  void assemble_vector(std::span<const double> q, std::span<const std::int32_t> dofs, Vec b);

  /// A[dofs, dofs] += contact tangent.
  void assemble_matrix(std::span<const double> q, std::span<const std::int32_t> dofs,
                       Mat A) const;

  /// Declare the entries the elements can fill (each element's dofs x its
  /// dofs, global indices) into a matrix being preallocated: the elements
  /// whose last evaluated gap is below `margin` (length); farther ones
  /// cannot close within a Newton solve, and are added by a later rebuild
  /// if they come near.
  void insert_pattern(Mat P, std::span<const std::int32_t> dofs, double margin) const;

  /// Evaluate every element at q (results only, no assembly).
  void evaluate(std::span<const double> q);

  /// Contact forces on every unknown (9 per global node, like q) at q:
  /// lets two element sets be compared by what they do to the fibres.
  std::vector<double> nodal_forces(std::span<const double> q) const;

  /// After a converged step: move the stick points of slipping elements.
  void commit();

  /// Number of elements that keep friction history (mu > 0).
  std::size_t num_friction_histories() const;

  /// Elastic tangential slip P (Delta - stick) of element e at its last
  /// evaluation: the friction history carried to a re-detected element.
  Eigen::Vector3d elastic_slip(const ContactElementState& e) const;

private:
  /// Residual (and tangent if K) of one element (times its length).
  ContactResult element(const ContactElementState& e, std::span<const double> q,
                        std::vector<double>& r, std::vector<double>* K) const;
  void gather(const ContactElementState& e, std::span<const double> q, std::vector<double>& xi,
              std::vector<double>& xj) const;
};

} // namespace textile::contact
