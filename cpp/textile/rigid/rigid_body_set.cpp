#include "rigid_body_set.h"
#include "../assembly/petsc_error.h"

#include <array>
#include <stdexcept>

namespace textile::rigid
{
namespace
{
using assembly::check;

/// Unknowns of one coupling gathered from the local arrays, and its kernel output.
struct Local
{
  int m = 9;
  std::array<double, 9> q{}, lambda{}, scale{};
  std::array<double, 3> centre{}, theta{};
  std::vector<double> r, K;
};
} // namespace

template <typename Visit>
void RigidBodySet::each(std::span<const double> X, std::span<const double> u_fibre,
                        std::span<const double> u_body, std::span<const double> lambda,
                        bool tangent, Visit&& visit) const
{
  Local l;
  for (const auto& c : couplings)
  {
    l.m = c.base.rows();
    for (int k = 0; k < l.m; ++k)
    {
      const std::size_t i = 9 * static_cast<std::size_t>(c.node) + k;
      l.q[k] = X[i] + u_fibre[i];
      l.lambda[k] = lambda[c.multiplier + k];
      l.scale[k] = k < 3 ? c.scale_position : c.scale_section;
    }
    for (int k = 0; k < 3; ++k)
    {
      l.centre[k] = centres[c.body](k) + u_body[6 * c.body + k];
      l.theta[k] = u_body[6 * c.body + 3 + k];
    }
    const int n = 2 * l.m + 6;
    l.r.assign(n, 0.0);
    if (tangent)
      l.K.assign(n * n, 0.0);
    rigid_coupling(c.base, std::span(l.q).first(l.m), l.centre, l.theta,
                   std::span(l.lambda).first(l.m), std::span(l.scale).first(l.m), l.r,
                   tangent ? std::span<double>(l.K) : std::span<double>());
    visit(c, l);
  }
}

void RigidBodySet::assemble_vector(std::span<const double> X,
                                   std::span<const double> u_fibre,
                                   std::span<const double> u_body,
                                   std::span<const double> lambda, std::span<double> b_fibre,
                                   std::span<double> b_body, std::span<double> b_lambda) const
{
  each(X, u_fibre, u_body, lambda, false,
       [&](const Coupling& c, const Local& l)
       {
         for (int k = 0; k < l.m; ++k)
         {
           b_fibre[9 * static_cast<std::size_t>(c.node) + k] += l.r[k];
           b_lambda[c.multiplier + k] += l.r[l.m + 6 + k];
         }
         for (int k = 0; k < 6; ++k)
           b_body[6 * c.body + k] += l.r[l.m + k];
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
                                   std::span<const double> lambda,
                                   std::span<const std::int32_t> dofs_fibre,
                                   std::span<const std::int32_t> dofs_body,
                                   std::span<const std::int32_t> dofs_lambda) const
{
  std::vector<PetscInt> idx;
  each(X, u_fibre, u_body, lambda, true,
       [&](const Coupling& c, const Local& l)
       {
         idx.clear();
         for (int k = 0; k < l.m; ++k)
           idx.push_back(dofs_fibre[9 * static_cast<std::size_t>(c.node) + k]);
         for (int k = 0; k < 6; ++k)
           idx.push_back(dofs_body[6 * c.body + k]);
         for (int k = 0; k < l.m; ++k)
           idx.push_back(dofs_lambda[c.multiplier + k]);
         const auto n = static_cast<PetscInt>(idx.size());
         check(MatSetValuesLocal(A, n, idx.data(), n, idx.data(), l.K.data(), ADD_VALUES),
               "MatSetValuesLocal");
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
                                                  std::span<const double> lambda) const
{
  std::vector<BodyReaction> out(centres.size());
  each(X, u_fibre, u_body, lambda, false,
       [&](const Coupling& c, const Local& l)
       {
         // the body pushes the held unknowns with -s lambda (the coupling's
         // internal force on them is +s lambda); section-vector forces f_a
         // carry the moment g_a x f_a
         const Eigen::Vector3d centre(l.centre.data());
         auto& rb = out[c.body];
         for (int v = 0; v * 3 < l.m; ++v)
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
