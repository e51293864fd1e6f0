#include "wrap_contact.h"
#include "tolerances.h"
#include "closest_points.h"
#include "contact_normal.h"

#include <algorithm>
#include <cmath>

namespace textile::contact
{
namespace
{
/// Angle (radians) by which fibre f's unit tangent turns from a to b.
double turn(const Centrelines& c, int f, double a, double b)
{
  const double cosine = unit_tangent(c, f, a).dot(unit_tangent(c, f, b));
  return std::acos(std::clamp(cosine, -1.0, 1.0));
}

/// Length of fibre f over [a, b] that stays within `band` of its smallest
/// distance to the centre line of fibre `other` (sampled four times an
/// element, at least 16 times; from the first to the last sample inside).
double contact_region_length(const Centrelines& c, int f, double a, double b, int other,
                             double guess, double band)
{
  const int n = std::max(16, static_cast<int>(std::ceil(4 * (b - a))));
  std::vector<double> distance(n + 1);
  std::vector<Eigen::Vector3d> x(n + 1);
  for (int k = 0; k <= n; ++k)
  {
    x[k] = c.position(f, a + (b - a) * k / n);
    guess = project_onto(c, other, x[k], guess);
    distance[k] = (x[k] - c.position(other, guess)).norm();
  }
  const double limit = *std::min_element(distance.begin(), distance.end()) + band;
  int first = -1, last = -1;
  for (int k = 0; k <= n; ++k)
    if (distance[k] <= limit)
    {
      first = first < 0 ? k : first;
      last = k;
    }
  double length = 0;
  for (int k = first; k < last; ++k)
    length += (x[k + 1] - x[k]).norm();
  return length;
}
} // namespace

int wrapping_fibre(const Centrelines& c, const ProximityZone& z, double wrap_angle,
                   double min_length)
{
  // a wrap's elements measure the gap radially from the other centre line:
  // deeply interpenetrating centre lines have no such direction, the
  // crossing normal holds them apart
  const double contact_distance = c.radius[z.fibre_i] + c.radius[z.fibre_j];
  if (z.min_distance < crossing_separation * contact_distance)
    return -1;
  const double turn_i = turn(c, z.fibre_i, z.a_i, z.b_i);
  const double turn_j = turn(c, z.fibre_j, z.a_j, z.b_j);
  if (std::max(turn_i, turn_j) <= wrap_angle)
    return -1;
  const bool i_wraps = turn_i >= turn_j;
  const double region
      = i_wraps ? contact_region_length(c, z.fibre_i, z.a_i, z.b_i, z.fibre_j, z.s_j,
                                        wrap_band * contact_distance)
                : contact_region_length(c, z.fibre_j, z.a_j, z.b_j, z.fibre_i, z.s_i,
                                        wrap_band * contact_distance);
  if (region < min_length)
    return -1;
  return i_wraps ? z.fibre_i : z.fibre_j;
}

std::vector<ContactPoint> wrap_points(const Centrelines& c, const SectionVectors& g,
                                      const ProximityZone& z, int wrapping, double spacing)
{
  const bool i_wraps = wrapping == z.fibre_i;
  const int f = i_wraps ? z.fibre_i : z.fibre_j, other = i_wraps ? z.fibre_j : z.fibre_i;
  const double a = i_wraps ? z.a_i : z.a_j, b = i_wraps ? z.b_i : z.b_j;
  // the wrapping fibre's arc length over the zone (its chord polyline is
  // enough to size the rule; each point's own length is exact below)
  double length = 0;
  constexpr int samples = 16;
  for (int k = 0; k < samples; ++k)
    length += (c.position(f, a + (b - a) * (k + 1) / samples)
               - c.position(f, a + (b - a) * k / samples))
                  .norm();
  std::vector<double> cuts;
  add_element_cuts(a, b, cuts);
  const auto [params, weights] = composite_gauss_rule(std::move(cuts), length, spacing);
  std::vector<ContactPoint> out;
  double guess = i_wraps ? z.s_j : z.s_i;
  for (std::size_t k = 0; k < params.size(); ++k)
  {
    const double s = a + (b - a) * params[k];
    const Eigen::Vector3d x = c.position(f, s);
    guess = project_onto(c, other, x, guess);
    ContactPoint p;
    p.fibre_i = z.fibre_i;
    p.fibre_j = z.fibre_j;
    p.s_i = i_wraps ? s : guess;
    p.s_j = i_wraps ? guess : s;
    p.parameter = params[k];
    p.crossing = false;
    p.wrap = true;
    // arc length: the Gauss weight times |dx/du| (u in [0, 1] over [a, b])
    p.length = weights[k] * (b - a) * c.tangent(f, s).norm();
    p.tangent_i = unit_tangent(c, z.fibre_i, p.s_i);
    p.tangent_j = unit_tangent(c, z.fibre_j, p.s_j);
    p.tangent = i_wraps ? p.tangent_j : p.tangent_i; // the wrapped fibre's
    p.centroid_gap = c.position(z.fibre_i, p.s_i) - c.position(z.fibre_j, p.s_j);
    const Eigen::Vector3d d = -p.centroid_gap; // from i towards j
    if (!(d.norm() > 1e-12 * c.radius[z.fibre_i])
        or std::abs(d.dot(p.tangent_i)) > end_cap_cosine * d.norm()
        or std::abs(d.dot(p.tangent_j)) > end_cap_cosine * d.norm())
      continue; // coincident centroids or a fibre end: no facing particles
    place_particles(c, g, p, d);
    out.push_back(p);
  }
  return out;
}
} // namespace textile::contact
