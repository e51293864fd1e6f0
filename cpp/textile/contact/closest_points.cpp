#include "closest_points.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace textile::contact
{
namespace
{
/// One abscissa of the search, with the element interval a step may not
/// leave.
struct Abscissa
{
  double value = 0, end = 0; ///< s in [0, end]
  bool locked = false;       ///< at a node or a fibre end where the distance grows both ways
  Eigen::Vector3d derivative = Eigen::Vector3d::Zero(); ///< dx/ds on the side the search goes

  /// Choose the side from the derivative of phi = |r|^2 / 2 along each
  /// side (sign: +1 when r = x - other, -1 when r = other - x).
  void choose(const Centrelines& c, int f, const Eigen::Vector3d& r, double sign)
  {
    const Eigen::Vector3d right = c.tangent(f, value), left = c.tangent_left(f, value);
    const double up = sign * right.dot(r), down = sign * left.dot(r); // dphi/ds each side
    const bool at_node = value == std::floor(value);
    const bool grows_right = value >= end or up >= 0;   // phi grows (or the fibre ends) going right
    const bool grows_left = value <= 0 or down <= 0;    // phi grows (or the fibre ends) going left
    locked = at_node and grows_right and grows_left;
    derivative = at_node and !grows_left and (grows_right or down > -up) ? left : right;
  }

  /// The step ds, kept within the element the search is in (or enters).
  double limited(double ds) const
  {
    const double lo = ds < 0 ? std::ceil(value) - 1.0 : std::floor(value);
    return std::clamp(value + ds, std::max(lo, 0.0), std::min(lo + 1.0, end)) - value;
  }
};
} // namespace

std::pair<double, double> closest_points(const Centrelines& c, int f, double s, int g, double t)
{
  Abscissa u{std::clamp(s, 0.0, double(c.num_elements(f))), double(c.num_elements(f))};
  Abscissa v{std::clamp(t, 0.0, double(c.num_elements(g))), double(c.num_elements(g))};
  for (int it = 0; it < 60; ++it)
  {
    const Eigen::Vector3d r = c.position(f, u.value) - c.position(g, v.value);
    u.choose(c, f, r, 1.0);
    v.choose(c, g, r, -1.0);
    const Eigen::Vector3d& a = u.derivative;
    const Eigen::Vector3d b = -v.derivative;
    // Gauss-Newton on the abscissas that are not locked
    double ds = 0, dt = 0;
    if (!u.locked and !v.locked)
    {
      Eigen::Matrix2d JtJ;
      JtJ << a.dot(a), a.dot(b), a.dot(b), b.dot(b);
      if (std::abs(JtJ.determinant()) <= 1e-12 * JtJ.trace() * JtJ.trace())
        break; // parallel tangents: no unique closest pair
      const Eigen::Vector2d d = JtJ.ldlt().solve(Eigen::Vector2d(-a.dot(r), -b.dot(r)));
      ds = d(0);
      dt = d(1);
    }
    else if (!u.locked)
      ds = -a.dot(r) / a.dot(a);
    else if (!v.locked)
      dt = -b.dot(r) / b.dot(b);
    ds = u.limited(ds);
    dt = v.limited(dt);
    u.value += ds;
    v.value += dt;
    if (std::abs(ds) + std::abs(dt) < 1e-13)
      break;
  }
  return {u.value, v.value};
}
double project_onto(const Centrelines& c, int f, const Eigen::Vector3d& point, double s)
{
  Abscissa u{std::clamp(s, 0.0, double(c.num_elements(f))), double(c.num_elements(f))};
  for (int it = 0; it < 60; ++it)
  {
    const Eigen::Vector3d r = c.position(f, u.value) - point;
    u.choose(c, f, r, 1.0);
    if (u.locked)
      break;
    const Eigen::Vector3d& a = u.derivative;
    const double ds = u.limited(-a.dot(r) / a.dot(a));
    u.value += ds;
    if (std::abs(ds) < 1e-13)
      break;
  }
  return u.value;
}
} // namespace textile::contact
