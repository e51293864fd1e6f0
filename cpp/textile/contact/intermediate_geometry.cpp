#include "intermediate_geometry.h"
#include "tolerances.h"
#include "../beam/quadrature.h"
#include "../beam/shape_functions.h"
#include "../geometry_error.h"
#include "wrap_contact.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <tuple>

namespace textile::contact
{
namespace
{
/// Bound on the elements of one zone, in units of the spacing: only a
/// diverged iterate stretches a zone that far.
constexpr double max_points_per_zone = 1e6;

/// Abscissa on fibre i / j at intermediate parameter s.
double along(double a, double b, double s) { return (1.0 - s) * a + s * b; }


Eigen::Vector3d intermediate_point(const Centrelines& c, const ProximityZone& z, double s)
{
  return 0.5 * (c.position(z.fibre_i, along(z.a_i, z.b_i, s))
                + c.position(z.fibre_j, z.along_j(s)));
}
} // namespace

double element_of(const Centrelines& c, int f, double s, std::array<std::int64_t, 3>& nodes)
{
  const int ne = c.num_elements(f);
  if (!(s >= 0.0 and s <= ne))
    throw std::invalid_argument("element_of: abscissa outside the fibre");
  const int e = std::min(static_cast<int>(std::floor(s)), ne - 1);
  nodes = {-1, -1, -1};
  for (int a = 0; a <= c.order; ++a)
    nodes[a] = c.fibre_offsets[f] + c.order * e + a;
  return 2.0 * (s - e) - 1.0;
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> SectionVectors::at(const Centrelines& c, int f,
                                                               double s) const
{
  std::array<std::int64_t, 3> nodes;
  const double xi = element_of(c, f, s, nodes);
  std::array<double, 3> n, dn;
  beam::lagrange(c.order + 1, xi, n, dn);
  Eigen::Vector3d g1 = Eigen::Vector3d::Zero(), g2 = Eigen::Vector3d::Zero();
  for (int a = 0; a <= c.order; ++a)
  {
    const std::size_t k = stride * nodes[a] + offset;
    g1 += n[a] * Eigen::Map<const Eigen::Vector3d>(g.data() + k);
    g2 += n[a] * Eigen::Map<const Eigen::Vector3d>(g.data() + k + 3);
  }
  return {g1, g2};
}

Eigen::Vector3d unit_tangent(const Centrelines& c, int f, double s)
{
  return c.smooth_tangent(f, s).normalized();
}

Eigen::Vector3d blended_tangent(const Centrelines& c, int f, double s)
{
  const double node = std::round(s);
  const double off = std::abs(s - node);
  const Eigen::Vector3d t = c.tangent(f, s).normalized();
  if (off >= kink_blend or node <= 0 or node >= c.num_elements(f))
    return t;
  // the jump of unit tangents at the node, from this side to the other
  const Eigen::Vector3d right = c.tangent(f, node).normalized();
  const Eigen::Vector3d left = c.tangent_left(f, node).normalized();
  const Eigen::Vector3d jump = s < node ? Eigen::Vector3d(right - left)
                                        : Eigen::Vector3d(left - right);
  return (t + 0.5 * (1.0 - off / kink_blend) * jump).normalized();
}

Eigen::Vector3d mean_tangent(const Eigen::Vector3d& ti, const Eigen::Vector3d& tj)
{
  const Eigen::Vector3d t = ti + (ti.dot(tj) >= 0 ? tj : Eigen::Vector3d(-tj));
  return t.normalized();
}

double crossing_length(double r_i, double r_j) { return r_i + r_j; }

double intermediate_length(const Centrelines& c, const ProximityZone& z, int samples)
{
  double length = 0;
  Eigen::Vector3d prev = intermediate_point(c, z, 0.0);
  for (int k = 1; k < samples; ++k)
  {
    const Eigen::Vector3d p = intermediate_point(c, z, double(k) / (samples - 1));
    length += (p - prev).norm();
    prev = p;
  }
  return length;
}

double section_cut(const Centrelines& c, int f, const Eigen::Vector3d& point,
                   const Eigen::Vector3d& normal, double guess)
{
  const double lo = 0.0, hi = c.num_elements(f);
  double s = std::clamp(guess, lo, hi);
  // Newton on phi(s) = (x0(s) - point) . normal; the centre line crosses
  // the plane once near the guess for any sensible zone
  for (int it = 0; it < 30; ++it)
  {
    const double phi = (c.position(f, s) - point).dot(normal);
    const double dphi = c.tangent(f, s).dot(normal);
    if (std::abs(dphi) < 1e-14 * c.tangent(f, s).norm())
      break; // tangent in the plane: keep the guess
    const double next = std::clamp(s - phi / dphi, lo, hi);
    if (std::abs(next - s) < 1e-13)
    {
      s = next;
      break;
    }
    s = next;
  }
  return s;
}

Eigen::Vector2d border_particle(const Eigen::Vector3d& g1, const Eigen::Vector3d& g2, double R,
                                const Eigen::Vector3d& d)
{
  // least squares [g1 g2] c = d: the projection of d on the section plane
  // in section coordinates (exact for deformed, non-orthogonal sections)
  Eigen::Matrix2d G;
  G << g1.dot(g1), g1.dot(g2), g1.dot(g2), g2.dot(g2);
  const Eigen::Vector2d rhs(g1.dot(d), g2.dot(d));
  Eigen::Vector2d cvec = G.ldlt().solve(rhs);
  const double n = cvec.norm();
  if (!(n > 0) or !std::isfinite(n))
    throw GeometryError("border_particle: direction orthogonal to the section plane");
  return R * cvec / n;
}

void place_particles(const Centrelines& c, const SectionVectors& g, ContactPoint& p,
                     const Eigen::Vector3d& towards_j)
{
  const auto [g1i, g2i] = g.at(c, p.fibre_i, p.s_i);
  const auto [g1j, g2j] = g.at(c, p.fibre_j, p.s_j);
  const Eigen::Vector2d qi = border_particle(g1i, g2i, c.radius[p.fibre_i], towards_j);
  const Eigen::Vector2d qj = border_particle(g1j, g2j, c.radius[p.fibre_j], -towards_j);
  p.xi1_i = qi(0);
  p.xi2_i = qi(1);
  p.xi1_j = qj(0);
  p.xi2_j = qj(1);
}

bool is_crossing(const Centrelines& c, const ProximityZone& z, double parallel_angle,
                 double delta_factor, double bias)
{
  const Eigen::Vector3d ti = unit_tangent(c, z.fibre_i, z.s_i);
  const Eigen::Vector3d tj = unit_tangent(c, z.fibre_j, z.s_j);
  const double sin_angle = ti.cross(tj).norm();
  if (sin_angle <= std::sin((1.0 - bias) * parallel_angle))
    return false;
  // A crossing zone ends where the centre lines move apart (distance near
  // the search distance at both ends); fibres that are twisted or wound
  // together stay close up to a fibre end, whatever their angle.
  const double delta = delta_factor * (c.radius[z.fibre_i] + c.radius[z.fibre_j]);
  const double threshold = z.min_distance + (0.5 - bias) * (delta - z.min_distance);
  const double d0 = (c.position(z.fibre_i, z.a_i) - c.position(z.fibre_j, z.along_j(0.0))).norm();
  const double d1 = (c.position(z.fibre_i, z.b_i) - c.position(z.fibre_j, z.along_j(1.0))).norm();
  return d0 > threshold and d1 > threshold;
}

void add_element_cuts(double a, double b, std::vector<double>& cuts)
{
  if (b - a > 1e-12)
    for (double k = std::ceil(a); k < b; k += 1.0)
      if (k > a)
        cuts.push_back((k - a) / (b - a));
}

std::pair<std::vector<double>, std::vector<double>>
composite_gauss_rule(std::vector<double> cuts, double length, double spacing)
{
  cuts.push_back(0.0);
  cuts.push_back(1.0);
  std::sort(cuts.begin(), cuts.end());
  // Cuts of the two fibres that nearly coincide (parallel fibres meshed
  // alike, slid by a fraction of a radius) would leave pieces far shorter
  // than the spacing, each with two elements that carry next to nothing but
  // cost as much as the others: a piece shorter than merge_fraction x
  // spacing is merged into its neighbour.
  std::vector<double> kept = {cuts.front()};
  for (std::size_t k = 1; k < cuts.size(); ++k)
    if ((cuts[k] - kept.back()) * length >= merge_fraction * spacing)
      kept.push_back(cuts[k]);
  if (kept.size() > 1 and (1.0 - kept.back()) * length < merge_fraction * spacing)
    kept.pop_back();
  if (kept.back() != 1.0)
    kept.push_back(1.0);
  // a state far outside the fibres' scale (a diverged iterate) would ask
  // for an absurd number of elements: refuse it, the step is cut
  if (!(length <= max_points_per_zone * spacing))
    throw GeometryError("contact zone of length " + std::to_string(length)
                        + " for an element spacing of " + std::to_string(spacing)
                        + ": implausible state");
  std::vector<double> params, weights;
  const beam::GaussLegendre gl = beam::gauss_legendre(2); // the beam's rule, on [-1, 1]
  for (std::size_t k = 0; k + 1 < kept.size(); ++k)
  {
    const double s0 = kept[k], s1 = kept[k + 1], ds = s1 - s0;
    if (ds * length < 1e-9 * spacing)
      continue; // a zone of (next to) no length
    // pieces of about 2 x spacing at most: the default spacing (half an
    // element) gives one piece per element, and keeps giving one when the
    // zone stretches by a hair (a strict bound would double the elements of
    // a zone between two passes for a strain of 1e-9)
    const double pieces = ds * length / (2.0 * spacing);
    const int parts = std::max(1, static_cast<int>(std::ceil(pieces - piece_tolerance)));
    for (int m = 0; m < parts; ++m)
      for (std::size_t gpt = 0; gpt < gl.points.size(); ++gpt)
      {
        const double h = ds / parts;
        params.push_back(s0 + h * (m + 0.5 * (1.0 + gl.points[gpt])));
        weights.push_back(0.5 * h * gl.weights[gpt]);
      }
  }
  return {params, weights};
}

std::vector<ContactPoint> contact_points(const Centrelines& c, const SectionVectors& g,
                                         const ProximityZone& z, double spacing,
                                         double parallel_angle, double delta_factor,
                                         const Eigen::Vector3d& fallback, double wrap_angle,
                                         double kind_bias)
{
  if (!(spacing > 0) or !std::isfinite(spacing))
    throw std::invalid_argument("contact_points: spacing must be positive and finite");
  const bool crossing = is_crossing(c, z, parallel_angle, delta_factor, kind_bias);
  if (crossing and wrap_angle >= 0)
    if (const int wrapping = wrapping_fibre(c, z, wrap_angle, 2 * spacing); wrapping >= 0)
      return wrap_points(c, g, z, wrapping, spacing); // wrap_contact.h
  const double length = intermediate_length(c, z);
  // parameters and contact lengths of the elements on the intermediate geometry
  std::vector<double> params, lengths;
  if (crossing)
  {
    params = {0.5};
    lengths = {crossing_length(c.radius[z.fibre_i], c.radius[z.fibre_j])};
  }
  else
  {
    // Line contact: a composite 2-point Gauss rule between the element
    // boundaries of both fibres (further cut to about `spacing`), each point
    // standing for its share of the length. Uniform penetration then gives
    // contact nodal forces equal to the consistent nodal forces of a uniform
    // line load (the patch test), which collocation at evenly spaced points
    // fails; and the forces do not depend on `spacing`.
    std::vector<double> cuts;
    add_element_cuts(z.a_i, z.b_i, cuts);
    std::vector<double> cuts_j;
    add_element_cuts(z.a_j, z.b_j, cuts_j);
    for (double f : cuts_j)
      cuts.push_back(z.reversed ? 1.0 - f : f);
    std::vector<double> weights;
    std::tie(params, weights) = composite_gauss_rule(std::move(cuts), length, spacing);
    for (double w : weights)
      lengths.push_back(w * length);
  }
  const std::size_t nc = params.size();
  std::vector<ContactPoint> out;
  out.reserve(nc);
  for (std::size_t l = 0; l < nc; ++l)
  {
    ContactPoint p;
    p.fibre_i = z.fibre_i;
    p.fibre_j = z.fibre_j;
    p.parameter = params[l];
    p.crossing = crossing;
    p.length = lengths[l];
    if (crossing)
    {
      // on the centre lines smoothed at their nodes, where Newton moves the
      // crossing's point (closest_points.h)
      std::tie(p.s_i, p.s_j) = closest_points(c, z.fibre_i, z.s_i, z.fibre_j, z.s_j);
      p.tangent = mean_tangent(unit_tangent(c, z.fibre_i, p.s_i),
                               unit_tangent(c, z.fibre_j, p.s_j));
    }
    else
    {
      const double si0 = along(z.a_i, z.b_i, p.parameter), sj0 = z.along_j(p.parameter);
      const Eigen::Vector3d point = intermediate_point(c, z, p.parameter);
      p.tangent = mean_tangent(blended_tangent(c, z.fibre_i, si0), blended_tangent(c, z.fibre_j, sj0));
      p.s_i = section_cut(c, z.fibre_i, point, p.tangent, si0);
      p.s_j = section_cut(c, z.fibre_j, point, p.tangent, sj0);
      // The section plane is orthogonal to the mean of the tangents where it
      // cuts the fibres, not where the zone's linear parametrization puts
      // them (si0, sj0): where that map is not proportional to the arc
      // lengths (a fibre leaving the other, a zone ending at a fibre's end,
      // meshes of different sizes), those tangents differ, the plane and the
      // normal tilted off both fibres, and frictionless contact dragged a
      // fibre sliding over a curved one (stability issue item 8).
      for (int pass = 0; pass < max_section_passes; ++pass)
      {
        const Eigen::Vector3d t = mean_tangent(blended_tangent(c, z.fibre_i, p.s_i),
                                               blended_tangent(c, z.fibre_j, p.s_j));
        const bool settled = (t - p.tangent).norm() < 1e-12;
        p.tangent = t;
        if (settled)
          break;
        p.s_i = section_cut(c, z.fibre_i, point, p.tangent, p.s_i);
        p.s_j = section_cut(c, z.fibre_j, point, p.tangent, p.s_j);
      }
    }
    p.tangent_i = crossing ? unit_tangent(c, z.fibre_i, p.s_i) : blended_tangent(c, z.fibre_i, p.s_i);
    p.tangent_j = crossing ? unit_tangent(c, z.fibre_j, p.s_j) : blended_tangent(c, z.fibre_j, p.s_j);
    // a crossing's points are the smoothed lines' (closest_points)
    p.centroid_gap = crossing ? Eigen::Vector3d(c.smooth_position(z.fibre_i, p.s_i)
                                                - c.smooth_position(z.fibre_j, p.s_j))
                              : Eigen::Vector3d(c.position(z.fibre_i, p.s_i)
                                                - c.position(z.fibre_j, p.s_j));
    // direction from i towards j for particle i, and back for j
    Eigen::Vector3d d = -p.centroid_gap;
    if (d.norm() <= 1e-12 * c.radius[z.fibre_i])
    {
      d = fallback.norm() > 0 ? Eigen::Vector3d(-fallback)
                              : Eigen::Vector3d(p.tangent_i.cross(p.tangent_j));
      if (d.norm() == 0)
        d = p.tangent.unitOrthogonal();
    }
    // End caps are excluded: where the centroid gap runs along a fibre's
    // axis (a fibre end pushed head-on into another fibre) the section
    // border has no point facing the other fibre, so no element is made.
    if (std::abs(d.dot(p.tangent_i)) > end_cap_cosine * d.norm()
        or std::abs(d.dot(p.tangent_j)) > end_cap_cosine * d.norm())
      continue;
    place_particles(c, g, p, d);
    out.push_back(p);
  }
  return out;
}

} // namespace textile::contact
