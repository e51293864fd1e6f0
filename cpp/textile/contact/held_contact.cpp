#include "held_contact.h"
#include "tolerances.h"

#include <algorithm>
#include <cmath>

namespace textile::contact
{
namespace
{
/// Whether the centre line of the other fibre lies beyond fibre f's end at
/// abscissa s (s at 0 or at the last node): `towards_other` points from
/// fibre f's centroid to the other's.
bool beyond_end(const Centrelines& c, int f, double s, const Eigen::Vector3d& towards_other)
{
  const double end = c.num_elements(f);
  if (s > 0 and s < end)
    return false;
  const Eigen::Vector3d outward = (s <= 0 ? -1.0 : 1.0) * unit_tangent(c, f, s);
  return towards_other.dot(outward) > 0;
}

/// Does a zone of d cover the held contact (same fibres, within one
/// element of its intervals on both)?
bool covered(const Detection& d, const HeldContact& h)
{
  return std::any_of(d.zones.begin(), d.zones.end(),
                     [&](const ProximityZone& z)
                     {
                       return z.fibre_i == h.fibre_i and z.fibre_j == h.fibre_j
                              and h.s_i >= z.a_i - 1 and h.s_i <= z.b_i + 1
                              and h.s_j >= z.a_j - 1 and h.s_j <= z.b_j + 1;
                     });
}
} // namespace

std::vector<HeldContact> contacts_to_hold(const ContactSet& set, const Centrelines& c,
                                          double delta_factor)
{
  std::vector<HeldContact> out;
  for (const auto& e : set.elements())
  {
    if (!(e.result.gap < 0))
      continue;
    const double reach = delta_factor * (c.radius[e.fibre_i] + c.radius[e.fibre_j]);
    const Eigen::Vector3d d = c.position(e.fibre_i, e.s_i) - c.position(e.fibre_j, e.s_j);
    if (d.norm() >= hold_fraction * reach)
      out.push_back({e.fibre_i, e.fibre_j, e.s_i, e.s_j, e.normal, e.length, e.crossing});
  }
  return out;
}

int add_held_contacts(Detection& d, const Centrelines& c, const SectionVectors& g,
                      std::span<const HeldContact> held)
{
  int added = 0;
  for (std::size_t k = 0; k < held.size(); ++k)
  {
    const HeldContact& h = held[k];
    // a fibre this rank does not hold: another rank's (Centrelines::present)
    if (!c.has(h.fibre_i) or !c.has(h.fibre_j) or covered(d, h))
      continue;
    ContactPoint p;
    p.fibre_i = h.fibre_i;
    p.fibre_j = h.fibre_j;
    p.crossing = h.crossing;
    p.length = h.length;
    p.parameter = 0.5;
    p.s_i = h.s_i;
    p.s_j = h.s_j;
    if (h.crossing)
    {
      std::tie(p.s_i, p.s_j) = closest_points(c, h.fibre_i, h.s_i, h.fibre_j, h.s_j);
    }
    p.tangent_i = unit_tangent(c, h.fibre_i, p.s_i);
    p.tangent_j = unit_tangent(c, h.fibre_j, p.s_j);
    p.tangent = mean_tangent(p.tangent_i, p.tangent_j);
    p.centroid_gap = c.smooth_position(h.fibre_i, p.s_i) - c.smooth_position(h.fibre_j, p.s_j);
    const Eigen::Vector3d& N = h.normal;
    const double contact_distance = c.radius[h.fibre_i] + c.radius[h.fibre_j];
    // across the normal and the fibres, the sections must still overlap
    Eigen::Vector3d across = p.centroid_gap - p.centroid_gap.dot(N) * N;
    across -= across.dot(p.tangent) * p.tangent;
    if (!(p.centroid_gap.dot(N) < contact_distance) or across.norm() >= contact_distance
        or beyond_end(c, h.fibre_i, p.s_i, -p.centroid_gap)
        or beyond_end(c, h.fibre_j, p.s_j, p.centroid_gap))
      continue;
    p.held_normal = N;
    place_particles(c, g, p, -N);
    ProximityZone z{h.fibre_i, h.fibre_j, p.s_i, p.s_i, p.s_j, p.s_j, p.centroid_gap.norm(),
                    p.s_i, p.s_j};
    d.zone_of_point.push_back(static_cast<int>(d.zones.size()));
    d.zones.push_back(z);
    d.held_source.push_back(static_cast<int>(k));
    d.points.push_back(p);
    ++added;
  }
  return added;
}
} // namespace textile::contact
