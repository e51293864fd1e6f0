#include "centreline.h"
#include "../geometry_error.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace textile::contact
{

namespace
{
/// Lagrange shape functions (values and d/dxi) of a 2- or 3-node element,
/// the same as the beam element's.
void shape(int order, double xi, double n[3], double dn[3])
{
  if (order == 1)
  {
    n[0] = 0.5 * (1.0 - xi);
    n[1] = 0.5 * (1.0 + xi);
    dn[0] = -0.5;
    dn[1] = 0.5;
  }
  else
  {
    n[0] = 0.5 * xi * (xi - 1.0);
    n[1] = 1.0 - xi * xi;
    n[2] = 0.5 * xi * (xi + 1.0);
    dn[0] = xi - 0.5;
    dn[1] = -2.0 * xi;
    dn[2] = xi + 0.5;
  }
}

Eigen::Vector3d node(const Centrelines& c, std::int64_t n)
{
  return {c.x[3 * n], c.x[3 * n + 1], c.x[3 * n + 2]};
}

/// Element number and local coordinate xi of abscissa s on fibre f.
std::pair<int, double> locate(const Centrelines& c, int f, double s)
{
  const int ne = c.num_elements(f);
  if (!(s >= 0.0 && s <= ne))
    throw std::invalid_argument("Centrelines: abscissa s = " + std::to_string(s)
                                + " is outside [0, " + std::to_string(ne) + "] of fibre "
                                + std::to_string(f));
  const int e = std::min(static_cast<int>(std::floor(s)), ne - 1);
  return {e, 2.0 * (s - e) - 1.0};
}

/// Sum over element e of fibre f's nodes of the shape functions (or, with
/// `derivative`, of d/ds = 2 d/dxi) at local coordinate xi (continued past
/// [-1, 1]) times the nodes: the point (dx0/ds) there.
Eigen::Vector3d element_sum(const Centrelines& c, int f, int e, double xi, bool derivative)
{
  double n[3], dn[3];
  shape(c.order, xi, n, dn);
  const std::int64_t first = c.fibre_offsets[f] + static_cast<std::int64_t>(c.order) * e;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (int a = 0; a <= c.order; ++a)
    p += (derivative ? 2.0 * dn[a] : n[a]) * node(c, first + a);
  return p;
}

Eigen::Vector3d element_point(const Centrelines& c, int f, int e, double xi)
{
  return element_sum(c, f, e, xi, false);
}

Eigen::Vector3d element_tangent(const Centrelines& c, int f, int e, double xi)
{
  return element_sum(c, f, e, xi, true);
}
} // namespace

void Centrelines::validate() const
{
  if (order != 1 && order != 2)
    throw std::invalid_argument("Centrelines: order must be 1 or 2, got " + std::to_string(order));
  if (x.size() % 3 != 0)
    throw std::invalid_argument("Centrelines: x must hold 3 coordinates per node, got "
                                + std::to_string(x.size()) + " values");
  if (fibre_offsets.size() < 2)
    throw std::invalid_argument("Centrelines: fibre_offsets needs nfib+1 >= 2 entries");
  if (fibre_offsets.front() != 0)
    throw std::invalid_argument("Centrelines: fibre_offsets must start at 0");
  const auto num_nodes = static_cast<std::int64_t>(x.size() / 3);
  if (fibre_offsets.back() != num_nodes)
    throw std::invalid_argument("Centrelines: fibre_offsets ends at "
                                + std::to_string(fibre_offsets.back()) + " but x holds "
                                + std::to_string(num_nodes) + " nodes");
  const std::size_t nfib = fibre_offsets.size() - 1;
  if (radius.size() != nfib)
    throw std::invalid_argument("Centrelines: radius has " + std::to_string(radius.size())
                                + " entries for " + std::to_string(nfib) + " fibres");
  for (std::size_t f = 0; f < nfib; ++f)
  {
    const std::int64_t n = fibre_offsets[f + 1] - fibre_offsets[f];
    if (n < order + 1 || (n - 1) % order != 0)
      throw std::invalid_argument("Centrelines: fibre " + std::to_string(f) + " has "
                                  + std::to_string(n) + " nodes, not a whole number (>= 1) of "
                                  + "elements of order " + std::to_string(order));
    if (!(std::isfinite(radius[f]) && radius[f] > 0.0))
      throw std::invalid_argument("Centrelines: radius of fibre " + std::to_string(f)
                                  + " must be finite and > 0, got " + std::to_string(radius[f]));
  }
  // a state's coordinates, not the caller's input: a diverged iterate is a
  // domain error (the step is cut), not a bug
  if (!present.empty() and present.size() != nfib)
    throw std::invalid_argument("Centrelines: present has " + std::to_string(present.size())
                                + " flags for " + std::to_string(nfib) + " fibres");
  for (std::size_t f = 0; f < nfib; ++f)
  {
    if (!has(static_cast<int>(f)))
      continue;
    for (auto i = 3 * fibre_offsets[f]; i < 3 * fibre_offsets[f + 1]; ++i)
      if (!std::isfinite(x[i]))
        throw GeometryError("Centrelines: coordinate " + std::to_string(i % 3) + " of node "
                            + std::to_string(i / 3) + " is NaN or infinite");
  }
}

int Centrelines::num_fibres() const { return static_cast<int>(fibre_offsets.size()) - 1; }

int Centrelines::num_elements(int f) const
{
  if (f < 0 || f >= num_fibres())
    throw std::invalid_argument("Centrelines: fibre " + std::to_string(f) + " does not exist");
  return static_cast<int>((fibre_offsets[f + 1] - fibre_offsets[f] - 1) / order);
}

Eigen::Vector3d Centrelines::position(int f, double s) const
{
  const auto [e, xi] = locate(*this, f, s);
  return element_point(*this, f, e, xi);
}

Eigen::Vector3d Centrelines::tangent_left(int f, double s) const
{
  const auto [e, xi] = locate(*this, f, s);
  if (xi == -1.0 and e > 0) // an interior node: the element before it
    return element_tangent(*this, f, e - 1, 1.0);
  return element_tangent(*this, f, e, xi);
}

Eigen::Vector3d Centrelines::tangent(int f, double s) const
{
  const auto [e, xi] = locate(*this, f, s);
  return element_tangent(*this, f, e, xi);
}

namespace
{
/// The smoothed line's point and d/ds at s (Centrelines::smooth_position).
std::pair<Eigen::Vector3d, Eigen::Vector3d> smoothed(const Centrelines& c, int f, double s)
{
  const auto [e, xi] = locate(c, f, s);
  const double node = std::round(s);
  const double w = patch_smoothing;
  if (node <= 0 or node >= c.num_elements(f) or std::abs(s - node) >= w)
    return {element_point(c, f, e, xi), element_tangent(c, f, e, xi)};
  const int n = static_cast<int>(node);
  const double tau = (s - (node - w)) / (2.0 * w);
  const double phi = tau * tau * (3.0 - 2.0 * tau), dphi = 6.0 * tau * (1.0 - tau) / (2.0 * w);
  const double xi_left = 2.0 * (s - (n - 1)) - 1.0, xi_right = 2.0 * (s - n) - 1.0;
  const Eigen::Vector3d a = element_point(c, f, n - 1, xi_left), b = element_point(c, f, n, xi_right);
  const Eigen::Vector3d da = element_tangent(c, f, n - 1, xi_left);
  const Eigen::Vector3d db = element_tangent(c, f, n, xi_right);
  return {(1.0 - phi) * a + phi * b, (1.0 - phi) * da + phi * db + dphi * (b - a)};
}
} // namespace

Eigen::Vector3d Centrelines::smooth_position(int f, double s) const
{
  return smoothed(*this, f, s).first;
}

Eigen::Vector3d Centrelines::smooth_tangent(int f, double s) const
{
  return smoothed(*this, f, s).second;
}

std::vector<Segment> make_segments(const Centrelines& c)
{
  c.validate();
  std::vector<Segment> segs;
  segs.reserve(c.x.size() / 3);
  for (int f = 0; f < c.num_fibres(); ++f)
  {
    if (!c.has(f))
      continue;
    const int ne = c.num_elements(f);
    double arc = 0.0;
    for (int e = 0; e < ne; ++e)
    {
      const std::int64_t first = c.fibre_offsets[f] + static_cast<std::int64_t>(c.order) * e;
      double sag = 0.0;
      if (c.order == 2)
        sag = (node(c, first) - 2.0 * node(c, first + 1) + node(c, first + 2)).norm() / 8.0;
      for (int k = 0; k < c.order; ++k)
      {
        Segment g;
        g.fibre = f;
        g.index = c.order * e + k;
        g.s0 = e + static_cast<double>(k) / c.order;
        g.s1 = e + static_cast<double>(k + 1) / c.order;
        g.p0 = node(c, first + k);
        g.p1 = node(c, first + k + 1);
        g.arc0 = arc;
        arc += (g.p1 - g.p0).norm();
        g.arc1 = arc;
        g.sag = sag;
        segs.push_back(g);
      }
    }
  }
  return segs;
}

} // namespace textile::contact
