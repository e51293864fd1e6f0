#include "vertical_crossing.h"

#include <Eigen/Dense>

#include <cmath>

namespace textile::contact
{

bool facing_crossing(const Centrelines& c, ContactPoint& p, const Eigen::Vector3d& n)
{
  // an orthonormal basis (e1, e2) of the plane normal to n
  const Eigen::Vector3d e1 = n.unitOrthogonal(), e2 = n.cross(e1);
  double si = p.s_i, sj = p.s_j;
  const double ni = c.num_elements(p.fibre_i), nj = c.num_elements(p.fibre_j);
  for (int it = 0; it < 20; ++it)
  {
    const Eigen::Vector3d d = c.smooth_position(p.fibre_i, si) - c.smooth_position(p.fibre_j, sj);
    const Eigen::Vector3d ti = c.smooth_tangent(p.fibre_i, si), tj = c.smooth_tangent(p.fibre_j, sj);
    Eigen::Matrix2d J;
    J << e1.dot(ti), -e1.dot(tj), e2.dot(ti), -e2.dot(tj);
    const double pi = std::hypot(e1.dot(ti), e2.dot(ti)), pj = std::hypot(e1.dot(tj), e2.dot(tj));
    if (std::abs(J.determinant()) < 0.1 * pi * pj)
      return false; // near-parallel projections: no single crossing point
    const Eigen::Vector2d step = J.partialPivLu().solve(-Eigen::Vector2d(e1.dot(d), e2.dot(d)));
    si += step(0);
    sj += step(1);
    if (si < 0 or si > ni or sj < 0 or sj > nj)
      return false;
    if (step.norm() < 1e-12)
      break;
  }
  p.s_i = si;
  p.s_j = sj;
  // the facing point moves across nodes from pass to pass, and a crossing
  // kinks the fibres at the node under it: the point is searched on the
  // lines smoothed there, as Newton's facing point (gap_function.h), and
  // the tangents are blended across the kink, or the crossing normal would
  // jump by the kink angle between passes. (The smoothed line's own
  // tangent turns 1.5 times as fast at the node: a picture frame of
  // monofilaments 4 widths apart then folded an element at 20 deg,
  // tests/virtual/test_picture_frame.py.)
  p.tangent_i = blended_tangent(c, p.fibre_i, si);
  p.tangent_j = blended_tangent(c, p.fibre_j, sj);
  p.centroid_gap = c.smooth_position(p.fibre_i, si) - c.smooth_position(p.fibre_j, sj);
  return true;
}

bool vertical_crossing(const Centrelines& c, ContactPoint& p)
{
  return facing_crossing(c, p, Eigen::Vector3d::UnitZ());
}

} // namespace textile::contact
