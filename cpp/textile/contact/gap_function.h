// The gap of a contact element as a function of its two fibres' unknowns
// within one Newton solve, with its exact gradient and Hessian.
//
// A detection pass (docs/method.md §3) places an element's particles and
// sets its normal N; Newton then sees the gap as a function of the unknowns
// alone. How much of the element's geometry moves with the unknowns is the
// element's *gap kind*. With r = x0_i(u) - x0_j(v) the centre lines' offset
// at the points measured (patch coordinates u, v, particle.h):
//
// - held: u, v at the particles, N fixed (docs/method.md §4.2 as the paper
//   has it):  gap = N . r - h_i - h_j,
//   h = R |(g1.N, g2.N)| the section's extent along N (its support, so a
//   section turning about its axis does not change the gap).
// - following (line contacts): u, v where both centre lines cross one
//   plane normal to t, the pass's intermediate tangent (t . r = 0), moved
//   from the particles by equal and opposite lengths along the fibres
//   (|x0_i'| (u - u0) + s |x0_j'| (v - v0) = 0, the lengths |x0'| of the
//   pass, s = -1 for fibres running against each other, else 1): as the
//   fibres slide along each other by d, the plane moves by
//   d / 2 on each, as the intermediate geometry's would (section 2), and
//   neither fibre is the other's master. The distance is measured in that
//   plane, gap = |P r| - h_i - h_j, P = I - t t^T.
//   Its direction P r / |P r| turns as one fibre rolls around the other,
//   and the point on j slides as the fibres slide along each other. Held,
//   a fibre pressed into the groove between two others slides along the
//   tangent planes of its contacts, the next pass turns the normals after
//   it and the passes swing for ever (a stacked yarn's normals by about
//   10 deg a pass, period 2 or 3); and fibres of a yarn that cross at a
//   few degrees move their pairs of particles by a fraction of an element
//   a pass, with a growing period-2 swing of their forces.
// - facing (crossings, one element at a point): N fixed, (u, v) where the
//   centre lines face each other along N, E^T r = 0 (E = [e1 e2] spans the
//   plane normal to N): a fibre pressed at one point bends and slides, and
//   the point it is pressed at moves with it. Held, the next pass moves it
//   by a fraction of an element, and the contact loop creeps along at a
//   rate near 1 (hundreds of Newton iterations a step on a 3-fibre yarn).
//   The point moves on its patch (particle.h): the element the pass put it
//   on and the neighbour across the nearer node, smoothed to C1 across that
//   node. Where it would leave the patch it stops at the patch's end, and
//   only the other fibre's point moves, to where that fibre crosses the
//   plane through the end spanned by N and the first fibre's tangent t_i
//   of the pass (b . r = 0, b = N x t_i / |N x t_i|): the gap is continuous
//   there (at the end both conditions hold), and the next pass puts the
//   point on a patch around it. Where the projected centre lines run
//   parallel (facing_min_sine) there is no single point: the gap is the
//   held one until the next pass makes the zone a line contact.
// A following point that leaves its patch goes on along the patch's line
// continued straight past its end (PatchShape, C1 there), up to the next
// pass, which puts it on its own element. A stop there kinked the gap's
// gradient: the force turned by several degrees at the end node, and
// Newton cycled between iterates on either side of the kink
// (benchmarks/README.md, "A line contact's point past its patch"). Past
// its fibre's end (Particle::past_fibre_end) there is no fibre: both
// points stop, as held.
// In all kinds the supports are evaluated along N (their dependence on the
// direction is of the order of the sections' ovality) and N is the
// separation's direction (separation < 0: the centre lines have passed
// through each other along N).
//
// Exactness: the gradient and Hessian are those of the gap function
// evaluated, the moving points included (checked against central finite
// differences, cpp/tests/test_gap_function.cpp). With z = (q, w), w the
// moving coordinates, f = [A^T r; B^T (w - w0)] = 0 their conditions (A =
// E, or t with the row B of following's equal lengths), c(r) the centre
// lines' part (N . r or |P r|) and lambda = f_w^-T g_w (lambda_A its part
// on the rows A^T r):
//     dgap/dq = r_q^T m - h_q,  m = grad c - A lambda_A,
// and the Hessian is that of L = g - lambda . f on the implicit motion
// w_q = -f_w^-1 f_q: L_qq + L_qw w_q + w_q^T L_wq + w_q^T L_ww w_q, where
// L_zz = r_z^T (hess c) r_z + m . r_zz - h_zz.
#pragma once

#include "particle.h"
#include "tolerances.h"

#include <Eigen/Dense>

#include <array>
#include <span>

namespace textile::contact
{

/// How an element's gap moves with the unknowns within Newton (above).
enum class GapKind : int
{
  held = 0,
  following = 1,
  facing = 2
};

/// An element's gap kind and what it needs.
struct GapMotion
{
  GapKind kind = GapKind::held;
  /// the two centre lines' derivatives dx0/dxi where the pass placed the
  /// particles (following: the section plane is normal to the mean of
  /// their directions, and their lengths weigh the points' motion; facing:
  /// the directions of the planes a point stopped at its patch's end
  /// projects along)
  Eigen::Vector3d tangent_i = Eigen::Vector3d::Zero(), tangent_j = Eigen::Vector3d::Zero();
};

/// The gap of one element at the unknowns xi, xj (9 per node of each
/// side's patch, particle.h: [patch i, patch j]) and, if asked, its
/// derivatives.
class GapFunction
{
public:
  /// @param gap_offset  constant added to the gap and separation (the
  ///                    weaving stage's, contact_set.h)
  /// @param derivatives compute the gradient (and keep what add_hessian needs)
  GapFunction(const Particle& pi, const Particle& pj, const Eigen::Vector3d& N,
              const GapMotion& motion, std::span<const double> xi,
              std::span<const double> xj, double gap_offset, bool derivatives);

  double gap() const { return _gap; }
  double separation() const { return _separation; }
  /// d gap / d [q_i, q_j] (derivatives only)
  const Eigen::VectorXd& gradient() const { return _G; }
  /// The patch coordinates the gap is measured at.
  double patch_xi_i() const { return _w[0]; }
  double patch_xi_j() const { return _w[1]; }

  /// K += scale x (Hessian of the gap), K row-major n x n (derivatives
  /// only). `motion` false: without the terms of the points' motion (those
  /// with w_q), as if the points were held where they are.
  void add_hessian(double scale, Eigen::Ref<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic,
                                                          Eigen::RowMajor>> K,
                   bool motion = true) const;

private:
  Particle _pi, _pj;
  Eigen::Vector3d _N;
  GapMotion _motion;
  std::span<const double> _xi, _xj;
  std::size_t _off_j = 0, _n = 0;
  std::array<double, 2> _w{0, 0};         // (u, v)
  std::array<bool, 2> _free{false, false}; // which of them move with q
  Eigen::MatrixXd _A;                      // 3 x rows of the conditions A^T r = 0
  Eigen::RowVector2d _B = Eigen::RowVector2d::Zero(); // following: B (w - w0) = 0
  double _gap = 0, _separation = 0;
  Eigen::VectorXd _G;
  // the centre lines' part: its gradient and Hessian in r
  Eigen::Vector3d _grad_c = Eigen::Vector3d::Zero();
  Eigen::Matrix3d _hess_c = Eigen::Matrix3d::Zero();
  Eigen::Vector3d _m = Eigen::Vector3d::Zero(); // grad c - A lambda
  Eigen::MatrixXd _wq;                          // w_q (moving x n)
};

} // namespace textile::contact
