// Contacts a detection pass must not lose (stability issue item 9).
//
// Detection keeps the centre lines closer than delta (r_i + r_j). A fibre
// pushed through another faster than the penalty can hold it (a soft
// penalty, a large step) ends the Newton solve with centre lines that have
// passed each other; once they are farther apart than delta on the wrong
// side, a fresh detection finds nothing and the fibres tunnel through each
// other silently. So every pass carries the elements that are closed and
// whose centroids are near the search distance to the next pass (as 4C's
// "new gap" measures the gap with the previous normal): where detection
// finds no zone for such a contact and its fibres still interpenetrate
// along the held normal, it is kept as a zone of its own, at the closest
// points (a crossing) or at its abscissas (a line contact's element), with
// that normal, until the fibres are pushed back within the search distance
// and detection finds them again. The normal's orientation is what tells
// which side each fibre belongs on; the solver's statistics count the
// elements whose centre lines lie on the wrong side (FibreContact).
#pragma once

#include "centreline.h"
#include "contact_set.h"
#include "detection.h"
#include "intermediate_geometry.h"

#include <Eigen/Core>

#include <span>
#include <vector>

namespace textile::contact
{

/// An element of the last pass, held for the next one.
struct HeldContact
{
  int fibre_i = 0, fibre_j = 0;
  double s_i = 0, s_j = 0;   ///< abscissas (element coordinates)
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ(); ///< from j towards i
  double length = 0;         ///< contact length it stands for
  bool crossing = false;
};

/// The elements of `set` (at their last evaluation) a detection with this
/// delta_factor might lose: closed (gap < 0) and with centroids at least
/// 0.9 delta_factor (r_i + r_j) apart. Each rank holds its own elements:
/// gather them from every rank before add_held_contacts (detection is
/// replicated).
std::vector<HeldContact> contacts_to_hold(const ContactSet& set, const Centrelines& c,
                                          double delta_factor);

/// Add to d, as zones of one point each, the held contacts that no zone of d
/// covers (same fibres, within one element on both) and whose fibres still
/// interpenetrate along the held normal: N . (x0_i - x0_j) < r_i + r_j at
/// the closest points near the held abscissas (a crossing; a line contact's
/// element keeps its abscissas), the sections overlapping across the
/// normal, and neither fibre slid off the other's end. Returns how many
/// were added.
int add_held_contacts(Detection& d, const Centrelines& c, const SectionVectors& g,
                      std::span<const HeldContact> held);

} // namespace textile::contact
