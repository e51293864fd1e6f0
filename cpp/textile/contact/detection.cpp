#include "detection.h"

#include <algorithm>
#include <cmath>

namespace textile::contact
{
Detection detect(const Centrelines& c, const SectionVectors& g, double delta_factor,
                 double self_exclusion, double spacing, double parallel_angle,
                 const WeavingOrder* weaving, std::span<const WrapMark> previous_wraps)
{
  Detection d;
  d.zones = find_proximity_zones(c, delta_factor, self_exclusion);
  for (std::size_t z = 0; z < d.zones.size(); ++z)
  {
    const ProximityZone& zone = d.zones[z];
    const bool ordered = weaving and weaving->sign(zone.fibre_i, zone.fibre_j) != 0;
    const bool was_wrap = std::any_of(
        previous_wraps.begin(), previous_wraps.end(),
        [&](const WrapMark& w)
        {
          return w.fibre_i == zone.fibre_i and w.fibre_j == zone.fibre_j
                 and w.s_i >= zone.a_i - 1 and w.s_i <= zone.b_i + 1 and w.s_j >= zone.a_j - 1
                 and w.s_j <= zone.b_j + 1;
        });
    const double wrap_angle = ordered ? -1.0 : was_wrap ? 0.5 * parallel_angle : parallel_angle;
    for (auto& p : contact_points(c, g, zone, spacing, parallel_angle, delta_factor,
                                  Eigen::Vector3d::Zero(), wrap_angle))
    {
      d.points.push_back(p);
      d.zone_of_point.push_back(static_cast<int>(z));
    }
  }
  return d;
}

ContactElementState restore_element(const Centrelines& c, const SavedElement& saved, double g_r,
                                    const RegularizedCoulomb& friction,
                                    std::span<const double> q)
{
  const ContactPoint p{.fibre_i = saved.fibre_i, .fibre_j = saved.fibre_j,
                       .s_i = saved.s_i,         .s_j = saved.s_j,
                       .xi1_i = saved.xi1_i,     .xi2_i = saved.xi2_i,
                       .xi1_j = saved.xi1_j,     .xi2_j = saved.xi2_j,
                       .crossing = saved.crossing, .wrap = saved.wrap,
                       .length = saved.length};
  ContactElementState e = make_element(c, p, saved.zone, saved.normal, saved.penalty, g_r,
                                       friction, Eigen::Vector3d::Zero(), q);
  e.stick = saved.stick;
  return e;
}

std::vector<WrapMark> wrap_marks(const ContactSet& set)
{
  std::vector<WrapMark> out;
  std::vector<char> seen(set.num_zones(), 0);
  for (const auto& e : set.elements())
    if (e.wrap and !seen[e.zone])
    {
      seen[e.zone] = 1;
      out.push_back({e.fibre_i, e.fibre_j, e.s_i, e.s_j});
    }
  return out;
}

ContactElementState make_element(const Centrelines& c, const ContactPoint& p, int zone,
                                 const Eigen::Vector3d& normal, double penalty, double g_r,
                                 const RegularizedCoulomb& friction,
                                 const Eigen::Vector3d& elastic_slip, std::span<const double> q)
{
  ContactElementState e;
  e.fibre_i = p.fibre_i;
  e.fibre_j = p.fibre_j;
  e.s_i = p.s_i;
  e.s_j = p.s_j;
  e.zone = zone;
  e.crossing = p.crossing;
  e.wrap = p.wrap;
  e.length = p.length;
  const int nn = c.order + 1;
  e.particle_i = {nn, element_of(c, p.fibre_i, p.s_i, e.nodes_i), p.xi1_i, p.xi2_i,
                  c.radius[p.fibre_i]};
  e.particle_j = {nn, element_of(c, p.fibre_j, p.s_j, e.nodes_j), p.xi1_j, p.xi2_j,
                  c.radius[p.fibre_j]};
  e.normal = normal;
  e.penalty = penalty;
  e.regularization = g_r;
  e.friction = friction;
  // the stick point that reproduces the carried elastic slip
  std::vector<double> xi, xj;
  for (int a = 0; a < nn; ++a)
    for (int k = 0; k < 9; ++k)
    {
      xi.push_back(q[9 * e.nodes_i[a] + k]);
      xj.push_back(q[9 * e.nodes_j[a] + k]);
    }
  const Eigen::Vector3d delta = particle_position(e.particle_i, xi)
                                - particle_position(e.particle_j, xj);
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - normal * normal.transpose();
  e.stick = delta - P * elastic_slip;
  e.result.delta = delta;
  return e;
}
} // namespace textile::contact
