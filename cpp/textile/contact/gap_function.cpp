#include "gap_function.h"
#include "../node_unknowns.h"
#include "../geometry_error.h"
#include "intermediate_geometry.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace textile::contact
{
namespace
{

/// Newton on the moving points: at most this many iterations, converged
/// when the step in patch coordinates is below point_tolerance.
constexpr int point_iterations = 30;
constexpr double point_tolerance = 1e-13;

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// One side of the element at patch coordinate xi (particle.h): its
/// centroid and the section's support along N, with their derivatives in xi.
struct Side
{
  int num_nodes = 0; ///< of the patch
  double radius = 0;
  PatchShape shape;
  Eigen::Vector3d x = Eigen::Vector3d::Zero(), dx = Eigen::Vector3d::Zero(),
                  ddx = Eigen::Vector3d::Zero();
  Eigen::Vector2d c = Eigen::Vector2d::Zero(), dc = Eigen::Vector2d::Zero(),
                  ddc = Eigen::Vector2d::Zero(); ///< (g1.N, g2.N) and derivatives
  double norm_c = 0; ///< |c|; 0 when the section is edge-on to N (no support)
  double h = 0;      ///< R |c|

  Side(const Particle& p, double xi, std::span<const double> q, const Eigen::Vector3d& N)
      : num_nodes(p.patch_nodes()), radius(p.radius), shape(p, xi)
  {
    Eigen::Vector3d g[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    for (int a = 0; a < num_nodes; ++a)
    {
      const Eigen::Map<const Eigen::Vector3d> X(q.data() + dofs_per_node * a);
      x += shape.n[a] * X;
      dx += shape.dn[a] * X;
      ddx += shape.ddn[a] * X;
      for (int al = 0; al < 2; ++al)
      {
        const Eigen::Map<const Eigen::Vector3d> ga(q.data() + dofs_per_node * a + 3 + 3 * al);
        g[al] += shape.n[a] * ga;
        c(al) += shape.n[a] * ga.dot(N);
        dc(al) += shape.dn[a] * ga.dot(N);
        ddc(al) += shape.ddn[a] * ga.dot(N);
      }
    }
    // a section edge-on to N has no extent along it, and no direction to
    // differentiate
    norm_c = c.norm() < 1e-12 * (g[0].norm() + g[1].norm()) ? 0.0 : c.norm();
    h = radius * norm_c;
  }

  Eigen::Vector2d unit_c() const
  {
    return norm_c > 0 ? Eigen::Vector2d(c / norm_c) : Eigen::Vector2d::Zero();
  }
  /// d(c / |c|) / dxi
  Eigen::Vector2d d_unit_c() const
  {
    if (norm_c == 0)
      return Eigen::Vector2d::Zero();
    const Eigen::Vector2d ch = unit_c();
    return (dc - ch * ch.dot(dc)) / norm_c;
  }
  /// dh/dxi and d2h/dxi2
  double h_u() const { return norm_c > 0 ? radius * unit_c().dot(dc) : 0.0; }
  double h_uu() const
  {
    if (norm_c == 0)
      return 0.0;
    const double along = unit_c().dot(dc);
    return radius * (unit_c().dot(ddc) + (dc.squaredNorm() - along * along) / norm_c);
  }
};

/// K += scale x (minus the support's Hessian in the section unknowns at
/// fixed xi): -R n_a n_b (I/|c| - c c^T/|c|^3)_{al be} N N^T.
void add_support_hessian(const Side& s, const Eigen::Vector3d& N, double scale, std::size_t offset,
                         Eigen::Ref<RowMajor> K)
{
  if (s.norm_c == 0)
    return;
  const double nc = s.norm_c;
  const Eigen::Matrix2d M
      = -scale * s.radius
        * (Eigen::Matrix2d::Identity() / nc - s.c * s.c.transpose() / (nc * nc * nc));
  const Eigen::Matrix3d NN = N * N.transpose();
  for (int a = 0; a < s.num_nodes; ++a)
    for (int b = 0; b < s.num_nodes; ++b)
      for (int al = 0; al < 2; ++al)
        for (int be = 0; be < 2; ++be)
          K.block<3, 3>(offset + dofs_per_node * a + 3 + 3 * al,
                        offset + dofs_per_node * b + 3 + 3 * be)
              += s.shape.n[a] * s.shape.n[b] * M(al, be) * NN;
}

/// The moving coordinates (free[0]: u on fibre i, free[1]: v on fibre j)
/// and their conditions: A^T r = 0 (A: 3 x rows), and with `metric` the
/// row B (w - w0) = 0 (B = metric; following's equal lengths).
struct Motion
{
  std::array<bool, 2> free{false, false};
  Eigen::MatrixXd A;
  bool metric = false;
  Eigen::RowVector2d B = Eigen::RowVector2d::Zero();
  std::array<double, 2> w0{0, 0};
  int size() const { return int(free[0]) + int(free[1]); }

  /// r_w: 3 x (number moving), dr/du = x_i', dr/dv = -x_j'.
  Eigen::MatrixXd r_w(const Side& si, const Side& sj) const
  {
    Eigen::MatrixXd R(3, size());
    int col = 0;
    if (free[0])
      R.col(col++) = si.dx;
    if (free[1])
      R.col(col++) = -sj.dx;
    return R;
  }
  /// f (rows: A^T r, then B (w - w0)).
  Eigen::VectorXd f(const Side& si, const Side& sj, const std::array<double, 2>& w) const
  {
    Eigen::VectorXd out(A.cols() + (metric ? 1 : 0));
    out.head(A.cols()) = A.transpose() * (si.x - sj.x);
    if (metric)
      out(A.cols()) = B(0) * (w[0] - w0[0]) + B(1) * (w[1] - w0[1]);
    return out;
  }
  /// f_w (rows of f, columns the moving coordinates)
  Eigen::MatrixXd f_w(const Side& si, const Side& sj) const
  {
    Eigen::MatrixXd J(A.cols() + (metric ? 1 : 0), size());
    J.topRows(A.cols()) = A.transpose() * r_w(si, sj);
    if (metric)
    {
      int col = 0;
      for (int side = 0; side < 2; ++side)
        if (free[side])
          J(A.cols(), col++) = B(side);
    }
    return J;
  }
};

/// Solve A^T r = 0 for the moving coordinates w (in place), by Newton from
/// their current values. False (w unchanged) when the conditions are (close
/// to) singular (min_sine: |det f_w| relative to the product of its
/// columns' norms) or the iteration does not converge.
bool solve_points(const Motion& mo, const Particle& pi, const Particle& pj, std::array<double, 2>& w,
                  std::span<const double> xi, std::span<const double> xj, const Eigen::Vector3d& N,
                  double min_sine)
{
  if (mo.size() == 0)
    return true;
  std::array<double, 2> wk = w;
  for (int it = 0; it < point_iterations; ++it)
  {
    const Side si(pi, wk[0], xi, N), sj(pj, wk[1], xj, N);
    const Eigen::VectorXd f = mo.f(si, sj, wk);
    const Eigen::MatrixXd J = mo.f_w(si, sj);
    double scale = 1;
    for (int k = 0; k < J.cols(); ++k)
      scale *= J.col(k).norm();
    const double det = J.determinant();
    if (det == 0 or !(std::abs(det) >= min_sine * scale))
      return false;
    const Eigen::VectorXd step = -J.partialPivLu().solve(f);
    int k = 0;
    for (int side = 0; side < 2; ++side)
      if (mo.free[side])
        wk[side] += step(k++);
    if (!std::isfinite(wk[0]) or !std::isfinite(wk[1]))
      return false;
    if (step.norm() < point_tolerance)
    {
      w = wk;
      return true;
    }
  }
  return false;
}

bool outside(const Particle& p, double xi) { return xi < p.patch_min() or xi > p.patch_max(); }

/// Normal of the plane spanned by N and a fibre's tangent t (where the
/// other fibre's point goes when this one stopped at its patch's end).
Eigen::Vector3d facing_plane_normal(const Eigen::Vector3d& t, const Eigen::Vector3d& N)
{
  const Eigen::Vector3d b = N.cross(t);
  if (!(b.norm() > 0))
    throw GeometryError("crossing contact: a fibre's tangent along the contact normal");
  return b.normalized();
}
} // namespace

GapFunction::GapFunction(const Particle& pi, const Particle& pj, const Eigen::Vector3d& N,
                         const GapMotion& motion, std::span<const double> xi,
                         std::span<const double> xj, double gap_offset, bool derivatives)
    : _pi(pi), _pj(pj), _N(N), _motion(motion), _xi(xi), _xj(xj),
      _off_j(dofs_per_node * pi.patch_nodes()),
      _n(dofs_per_node * (pi.patch_nodes() + pj.patch_nodes())),
      _w{pi.patch_xi(), pj.patch_xi()}
{
  if (xi.size() != dofs_per_node * std::size_t(pi.patch_nodes())
      or xj.size() != dofs_per_node * std::size_t(pj.patch_nodes()))
    throw std::invalid_argument("GapFunction: wrong nodal array size");
  Motion mo;
  Eigen::Vector3d t = Eigen::Vector3d::Zero(); // following: the section plane's normal
  if (motion.kind == GapKind::following)
  {
    // both points in one section plane, moved by equal and opposite lengths
    t = mean_tangent(motion.tangent_i.normalized(), motion.tangent_j.normalized());
    mo.free = {true, true};
    mo.A = t;
    mo.metric = true;
    // fibres running against each other: the same material direction on both
    const double along = motion.tangent_i.dot(motion.tangent_j) >= 0 ? 1.0 : -1.0;
    mo.B = Eigen::RowVector2d(motion.tangent_i.norm(), along * motion.tangent_j.norm());
    mo.w0 = _w;
    // a point may pass its patch's end: the line goes on straight (C1,
    // where a stop kinks the gap's gradient), the next pass puts it on its
    // own element; not past its fibre's end, where both stop
    const bool found = solve_points(mo, pi, pj, _w, xi, xj, N, 0.0);
    if (!found or pi.past_fibre_end(_w[0]) or pj.past_fibre_end(_w[1]))
    {
      _w = found ? std::array<double, 2>{std::clamp(_w[0], pi.patch_min(), pi.patch_max()),
                                         std::clamp(_w[1], pj.patch_min(), pj.patch_max())}
                 : mo.w0;
      mo.free = {false, false};
      mo.metric = false;
    }
  }
  else if (motion.kind == GapKind::facing)
  {
    // where the centre lines face each other, from the particles of the
    // pass (the same start at every evaluation: the gap is a function of
    // the unknowns alone)
    const Eigen::Vector3d e1 = N.unitOrthogonal(), e2 = N.cross(e1);
    mo.free = {true, true};
    mo.A.resize(3, 2);
    mo.A << e1, e2;
    if (!solve_points(mo, pi, pj, _w, xi, xj, N, facing_min_sine))
      mo.free = {false, false}; // no single facing point: as held
    // a point that would leave its patch stops at the patch's end
    const std::array<bool, 2> out{outside(pi, _w[0]), outside(pj, _w[1])};
    if (out[0] or out[1])
    {
      _w[0] = out[0] ? std::clamp(_w[0], pi.patch_min(), pi.patch_max()) : pi.patch_xi();
      _w[1] = out[1] ? std::clamp(_w[1], pj.patch_min(), pj.patch_max()) : pj.patch_xi();
      mo.free = {!out[0], !out[1]};
      if (mo.size() == 1)
      {
        mo.A = facing_plane_normal(out[0] ? motion.tangent_i.normalized()
                                          : motion.tangent_j.normalized(), N);
        if (!solve_points(mo, pi, pj, _w, xi, xj, N, 0.0) or outside(pi, _w[0])
            or outside(pj, _w[1]))
        {
          // the other point reached its patch's end too
          _w[0] = std::clamp(_w[0], pi.patch_min(), pi.patch_max());
          _w[1] = std::clamp(_w[1], pj.patch_min(), pj.patch_max());
          mo.free = {false, false};
        }
      }
    }
  }
  _free = mo.free;
  _A = mo.A;
  _B = mo.metric ? mo.B : Eigen::RowVector2d::Zero();

  const Side si(pi, _w[0], xi, N), sj(pj, _w[1], xj, N);
  const Eigen::Vector3d r = si.x - sj.x;
  double centre = N.dot(r);
  _grad_c = N;
  _separation = N.dot(r) + gap_offset;
  if (motion.kind == GapKind::following)
  {
    const Eigen::Vector3d Pr = r - t.dot(r) * t;
    // centre lines meeting in the plane: no direction there, measured along N
    if (Pr.norm() > 1e-12 * r.norm())
    {
      const double L = Pr.norm();
      centre = L;
      _grad_c = Pr / L;
      _hess_c = (Eigen::Matrix3d::Identity() - t * t.transpose()
                 - _grad_c * _grad_c.transpose())
                / L;
      _separation = N.dot(Pr) + gap_offset;
    }
  }
  _gap = centre + gap_offset - si.h - sj.h;
  if (!derivatives)
    return;
  _m = _grad_c;
  const int k = mo.size();
  if (k > 0)
  {
    // lambda = f_w^-T g_w on the moving coordinates w; m takes the part on
    // the rows A^T r (B's rows do not depend on q)
    const Eigen::MatrixXd Rw = mo.r_w(si, sj);
    const Eigen::MatrixXd fw = mo.f_w(si, sj);
    Eigen::VectorXd gw = Rw.transpose() * _grad_c;
    int col = 0;
    if (mo.free[0])
      gw(col++) -= si.h_u();
    if (mo.free[1])
      gw(col++) -= sj.h_u();
    const auto lu = fw.partialPivLu();
    const Eigen::VectorXd lambda = fw.transpose().partialPivLu().solve(gw);
    const int rows = static_cast<int>(mo.A.cols());
    _m = _grad_c - mo.A * lambda.head(rows);
    // w_q = -f_w^-1 f_q: f_q is A^T r_q on its first rows (r_q: n_a I on
    // fibre i's centroids, -n_b I on j's), 0 on B's
    Eigen::MatrixXd Fq = Eigen::MatrixXd::Zero(fw.rows(), 3);
    Fq.topRows(rows) = mo.A.transpose();
    const Eigen::MatrixXd JA = lu.solve(Fq);
    _wq = Eigen::MatrixXd::Zero(k, _n);
    for (int a = 0; a < si.num_nodes; ++a)
      _wq.block(0, dofs_per_node * a, k, 3) = -si.shape.n[a] * JA;
    for (int b = 0; b < sj.num_nodes; ++b)
      _wq.block(0, _off_j + dofs_per_node * b, k, 3) = sj.shape.n[b] * JA;
  }
  // dgap/dq = r_q^T m - h_q
  _G = Eigen::VectorXd::Zero(_n);
  for (int side = 0; side < 2; ++side)
  {
    const Side& s = side == 0 ? si : sj;
    const std::size_t offset = side == 0 ? 0 : _off_j;
    const double sign = side == 0 ? 1.0 : -1.0;
    const Eigen::Vector2d ch = s.unit_c();
    for (int a = 0; a < s.num_nodes; ++a)
    {
      _G.segment<3>(offset + dofs_per_node * a) += sign * s.shape.n[a] * _m;
      for (int al = 0; al < 2; ++al)
        _G.segment<3>(offset + dofs_per_node * a + 3 + 3 * al)
            -= s.radius * s.shape.n[a] * ch(al) * N;
    }
  }
}

void GapFunction::add_hessian(double scale, Eigen::Ref<RowMajor> K, bool motion) const
{
  if (_G.size() == 0)
    throw std::logic_error("GapFunction::add_hessian: built without derivatives");
  const Side si(_pi, _w[0], _xi, _N), sj(_pj, _w[1], _xj, _N);
  // L_qq: the supports' Hessian, and r_q^T (hess c) r_q on the centroids
  add_support_hessian(si, _N, scale, 0, K);
  add_support_hessian(sj, _N, scale, _off_j, K);
  std::array<std::pair<std::size_t, double>, 2 * max_patch_nodes> rows; // (offset, +-n_a)
  std::size_t count = 0;
  for (int a = 0; a < si.num_nodes; ++a)
    rows[count++] = {dofs_per_node * a, si.shape.n[a]};
  for (int b = 0; b < sj.num_nodes; ++b)
    rows[count++] = {_off_j + dofs_per_node * b, -sj.shape.n[b]};
  if (!_hess_c.isZero(0))
  {
    const Eigen::Matrix3d M = scale * _hess_c;
    for (std::size_t a = 0; a < count; ++a)
      for (std::size_t b = 0; b < count; ++b)
        K.block<3, 3>(rows[a].first, rows[b].first) += rows[a].second * rows[b].second * M;
  }
  const int k = static_cast<int>(_wq.rows());
  if (k == 0 or !motion)
    return;
  // L_qw (n x moving) and L_ww
  Motion mo;
  mo.free = _free;
  mo.A = _A;
  const Eigen::MatrixXd Rw = mo.r_w(si, sj);
  const Eigen::MatrixXd HRw = _hess_c * Rw; // 3 x k
  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(_n, k);
  for (std::size_t a = 0; a < count; ++a)
    Q.block(rows[a].first, 0, 3, k) += rows[a].second * HRw;
  Eigen::MatrixXd Lww = Rw.transpose() * HRw;
  int col = 0;
  for (int side = 0; side < 2; ++side)
  {
    if (!_free[side])
      continue;
    const Side& s = side == 0 ? si : sj;
    const std::size_t offset = side == 0 ? 0 : _off_j;
    const double sign = side == 0 ? 1.0 : -1.0;
    const Eigen::Vector2d ch = s.unit_c(), dch = s.d_unit_c();
    for (int a = 0; a < s.num_nodes; ++a)
    {
      // m . r_qw on the centroids, minus the supports' h_qw
      Q.block<3, 1>(offset + dofs_per_node * a, col) += sign * s.shape.dn[a] * _m;
      for (int al = 0; al < 2; ++al)
        Q.block<3, 1>(offset + dofs_per_node * a + 3 + 3 * al, col)
            -= s.radius * (s.shape.dn[a] * ch(al) + s.shape.n[a] * dch(al)) * _N;
    }
    // m . r_ww - h_ww (r_uu = x_i'', r_vv = -x_j'')
    Lww(col, col) += sign * _m.dot(s.ddx) - s.h_uu();
    ++col;
  }
  const Eigen::MatrixXd QW = Q * _wq;
  K += scale * (QW + QW.transpose() + _wq.transpose() * Lww * _wq);
}

} // namespace textile::contact
