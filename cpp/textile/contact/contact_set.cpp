#include "contact_set.h"
#include "../assembly/petsc_error.h"
#include "regularized_penalty.h"

#include <stdexcept>
#include <string>

namespace textile::contact
{
namespace
{
using assembly::check;

/// Global dof indices of the element pair, [element i, element j].
std::vector<std::int32_t> element_dofs(const ContactElementState& e,
                                       std::span<const std::int32_t> dofs)
{
  std::vector<std::int32_t> idx;
  for (const auto* nodes : {&e.nodes_i, &e.nodes_j})
  {
    const int nn = (nodes == &e.nodes_i ? e.particle_i : e.particle_j).num_nodes;
    for (int a = 0; a < nn; ++a)
      for (int k = 0; k < 9; ++k)
        idx.push_back(dofs[9 * (*nodes)[a] + k]);
  }
  return idx;
}
} // namespace

void ContactSet::gather(const ContactElementState& e, std::span<const double> q,
                        std::vector<double>& xi, std::vector<double>& xj) const
{
  xi.clear();
  xj.clear();
  for (int a = 0; a < e.particle_i.num_nodes; ++a)
    for (int k = 0; k < 9; ++k)
      xi.push_back(q[9 * e.nodes_i[a] + k]);
  for (int a = 0; a < e.particle_j.num_nodes; ++a)
    for (int k = 0; k < 9; ++k)
      xj.push_back(q[9 * e.nodes_j[a] + k]);
}

ContactResult ContactSet::element(const ContactElementState& e, std::span<const double> q,
                                  std::vector<double>& r, std::vector<double>* K) const
{
  std::vector<double> xi, xj;
  gather(e, q, xi, xj);
  const std::size_t n = xi.size() + xj.size();
  r.assign(n, 0.0);
  if (K)
    K->assign(n * n, 0.0);
  // the element stands for `length` of contact: the per-length law times
  // its length (R_N and friction are linear in k)
  const RegularizedPenalty law(e.penalty * e.length, e.regularization);
  ContactResult res = contact_element(e.particle_i, e.particle_j, e.normal, law,
                                      e.friction.mu > 0 ? &e.friction : nullptr, e.stick, xi, xj,
                                      r, K ? std::span<double>(*K) : std::span<double>());
  return res;
}

void ContactSet::evaluate(std::span<const double> q)
{
  std::vector<double> r;
  for (auto& e : elements)
    e.result = element(e, q, r, nullptr);
}

void ContactSet::insert_pattern(Mat P, std::span<const std::int32_t> dofs, double margin) const
{
  std::vector<double> zeros;
  for (const auto& e : elements)
  {
    if (e.result.gap > margin)
      continue;
    auto idx = element_dofs(e, dofs);
    std::erase_if(idx, [](std::int32_t i) { return i < 0; });
    zeros.assign(idx.size() * idx.size(), 0.0);
    check(MatSetValues(P, static_cast<PetscInt>(idx.size()), idx.data(),
                       static_cast<PetscInt>(idx.size()), idx.data(), zeros.data(), INSERT_VALUES),
          "MatSetValues");
  }
}

std::vector<double> ContactSet::nodal_forces(std::span<const double> q) const
{
  std::vector<double> out(q.size(), 0.0), r;
  for (const auto& e : elements)
  {
    element(e, q, r, nullptr);
    std::size_t k = 0;
    for (const auto* nodes : {&e.nodes_i, &e.nodes_j})
    {
      const int nn = (nodes == &e.nodes_i ? e.particle_i : e.particle_j).num_nodes;
      for (int a = 0; a < nn; ++a)
        for (int d = 0; d < 9; ++d)
          out[9 * (*nodes)[a] + d] += r[k++];
    }
  }
  return out;
}

void ContactSet::assemble_vector(std::span<const double> q, std::span<const std::int32_t> dofs,
                                 Vec b)
{
  std::vector<double> r;
  for (auto& e : elements)
  {
    e.result = element(e, q, r, nullptr);
    if (e.result.normal_force == 0)
      continue; // open: nothing to add
    const auto idx = element_dofs(e, dofs);
    check(VecSetValues(b, static_cast<PetscInt>(idx.size()), idx.data(), r.data(), ADD_VALUES),
          "VecSetValues");
  }
}

void ContactSet::assemble_matrix(std::span<const double> q, std::span<const std::int32_t> dofs,
                                 Mat A) const
{
  std::vector<double> r, K;
  for (const auto& e : elements)
  {
    const auto res = element(e, q, r, &K);
    const std::size_t n = r.size();
    if (res.normal_force == 0) // open (R_N = 0 implies dR_N = 0 for this law)
      continue;
    const auto idx = element_dofs(e, dofs);
    check(MatSetValues(A, static_cast<PetscInt>(n), idx.data(), static_cast<PetscInt>(n),
                       idx.data(), K.data(), ADD_VALUES),
          "MatSetValues");
  }
}

Eigen::Vector3d ContactSet::elastic_slip(const ContactElementState& e) const
{
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - e.normal * e.normal.transpose();
  return P * (e.result.delta - e.stick);
}

std::size_t ContactSet::num_friction_histories() const
{
  std::size_t n = 0;
  for (const auto& e : elements)
    n += e.friction.mu > 0;
  return n;
}

void ContactSet::commit()
{
  for (auto& e : elements)
  {
    if (e.friction.mu <= 0)
      continue;
    if (e.result.normal_force > 0)
      e.stick = updated_stick(e.normal, e.friction, e.result.delta, e.stick);
    else
      e.stick = e.result.delta; // open: sliding starts from where contact begins
  }
}
} // namespace textile::contact
