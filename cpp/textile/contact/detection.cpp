#include "detection.h"
#include "../node_unknowns.h"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace textile::contact
{
Detection detect(const Centrelines& c, const SectionVectors& g, double delta_factor,
                 double self_exclusion, double spacing, double parallel_angle,
                 const WeavingOrder* weaving, std::span<const ZoneMark> previous,
                 bool keep_kinds)
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
    double wrap_angle = ordered ? -1.0 : was_wrap ? 0.5 * parallel_angle : parallel_angle;
    // a zone that was a point contact (crossing or wrap) stays one with a
    // margin; a line contact alone becomes one only past the margin
    double bias = (was_crossing or was_wrap) ? crossing_bias : was_line ? -crossing_bias : 0.0;
    if (keep_kinds and (was_crossing or was_wrap or was_line))
    {
      // within a step: the same kind outright (a bias of 1 accepts any angle
      // and any ends for a crossing, -1 none short of twice the criteria)
      bias = (was_crossing or was_wrap) ? 1.0 : -1.0;
      if (!ordered)
        wrap_angle = was_wrap ? 0.0 : -1.0;
    }
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
                                    std::span<const double> q, int crossing_patch)
{
  const ContactPoint p{.fibre_i = saved.fibre_i, .fibre_j = saved.fibre_j,
                       .s_i = saved.s_i,         .s_j = saved.s_j,
                       .xi1_i = saved.xi1_i,     .xi2_i = saved.xi2_i,
                       .xi1_j = saved.xi1_j,     .xi2_j = saved.xi2_j,
                       .crossing = saved.crossing, .wrap = saved.wrap,
                       .length = saved.length};
  ContactElementState e = make_element(c, p, saved.zone, saved.normal, saved.penalty, g_r,
                                       friction, Eigen::Vector3d::Zero(), q, saved.gap_kind,
                                       crossing_patch);
  e.stick = saved.stick;
  // an element kept over passes within a step (history_transfer.h, persist)
  // saw the geometry of an earlier pass
  if (e.motion.kind != GapKind::held and saved.tangent_i.squaredNorm() > 0)
  {
    e.motion.tangent_i = saved.tangent_i;
    e.motion.tangent_j = saved.tangent_j;
  }
  return e;
}

void renumber_zones(Detection& d, std::span<const int> global_of_local, int num_zones)
{
  if (global_of_local.size() != d.zones.size())
    throw std::invalid_argument("renumber_zones: " + std::to_string(global_of_local.size())
                                + " numbers for " + std::to_string(d.zones.size()) + " zones");
  std::vector<ProximityZone> zones(num_zones);
  for (std::size_t z = 0; z < d.zones.size(); ++z)
  {
    const int g = global_of_local[z];
    if (g < 0 or g >= num_zones)
      throw std::invalid_argument("renumber_zones: zone number " + std::to_string(g)
                                  + " outside 0 .. " + std::to_string(num_zones - 1));
    zones[g] = d.zones[z];
  }
  for (int& z : d.zone_of_point)
    z = global_of_local[z];
  d.zones = std::move(zones);
}

std::vector<double> zone_keys(const Detection& d)
{
  const std::size_t first_held = d.zones.size() - d.held_source.size();
  std::vector<double> out;
  out.reserve(9 * d.zones.size());
  for (std::size_t z = 0; z < d.zones.size(); ++z)
  {
    const ProximityZone& p = d.zones[z];
    const double held = z >= first_held ? d.held_source[z - first_held] : -1.0;
    for (double v : {double(p.fibre_i), double(p.fibre_j), p.a_i, p.b_i, p.a_j, p.b_j, p.s_i,
                     p.s_j, held})
      out.push_back(v);
  }
  return out;
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

namespace
{
/// The patch of fibre f a side is evaluated on (particle.h): the element
/// holding abscissa s, and with `two` its neighbour across the nearer
/// interior node.
void set_patch(const Centrelines& c, int f, double s, bool two, Particle& p,
               std::array<std::int64_t, max_patch_nodes>& nodes)
{
  std::array<std::int64_t, 3> element;
  element_of(c, f, s, element);
  const int node = static_cast<int>(std::lround(s));
  nodes.fill(-1);
  if (two and node > 0 and node < c.num_elements(f))
  {
    p.patch_elements = 2;
    p.patch_position = element[0] == c.fibre_offsets[f] + std::int64_t(c.order) * node ? 1 : 0;
    for (int a = 0; a <= 2 * c.order; ++a)
      nodes[a] = c.fibre_offsets[f] + std::int64_t(c.order) * (node - 1) + a;
  }
  else
  {
    p.patch_elements = 1;
    p.patch_position = 0;
    std::copy(element.begin(), element.begin() + c.order + 1, nodes.begin());
  }
  p.fibre_end_below = nodes[0] == c.fibre_offsets[f];
  p.fibre_end_above = nodes[p.patch_nodes() - 1]
                      == c.fibre_offsets[f] + std::int64_t(c.order) * c.num_elements(f);
}
} // namespace

ContactElementState make_element(const Centrelines& c, const ContactPoint& point, int zone,
                                 const Eigen::Vector3d& normal, double penalty, double g_r,
                                 const RegularizedCoulomb& friction,
                                 const Eigen::Vector3d& elastic_slip, std::span<const double> q,
                                 GapKind gap_kind, int crossing_patch)
{
  const ContactPoint& p = point;
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
  std::array<std::int64_t, 3> element_nodes;
  e.particle_i = {nn, element_of(c, p.fibre_i, p.s_i, element_nodes), p.xi1_i, p.xi2_i,
                  c.radius[p.fibre_i]};
  e.particle_j = {nn, element_of(c, p.fibre_j, p.s_j, element_nodes), p.xi1_j, p.xi2_j,
                  c.radius[p.fibre_j]};
  // a crossing's point moves within Newton: on the element and its
  // neighbour across the nearer node (particle.h)
  const bool moving_point = gap_kind == GapKind::facing and crossing_patch == 2;
  set_patch(c, p.fibre_i, p.s_i, moving_point, e.particle_i, e.nodes_i);
  set_patch(c, p.fibre_j, p.s_j, moving_point, e.particle_j, e.nodes_j);
  e.normal = normal;
  e.motion.kind = gap_kind;
  if (gap_kind != GapKind::held)
  {
    // dx0/dxi: the blended direction, the element's length per xi
    e.motion.tangent_i = 0.5 * c.tangent(p.fibre_i, p.s_i).norm() * blended_tangent(c, p.fibre_i, p.s_i);
    e.motion.tangent_j = 0.5 * c.tangent(p.fibre_j, p.s_j).norm() * blended_tangent(c, p.fibre_j, p.s_j);
  }
  e.penalty = penalty;
  e.regularization = g_r;
  e.friction = friction;
  // the stick point that reproduces the carried elastic slip
  std::vector<double> xi, xj;
  for (int a = 0; a < e.particle_i.patch_nodes(); ++a)
    for (int k = 0; k < dofs_per_node; ++k)
      xi.push_back(q[dofs_per_node * e.nodes_i[a] + k]);
  for (int a = 0; a < e.particle_j.patch_nodes(); ++a)
    for (int k = 0; k < dofs_per_node; ++k)
      xj.push_back(q[dofs_per_node * e.nodes_j[a] + k]);
  const Eigen::Vector3d delta = particle_position(e.particle_i, xi)
                                - particle_position(e.particle_j, xj);
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - normal * normal.transpose();
  e.stick = delta - P * elastic_slip;
  e.result.delta = delta;
  return e;
}
} // namespace textile::contact
