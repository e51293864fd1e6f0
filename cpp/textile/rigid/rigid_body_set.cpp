#include "rigid_body_set.h"
#include "../assembly/petsc_error.h"

#include <array>
#include <stdexcept>

namespace textile::rigid
{
namespace
{
using assembly::check;

/// Unknowns of one coupling gathered from the local arrays, and its kernel
/// output: nq held unknowns, m constraint rows.
struct Local
{
  int nq = 9, m = 9;
  std::array<double, 9> q{}, lambda{}, scale{};
  std::array<double, 3> centre{}, theta{};
  std::vector<double> r, K;
};
} // namespace

template <typename Visit>
void RigidBodySet::each(std::span<const double> X, std::span<const double> u_fibre,
                        std::span<const double> u_body, std::span<const double> lambda,
                        BlockArrays block, bool tangent, Visit&& visit) const
{
  Local l;
  for (const auto& c : couplings)
  {
    l.nq = c.unknowns();
    l.m = c.rows();
    const bool fibre = c.holds == Holds::fibre;
    // fibre nodes carry 9 unknowns (positions = X + u), block nodes 3
    const std::size_t stride = fibre ? 9 : 3;
    const auto& Xq = fibre ? X : block.X;
    const auto& uq = fibre ? u_fibre : block.u;
    for (int k = 0; k < l.nq; ++k)
    {
      const std::size_t i = stride * static_cast<std::size_t>(c.node) + k;
      l.q[k] = Xq[i] + uq[i];
    }
    for (int k = 0; k < l.m; ++k)
    {
      l.lambda[k] = lambda[c.multiplier + k];
      const bool position = c.sliding.empty() ? k < 3 : c.sliding[k].vector == 0;
      l.scale[k] = position ? c.scale_position : c.scale_section;
    }
    for (int k = 0; k < 3; ++k)
    {
      l.centre[k] = centres[c.body](k) + u_body[6 * c.body + k];
      l.theta[k] = u_body[6 * c.body + 3 + k];
    }
    const int n = l.nq + 6 + l.m;
    l.r.assign(n, 0.0);
    if (tangent)
      l.K.assign(n * n, 0.0);
    const auto K = tangent ? std::span<double>(l.K) : std::span<double>();
    if (c.sliding.empty())
      rigid_coupling(c.base, std::span(l.q).first(l.nq), l.centre, l.theta,
                     std::span(l.lambda).first(l.m), std::span(l.scale).first(l.m), l.r, K);
    else
      sliding_coupling(c.base, c.sliding, std::span(l.q).first(l.nq), l.centre, l.theta,
                       std::span(l.lambda).first(l.m), std::span(l.scale).first(l.m), l.r, K);
    visit(c, l);
  }
}

void RigidBodySet::assemble_vector(std::span<const double> X,
                                   std::span<const double> u_fibre,
                                   std::span<const double> u_body,
                                   std::span<const double> lambda, BlockArrays block,
                                   std::span<double> b_fibre, std::span<double> b_body,
                                   std::span<double> b_lambda, std::span<double> b_block) const
{
  each(X, u_fibre, u_body, lambda, block, false,
       [&](const Coupling& c, const Local& l)
       {
         const bool fibre = c.holds == Holds::fibre;
         auto& bq = fibre ? b_fibre : b_block;
         const std::size_t stride = fibre ? 9 : 3;
         for (int k = 0; k < l.nq; ++k)
           bq[stride * static_cast<std::size_t>(c.node) + k] += l.r[k];
         for (int k = 0; k < l.m; ++k)
           b_lambda[c.multiplier + k] += l.r[l.nq + 6 + k];
         for (int k = 0; k < 6; ++k)
           b_body[6 * c.body + k] += l.r[l.nq + k];
       });
  // body loads live with the bodies' owner: the caller passes them only there
  for (std::size_t b = 0; b < forces.size(); ++b)
  {
    for (int k = 0; k < 3; ++k)
      b_body[6 * b + k] -= forces[b](k);
    if (moments[b].squaredNorm() > 0)
    {
      const Eigen::Vector3d& M = moments[b];
      std::array<double, 3> r{};
      body_moment(u_body.subspan(6 * b + 3, 3), std::span<const double>(M.data(), 3), r, {});
      for (int k = 0; k < 3; ++k)
        b_body[6 * b + 3 + k] += r[k];
    }
  }
}

void RigidBodySet::assemble_matrix(Mat A, std::span<const double> X,
                                   std::span<const double> u_fibre,
                                   std::span<const double> u_body,
                                   std::span<const double> lambda, BlockArrays block,
                                   std::span<const std::int32_t> dofs_fibre,
                                   std::span<const std::int32_t> dofs_body,
                                   std::span<const std::int32_t> dofs_lambda,
                                   std::span<const std::int32_t> dofs_block) const
{
  std::vector<PetscInt> idx;
  std::vector<double> rows;
  each(X, u_fibre, u_body, lambda, block, true,
       [&](const Coupling& c, const Local& l)
       {
         const bool fibre = c.holds == Holds::fibre;
         const auto& dq = fibre ? dofs_fibre : dofs_block;
         const std::size_t stride = fibre ? 9 : 3;
         idx.clear();
         for (int k = 0; k < l.nq; ++k)
           idx.push_back(dq[stride * static_cast<std::size_t>(c.node) + k]);
         for (int k = 0; k < 6; ++k)
           idx.push_back(dofs_body[6 * c.body + k]);
         for (int k = 0; k < l.m; ++k)
           idx.push_back(dofs_lambda[c.multiplier + k]);
         const int n = static_cast<int>(idx.size());
         // the q-q and lambda-lambda blocks are zero: insert the rest only,
         // so the sparsity needs no multiplier-multiplier or extra node-node
         // entries. Rows q: columns [u, theta, lambda]; rows body: all;
         // rows lambda: columns [q, u, theta].
         const int nb = l.nq + 6;
         rows.resize(static_cast<std::size_t>(n) * n);
         auto insert = [&](int r0, int nr, int c0, int nc)
         {
           for (int i = 0; i < nr; ++i)
             for (int j = 0; j < nc; ++j)
               rows[i * nc + j] = l.K[(r0 + i) * n + c0 + j];
           check(MatSetValuesLocal(A, nr, idx.data() + r0, nc, idx.data() + c0, rows.data(),
                                   ADD_VALUES),
                 "MatSetValuesLocal");
         };
         insert(0, l.nq, l.nq, n - l.nq);
         insert(l.nq, 6, 0, n);
         insert(nb, l.m, 0, nb);
       });
  for (std::size_t b = 0; b < moments.size(); ++b)
  {
    if (moments[b].squaredNorm() == 0)
      continue;
    const Eigen::Vector3d& M = moments[b];
    std::array<double, 3> r{};
    std::array<double, 9> K{};
    body_moment(u_body.subspan(6 * b + 3, 3), std::span<const double>(M.data(), 3), r, K);
    std::array<PetscInt, 3> i3;
    for (int k = 0; k < 3; ++k)
      i3[k] = dofs_body[6 * b + 3 + k];
    check(MatSetValuesLocal(A, 3, i3.data(), 3, i3.data(), K.data(), ADD_VALUES),
          "MatSetValuesLocal");
  }
}

std::vector<BodyReaction> RigidBodySet::reactions(std::span<const double> X,
                                                  std::span<const double> u_fibre,
                                                  std::span<const double> u_body,
                                                  std::span<const double> lambda,
                                                  BlockArrays block) const
{
  std::vector<BodyReaction> out(centres.size());
  each(X, u_fibre, u_body, lambda, block, false,
       [&](const Coupling& c, const Local& l)
       {
         // the body pushes the held unknowns with minus the coupling's
         // internal force on them; section-vector forces f_a carry the
         // moment g_a x f_a
         const Eigen::Vector3d centre(l.centre.data());
         auto& rb = out[c.body];
         for (int v = 0; v * 3 < l.nq; ++v)
         {
           Eigen::Vector3d f, x;
           for (int k = 0; k < 3; ++k)
           {
             f(k) = -l.r[3 * v + k];
             x(k) = l.q[3 * v + k];
           }
           if (v == 0)
           {
             rb.force += f;
             rb.moment += (x - centre).cross(f);
           }
           else
             rb.moment += x.cross(f);
         }
       });
  return out;
}

bool RigidBodySet::has_moments() const
{
  for (const auto& M : moments)
    if (M.squaredNorm() > 0)
      return true;
  return false;
}
} // namespace textile::rigid
