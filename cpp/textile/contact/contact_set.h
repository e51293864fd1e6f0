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
#include "node_block_matrix.h"
#include "regularized_coulomb.h"

#include <petscmat.h>
#include <petscvec.h>

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <utility>
#include <vector>

namespace textile::contact
{

/// Which rank owns each global fibre node (the fibre mesh's partition,
/// textile/beam/node_partition.py), and this rank.
struct NodeOwners
{
  std::span<const std::int32_t> owner; ///< by global node number
  int rank = 0;
  bool owns(std::int64_t node) const { return owner[node] == rank; }
};

/// Whether this rank evaluates (and assembles) the element between fibres
/// i and j whose first nodes are node_i and node_j. The owner of the first
/// node on fibre i when i + j is even, on fibre j when odd: when the ranks
/// split the fibres into warp and weft (the partition by number), the pairs
/// of fibres on different ranks are shared out between the two ranks
/// instead of all falling to the rank of the lower fibre; partitioned by
/// place, both nodes are mostly the same rank's.
inline bool evaluated_here(int fibre_i, int fibre_j, std::int64_t node_i, std::int64_t node_j,
                           const NodeOwners& owners)
{
  return owners.owns((fibre_i + fibre_j) % 2 == 0 ? node_i : node_j);
}

/// One contact element with everything held fixed during a Newton solve
/// (particles, normal, penalty) and its friction history (stick point).
struct ContactElementState
{
  int fibre_i = 0, fibre_j = 0;  ///< fibres of the two particles
  double s_i = 0, s_j = 0;       ///< their abscissas (element coordinates)
  int zone = 0;                  ///< proximity zone of this pass
  bool crossing = false;         ///< the element of a crossing (else of a line contact)
  bool wrap = false;             ///< an element of a wrap (wrap_contact.h)
  /// global nodes of the patch (particle.h) on fibre i, and on fibre j
  std::array<std::int64_t, max_patch_nodes> nodes_i{-1, -1, -1, -1, -1};
  std::array<std::int64_t, max_patch_nodes> nodes_j{-1, -1, -1, -1, -1};
  /// first node of the particle's element (which rank evaluates the element)
  std::int64_t element_node_i() const { return nodes_i[particle_i.node_offset()]; }
  std::int64_t element_node_j() const { return nodes_j[particle_j.node_offset()]; }
  Particle particle_i, particle_j;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ(); ///< from j towards i
  GapMotion motion; ///< how the gap moves with the unknowns in Newton (gap_function.h)
  double length = 0;         ///< contact length it stands for (length, see above)
  double penalty = 0;        ///< k_c per unit length (force/length^2, see above)
  double regularization = 0; ///< g_r (length)
  double tangent_floor = 0;  ///< fraction of the penalty Newton's tangent keeps near
                             ///< gap = 0 (regularized_penalty.h)
  RegularizedCoulomb friction{0.0, 1.0};
  Eigen::Vector3d stick = Eigen::Vector3d::Zero(); ///< Delta at the stick point
  /// Weaving: the pair's interpenetration in the reference (straight,
  /// coplanar) state that the weaving stage makes up progressively (length,
  /// >= 0; see set_depth_scale). 0 otherwise.
  double depth = 0;
  /// Last evaluation; forces are the element's (length x per-length values).
  /// After an assembly an open element's result holds only its gap (and
  /// zero forces); evaluate() fills every field.
  ContactResult result;
};

/// A set of contact elements evaluated together.
///
/// Unknowns are addressed globally: q holds the current [x0, g1, g2] of
/// every fibre node (9 per global node), dofs the global index in the PETSc
/// system of each of those unknowns (-1 where constrained). Each rank
/// evaluates the elements it was given; insertion uses global indices, so
/// an element may touch nodes owned by other ranks.
///
/// Open elements (gap >= 0: R_N = 0 and dR_N = 0, hence no friction force
/// either) are recognised by their gap alone: no kernel runs and nothing is
/// inserted for them.
class ContactSet
{
public:
  ContactSet() = default;
  /// Elements of a pass whose zones are numbered 0 .. num_zones - 1.
  ContactSet(std::vector<ContactElementState> elements, int num_zones);
  /// Copies the elements; the assembly layout is rebuilt when needed.
  ContactSet(const ContactSet& other);
  ContactSet& operator=(const ContactSet& other);
  ContactSet(ContactSet&&) = default;
  ContactSet& operator=(ContactSet&&) = default;

  const std::vector<ContactElementState>& elements() const { return _elements; }
  int num_zones() const { return _num_zones; }

  /// b[dofs] += contact residual; updates each element's result.
  void assemble_vector(std::span<const double> q, std::span<const std::int32_t> dofs, Vec b);

  /// A[dofs, dofs] += contact tangent: element tangents summed per pair of
  /// fibre nodes, inserted one block row at a time (node_block_matrix.h).
  /// Collective on an mpiaij matrix of several ranks.
  void assemble_matrix(std::span<const double> q, std::span<const std::int32_t> dofs, Mat A);

  /// Take over `previous`'s assembly layout (node blocks and their slots in
  /// the matrix) when its elements couple the same nodes in the same order,
  /// as a re-detection usually finds: the layout then costs nothing. True if
  /// taken; `previous` keeps its elements but loses its layout.
  bool take_layout(ContactSet& previous);

  /// Evaluate every element at q (results only, no assembly).
  void evaluate(std::span<const double> q);

  /// The kernels alone: residual and tangent of every closed element at q,
  /// as the two assemblies compute them, nothing inserted (the least an
  /// assembly can cost; for benchmarks). Returns the number of kernels run.
  std::size_t run_kernels(std::span<const double> q);

  /// Contact forces on every unknown (9 per global node, like q) at q:
  /// lets two element sets be compared by what they do to the fibres.
  std::vector<double> nodal_forces(std::span<const double> q) const;

  /// The global fibre nodes the elements read (their particles' patches),
  /// sorted, each once: the part of q an evaluation needs.
  std::vector<std::int64_t> nodes() const;

  /// After a converged step: move the stick points of slipping elements
  /// (from the results of the last evaluate()).
  void commit();

  /// Number of elements that keep friction history (mu > 0).
  std::size_t num_friction_histories() const;

  /// Elastic tangential slip P (Delta - stick) of element e at its last
  /// evaluation: the friction history carried to a re-detected element.
  Eigen::Vector3d elastic_slip(const ContactElementState& e) const;

  /// Per zone (num_zones values), from this set's elements at their last
  /// evaluation; a zone without elements here gets 0. Zone numbers are
  /// shared by all ranks: reduce over ranks with MAX, MAX, SUM.
  std::vector<double> zone_max_penetration() const; ///< largest max(-gap, 0) (length)
  std::vector<double> zone_penalty() const;         ///< largest k_c
  std::vector<double> zone_force() const;           ///< sum of normal forces (force)
  /// elements whose centre lines lie on the wrong side of each other along
  /// the normal (separation < 0: the fibres have passed through), per zone
  std::vector<double> zone_crossed() const;

  /// Every element takes its zone's penalty k[zone] (> 0).
  void set_zone_penalties(std::span<const double> k);

  /// Element e's depth (one value per element, >= 0, length).
  void set_depths(std::span<const double> depth);

  /// Every gap the elements compute and report is shifted by
  /// scale x depth (constant in the unknowns). The weaving stage sets
  /// scale = 1 - s at stage progress s: the yarns' initial interpenetration
  /// is made up in as many load steps as the stage has, instead of all in
  /// the first Newton iterate (which a step cut could not make smaller).
  void set_depth_scale(double scale);

  /// Newton's tangents keep the terms of the points' motion (gap_function.h:
  /// following and facing elements) only for elements closed by at most
  /// `depth` (length, > 0; infinite by default). Deeper ones are far from a
  /// contact Newton can settle (the penalty adaptation keeps penetrations
  /// within its band): their force, R_N times those terms, outweighs the
  /// fibres' stiffness and makes the tangent indefinite (coplanar yarns
  /// pushed apart by ordinary contact from 2 radii of interpenetration:
  /// folded elements in 3 Newton iterations, tests/contact/
  /// test_coplanar_fibres.py), so they get the tangent of points held
  /// where they are. Changes Newton's path, never the converged answer.
  void set_motion_depth(double depth);

  /// Every element's tangent floor (a fraction of its penalty in [0, 1],
  /// regularized_penalty.h): what Newton's next tangents keep near gap = 0.
  void set_tangent_floor(double fraction);

  /// Seconds spent in assemble_vector and assemble_matrix since the last
  /// reset: in the element kernels (contact_element), and in all; node
  /// blocks of other ranks' rows that assemble_matrix sent to their owners
  /// and that went through PETSc's stash (node_block_matrix.h).
  struct Timing
  {
    double kernel = 0, total = 0;
    std::size_t kernel_calls = 0;
    std::size_t off_rank_sent = 0, off_rank_stashed = 0;
  };
  const Timing& timing() const { return _timing; }
  void reset_timing() { _timing = {}; }

private:
  double offset(const ContactElementState& e) const { return _depth_scale * e.depth; }

  std::vector<ContactElementState> _elements;
  int _num_zones = 0;
  double _depth_scale = 0;
  double _motion_depth = std::numeric_limits<double>::infinity();
  NodeBlockMatrix _blocks; // layout of the tangent's node blocks (built on demand)
  std::vector<double> _K;  // scratch tangent of one element
  Timing _timing;

  /// Residual (and tangent if K) of one closed element with its current
  /// unknowns xi, xj; forces are the element's (times its length).
  ContactResult element(const ContactElementState& e, std::span<const double> xi,
                        std::span<const double> xj, std::span<double> r,
                        std::span<double> K) const;
};

} // namespace textile::contact
