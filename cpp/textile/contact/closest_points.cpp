#include "closest_points.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace textile::contact
{
namespace
{
/// One abscissa of the search, on [0, end].
struct Abscissa
{
  double value = 0, end = 0; ///< s in [0, end]
  bool locked = false;       ///< at a fibre end where the distance grows inwards
  Eigen::Vector3d derivative = Eigen::Vector3d::Zero(); ///< dx/ds of the smoothed line

  /// The derivative at the abscissa, and whether it is locked at an end
  /// (sign: +1 when r = x - other, -1 when r = other - x).
  void choose(const Centrelines& c, int f, const Eigen::Vector3d& r, double sign)
  {
    derivative = c.smooth_tangent(f, value);
    const double slope = sign * derivative.dot(r); // dphi/ds, phi = |r|^2 / 2
    locked = (value <= 0 and slope >= 0) or (value >= end and slope <= 0);
  }

  /// The step ds, at most half an element, within [0, end].
  double limited(double ds) const
  {
    return std::clamp(value + std::clamp(ds, -0.5, 0.5), 0.0, end) - value;
  }
};
} // namespace

std::pair<double, double> closest_points(const Centrelines& c, int f, double s, int g, double t)
{
  Abscissa u{std::clamp(s, 0.0, double(c.num_elements(f))), double(c.num_elements(f))};
  Abscissa v{std::clamp(t, 0.0, double(c.num_elements(g))), double(c.num_elements(g))};
  for (int it = 0; it < 60; ++it)
  {
    const Eigen::Vector3d r = c.smooth_position(f, u.value) - c.smooth_position(g, v.value);
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
    const Eigen::Vector3d r = c.smooth_position(f, u.value) - point;
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
