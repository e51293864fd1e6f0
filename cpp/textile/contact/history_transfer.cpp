#include "history_transfer.h"
#include "../node_unknowns.h"
#include "vertical_crossing.h"
#include "contact_normal.h"

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <tuple>

namespace textile::contact
{
namespace
{
/// (fibre_i, fibre_j, element of s_i) in one integer: 21 bits each.
std::uint64_t pair_element_key(int fibre_i, int fibre_j, std::int64_t element)
{
  constexpr std::int64_t limit = std::int64_t{1} << 21;
  if (fibre_i < 0 or fibre_j < 0 or fibre_i >= limit or fibre_j >= limit or element < -1
      or element + 1 >= limit)
    throw std::invalid_argument("match_history: fibre or element number out of range");
  // element + 1: a window may start one element before the first
  return (static_cast<std::uint64_t>(fibre_i) << 42) | (static_cast<std::uint64_t>(fibre_j) << 21)
         | static_cast<std::uint64_t>(element + 1);
}

std::int64_t element_index(double s) { return static_cast<std::int64_t>(std::floor(s)); }

/// Abscissa on fibre f of patch coordinate xi (particle.h) of a patch whose
/// first node is `first_node`.
double measured_abscissa(const Centrelines& c, int f, std::int64_t first_node, double xi)
{
  return double(first_node - c.fibre_offsets[f]) / c.order + 0.5 * (xi + 1.0);
}

/// Is abscissa s one of fibre f's ends?
bool at_fibre_end(const Centrelines& c, int f, double s) { return s <= 0 or s >= c.num_elements(f); }

} // namespace

std::vector<int> match_history(std::span<const ContactPoint> points,
                               std::span<const ContactElementState> old, double max_distance)
{
  if (!(max_distance > 0) or !std::isfinite(max_distance))
    throw std::invalid_argument("match_history: max_distance must be positive and finite");
  std::vector<std::pair<std::uint64_t, int>> keyed(old.size());
  for (std::size_t k = 0; k < old.size(); ++k)
    keyed[k] = {pair_element_key(old[k].fibre_i, old[k].fibre_j, element_index(old[k].s_i)),
                static_cast<int>(k)};
  std::sort(keyed.begin(), keyed.end()); // by key, then by index: ties go to the lower index

  std::vector<int> match(points.size(), -1);
  for (std::size_t p = 0; p < points.size(); ++p)
  {
    const ContactPoint& pt = points[p];
    double best = max_distance;
    int best_index = -1;
    const std::int64_t lo = std::max<std::int64_t>(element_index(pt.s_i - max_distance), -1);
    const std::int64_t hi = element_index(pt.s_i + max_distance);
    for (std::int64_t e = lo; e <= hi; ++e)
    {
      const std::uint64_t key = pair_element_key(pt.fibre_i, pt.fibre_j, e);
      auto it = std::lower_bound(keyed.begin(), keyed.end(), std::pair{key, -1});
      for (; it != keyed.end() and it->first == key; ++it)
      {
        const ContactElementState& o = old[it->second];
        const double d = std::abs(o.s_i - pt.s_i) + std::abs(o.s_j - pt.s_j);
        if (d < best or (d == best and best_index >= 0 and it->second < best_index))
        {
          best = d;
          best_index = it->second;
        }
      }
    }
    match[p] = best_index;
  }
  return match;
}

std::pair<ContactSet, ZoneInheritance>
next_contact_set(const ContactSet& old, const Detection& d, const Centrelines& c,
                 std::span<const double> q, const ElementParameters& par,
                 const NodeOwners& owners)
{
  const auto& previous = old.elements();
  const std::size_t nz = d.zones.size();
  // weaving: fibres of a warp and a weft yarn touch at one point, where
  // they pass over each other (the vertical normal's facing point), not at
  // the 3D closest point, which wanders along fibres bent around each
  // other, nor along a line (a zone of crimped fibres can look like one):
  // one crossing element per zone, at the projected intersection. Placed
  // before history matching, so an element finds its predecessor there.
  std::vector<ContactPoint> points(d.points.begin(), d.points.end());
  std::vector<char> keep(points.size(), 1), woven(nz, 0);
  for (std::size_t k = 0; k < points.size(); ++k)
  {
    ContactPoint& p = points[k];
    if (!par.weaving or par.weaving->sign(p.fibre_i, p.fibre_j) == 0)
      continue;
    if (par.weaving->pass_through()) // the yarns pass through each other
    {
      keep[k] = 0;
      continue;
    }
    const int z = d.zone_of_point[k];
    keep[k] = !woven[z];
    woven[z] = 1;
    if (keep[k] and vertical_crossing(c, p))
    {
      p.crossing = true;
      p.length = crossing_length(c.radius[p.fibre_i], c.radius[p.fibre_j]);
    }
  }
  const std::vector<int> match = match_history(points, previous);
  // a woven crossing with a predecessor (ordinary contact after weaving):
  // where the fibres face each other along the predecessor's normal
  // (vertical_crossing.h; right after the weaving stage, the vertical)
  std::vector<char> relocated(points.size(), 0);
  for (std::size_t k = 0; k < points.size(); ++k)
    if (par.woven and keep[k] and points[k].crossing and match[k] >= 0
        and par.woven->sign(points[k].fibre_i, points[k].fibre_j) != 0)
      relocated[k] = facing_crossing(c, points[k], previous[match[k]].normal);
  ZoneInheritance zones{std::vector<double>(nz, 0.0),
                        std::vector<int>(nz, std::numeric_limits<int>::max()),
                        std::vector<int>(nz, -1), std::vector<int>(nz, 0)};
  std::vector<ContactElementState> elements;
  std::vector<char> claimed(previous.size(), 0); // old line elements kept (persist)
  for (std::size_t k = 0; k < points.size(); ++k)
  {
    if (!keep[k])
      continue;
    ContactPoint p = points[k];
    const int z = d.zone_of_point[k];
    const ContactElementState* from = match[k] >= 0 ? &previous[match[k]] : nullptr;
    if (from)
    {
      zones.penalty[z] = std::max(zones.penalty[z], from->penalty);
      zones.previous_zone_min[z] = std::min(zones.previous_zone_min[z], from->zone);
      zones.previous_zone_max[z] = std::max(zones.previous_zone_max[z], from->zone);
      zones.changed_kind[z] |= from->crossing != p.crossing;
    }
    std::array<std::int64_t, 3> nodes, nodes_j; // of the particles' elements
    element_of(c, p.fibre_i, p.s_i, nodes);
    element_of(c, p.fibre_j, p.s_j, nodes_j);
    if (!evaluated_here(p.fibre_i, p.fibre_j, nodes[0], nodes_j[0], owners))
      continue;
    const Eigen::Vector3d previous_normal
        = from and !par.reset_normals ? from->normal : Eigen::Vector3d::Zero();
    const int order = par.weaving ? par.weaving->sign(p.fibre_i, p.fibre_j) : 0;
    Eigen::Vector3d normal;
    GapKind kind = GapKind::held;
    if (order != 0)
    {
      normal = order * Eigen::Vector3d::UnitZ();
      place_particles(c, SectionVectors{q, dofs_per_node, 3}, p, -normal);
      if (p.crossing) // at the vertical crossing: it moves with the fibres
        kind = GapKind::facing;
    }
    else if (p.held_normal.squaredNorm() > 0)
      normal = p.held_normal; // the fibres have crossed along it: keep it
    else if (p.wrap)
      normal = centroid_normal(p.tangent, p.centroid_gap, previous_normal);
    else if (!p.crossing)
    {
      // a line contact: the centroid direction in the section plane,
      // following the centre lines as they roll around each other
      normal = centroid_normal(p.tangent, p.centroid_gap, previous_normal);
      kind = GapKind::following;
    }
    else if ((at_fibre_end(c, p.fibre_i, p.s_i) or at_fibre_end(c, p.fibre_j, p.s_j)))
    {
      // a fibre's end next to another fibre: they do not cross, the end
      // stops short of it; t_i x t_j would read the height between them as
      // the gap, however far apart they are in the plane (a picture
      // frame's yarn end 3.8 R from its neighbour "touched" it), and the
      // centroids' direction measures the real distance
      normal = centroid_normal(p.tangent, p.centroid_gap, previous_normal);
      kind = GapKind::facing;
    }
    else
    {
      normal = contact_normal(p.tangent_i, p.tangent_j, p.tangent, p.centroid_gap,
                              previous_normal, par.parallel_angle, p.crossing,
                              c.radius[p.fibre_i] + c.radius[p.fibre_j]);
      // a relocated crossing turns its normal half way from the previous
      // one: between fibres bent around each other, placement along a
      // normal and the normal at that place over-correct each other (a
      // growing period-2 swing); halving the turn keeps the fixed point
      if (relocated[k])
        normal = (from->normal + normal).normalized();
      kind = GapKind::facing;
    }
    if (par.persist and kind == GapKind::following and from and from->motion.kind == kind
        and !claimed[match[k]]
        and std::abs(from->s_i - measured_abscissa(c, from->fibre_i, from->nodes_i[0],
                                                   from->result.gap_xi[0]))
                + std::abs(from->s_j - measured_abscissa(c, from->fibre_j, from->nodes_j[0],
                                                         from->result.gap_xi[1]))
            <= persist_drift)
    {
      claimed[match[k]] = 1;
      ContactElementState e = *from;
      e.zone = z;
      elements.push_back(e);
      continue;
    }
    const Eigen::Vector3d slip = from ? old.elastic_slip(*from) : Eigen::Vector3d::Zero();
    RegularizedCoulomb friction = par.friction;
    if (par.coefficients)
      friction.mu = par.coefficients->mu(p.fibre_i, p.fibre_j);
    elements.push_back(make_element(c, p, z, normal, from ? from->penalty : par.penalty,
                                    par.regularization, friction, slip, q, kind,
                                    par.crossing_patch));
  }
  return {ContactSet(std::move(elements), static_cast<int>(nz)), std::move(zones)};
}
} // namespace textile::contact
