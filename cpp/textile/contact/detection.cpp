#include "detection.h"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace textile::contact
{
Detection detect(const Centrelines& c, const SectionVectors& g, double delta_factor,
                 double self_exclusion, double spacing, double parallel_angle,
                 const WeavingOrder* weaving, std::span<const ZoneMark> previous)
{
  Detection d;
  d.zones = find_proximity_zones(c, delta_factor, self_exclusion);
  // the marks sorted by fibre pair: each zone looks up its pair's marks
  // (one mark a zone of the last pass: a scan per zone would be quadratic)
  std::vector<ZoneMark> marks(previous.begin(), previous.end());
  const auto pair_less = [](const ZoneMark& a, const ZoneMark& b)
  { return std::tie(a.fibre_i, a.fibre_j) < std::tie(b.fibre_i, b.fibre_j); };
  std::sort(marks.begin(), marks.end(), pair_less);
  for (std::size_t z = 0; z < d.zones.size(); ++z)
  {
    const ProximityZone& zone = d.zones[z];
    const bool ordered = weaving and weaving->sign(zone.fibre_i, zone.fibre_j) != 0;
    // the last pass's kinds of zone here (within one element on both fibres)
    bool was_wrap = false, was_crossing = false, was_line = false;
    const ZoneMark key{.fibre_i = zone.fibre_i, .fibre_j = zone.fibre_j};
    const auto [first, last] = std::equal_range(marks.begin(), marks.end(), key, pair_less);
    for (const ZoneMark& m : std::span(first, last))
      if (m.s_i >= zone.a_i - 1 and m.s_i <= zone.b_i + 1 and m.s_j >= zone.a_j - 1
          and m.s_j <= zone.b_j + 1)
      {
        was_wrap = was_wrap or m.kind == ZoneKind::wrap;
        was_crossing = was_crossing or m.kind == ZoneKind::crossing;
        was_line = was_line or m.kind == ZoneKind::line;
      }
    const double wrap_angle = ordered ? -1.0 : was_wrap ? 0.5 * parallel_angle : parallel_angle;
    // a zone that was a point contact (crossing or wrap) stays one with a
    // margin; a line contact alone becomes one only past the margin
    const double bias = (was_crossing or was_wrap) ? crossing_bias : was_line ? -crossing_bias : 0.0;
    for (auto& p : contact_points(c, g, zone, spacing, parallel_angle, delta_factor,
                                  Eigen::Vector3d::Zero(), wrap_angle, bias))
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

std::vector<ZoneMark> zone_marks(const ContactSet& set)
{
  std::vector<ZoneMark> out;
  std::vector<char> seen(set.num_zones(), 0);
  for (const auto& e : set.elements())
    if (!seen[e.zone])
    {
      seen[e.zone] = 1;
      const ZoneKind kind = e.wrap ? ZoneKind::wrap
                            : e.crossing ? ZoneKind::crossing
                                         : ZoneKind::line;
      out.push_back({e.fibre_i, e.fibre_j, e.s_i, e.s_j, kind});
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
