// One detection pass: proximity zones, then contact elements on their
// intermediate geometries (docs/method.md §3).
#pragma once

#include "centreline.h"
#include "contact_set.h"
#include "intermediate_geometry.h"
#include "proximity_zone.h"
#include "weaving_order.h"

#include <span>
#include <vector>

namespace textile::contact
{

/// Contact points found by one pass, with the zone each belongs to.
struct Detection
{
  std::vector<ProximityZone> zones;
  std::vector<ContactPoint> points;
  std::vector<int> zone_of_point;
  /// the zones add_held_contacts appended (held_contact.h; the last
  /// held_source.size() zones, a point each): the index of each one's held
  /// contact in its list
  std::vector<int> held_source;
};

/// Zone numbers shared by all ranks (a rank that detects among the fibres
/// near its own finds only some zones): `global_of_local[z]` for each
/// zone of d, in 0 .. num_zones - 1. The zones are renumbered in place
/// (zones without a local one are empty placeholders), and d.zones gets
/// num_zones entries. Throws std::invalid_argument for a size mismatch or
/// a number outside the range.
void renumber_zones(Detection& d, std::span<const int> global_of_local, int num_zones);

/// Each zone of d as the key every rank that finds it computes alike
/// (fibre_i, fibre_j, a_i, b_i, a_j, b_j, s_i, s_j, held contact index
/// or -1): 9 values a zone, row-major.
std::vector<double> zone_keys(const Detection& d);

/// What a zone of the last pass was: a crossing, a wrap (wrap_contact.h)
/// or a line contact.
enum class ZoneKind : int
{
  crossing = 0,
  wrap = 1,
  line = 2
};

/// Where the last pass had a zone, and of which kind: the fibres and
/// abscissas of one of its elements.
struct ZoneMark
{
  int fibre_i = 0, fibre_j = 0;
  double s_i = 0, s_j = 0;
  ZoneKind kind = ZoneKind::crossing;
};

/// One element of each of the set's zones (this rank's; gather them from
/// every rank for detect: a zone may pass to a rank that had none of it).
std::vector<ZoneMark> zone_marks(const ContactSet& set);

/// Find zones closer than delta_factor (r_i + r_j) and place their contact
/// elements (see contact_points; parallel_angle in radians). A crossing zone
/// becomes a wrap when a fibre turns by more than parallel_angle over it,
/// or by more than half that where the last pass had a wrap
/// (`previous`, within one element on both fibres): a fibre pressed
/// at one point kinks, spread along a wrap it straightens, and without this
/// hysteresis a zone near the threshold would flip between the two kinds
/// from pass to pass. The crossing criterion (is_crossing) has the same
/// hysteresis: a zone that was a crossing or a wrap stays one until the
/// criterion fails by a margin, and a line contact becomes a crossing only
/// past a margin (crossing_bias); a crossing pressed deep next to a fibre
/// end would otherwise flip to a line contact of many elements and back.
/// `keep_kinds` (the passes within a step after its first): a zone the
/// last pass had keeps its kind outright (crossing, wrap or line contact),
/// as its line contacts keep their elements (history_transfer.h, persist);
/// a step's first pass sees the last pass's kind with margins (the penalty
/// continuity test's switch shows one step later,
/// tests/contact/test_penalty_units.py). Each kind makes the
/// fibres take the shape that calls for the other (pressed at a point, a
/// fibre bent over another kinks past the wrap criterion; spread along a
/// wrap, it straightens below its hysteresis), and near a picture frame's
/// locking a crossing and a wrap took turns from pass to pass until the
/// step was cut; between steps the criteria decide again.
/// Pairs that `weaving` orders (weaving_order.h) keep point crossings,
/// never wraps: their vertical normal measures the
/// penetration through the crossing, while along a wrap, away from it, the
/// vertical distance between facing points is no penetration.
Detection detect(const Centrelines& c, const SectionVectors& g, double delta_factor,
                 double self_exclusion, double spacing, double parallel_angle,
                 const WeavingOrder* weaving = nullptr,
                 std::span<const ZoneMark> previous = {}, bool keep_kinds = false);

/// A contact element rebuilt from its saved values (a saved state, see
/// FibreContact.save_state): fibres, abscissas and section coordinates of
/// its particles, kind, zone, normal, contact length, penalty and stick
/// point; nodes and particles' element coordinates follow from the
/// abscissas as in make_element.
struct SavedElement
{
  int fibre_i = 0, fibre_j = 0;
  double s_i = 0, s_j = 0;
  double xi1_i = 0, xi2_i = 0, xi1_j = 0, xi2_j = 0;
  int zone = 0;
  bool crossing = false, wrap = false;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double length = 0, penalty = 0;
  Eigen::Vector3d stick = Eigen::Vector3d::Zero();
  GapKind gap_kind = GapKind::held; ///< gap_function.h
  /// the tangents its pass saw (GapMotion); zero: from the geometry at q
  Eigen::Vector3d tangent_i = Eigen::Vector3d::Zero(), tangent_j = Eigen::Vector3d::Zero();
};

ContactElementState restore_element(const Centrelines& c, const SavedElement& saved, double g_r,
                                    const RegularizedCoulomb& friction,
                                    std::span<const double> q, int crossing_patch = 2);

/// The contact element of point p of this pass, with its history.
///
/// @param normal       normal held fixed in Newton (from j towards i)
/// @param penalty      zone penalty k_c, regularization g_r
/// @param friction     Coulomb law (mu = 0: none)
/// @param elastic_slip carried tangential elastic slip (zero for a new element)
/// @param q            current [x0, g1, g2] of all nodes (9 per node)
/// @param gap_kind     how the gap moves within Newton (gap_function.h); a
///                     following one measures in the plane orthogonal to the
///                     mean of the fibres' tangents at the particles
/// @param crossing_patch the elements a facing point moves over within
///                     Newton: 2 (its element and the neighbour across the
///                     nearer node: 5 nodes a side with quadratic elements)
///                     or 1 (its element: 3 nodes a side, a sparser tangent)
ContactElementState make_element(const Centrelines& c, const ContactPoint& p, int zone,
                                 const Eigen::Vector3d& normal, double penalty, double g_r,
                                 const RegularizedCoulomb& friction,
                                 const Eigen::Vector3d& elastic_slip, std::span<const double> q,
                                 GapKind gap_kind = GapKind::held, int crossing_patch = 2);

} // namespace textile::contact
