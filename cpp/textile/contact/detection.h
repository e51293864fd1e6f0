// One detection pass: proximity zones, then contact elements on their
// intermediate geometries (METHOD.md section 2).
#pragma once

#include "centreline.h"
#include "contact_set.h"
#include "intermediate_geometry.h"
#include "proximity_zone.h"

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
  int held = 0; ///< points added by add_held_contacts (held_contact.h)
};

/// Find zones closer than delta_factor (r_i + r_j) and place their contact
/// elements (see contact_points; parallel_angle in radians).
Detection detect(const Centrelines& c, const SectionVectors& g, double delta_factor,
                 double self_exclusion, double spacing, double parallel_angle);

/// The contact element of point p of this pass, with its history.
///
/// @param normal       normal held fixed in Newton (from j towards i)
/// @param penalty      zone penalty k_c, regularization g_r
/// @param friction     Coulomb law (mu = 0: none)
/// @param elastic_slip carried tangential elastic slip (zero for a new element)
/// @param q            current [x0, g1, g2] of all nodes (9 per node)
ContactElementState make_element(const Centrelines& c, const ContactPoint& p, int zone,
                                 const Eigen::Vector3d& normal, double penalty, double g_r,
                                 const RegularizedCoulomb& friction,
                                 const Eigen::Vector3d& elastic_slip, std::span<const double> q);

} // namespace textile::contact
