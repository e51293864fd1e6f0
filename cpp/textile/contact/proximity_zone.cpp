#include "proximity_zone.h"

#include "broad_phase.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <tuple>

namespace textile::contact
{

namespace
{
using Vec3 = Eigen::Vector3d;

double clamp01(double v) { return std::clamp(v, 0.0, 1.0); }

/// Distance from point x to segment [q0, q1].
double point_segment_distance(const Vec3& x, const Vec3& q0, const Vec3& q1)
{
  const Vec3 d = q1 - q0;
  const double dd = d.squaredNorm();
  const double u = dd > 0.0 ? clamp01(d.dot(x - q0) / dd) : 0.0;
  return (q0 + u * d - x).norm();
}

/// Parameter interval of [p0, p1] whose points are closer than `limit` to
/// [q0, q1], given a minimiser t_min of that distance. The distance is convex
/// in t, so the set is one interval around t_min; each end is the root of
/// the piecewise quadratic f(t) = dist^2 - limit^2 in its bracket, found by
/// the Illinois (modified regula falsi) method: always bracketed, and
/// superlinear, so about ten distance evaluations instead of ~50 bisections.
std::pair<double, double> close_part(const Vec3& p0, const Vec3& p1, const Vec3& q0,
                                     const Vec3& q1, double t_min, double limit)
{
  auto f = [&](double t)
  {
    const double g = point_segment_distance(p0 + t * (p1 - p0), q0, q1);
    return g * g - limit * limit;
  };
  const double f_min = f(t_min);
  if (!(f_min < 0.0)) // borderline pair: keep the closest point only
    return {t_min, t_min};
  auto edge = [&](double outside)
  {
    const double f_out = f(outside);
    if (f_out < 0.0)
      return outside;
    double in = t_min, out = outside;
    double fi = f_min, fo = f_out;           // weights of the secant (Illinois-scaled)
    double fi_true = f_min, fo_true = f_out; // function values at in, out
    int side = 0;
    for (int it = 0; it < 100 && std::abs(out - in) > 1e-15; ++it)
    {
      double t = (in * fo - out * fi) / (fo - fi);
      if (!(t > std::min(in, out) && t < std::max(in, out)))
        t = 0.5 * (in + out);
      const double ft = f(t);
      if (ft < 0.0)
      {
        in = t;
        fi = fi_true = ft;
        if (side == -1)
          fo *= 0.5;
        side = -1;
      }
      else
      {
        out = t;
        fo = fo_true = ft;
        if (ft == 0.0)
          break;
        if (side == 1)
          fi *= 0.5;
        side = 1;
      }
    }
    // the end nearer the root (regula falsi may keep one end far behind)
    return std::abs(fi_true) <= std::abs(fo_true) ? in : out;
  };
  return {edge(0.0), edge(1.0)};
}

void check_parameters(double delta_factor, double self_exclusion)
{
  if (!(std::isfinite(delta_factor) && delta_factor > 0.0))
    throw std::invalid_argument("proximity zones: delta_factor must be finite and > 0, got "
                                + std::to_string(delta_factor));
  if (std::isnan(self_exclusion) || self_exclusion < 0.0)
    throw std::invalid_argument("proximity zones: self_exclusion must be >= 0 (a length), got "
                                + std::to_string(self_exclusion));
}

/// Union-find root with path halving.
int root(std::vector<int>& parent, int a)
{
  while (parent[a] != a)
    a = parent[a] = parent[parent[a]];
  return a;
}
} // namespace

SegmentDistance segment_distance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1)
{
  // Ericson, Real-Time Collision Detection, 5.1.9, with a relative
  // parallelism test so that nearly parallel segments take the parallel
  // branch instead of dividing by a round-off-sized determinant.
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double t = 0.0, u = 0.0;
  if (a == 0.0 && e == 0.0)
  {
    t = u = 0.0;
  }
  else if (a == 0.0)
  {
    u = clamp01(f / e);
  }
  else
  {
    const double c = d1.dot(r);
    if (e == 0.0)
      t = clamp01(-c / a);
    else
    {
      const double b = d1.dot(d2);
      const double denom = a * e - b * b;
      t = denom > 1e-14 * a * e ? clamp01((b * f - c * e) / denom) : 0.0;
      u = (b * t + f) / e;
      if (u < 0.0)
      {
        u = 0.0;
        t = clamp01(-c / a);
      }
      else if (u > 1.0)
      {
        u = 1.0;
        t = clamp01((b - c) / a);
      }
    }
  }
  return {(p0 + t * d1 - q0 - u * d2).norm(), t, u};
}

std::optional<ClosePair> close_pair(const Centrelines& c, std::span<const Segment> segments,
                                    int seg_i, int seg_j, double delta_factor)
{
  const Segment& A = segments[seg_i];
  const Segment& B = segments[seg_j];
  const double limit = delta_factor * (c.radius[A.fibre] + c.radius[B.fibre]) + A.sag + B.sag;
  const SegmentDistance sd = segment_distance(A.p0, A.p1, B.p0, B.p1);
  if (!(sd.distance < limit))
    return std::nullopt;
  ClosePair p;
  p.seg_i = seg_i;
  p.seg_j = seg_j;
  p.distance = sd.distance;
  auto abscissa = [](const Segment& g, double t) { return g.s0 + t * (g.s1 - g.s0); };
  p.s_i = abscissa(A, sd.t);
  p.s_j = abscissa(B, sd.u);
  const auto [ti0, ti1] = close_part(A.p0, A.p1, B.p0, B.p1, sd.t, limit);
  const auto [tj0, tj1] = close_part(B.p0, B.p1, A.p0, A.p1, sd.u, limit);
  p.lo_i = abscissa(A, ti0);
  p.hi_i = abscissa(A, ti1);
  p.lo_j = abscissa(B, tj0);
  p.hi_j = abscissa(B, tj1);
  return p;
}

std::vector<ClosePair> find_close_pairs(const Centrelines& c, std::span<const Segment> segments,
                                        double delta_factor, double self_exclusion)
{
  check_parameters(delta_factor, self_exclusion);
  c.validate();
  std::vector<double> reach(segments.size());
  for (std::size_t s = 0; s < segments.size(); ++s)
  {
    if (segments[s].fibre < 0 || segments[s].fibre >= c.num_fibres())
      throw std::invalid_argument("find_close_pairs: segment " + std::to_string(s)
                                  + " names a fibre that does not exist");
    // half of the search distance delta (r_i + r_j), plus this chord's sag
    reach[s] = delta_factor * c.radius[segments[s].fibre] + segments[s].sag;
  }
  std::vector<ClosePair> out;
  for (const auto& [i, j] : find_candidate_pairs(segments, reach, self_exclusion))
    if (auto p = close_pair(c, segments, i, j, delta_factor))
      out.push_back(*p);
  return out; // candidates come sorted, so the close pairs are too
}

std::vector<ProximityZone> group_into_zones(std::span<const Segment> segments,
                                            std::span<const ClosePair> input)
{
  auto by_segments = [](const ClosePair& x, const ClosePair& y)
  { return std::tie(x.seg_i, x.seg_j) < std::tie(y.seg_i, y.seg_j); };
  std::vector<ClosePair> copy;
  std::span<const ClosePair> pairs = input;
  if (!std::is_sorted(input.begin(), input.end(), by_segments))
  {
    copy.assign(input.begin(), input.end());
    std::sort(copy.begin(), copy.end(), by_segments);
    pairs = copy;
  }
  const int n = static_cast<int>(pairs.size());
  auto same_fibre = [&](int a, int b) { return segments[a].fibre == segments[b].fibre; };

  // Union-find over the 8-neighbourhood in (seg_i, seg_j), walking rows of
  // equal seg_i: (a, b) links to (a, b+1) in its row and to (a+1, b-1..b+1)
  // in the next row (the other half of the neighbours link back), with a
  // two-pointer sweep, so grouping is linear in the number of close pairs.
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  auto join = [&](int p, int q) { parent[root(parent, q)] = root(parent, p); };
  for (int row = 0; row < n;)
  {
    int row_end = row + 1;
    while (row_end < n && pairs[row_end].seg_i == pairs[row].seg_i)
      ++row_end;
    const int a = pairs[row].seg_i;
    const bool next_row = row_end < n && pairs[row_end].seg_i == a + 1 && same_fibre(a, a + 1);
    int next_end = row_end;
    while (next_row && next_end < n && pairs[next_end].seg_i == a + 1)
      ++next_end;
    int q = row_end;
    for (int p = row; p < row_end; ++p)
    {
      const int b = pairs[p].seg_j;
      if (p + 1 < row_end && pairs[p + 1].seg_j == b + 1 && same_fibre(b, b + 1))
        join(p, p + 1);
      if (!next_row)
        continue;
      while (q < next_end && pairs[q].seg_j < b - 1)
        ++q;
      for (int r = q; r < next_end && pairs[r].seg_j <= b + 1; ++r)
        if (same_fibre(b, pairs[r].seg_j))
          join(p, r);
    }
    row = row_end;
  }

  std::vector<int> zone_of(n, -1);
  std::vector<ProximityZone> zones;
  for (int p = 0; p < n; ++p)
  {
    const ClosePair& cp = pairs[p];
    const int r = root(parent, p);
    if (zone_of[r] < 0)
    {
      zone_of[r] = static_cast<int>(zones.size());
      ProximityZone z;
      z.fibre_i = segments[cp.seg_i].fibre;
      z.fibre_j = segments[cp.seg_j].fibre;
      z.a_i = cp.lo_i;
      z.b_i = cp.hi_i;
      z.a_j = cp.lo_j;
      z.b_j = cp.hi_j;
      z.min_distance = cp.distance;
      z.s_i = cp.s_i;
      z.s_j = cp.s_j;
      zones.push_back(z);
      continue;
    }
    ProximityZone& z = zones[zone_of[r]];
    z.a_i = std::min(z.a_i, cp.lo_i);
    z.b_i = std::max(z.b_i, cp.hi_i);
    z.a_j = std::min(z.a_j, cp.lo_j);
    z.b_j = std::max(z.b_j, cp.hi_j);
    if (cp.distance < z.min_distance)
    {
      z.min_distance = cp.distance;
      z.s_i = cp.s_i;
      z.s_j = cp.s_j;
    }
  }
  std::sort(zones.begin(), zones.end(),
            [](const ProximityZone& x, const ProximityZone& y)
            {
              return std::tie(x.fibre_i, x.fibre_j, x.a_i, x.a_j, x.b_i, x.b_j)
                     < std::tie(y.fibre_i, y.fibre_j, y.a_i, y.a_j, y.b_i, y.b_j);
            });
  return zones;
}

std::vector<ProximityZone> find_proximity_zones(const Centrelines& c, double delta_factor,
                                                double self_exclusion)
{
  check_parameters(delta_factor, self_exclusion);
  const std::vector<Segment> segments = make_segments(c);
  const std::vector<ClosePair> pairs = find_close_pairs(c, segments, delta_factor, self_exclusion);
  std::vector<ProximityZone> zones = group_into_zones(segments, pairs);
  // the legs of a hairpin, or a fibre looping back along another, run
  // against each other: pairing a_i with a_j folds the intermediate
  // geometry onto one point (all of a self-contact's elements at one place)
  for (ProximityZone& z : zones)
    z.reversed = c.tangent(z.fibre_i, z.s_i).dot(c.tangent(z.fibre_j, z.s_j)) < 0;
  return zones;
}

} // namespace textile::contact
