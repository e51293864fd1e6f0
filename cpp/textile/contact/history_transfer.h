// History of contact elements carried from one detection pass to the next
// (docs/method.md §3.7).
//
// Each pass (loops 1-2) makes new elements; a new element takes over the
// history of the old element "at the same place": the same ordered fibre
// pair, and the nearest abscissas on both fibres. It inherits the normal's
// orientation (the side each fibre is on, kept under deep penetration), the
// friction stick point (as the elastic slip, so that sliding made in
// earlier steps is not undone), and its zone's penalty.
#pragma once

#include "contact_set.h"
#include "tolerances.h"
#include "detection.h"
#include "friction_coefficients.h"
#include "weaving_order.h"

#include <climits>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace textile::contact
{

/// For each new contact point, the index of the old element of the same
/// fibre pair with the smallest |s_i - s_i'| + |s_j - s_j'| (element
/// coordinates), if that is below max_distance (history_match_distance,
/// tolerances.h); -1 if there is none. Ties go to the lower index.
///
/// Old elements are sorted by the key (fibre_i, fibre_j, element of s_i),
/// and a point looks only at the keys whose element is within max_distance
/// of its s_i: O((points + old) log old), where comparing every point with
/// every element of its fibre pair was O(points x old).
std::vector<int> match_history(std::span<const ContactPoint> points,
                               std::span<const ContactElementState> old,
                               double max_distance = history_match_distance);

/// What the zones of a new pass inherit from one rank's old elements. Zone
/// numbers are shared by the ranks (renumber_zones in detection.h), so
/// every rank has the same arrays' meaning: reduce them over ranks (MAX, MIN, MAX, MAX) to get
/// the whole picture.
struct ZoneInheritance
{
  std::vector<double> penalty;          ///< largest carried penalty (0: none)
  std::vector<int> previous_zone_min;   ///< smallest old zone matched (INT_MAX: none)
  std::vector<int> previous_zone_max;   ///< largest old zone matched (-1: none)
  std::vector<int> changed_kind;        ///< 1 if a matched old element was of the other
                                        ///< kind (crossing vs line contact)
};

/// Parameters of the elements a pass makes.
struct ElementParameters
{
  double penalty = 0;         ///< k_c of an element without history (see contact_set.h)
  double regularization = 0;  ///< g_r (length)
  RegularizedCoulomb friction;  ///< u_rev, and mu where `coefficients` is null
  /// Each pair's mu (within a yarn, between yarns); nullptr: friction.mu
  const FrictionCoefficients* coefficients = nullptr;
  double parallel_angle = 0;  ///< radians, for the normals (contact_normal)
  /// Elements a crossing's (facing) point moves over within Newton: 2 or 1
  /// (make_element)
  int crossing_patch = 2;
  /// The weaving stage's crossing order (weaving_order.h): pairs of fibres
  /// of ordered yarns take the vertical normal it gives; nullptr: none.
  const WeavingOrder* weaving = nullptr;
  /// Ignore the old elements' normals (the contact mode changed): normals
  /// are set from the geometry again; penalties and stick points carry.
  bool reset_normals = false;
  /// A woven fabric's crossing order after the weaving stage (ordinary
  /// contact): crossings of fibres of ordered yarns are placed where the
  /// fibres face each other along the predecessor's normal, turning it half
  /// way (vertical_crossing.h): woven fibres are bent around each other.
  /// nullptr: closest points, as detection found them.
  const WeavingOrder* woven = nullptr;
  /// Within a load step (the passes after its first): a line contact found
  /// again keeps that element (particles, plane, normal; only its zone
  /// renumbered) while its points, which move within Newton
  /// (gap_function.h: following), are within persist_drift of where its
  /// pass put them. Placed anew, a line contact's points move with the
  /// zone's ends from pass to pass, over a penetration that varies along
  /// the line, and the contact forces of a stacked yarn swing by a percent
  /// between two places for ever. The first pass of a step places every
  /// element from the geometry again, and so does any pass for an element
  /// whose points slid further (a fibre sliding over a curved one: kept,
  /// the elements' planes lag behind the curve and drag it, 1e-3 of its
  /// tension instead of 2e-4, tests/contact/test_frictionless_drag.py).
  /// Crossings are placed anew at every pass: their normals converge over
  /// the passes (a woven crossing's turns half way each pass), and kept
  /// they stop at the step's first (a woven monofilament fabric's tension
  /// stiffness 7% off its crimp-interchange model instead of 1.6%,
  /// tests/virtual/test_fabric_references.py).
  bool persist = false;
};

/// The contact set of detection pass d at state q (all nodes, 9 unknowns
/// each), with history from `old` (normals: the weaving order's for pairs
/// it orders, with particles facing each other vertically; else
/// contact_normal): this rank's elements only (evaluated_here,
/// contact_set.h). The penalty
/// of an element is its match's, or par.penalty; callers make it one per
/// zone (ContactSet::set_zone_penalties) from the reduced inheritance,
/// which is computed over all points (an old element may pass its zone's
/// penalty to a point that another rank now evaluates).
std::pair<ContactSet, ZoneInheritance>
next_contact_set(const ContactSet& old, const Detection& d, const Centrelines& c,
                 std::span<const double> q, const ElementParameters& par,
                 const NodeOwners& owners);

} // namespace textile::contact
